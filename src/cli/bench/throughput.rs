//! `coin-log bench throughput`: runs the record and verify workloads of
//! [`coin_log_bench::throughput`] in child processes of this binary (each in its own process, so that its
//! peak RSS is its own), reads their `--json` summaries, and has the library measure the compression
//! bound, turn the runs into rows and format them.

use super::{create_dir, write, POLICY};
use crate::cli::Outcome;
use anyhow::{anyhow, bail, Context};
use coin_log::files::output::check;
use coin_log::files::shown;
use coin_log::format::Encoding;
use coin_log_bench::throughput::{
    self, channel_list, compression_bound, recording_path, workload_scene, DurationRuns, ExportRun,
    RecordRun, ThroughputError, ThroughputReport, ThroughputRow, VerifyRun, RATE, SCENE,
};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::time::Instant;

/// Arguments of `coin-log bench throughput`.
#[derive(Debug, clap::Args)]
pub struct ThroughputArgs {
    /// Folder for `throughput.csv` and the recordings (created if missing; the recordings are deleted
    /// afterwards unless --keep).
    #[arg(long, default_value = "bench-results")]
    out: PathBuf,
    /// Timed repeats of every workload; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    repeats: u32,
    /// Measure at 1000 and 10000 time units (7 and 70 million messages) instead of 100 and 1000.
    #[arg(long, conflicts_with = "durations")]
    long: bool,
    /// Durations of the record and verify workloads, comma-separated [time units].
    #[arg(long, value_delimiter = ',', value_name = "T,...")]
    durations: Option<Vec<f64>>,
    /// Keep the recordings in the output folder.
    #[arg(long)]
    keep: bool,
    /// Message encoding of the recordings.
    #[arg(long, default_value_t, value_parser = crate::cli::named::<Encoding>())]
    encoding: Encoding,
}

/// Runs `coin-log bench throughput`: measure, clean up, print the table, write the CSV.
pub fn run(args: &ThroughputArgs) -> anyhow::Result<Outcome> {
    let durations = durations(args)?;
    create_dir(&args.out, &["throughput.csv".into()])?;
    // The recordings are the bench's own files, replaced and deleted afterwards: a link, pipe or device of
    // their names is refused now, before any work, and so never reaches the clean-up below.
    for d in &durations {
        check(&recording_path(&args.out, *d), &POLICY)?;
    }
    let exe = std::env::current_exe().context("locating the coin-log binary")?;
    install_signals()?;
    let result = measure(
        &exe,
        &args.out,
        &durations,
        args.repeats as usize,
        args.encoding,
    );
    if !args.keep {
        for d in &durations {
            let _ = fs::remove_file(recording_path(&args.out, *d));
        }
    }
    if STOP.load(Ordering::SeqCst) {
        let kept = if args.keep { "kept" } else { "removed" };
        errln!("interrupted: the recordings are {kept} and throughput.csv is not written");
        return Ok(Outcome::Interrupted);
    }
    let report = result?;
    outln!("cores available: {}", report.cores);
    out!("{}", throughput::table(&report));
    let csv_path = args.out.join("throughput.csv");
    write(&csv_path, &throughput::csv(&report))?;
    outln!("CSV: {}", shown(&csv_path));
    Ok(Outcome::Success)
}

/// The durations asked for, each positive and finite.
fn durations(args: &ThroughputArgs) -> anyhow::Result<Vec<f64>> {
    let durations = match (&args.durations, args.long) {
        (Some(d), _) => d.clone(),
        (None, true) => vec![1000.0, 10_000.0],
        (None, false) => vec![100.0, 1000.0],
    };
    if let Some(bad) = durations.iter().find(|d| !(d.is_finite() && **d > 0.0)) {
        bail!("--durations: `{bad}` is not a positive duration");
    }
    // A duration the workload cannot record is refused now, not by the first child `record` after the
    // others have run (with its flags in the message, and the duration in the recording's name).
    for &d in &durations {
        if let Err(ThroughputError::Workload { reason, .. }) = workload_scene(d) {
            bail!(
                "--durations: {d:?} time units cannot be measured by the workload ({SCENE} at {RATE} samples \
                 per time unit): {reason}"
            );
        }
    }
    Ok(durations)
}

/// Record, bound, verify and export at every duration.
fn measure(
    exe: &Path,
    dir: &Path,
    durations: &[f64],
    repeats: usize,
    encoding: Encoding,
) -> anyhow::Result<ThroughputReport> {
    let mut rows = Vec::new();
    for &duration in durations {
        rows.extend(record_and_verify(exe, dir, duration, repeats, encoding)?);
    }
    Ok(ThroughputReport::new(rows))
}

/// Record, bound and verify at one duration: `repeats` runs each, as rows of medians.
fn record_and_verify(
    exe: &Path,
    dir: &Path,
    duration: f64,
    repeats: usize,
    encoding: Encoding,
) -> anyhow::Result<Vec<ThroughputRow>> {
    let path = recording_path(dir, duration);
    let mut runs = DurationRuns {
        encoding,
        ..DurationRuns::new(duration)
    };
    for _ in 0..repeats.max(1) {
        runs.records
            .push(record_run(exe, &path, duration, encoding)?);
        runs.bounds.push(compression_bound(&path)?);
        runs.verifies.push(verify_run(exe, &path)?);
        runs.exports.push(export_run(exe, &path)?);
    }
    Ok(runs.rows()?)
}

/// Set by SIGINT, SIGTERM or SIGHUP: the child running is stopped as that signal stops it (a recording
/// is finished, then removed with the others) and no other starts. Before, a signal to this process
/// alone killed it and left its recordings, and its child running on.
static STOP: AtomicBool = AtomicBool::new(false);

/// The running child's process id (0: none), for the signal handler to pass the signal on.
static CHILD: AtomicU32 = AtomicU32::new(0);

/// The first signal stops the bench as [`STOP`] says; a second quits at once.
fn install_signals() -> anyhow::Result<()> {
    ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            errln!("stopped again: quitting at once; the recordings may be left in the output folder");
            #[allow(
                clippy::disallowed_methods,
                reason = "a second signal quits at once, as its message says"
            )]
            std::process::exit(130);
        }
        errln!(
            "stopping: the run in progress is stopped and the recordings are cleaned up (signal again \
             to quit at once)"
        );
        // The child is not reaped before CHILD is cleared, so the id is still its own.
        terminate(CHILD.load(Ordering::SeqCst));
    })
    .context("cannot install the handler of SIGINT, SIGTERM and SIGHUP")
}

/// Sends SIGTERM to process `pid` (none for 0).
fn terminate(pid: u32) {
    #[cfg(unix)]
    if let Ok(pid @ 1..) = i32::try_from(pid) {
        let pid = nix::unistd::Pid::from_raw(pid);
        let _ = nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGTERM);
    }
}

/// Runs a child `coin-log` and returns its parsed JSON stdout and wall time; it must exit 0.
#[allow(
    clippy::disallowed_methods,
    reason = "each measured run is its own process, for its own peak memory"
)]
fn child_json(exe: &Path, args: &[String]) -> anyhow::Result<(serde_json::Value, f64)> {
    let command = format!("{} {}", exe.display(), args.join(" "));
    if STOP.load(Ordering::SeqCst) {
        bail!("interrupted before `{command}`");
    }
    let start = Instant::now();
    let child = Command::new(exe)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| anyhow!("cannot run `{command}`: {e}"))?;
    CHILD.store(child.id(), Ordering::SeqCst);
    // A signal that came between the check above and the store is passed on here.
    if STOP.load(Ordering::SeqCst) {
        terminate(child.id());
    }
    let output = child.wait_with_output();
    CHILD.store(0, Ordering::SeqCst);
    let output = output.map_err(|e| anyhow!("cannot run `{command}`: {e}"))?;
    let wall = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        bail!("`{command}` exited with {}: {stderr}", output.status);
    }
    let json = serde_json::from_slice(&output.stdout)
        .map_err(|e| anyhow!("`{command}` printed no JSON ({e}): {stderr}"))?;
    Ok((json, wall))
}

/// Records the workload for `duration` time units into `path` in a child process.
fn record_run(
    exe: &Path,
    path: &Path,
    duration: f64,
    encoding: Encoding,
) -> anyhow::Result<RecordRun> {
    let args: Vec<String> = [
        "record",
        SCENE,
        "--duration",
        &duration.to_string(),
        "--rate",
        &RATE.to_string(),
        "--channels",
        &channel_list(),
        "--compression",
        "zstd",
        "--encoding",
        encoding.name(),
        "-o",
        &path.display().to_string(),
        "--overwrite",
        "--json",
    ]
    .iter()
    .map(ToString::to_string)
    .collect();
    let (json, _) = child_json(exe, &args)?;
    let command = format!("{} record", exe.display());
    let termination = json.get("termination").and_then(serde_json::Value::as_str);
    if termination != Some("completed") {
        bail!("`{command}` ended with termination {termination:?}, not completed");
    }
    let bad = |what: &str| anyhow!("`{command}` printed a summary without `{what}`: {json}");
    let u64_field = |key: &str| json.get(key).and_then(serde_json::Value::as_u64);
    Ok(RecordRun {
        messages: u64_field("messages").ok_or_else(|| bad("messages"))?,
        bytes: u64_field("bytes").ok_or_else(|| bad("bytes"))?,
        seconds: json
            .get("wall_time_s")
            .and_then(serde_json::Value::as_f64)
            .ok_or_else(|| bad("wall_time_s"))?,
        peak_rss: u64_field("peak_rss_bytes"),
    })
}

/// Exports `path` as CSV tables in a child process, into a new folder of a unique name beside it that is
/// removed afterwards (a folder of the user's is never written into nor removed).
fn export_run(exe: &Path, path: &Path) -> anyhow::Result<ExportRun> {
    let beside = path.parent().unwrap_or(Path::new("."));
    let scratch = tempfile::Builder::new()
        .prefix(".coin-log-export-")
        .tempdir_in(beside)
        .with_context(|| format!("cannot create a folder in `{}`", shown(beside)))?;
    let args = vec![
        "export".to_string(),
        path.display().to_string(),
        "--out".to_string(),
        scratch.path().display().to_string(),
        "--json".to_string(),
    ];
    let result = child_json(exe, &args);
    drop(scratch);
    let (json, seconds) = result?;
    Ok(ExportRun {
        seconds,
        peak_rss: json
            .get("peak_rss_bytes")
            .and_then(serde_json::Value::as_u64),
    })
}

/// Verifies `path` in a child process; the file must pass (exit 0).
fn verify_run(exe: &Path, path: &Path) -> anyhow::Result<VerifyRun> {
    let args = vec![
        "verify".to_string(),
        path.display().to_string(),
        "--json".to_string(),
    ];
    let (json, seconds) = child_json(exe, &args)?;
    let file = json.get("files").and_then(|f| f.get(0));
    Ok(VerifyRun {
        seconds,
        peak_rss: file
            .and_then(|f| f.get("peak_rss_bytes"))
            .and_then(serde_json::Value::as_u64),
    })
}
