//! `coin-log bench sweep`: what a sweep costs beyond its runs (README.md, Sweeps). Each measurement is a
//! child `coin-log sweep --json` of this binary (each in its own process, so that its peak RSS is its
//! own), read back from its summary:
//! - speed: 200 short runs with `--jobs 1` and `--jobs 2`, alternating, medians of `--repeats`; the speed-up
//!   and the cost per run besides recording and verifying it (wall time − the recording and verifying
//!   seconds, over the runs, at `--jobs 1`);
//! - memory: peak RSS and catalogue size of 1000 and 10 000 tiny runs;
//! - resume: a finished 1000-run sweep run again (nothing to do), the child's whole wall time.

use super::{create_dir, write};
use crate::cli::Outcome;
use anyhow::{anyhow, bail, Context};
use coin_log_bench::throughput::{self, Target, ThroughputReport, ThroughputRow};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Runs of the speed workload.
const SPEED_RUNS: usize = 200;
/// Run counts of the memory workload.
const MEMORY_RUNS: [usize; 2] = [1000, 10_000];
/// Runs of the resume workload (the smaller memory sweep, finished).
const RESUME_RUNS: usize = 1000;

/// Arguments of `coin-log bench sweep`.
#[derive(Debug, clap::Args)]
pub struct SweepBenchArgs {
    /// Folder for `sweep.csv` and the sweeps (created if missing; the sweeps are deleted afterwards
    /// unless --keep).
    #[arg(long, default_value = "bench-results")]
    out: PathBuf,
    /// Timed repeats of the speed and resume workloads; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    repeats: u32,
    /// Keep the sweeps' folders in the output folder.
    #[arg(long)]
    keep: bool,
}

/// A sweep file of `runs` runs of `wobble` over θ₀, each `duration` time units long.
fn sweep_text(runs: usize, duration: f64) -> String {
    format!(
        "base = \"wobble\"\nset = {{ \"run.duration\" = {duration:?} }}\n[[axis]]\nkey = \"initial.theta\"\nlinspace = [0.1, 0.9, {runs}]\n"
    )
}

/// What one child sweep reported.
struct SweepRun {
    /// The summary's `wall_time_s` (the sweep itself, after loading).
    wall: f64,
    /// The child process's wall time, start to exit.
    process: f64,
    record: f64,
    verify: f64,
    /// CPU time of the child, all threads (NaN where not reported).
    cpu: f64,
    peak_rss: f64,
}

/// Runs `coin-log sweep FILE -o DIR --jobs N --json` and reads its summary; every run must finish.
#[allow(
    clippy::disallowed_methods,
    reason = "each measured sweep is its own process, for its own peak memory and a cold start"
)]
fn sweep(exe: &Path, file: &Path, dir: &Path, jobs: usize) -> anyhow::Result<SweepRun> {
    let command = format!(
        "{} sweep {} -o {} --jobs {jobs}",
        exe.display(),
        file.display(),
        dir.display()
    );
    let start = Instant::now();
    let mut child = Command::new(exe);
    // Never a shard of the scheduler's, if the bench runs inside a job array.
    for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"] {
        child.env_remove(v);
    }
    let output = child
        .args([
            "sweep",
            &file.display().to_string(),
            "-o",
            &dir.display().to_string(),
            "--jobs",
            &jobs.to_string(),
            "--json",
        ])
        .output()
        .map_err(|e| anyhow!("cannot run `{command}`: {e}"))?;
    let process = start.elapsed().as_secs_f64();
    if !output.status.success() {
        bail!(
            "`{command}` exited with {}: {}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let json: serde_json::Value = serde_json::from_slice(&output.stdout)
        .with_context(|| format!("`{command}` printed no JSON"))?;
    let number = |key: &str| {
        json.get(key)
            .and_then(serde_json::Value::as_f64)
            .ok_or_else(|| anyhow!("`{command}`: no `{key}` in {json}"))
    };
    #[allow(clippy::cast_precision_loss)]
    let peak_rss = json
        .get("peak_rss_bytes")
        .and_then(serde_json::Value::as_u64)
        .map_or(f64::NAN, |b| b as f64);
    Ok(SweepRun {
        wall: number("wall_time_s")?,
        process,
        record: number("record_seconds")?,
        verify: number("verify_seconds")?,
        cpu: json
            .get("cpu_seconds")
            .and_then(serde_json::Value::as_f64)
            .unwrap_or(f64::NAN),
        peak_rss,
    })
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

fn row(
    workload: &str,
    quantity: &str,
    value: f64,
    unit: &str,
    target: Option<Target>,
    note: String,
) -> ThroughputRow {
    ThroughputRow {
        workload: workload.into(),
        quantity: quantity.into(),
        value,
        unit: unit.into(),
        target,
        note,
    }
}

/// Runs `coin-log bench sweep`: measure, clean up, print the table, write the CSV.
pub fn run(args: &SweepBenchArgs) -> anyhow::Result<Outcome> {
    create_dir(&args.out, &["sweep.csv".into()])?;
    let exe = std::env::current_exe().context("locating the coin-log binary")?;
    let work = args.out.join("sweep-bench");
    refuse_foreign(&work)?;
    let _ = fs::remove_dir_all(&work);
    create_dir(&work, &[])?;
    let result = measure(&exe, &work, args.repeats as usize);
    if !args.keep {
        let _ = fs::remove_dir_all(&work);
    }
    let report = ThroughputReport::new(result?);
    outln!("cores available: {}", report.cores);
    out!("{}", throughput::table(&report));
    let csv_path = args.out.join("sweep.csv");
    write(&csv_path, &throughput::csv(&report))?;
    outln!("CSV: {}", coin_log::files::shown(&csv_path));
    Ok(Outcome::Success)
}

/// The entries the bench writes in its folder (speed workload, memory and resume workloads, and the
/// temporary files of its sweep files).
fn is_benchs_own(name: &str) -> bool {
    let stem = name.strip_suffix(".toml").unwrap_or(name);
    name.starts_with(".coin-log-")
        || stem == "speed"
        || [1, 2].iter().any(|jobs| name == format!("speed-{jobs}"))
        || MEMORY_RUNS
            .iter()
            .any(|runs| stem == format!("memory-{runs}"))
}

/// The bench deletes its folder before and after its work: anything else of that name (a sweep of the
/// user's, a link, a file) is refused before any work, never deleted.
fn refuse_foreign(work: &Path) -> anyhow::Result<()> {
    let shown = coin_log::files::shown(work);
    let foreign = match fs::symlink_metadata(work) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(anyhow!("cannot look at `{shown}`: {e}")),
        Ok(meta) if !meta.is_dir() => Some("it is not a folder".to_string()),
        Ok(_) => fs::read_dir(work)
            .with_context(|| format!("cannot read the folder `{shown}`"))?
            .filter_map(Result::ok)
            .map(|entry| entry.file_name().to_string_lossy().into_owned())
            .find(|name| !is_benchs_own(name))
            .map(|name| {
                format!(
                    "it holds `{}`, which the bench did not write",
                    coin_log::files::shown_name(&name)
                )
            }),
    };
    match foreign {
        None => Ok(()),
        Some(why) => bail!(
            "`{shown}` is the folder bench sweep works in and deletes, but {why}: move it away, or choose \
             another folder with --out"
        ),
    }
}

fn measure(exe: &Path, work: &Path, repeats: usize) -> anyhow::Result<Vec<ThroughputRow>> {
    let mut rows = speed(exe, work, repeats)?;
    rows.extend(memory_and_resume(exe, work, repeats)?);
    Ok(rows)
}

/// The speed workload's runs: `--jobs 1` and `--jobs 2` alternating (which goes first alternates too),
/// each in a fresh folder.
fn alternate(
    exe: &Path,
    work: &Path,
    repeats: usize,
) -> anyhow::Result<(Vec<SweepRun>, Vec<SweepRun>)> {
    let file = work.join("speed.toml");
    write(&file, &sweep_text(SPEED_RUNS, 2.0))?;
    let (mut one, mut two) = (Vec::new(), Vec::new());
    for r in 0..repeats {
        let order = if r % 2 == 0 { [1, 2] } else { [2, 1] };
        for jobs in order {
            let dir = work.join(format!("speed-{jobs}"));
            let _ = fs::remove_dir_all(&dir);
            let run = sweep(exe, &file, &dir, jobs)?;
            if jobs == 1 {
                one.push(run)
            } else {
                two.push(run)
            }
        }
    }
    Ok((one, two))
}

/// The speed workload: wall times, speed-up, cores kept busy, and the sweep's own cost per run.
#[allow(clippy::cast_precision_loss)]
fn speed(exe: &Path, work: &Path, repeats: usize) -> anyhow::Result<Vec<ThroughputRow>> {
    let (one, two) = alternate(exe, work, repeats)?;
    let n = SPEED_RUNS as f64;
    let workload = format!("sweep {SPEED_RUNS} runs of wobble, 2 u @ 100/u, verified");
    let wall = |runs: &[SweepRun]| median(runs.iter().map(|r| r.wall).collect());
    let (w1, w2) = (wall(&one), wall(&two));
    let overhead = median(
        one.iter()
            .map(|r| (r.wall - r.record - r.verify) / n)
            .collect(),
    );
    let work_per_run = median(one.iter().map(|r| (r.record + r.verify) / n).collect());
    let busy = |runs: &[SweepRun]| median(runs.iter().map(|r| r.cpu / r.process).collect());
    let note = |text: &str| text.to_string();
    let rows = [
        (
            "wall time, --jobs 1",
            w1,
            "s",
            None,
            format!("{repeats} repeats, alternating with --jobs 2"),
        ),
        ("wall time, --jobs 2", w2, "s", None, String::new()),
        (
            "speed-up --jobs 2 / --jobs 1",
            w1 / w2,
            "",
            Some(Target::AtLeast(1.8)),
            note("2 cores"),
        ),
        (
            "cores kept busy, --jobs 1",
            busy(&one),
            "",
            None,
            note("CPU time / wall time of the process"),
        ),
        (
            "cores kept busy, --jobs 2",
            busy(&two),
            "",
            None,
            note("each recording also runs a compression thread"),
        ),
        (
            "recording + verifying per run",
            work_per_run,
            "s",
            None,
            note("--jobs 1"),
        ),
        (
            "sweep's own cost per run",
            overhead,
            "s",
            Some(Target::Below(5e-3)),
            note("wall − recording − verifying, over the runs, --jobs 1"),
        ),
    ];
    Ok(rows
        .into_iter()
        .map(|(quantity, value, unit, target, note)| {
            row(&workload, quantity, value, unit, target, note)
        })
        .collect())
}

/// The memory workload (tiny runs: what grows with the run count) and the resume of the finished
/// 1000-run sweep.
#[allow(clippy::cast_precision_loss)]
fn memory_and_resume(
    exe: &Path,
    work: &Path,
    repeats: usize,
) -> anyhow::Result<Vec<ThroughputRow>> {
    let mut rows = Vec::new();
    for runs in MEMORY_RUNS {
        let file = work.join(format!("memory-{runs}.toml"));
        write(&file, &sweep_text(runs, 0.2))?;
        let dir = work.join(format!("memory-{runs}"));
        let run = sweep(exe, &file, &dir, 2)?;
        let workload = format!("sweep {runs} runs of wobble, 0.2 u, --jobs 2");
        let catalogue =
            fs::metadata(dir.join("catalogue.csv")).map_or(f64::NAN, |m| m.len() as f64);
        rows.push(row(
            &workload,
            "peak RSS",
            run.peak_rss,
            "B",
            None,
            String::new(),
        ));
        rows.push(row(
            &workload,
            "catalogue.csv",
            catalogue,
            "B",
            None,
            format!("{:.0} B per row", catalogue / runs as f64),
        ));
        rows.push(row(
            &workload,
            "wall time",
            run.wall,
            "s",
            None,
            format!("{:.2} ms per run", run.wall / runs as f64 * 1e3),
        ));
        if runs == RESUME_RUNS {
            let resumes: Vec<SweepRun> = (0..repeats)
                .map(|_| sweep(exe, &file, &dir, 2))
                .collect::<anyhow::Result<_>>()?;
            let workload = format!("resume a finished {runs}-run sweep (nothing to do)");
            rows.push(row(
                &workload,
                "wall time, whole process",
                median(resumes.iter().map(|r| r.process).collect()),
                "s",
                Some(Target::Below(2.0)),
                "no file re-hashed: sizes and times prove them unchanged".into(),
            ));
            rows.push(row(
                &workload,
                "wall time, the sweep",
                median(resumes.iter().map(|r| r.wall).collect()),
                "s",
                None,
                "after loading the sweep file".into(),
            ));
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::{is_benchs_own, refuse_foreign};

    /// A folder kept by `--keep` (or left by an interrupted bench) is the bench's own and is replaced; a
    /// sweep of the user's under that name is not.
    #[test]
    fn the_benchs_own_folder_is_told_from_a_users() {
        for name in [
            "speed.toml",
            "speed-1",
            "speed-2",
            "memory-1000.toml",
            "memory-1000",
            "memory-10000.toml",
            "memory-10000",
            ".coin-log-Ab12Cd.toml.tmp",
        ] {
            assert!(is_benchs_own(name), "{name}");
        }
        for name in [
            "my-dataset",
            "catalogue.csv",
            "speed-3",
            "memory-5",
            "speedy",
            "memory.toml",
        ] {
            assert!(!is_benchs_own(name), "{name}");
        }
        let dir = tempfile::tempdir().unwrap();
        let work = dir.path().join("sweep-bench");
        refuse_foreign(&work).unwrap();
        std::fs::create_dir_all(work.join("speed-1")).unwrap();
        std::fs::write(work.join("memory-1000.toml"), "").unwrap();
        refuse_foreign(&work).unwrap();
        std::fs::create_dir(work.join("mine")).unwrap();
        let e = refuse_foreign(&work).unwrap_err().to_string();
        assert!(
            e.contains("it holds `mine`, which the bench did not write"),
            "{e}"
        );
    }
}
