//! `coin-log sweep`: runs a sweep file into a folder (or one shard of it), resumes it, previews it
//! (`--dry-run`) or merges the shards' catalogues (`collect`). The library does the work
//! (`coin_log::sweep`); this file reads the flags and the scheduler's environment, installs the signal
//! handler, draws the progress bar, prints, and maps the result to the exit code.

use super::rss::peak_rss_bytes;
use super::text::{counted, padded, size, COLUMN_MAX};
use super::Outcome;
use anyhow::Context;
use coin_log::files::shown;
use coin_log::sweep::{
    self, Preview, Progress, RunOptions, Shard, Sweep, SweepError, SweepOutcome,
};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Runs in the `--dry-run` table.
const PREVIEW_ROWS: usize = 10;
/// Sweeps shorter than this show no progress bar.
const PROGRESS_DELAY: Duration = Duration::from_secs(1);

/// Arguments of `coin-log sweep`.
///
/// Records every run of SWEEP.toml (a base scene and what varies: grid axes and random draws;
/// docs/format.md, Sweeps) into DIR as `run-<index>.mcap`, each byte for byte what `coin-log record` writes
/// for the same resolved scene, --jobs at once, verifies each file, and writes DIR/catalogue.csv (one row
/// per run: the swept values, how it ended, the verdict, the file's size and SHA-256, analyse's
/// prediction) and DIR/sweep.json. Run again on the same DIR, it resumes: only runs that are missing,
/// failed on I/O or whose file does not match its row are redone. A run that fails is a row with its
/// reason. With --shard K/N (or a Slurm job array's variables, or Kubernetes' JOB_COMPLETION_INDEX with
/// --shard-count) it makes only the runs whose index is K mod N and writes catalogue.part-K-of-N.csv;
/// `coin-log sweep collect DIR` then merges the parts.
///
/// Ctrl-C, SIGTERM or SIGHUP stops starting runs, discards the runs in progress (redone on resume),
/// writes the catalogue of what finished and exits 130; a second signal quits at once. Exit codes: 0
/// every run finished (and verified), 1 some failed, 2 a bad sweep file or usage, 130 interrupted.
///
/// `collect` is a subcommand: a sweep file named `collect` is given as `./collect`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SweepArgs {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    /// The sweep file (TOML).
    #[arg(required = true, value_name = "SWEEP.toml")]
    sweep: Option<PathBuf>,
    /// The folder for the runs' files and the catalogue: created if missing; otherwise empty, or holding
    /// this same sweep (then it resumes).
    #[arg(short, long, value_name = "DIR", required_unless_present = "dry_run")]
    output: Option<PathBuf>,
    /// Runs at once, on threads of this process [default: the cores available].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    jobs: Option<u16>,
    /// Make only shard K of N: the runs whose index is K mod N (K from 0 to N − 1) [default: from
    /// SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT (or _MIN/_MAX), or JOB_COMPLETION_INDEX with
    /// --shard-count; else every run].
    #[arg(long, value_name = "K/N", conflicts_with = "shard_count")]
    shard: Option<Shard>,
    /// The number of shards of a Kubernetes Indexed Job (its `completions`); K is JOB_COMPLETION_INDEX.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    shard_count: Option<u64>,
    /// Redo the runs that failed (by default only those that failed on I/O are redone: the others failed
    /// because of their values and would fail again).
    #[arg(long)]
    retry_failed: bool,
    /// Print the run count, the first runs' values and the estimated size and time; write nothing.
    #[arg(long)]
    dry_run: bool,
    /// Print the end-of-sweep summary (or the dry run) as one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, clap::Subcommand)]
enum SweepCommand {
    /// Merge the shards' catalogue parts of DIR into DIR/catalogue.csv and DIR/sweep.json.
    ///
    /// Checks that every run is in exactly one part and that every file matches its row (size and
    /// SHA-256, each file read once); names what is missing or wrong and writes nothing if anything is
    /// (exit 1). Exit 0 when the catalogue is written and every run finished, 1 when some failed, 2 when
    /// DIR holds no sweep.
    Collect(CollectArgs),
}

/// Arguments of `coin-log sweep collect`.
#[derive(Debug, clap::Args)]
struct CollectArgs {
    /// The sweep's folder, where the shards wrote their files and parts.
    #[arg(value_name = "DIR")]
    dir: PathBuf,
    /// Files hashed at once [default: the cores available].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    jobs: Option<u16>,
    /// Print the result as one JSON object.
    #[arg(long)]
    json: bool,
}

/// Runs `coin-log sweep`.
pub fn run(args: SweepArgs) -> anyhow::Result<Outcome> {
    if let Some(SweepCommand::Collect(c)) = &args.command {
        return collect(c);
    }
    let Some(path) = &args.sweep else {
        anyhow::bail!("give a SWEEP.toml to run, or `collect DIR`");
    };
    // First, so that a signal at any later stage stops the sweep cleanly rather than killing it.
    let running = Arc::new(AtomicBool::new(false));
    let stop = install_signals(Arc::clone(&running))?;
    let sweep = match Sweep::load(path) {
        Ok(sweep) => sweep,
        Err(e) => return Ok(bad_sweep(&e)),
    };
    let shard = match shard(&args) {
        Ok(shard) => shard,
        Err(e) => {
            errln!("error: {e}");
            return Ok(Outcome::Unusable);
        }
    };
    let jobs = jobs(args.jobs);
    warn_about_coverage(&sweep);
    if args.dry_run {
        return dry_run(&args, &sweep, shard, jobs);
    }
    let dir = args.output.clone().unwrap_or_default();
    let options = RunOptions {
        jobs,
        shard,
        retry_failed: args.retry_failed,
    };
    let started = Instant::now();
    let bar = Bar::new();
    running.store(true, Ordering::SeqCst);
    let result = sweep::run(&sweep, &dir, &options, &stop, &mut |p| bar.update(p));
    bar.finish();
    let outcome = match result {
        Ok(outcome) => outcome,
        Err(e @ SweepError::Folder { .. }) => return Ok(bad_sweep(&e)),
        Err(e) => return Err(e.into()),
    };
    print_outcome(&args, path, &dir, shard, jobs, &outcome, started.elapsed())?;
    Ok(if outcome.interrupted {
        Outcome::Interrupted
    } else if outcome.failed > 0 || outcome.pending > 0 {
        Outcome::Failure
    } else {
        Outcome::Success
    })
}

/// A sweep file or folder that cannot be used: the message, exit 2.
fn bad_sweep(e: &SweepError) -> Outcome {
    errln!("error: {e}");
    Outcome::Unusable
}

/// `--shard`, else the scheduler's environment, else every run.
fn shard(args: &SweepArgs) -> Result<Shard, sweep::ShardError> {
    if let Some(shard) = args.shard {
        return Ok(shard);
    }
    let from_environment = Shard::from_environment(|k| std::env::var(k).ok(), args.shard_count)?;
    // A task resubmitted alone (`sbatch --array=7`) is a one-task array, which is the whole sweep: it
    // would redo no shard 7 of 16 and write the catalogue instead of that shard's part, so collect
    // would still miss the part.
    let task = std::env::var("SLURM_ARRAY_TASK_ID").ok();
    let task = task.filter(|t| t.trim().parse::<u64>().is_ok_and(|t| t > 0));
    if let (Some(task), Some(shard)) = (task, from_environment) {
        if shard.is_all() {
            errln!(
                "warning: this job array has one task (SLURM_ARRAY_TASK_ID = {}), so it makes the whole \
                 sweep (shard 0/1) and writes catalogue.csv, not a part; to redo shard {0} of an array of \
                 N tasks, pass --shard {0}/N",
                task.trim()
            );
        }
    }
    Ok(from_environment.unwrap_or(Shard::ALL))
}

fn jobs(flag: Option<u16>) -> usize {
    flag.map_or_else(
        || std::thread::available_parallelism().map_or(1, std::num::NonZero::get),
        usize::from,
    )
}

/// Says once, before the runs, which required checks `verify` will not be able to run on the first run
/// whose scene is valid: with verification on, that run and every run like it would fail. (It names the
/// run: a swept rate or duration can leave the others judgeable.)
fn warn_about_coverage(sweep: &Sweep) {
    let first = (0..sweep.runs().min(sweep::SAMPLED_RUNS))
        .find_map(|i| Some((i, sweep.scene(&sweep.values(i).ok()?).ok()?)));
    if let (true, Some((i, scene))) = (sweep.settings.verify, first) {
        for warning in coin_log::verify::coverage(&scene) {
            errln!("warning: verify will not be able to judge run {i}'s recording (it and every run like it would fail): {warning}");
        }
    }
}

/// SIGINT, SIGTERM and SIGHUP: the first stops the sweep (runs in progress are discarded and redone on
/// resume, the catalogue of what finished is written); a second quits at once (temporary files are
/// cleaned up on resume). Before `running` is set (checking the sweep file, the coverage warning, a dry
/// run: each may resolve up to a thousand runs' scenes, a minute for bounded normal draws that seldom
/// land) nothing has been written, so the first quits at once.
fn install_signals(running: Arc<AtomicBool>) -> anyhow::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || {
        if !running.load(Ordering::SeqCst) {
            errln!("stopped before any run: nothing written");
            #[allow(
                clippy::disallowed_methods,
                reason = "no run has started and nothing is written yet: quitting leaves nothing behind"
            )]
            std::process::exit(130);
        }
        // Said over the progress bar, which is cleared first (the message once ran on from its line).
        let say = |message: &str| match DRAWN_BAR.get() {
            Some(bar) => bar.suspend(|| errln!("{message}")),
            None => errln!("{message}"),
        };
        if !flag.swap(true, Ordering::SeqCst) {
            say(
                "stopping: no new runs; the runs in progress are discarded (redone on resume) and the \
                 catalogue of what finished is written (signal again to quit at once)",
            );
            return;
        }
        say("stopped again: quitting at once; run the sweep again to resume it");
        #[allow(
            clippy::disallowed_methods,
            reason = "a second signal quits at once; no final name holds a half file, and resume removes the temporary ones"
        )]
        std::process::exit(130);
    })
    .context("cannot install the handler of SIGINT, SIGTERM and SIGHUP")?;
    Ok(stop)
}

/// The sweep's progress bar once it is drawn, for the signal handler to print over.
static DRAWN_BAR: std::sync::OnceLock<ProgressBar> = std::sync::OnceLock::new();

/// The progress bar: runs done of those to do, failed, ETA; on stderr when it is a terminal, after a
/// second.
struct Bar {
    bar: ProgressBar,
    started: Instant,
    terminal: bool,
    /// Whether the first failed run was reported.
    warned: std::cell::Cell<bool>,
}

impl Bar {
    fn new() -> Self {
        let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::hidden());
        if let Ok(style) =
            ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {msg}, {elapsed} (eta {eta})")
        {
            bar.set_style(style);
        }
        Self {
            bar,
            started: Instant::now(),
            terminal: std::io::stderr().is_terminal(),
            warned: std::cell::Cell::new(false),
        }
    }

    fn update(&self, p: &Progress) {
        if let Some((index, why)) = &p.first_failure {
            if !self.warned.replace(true) {
                // Above the bar, not through it.
                self.bar.suspend(|| errln!(
                    "warning: run {index} failed: {why}; runs like it will fail too: Ctrl-C stops the \
                     sweep and keeps what finished, and the catalogue gives each failed run's reason"
                ));
            }
        }
        if self.terminal && self.bar.is_hidden() && self.started.elapsed() > PROGRESS_DELAY {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            let _ = DRAWN_BAR.set(self.bar.clone());
        }
        self.bar.set_length(p.todo);
        self.bar.set_position(p.done);
        self.bar.set_message(format!("{} failed", p.failed));
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// The end-of-sweep summary on stdout: a table, or one JSON object.
fn print_outcome(
    args: &SweepArgs,
    path: &Path,
    dir: &Path,
    shard: Shard,
    jobs: usize,
    o: &SweepOutcome,
    wall: Duration,
) -> anyhow::Result<()> {
    if args.json {
        let json = serde_json::json!({
            "sweep": path.display().to_string(),
            "folder": dir.display().to_string(),
            "shard": shard.to_string(),
            "jobs": jobs,
            "runs": o.runs,
            "finished": o.finished,
            "failed": o.failed,
            "pending": o.pending,
            "kept": o.kept,
            "done": o.done,
            "interrupted": o.interrupted,
            "catalogue": o.catalogue.display().to_string(),
            "summary": o.summary.as_ref().map(|p| p.display().to_string()),
            "wall_time_s": wall.as_secs_f64(),
            "record_seconds": o.record_seconds,
            "verify_seconds": o.verify_seconds,
            "cpu_seconds": cpu_seconds(),
            "peak_rss_bytes": peak_rss_bytes(),
        });
        outln!("{}", serde_json::to_string(&json)?);
        return Ok(());
    }
    let of_shard = if shard.is_all() {
        String::new()
    } else {
        format!(" of shard {shard}")
    };
    let rows = [
        (
            "sweep",
            format!("{} ({}{of_shard})", shown(path), counted(o.runs, "run")),
        ),
        ("folder", shown(dir)),
        (
            "done now",
            format!("{} ({} kept from before)", o.done, o.kept),
        ),
        ("finished", o.finished.to_string()),
        ("failed", failed_text(o.failed)),
        ("pending", pending_text(o)),
        ("catalogue", shown(&o.catalogue)),
        (
            "wall time",
            format!(
                "{:.3} s with {} (recording {:.3} s, verifying {:.3} s, summed over the runs)",
                wall.as_secs_f64(),
                counted(jobs, "job"),
                o.record_seconds,
                o.verify_seconds
            ),
        ),
    ];
    for (key, value) in rows {
        outln!("{key:<10} {value}");
    }
    Ok(())
}

/// Clock ticks per second of `/proc`'s times (Linux's USER_HZ, fixed at 100 for user space).
const USER_HZ: f64 = 100.0;

/// The CPU time (user + system, all threads) this process used so far \[s\]; `None` where `/proc` does not
/// report it. With the wall time it says how many cores the sweep kept busy.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command name (which may hold spaces) start at its closing parenthesis:
    // utime and stime are fields 14 and 15, the 12th and 13th after it.
    let rest = &stat[stat.rfind(')')? + 1..];
    let mut fields = rest.split_whitespace().skip(11);
    let user: f64 = fields.next()?.parse().ok()?;
    let system: f64 = fields.next()?.parse().ok()?;
    Some((user + system) / USER_HZ)
}

fn failed_text(failed: u64) -> String {
    if failed == 0 {
        "0".to_string()
    } else {
        format!("{failed} (the catalogue's `failure` and `reason` columns say why)")
    }
}

fn pending_text(o: &SweepOutcome) -> String {
    match (o.pending, o.interrupted) {
        (0, _) => "0".to_string(),
        (n, true) => format!("{n} (interrupted: run the same command again to resume)"),
        (n, false) => n.to_string(),
    }
}

/// `--dry-run`: the count, the first rows, the estimate; nothing written.
fn dry_run(args: &SweepArgs, sweep: &Sweep, shard: Shard, jobs: usize) -> anyhow::Result<Outcome> {
    let p = sweep::preview(sweep, shard, PREVIEW_ROWS, jobs);
    let keys: Vec<&str> = sweep.keys().collect();
    if args.json {
        let first: Vec<serde_json::Value> = p
            .first
            .iter()
            .map(|(i, v)| {
                let values: serde_json::Map<String, serde_json::Value> = keys
                    .iter()
                    .zip(v)
                    .map(|(k, v)| ((*k).to_string(), v.as_str().into()))
                    .collect();
                serde_json::json!({"index": i, "values": values})
            })
            .collect();
        let json = serde_json::json!({
            "runs": p.runs,
            "shard": shard.to_string(),
            "keys": keys,
            "first": first,
            "sampled": p.sampled,
            "invalid": p.invalid,
            "first_invalid": p.first_invalid.as_ref().map(|(i, r)| serde_json::json!({"index": i, "reason": r})),
            "messages": p.messages,
            "estimated_bytes": p.bytes,
            "estimated_seconds": p.seconds,
        });
        outln!("{}", serde_json::to_string(&json)?);
        return Ok(Outcome::Success);
    }
    print_preview(sweep, shard, jobs, &keys, &p);
    Ok(Outcome::Success)
}

fn print_preview(sweep: &Sweep, shard: Shard, jobs: usize, keys: &[&str], p: &Preview) {
    let of_shard = if shard.is_all() {
        String::new()
    } else {
        format!(" in shard {shard}, of {}", sweep.runs())
    };
    outln!(
        "{}{of_shard}; swept keys: {}",
        counted(p.runs, "run"),
        if keys.is_empty() {
            "none".to_string()
        } else {
            keys.join(", ")
        }
    );
    let mut header = vec!["index".to_string()];
    header.extend(keys.iter().map(|k| (*k).to_string()));
    let mut table = vec![header];
    table.extend(p.first.iter().map(|(i, v)| {
        std::iter::once(i.to_string())
            .chain(v.iter().cloned())
            .collect()
    }));
    let widths: Vec<usize> = (0..table[0].len())
        .map(|c| {
            table
                .iter()
                .map(|r| r.get(c).map_or(0, |s| s.chars().count()))
                .max()
                .unwrap_or(0)
                .min(COLUMN_MAX)
        })
        .collect();
    for row in &table {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .map(|(c, w)| padded(c, *w))
            .collect();
        outln!("  {}", cells.join("  ").trim_end());
    }
    if p.runs > p.first.len() as u64 {
        outln!("  … ({} more)", p.runs - p.first.len() as u64);
    }
    // Runs without a valid scene make no file: of all 200 runs invalid, "0 B in 200 files" was said.
    let files = if p.invalid == 0 || p.sampled == 0 {
        counted(p.runs, "file")
    } else {
        #[allow(
            clippy::cast_precision_loss,
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss
        )] // an estimate, at most the runs
        let valid =
            (p.runs as f64 * (p.sampled - p.invalid) as f64 / p.sampled as f64).round() as u64;
        format!("about {} (runs with a valid scene)", counted(valid, "file"))
    };
    outln!(
        "estimate: {} messages, about {} in {files}, about {:.0} s with {} (a rough guide: {} messages/s per job)",
        p.messages,
        size(p.bytes),
        p.seconds.ceil(),
        counted(jobs, "job"),
        sweep::MESSAGES_PER_SECOND
    );
    if let Some((index, reason)) = &p.first_invalid {
        outln!(
            "invalid scenes: {} of the {} runs checked give no valid scene (failed rows); the first, run {index}: {reason}",
            p.invalid, p.sampled
        );
    }
    outln!("nothing written (--dry-run)");
}

/// `coin-log sweep collect DIR`.
fn collect(args: &CollectArgs) -> anyhow::Result<Outcome> {
    let collected = match sweep::collect(&args.dir, jobs(args.jobs)) {
        Ok(c) => c,
        Err(e @ SweepError::Folder { .. }) => return Ok(bad_sweep(&e)),
        Err(e) => return Err(e.into()),
    };
    for problem in &collected.problems {
        errln!("error: {}: {problem}", shown(&args.dir));
    }
    if args.json {
        let json = serde_json::json!({
            "folder": args.dir.display().to_string(),
            "runs": collected.runs,
            "parts": collected.parts,
            "finished": collected.finished,
            "failed": collected.failed,
            "problems": collected.problems,
            "catalogue": collected.written.as_ref().map(|(c, _)| c.display().to_string()),
            "summary": collected.written.as_ref().map(|(_, s)| s.display().to_string()),
        });
        outln!("{}", serde_json::to_string(&json)?);
    } else if let Some((catalogue, summary)) = &collected.written {
        outln!(
            "collected {} parts: {} runs, {} finished, {} failed\ncatalogue  {}\nsummary    {}",
            collected.parts.len(),
            collected.runs,
            collected.finished,
            collected.failed,
            catalogue.display(),
            summary.display()
        );
    } else {
        let n = collected.problems.len();
        let problems = if n == 1 { "problem" } else { "problems" };
        errln!(
            "error: {}: {n} {problems}; nothing written",
            args.dir.display()
        );
    }
    Ok(if collected.problems.is_empty() && collected.failed == 0 {
        Outcome::Success
    } else {
        Outcome::Failure
    })
}
