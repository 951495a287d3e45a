//! `coin-log record`: load a scene, integrate it into a temporary file beside the target, move the finished
//! file into place without clobbering, print the summary. The library does the work; this file does paths,
//! signals, the progress bar, printing and exit codes.

use super::rss::peak_rss_bytes;
use super::Outcome;
use anyhow::{anyhow, bail, Context};
use coin_log::format::Termination;
use coin_log::record::{self, Compression, RecordOptions, RecordSummary};
use coin_log::scene::{self, presets, FlagOverrides, Scene, SceneFile};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{BufWriter, IsTerminal};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tempfile::NamedTempFile;

/// Runs shorter than this show no progress bar.
const PROGRESS_DELAY: Duration = Duration::from_secs(1);
/// Resolution of the progress bar.
const PROGRESS_STEPS: u64 = 1000;
/// Write buffer in front of the file: the mcap writer issues many small writes.
const WRITE_BUFFER: usize = 1 << 20;

/// Arguments of `coin-log record`.
///
/// Integrates SCENE and writes its trajectory as an MCAP file. The file is written to a temporary file
/// beside the target and moved into place only when finished; an existing file is never replaced without
/// `--overwrite`. A physical event (flat landing, lift-off, slip) ends the run normally (exit 0); a
/// numerical failure leaves the file finished up to it (exit 1); Ctrl-C finishes the file with what was
/// recorded, marked `interrupted` (exit 130).
#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    /// A built-in scene (listed by `coin-log scenes`) or a path to a `.toml` scene file.
    scene: String,
    /// Output file [default: <scene name or file stem>.mcap in the current folder].
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Duration in the scene's time unit (overrides `run.duration`).
    #[arg(long, value_name = "T")]
    duration: Option<f64>,
    /// Samples per time unit (overrides `run.rate`; scene default 100).
    #[arg(long, value_name = "R")]
    rate: Option<f64>,
    /// Integrator: rk4, dopri5, dop853, gauss4 (overrides `run.integrator`; scene default dop853).
    #[arg(long, value_name = "NAME")]
    integrator: Option<String>,
    /// Relative tolerance of adaptive methods (overrides `run.rtol`; scene default 1e-10).
    #[arg(long, value_name = "X")]
    rtol: Option<f64>,
    /// Absolute tolerance of adaptive methods (overrides `run.atol`; scene default 1e-12).
    #[arg(long, value_name = "X")]
    atol: Option<f64>,
    /// Step of fixed-step methods, rounded down to divide 1/rate (overrides `run.step`; default 1e-3).
    #[arg(long, value_name = "H")]
    step: Option<f64>,
    /// Comma-separated channels: omega, angles, quaternion, position, contact, reaction, energy,
    /// invariants, tf, scene (overrides `record.channels`; default all).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    channels: Option<Vec<String>>,
    /// Chunk compression.
    #[arg(long, value_enum, default_value_t = CompressionArg::Zstd)]
    compression: CompressionArg,
    /// Set a scene key before the flags above apply: KEY is a dotted path (`initial.theta`, `run.rtol`,
    /// `body.shape`), VALUE a TOML value or a bare string. Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Replace FILE if it exists.
    #[arg(long)]
    overwrite: bool,
    /// Print the end-of-run summary as one JSON object.
    #[arg(long)]
    json: bool,
}

/// `--compression`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum CompressionArg {
    /// zstd, level 1 (faster and smaller than level 3 on these JSON chunks).
    Zstd,
    /// lz4.
    Lz4,
    /// No compression.
    None,
}

impl From<CompressionArg> for Compression {
    fn from(c: CompressionArg) -> Self {
        match c {
            CompressionArg::Zstd => Compression::Zstd,
            CompressionArg::Lz4 => Compression::Lz4,
            CompressionArg::None => Compression::None,
        }
    }
}

/// Where a scene came from: its name in messages and its default output stem.
struct SceneSource {
    label: String,
    stem: String,
    file: SceneFile,
}

fn load_source(arg: &str, sets: &[String]) -> anyhow::Result<SceneSource> {
    if let Some(preset) = presets::preset(arg) {
        let file =
            scene::file_with_sets(&preset, sets).map_err(|e| anyhow!("scene `{arg}`: {e}"))?;
        return Ok(SceneSource {
            label: arg.to_string(),
            stem: arg.to_string(),
            file,
        });
    }
    let path = Path::new(arg);
    if !path.exists() && !arg.ends_with(".toml") && !arg.contains(std::path::MAIN_SEPARATOR) {
        bail!(
            "no built-in scene `{arg}` and no such file; built-in scenes: {}",
            presets::NAMES.join(", ")
        );
    }
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read scene file `{}`", path.display()))?;
    let file = scene::parse_with_sets(&text, sets).map_err(|e| anyhow!("scene `{arg}`: {e}"))?;
    let stem = path
        .file_stem()
        .map_or_else(|| "scene".to_string(), |s| s.to_string_lossy().into_owned());
    Ok(SceneSource {
        label: arg.to_string(),
        stem,
        file,
    })
}

/// Runs `coin-log record`: load → resolve → prepare the output → record → persist → summary and exit code.
pub fn run(args: RecordArgs) -> anyhow::Result<Outcome> {
    let source = load_source(&args.scene, &args.set)?;
    let scene = resolve(&args, &source)?;
    // Before simulating: say which required checks `verify` will not be able to run on this recording.
    for warning in coin_log::verify::coverage(&scene) {
        eprintln!("warning: verify will not be able to judge this recording: {warning}");
    }
    let target = output_path(&args, &source)?;
    let mut temp = temp_file_beside(&target)?;
    let (summary, wall) = record_into(&args, &scene, &target, &mut temp)?;
    persist(temp, &target, args.overwrite)?;
    print_summary(&args, &scene, &source.label, &target, &summary, wall)?;
    Ok(outcome(&summary, &target))
}

/// The scene with the command-line flags applied and validated.
fn resolve(args: &RecordArgs, source: &SceneSource) -> anyhow::Result<Scene> {
    let flags = FlagOverrides {
        duration: args.duration,
        rate: args.rate,
        integrator: args.integrator.clone(),
        rtol: args.rtol,
        atol: args.atol,
        step: args.step,
        channels: args.channels.clone(),
    };
    scene::resolve(&source.file, &flags).map_err(|e| anyhow!("scene `{}`: {e}", source.label))
}

/// Where the recording goes (`-o`, or the scene's stem in the current folder): never a folder, and an
/// existing file only with `--overwrite`.
fn output_path(args: &RecordArgs, source: &SceneSource) -> anyhow::Result<PathBuf> {
    let target = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.mcap", source.stem)));
    if target.is_dir() {
        bail!(
            "`{}` is a folder; give the recording a file name, e.g. -o {}",
            target.display(),
            target.join(format!("{}.mcap", source.stem)).display()
        );
    }
    if target.exists() && !args.overwrite {
        bail!(
            "`{}` already exists; pass --overwrite to replace it, or choose another file with -o",
            target.display()
        );
    }
    Ok(target)
}

/// A temporary file in the target's folder, so that the finished recording is moved, not copied.
fn temp_file_beside(target: &Path) -> anyhow::Result<NamedTempFile> {
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    tempfile::Builder::new()
        .prefix(".coin-log-")
        .suffix(".mcap.tmp")
        .tempfile_in(&folder)
        .with_context(|| {
            format!(
                "cannot write in `{}` (for `{}`)",
                folder.display(),
                target.display()
            )
        })
}

/// Records the scene into `temp` with Ctrl-C finishing the file early and a progress bar on long runs;
/// returns the summary and the wall time, the file synced to disk and readable.
fn record_into(
    args: &RecordArgs,
    scene: &Scene,
    target: &Path,
    temp: &mut NamedTempFile,
) -> anyhow::Result<(RecordSummary, Duration)> {
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = Arc::clone(&stop);
        ctrlc::set_handler(move || stop.store(true, Ordering::Relaxed))
            .context("cannot install the Ctrl-C handler")?;
    }

    let options = RecordOptions {
        compression: args.compression.into(),
    };
    let bar = progress_bar();
    let started = Instant::now();
    let duration = scene.run.duration;
    let result = record::record(
        scene,
        &options,
        BufWriter::with_capacity(WRITE_BUFFER, temp.as_file_mut()),
        &stop,
        |t| update_progress(&bar, started, t / duration),
    );
    bar.finish_and_clear();
    let summary = result.with_context(|| format!("recording `{}`", target.display()))?;
    temp.as_file()
        .sync_all()
        .with_context(|| format!("writing `{}`", target.display()))?;
    let wall = started.elapsed();
    make_readable(temp.as_file());
    Ok((summary, wall))
}

/// Moves the finished recording into place; without `--overwrite` a file that appeared meanwhile is left
/// alone and the recording kept under its temporary name.
fn persist(temp: NamedTempFile, target: &Path, overwrite: bool) -> anyhow::Result<()> {
    if overwrite {
        temp.persist(target).map_err(|e| {
            anyhow!(
                "cannot move the recording to `{}`: {}",
                target.display(),
                e.error
            )
        })?;
    } else if let Err(e) = temp.persist_noclobber(target) {
        // The target appeared while we were recording: keep our file rather than lose it.
        let kept = e.file.keep().map(|(_, p)| p);
        let kept = kept.map_or_else(|_| "(lost)".to_string(), |p| p.display().to_string());
        bail!(
            "`{}` appeared while recording and was left alone; the recording is kept at `{kept}`",
            target.display()
        );
    }
    Ok(())
}

/// The exit code of a finished recording; a numerical failure says where the samples stop.
fn outcome(summary: &RecordSummary, target: &Path) -> Outcome {
    match &summary.failure {
        Some(f) => {
            eprintln!(
                "error: the integration failed at t = {}: {f}; `{}` holds the samples up to it",
                summary.termination_time,
                target.display()
            );
            Outcome::Failure
        }
        None if summary.termination == Termination::Interrupted => Outcome::Interrupted,
        None => Outcome::Success,
    }
}

/// A bar that stays hidden for the first second and when stderr is not a terminal.
fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(PROGRESS_STEPS), ProgressDrawTarget::hidden());
    if let Ok(style) = ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed} (eta {eta})")
    {
        bar.set_style(style);
    }
    bar
}

fn update_progress(bar: &ProgressBar, started: Instant, fraction: f64) {
    if bar.is_hidden() && started.elapsed() > PROGRESS_DELAY && std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::stderr());
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    bar.set_position((fraction.clamp(0.0, 1.0) * PROGRESS_STEPS as f64) as u64);
}

/// Temporary files are created owner-only; a recording is an ordinary file.
fn make_readable(file: &std::fs::File) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = file.set_permissions(std::fs::Permissions::from_mode(0o644));
    }
    #[cfg(not(unix))]
    let _ = file;
}

#[allow(clippy::cast_precision_loss)]
fn print_summary(
    args: &RecordArgs,
    scene: &Scene,
    label: &str,
    target: &Path,
    s: &RecordSummary,
    wall: Duration,
) -> anyhow::Result<()> {
    let seconds = wall.as_secs_f64();
    let rate = if seconds > 0.0 {
        s.messages as f64 / seconds
    } else {
        0.0
    };
    if args.json {
        let json = serde_json::json!({
            "scene": label,
            "file": target.display().to_string(),
            "samples": s.samples,
            "messages": s.messages,
            "bytes": s.bytes,
            "wall_time_s": seconds,
            "messages_per_second": rate,
            "integrator": scene.run.method.method.name(),
            "steps": s.stats.steps,
            "rhs_evaluations": s.stats.rhs_evaluations,
            "rejected_steps": s.stats.rejected_steps,
            "energy_drift": s.energy_drift,
            "invariant_drift": s.invariant_drift,
            "steady_residual": s.steady_residual,
            "termination": s.termination.name(),
            "termination_time": s.termination_time,
            "peak_rss_bytes": peak_rss_bytes(),
        });
        println!("{}", serde_json::to_string(&json)?);
        return Ok(());
    }
    let mut rows: Vec<(&str, String)> = vec![
        ("scene", label.to_string()),
        ("file", format!("{} ({})", target.display(), size(s.bytes))),
        ("samples", s.samples.to_string()),
        ("messages", s.messages.to_string()),
        (
            "wall time",
            format!("{seconds:.3} s ({:.0} messages/s)", rate),
        ),
        (
            "integrator",
            format!(
                "{}: {} steps, {} RHS evaluations, {} rejected",
                scene.run.method.method.name(),
                s.stats.steps,
                s.stats.rhs_evaluations,
                s.stats.rejected_steps
            ),
        ),
        ("energy drift", format!("{:.3e}", s.energy_drift)),
    ];
    if let Some(d) = s.invariant_drift {
        rows.push(("C1/C2 drift", format!("{d:.3e}")));
    }
    if let Some(r) = s.steady_residual {
        rows.push(("steady residual", format!("{r:.3e}")));
    }
    rows.push((
        "termination",
        format!("{} at t = {}", s.termination.name(), s.termination_time),
    ));
    for (key, value) in rows {
        println!("{key:<16} {value}");
    }
    Ok(())
}

#[allow(clippy::cast_precision_loss)]
fn size(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 20 => format!("{:.1} MiB", b as f64 / f64::from(1 << 20)),
        b if b >= 1 << 10 => format!("{:.1} KiB", b as f64 / f64::from(1 << 10)),
        b => format!("{b} B"),
    }
}
