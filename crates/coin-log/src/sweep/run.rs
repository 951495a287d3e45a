//! Running a sweep (format.md: Running a sweep): the runs still to do (resume), `jobs` of them at once on
//! threads of this process, each recorded to a temporary file, hashed, verified and moved into place, its
//! row journalled as it finishes; then the catalogue (or this shard's part) and, for a whole sweep,
//! `sweep.json`.

use super::catalogue::{consistent, FailureKind, Prediction, Recorded, Row, RunStatus};
use super::definition::{self, RunSceneError, Sweep};
use super::error::SweepError;
use super::folder::{self, Folder, JournalRow};
use super::hash::sha256_file;
use super::shard::Shard;
use crate::analyse::{motion_name, Analysis};
use crate::format::{promise, Termination};
use crate::model::nutation::Motion;
use crate::record::{self, RecordSummary};
use crate::scene::Scene;
use crate::verify::{self, CheckId, FileReport, Status, Verdict};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Write buffer in front of each run's file (as `record`'s: the writer issues many small writes).
const WRITE_BUFFER: usize = 1 << 20;

/// How to run a sweep: `jobs` runs at once (threads, ≥ 1), the `shard`'s runs, and whether to redo failed
/// runs on resume (`retry_failed`; runs that failed for a reason other than I/O are kept otherwise: their
/// failure is a property of their values).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub struct RunOptions {
    pub jobs: usize,
    pub shard: Shard,
    pub retry_failed: bool,
}

/// Where a sweep stands, after each run: of this shard's `runs`, the `todo` ones of this invocation (the
/// rest were done before) and the `done` ones of those so far; the shard's rows `failed` so far (kept and
/// new).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
#[allow(missing_docs)]
pub struct Progress {
    pub runs: u64,
    pub todo: u64,
    pub done: u64,
    pub failed: u64,
    /// The first run this invocation saw fail: its index and its row's reason, led by the `failure` kind,
    /// so that a front end can say so while the runs like it are still ahead.
    pub first_failure: Option<(u64, String)>,
}

/// How a sweep invocation ended: of this shard's `runs`, the rows `finished` and `failed` and the runs
/// `pending` without a row (interrupted, or not started); the rows `kept` from an earlier invocation
/// (resume) and the runs `done` now (finished or failed); the seconds spent recording and verifying,
/// summed over the runs done now.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub struct SweepOutcome {
    pub runs: u64,
    pub finished: u64,
    pub failed: u64,
    pub pending: u64,
    pub kept: u64,
    pub done: u64,
    /// Whether a stop request ended it early: with runs left without a row (one that came after the
    /// last run ended nothing early, and exited 130, so that `afterok` skipped collect).
    pub interrupted: bool,
    /// The catalogue written (`catalogue.csv`, or this shard's part).
    pub catalogue: PathBuf,
    /// `sweep.json`, for a whole sweep.
    pub summary: Option<PathBuf>,
    pub record_seconds: f64,
    pub verify_seconds: f64,
}

/// A run done, as a worker hands it over (none for a run a stop ended: it is redone on resume).
struct Done {
    row: Row,
    spent: Spent,
}

/// A run's file: its modification time once in place, and the seconds spent recording and verifying it
/// (all 0 without a file).
#[derive(Default)]
struct Spent {
    mtime_ns: u128,
    record_seconds: f64,
    verify_seconds: f64,
}

/// What resume found: the lines to keep and how many of them are failed rows, and kept rows whose file
/// was touched but not changed (to journal again with the new modification time). The runs to do are
/// the shard's others.
#[derive(Default)]
struct Resumed {
    held: BTreeMap<u64, String>,
    failed: u64,
    refreshed: Vec<(u128, String)>,
}

/// Runs `sweep` into the folder `dir` (or resumes it there). `stop` set (by a signal handler) stops
/// starting runs and ends the running recordings early; their files are discarded and the runs redone on
/// resume. The sweep sets `stop` itself when it cannot write its journal. `progress` is called as runs
/// end, on the calling thread. A run that fails is a row, not an error.
pub fn run(
    sweep: &Sweep,
    dir: &std::path::Path,
    options: &RunOptions,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&Progress),
) -> Result<SweepOutcome, SweepError> {
    let folder = Folder::open(dir, sweep)?;
    let _lock = folder.lock(options.shard)?;
    folder.check_outputs(options.shard)?;
    let resumed = resume(sweep, &folder, options)?;
    folder.remove_stale_temps(options.shard);
    let mut journal = folder.journal(options.shard)?;
    journal.append(&resumed.refreshed)?;
    let shard = options.shard;
    let runs = shard.len(sweep.runs());
    // The kept runs, to skip: as many as rows journalled, never a list of every run.
    let kept: Vec<u64> = resumed.held.keys().copied().collect();
    let mut tally = Tally {
        kept: resumed.held.len() as u64,
        held: resumed.held,
        progress: Progress {
            runs,
            todo: runs - kept.len() as u64,
            failed: resumed.failed,
            ..Progress::default()
        },
        record_seconds: 0.0,
        verify_seconds: 0.0,
    };
    progress(&tally.progress);
    let mut error = None;
    let work = |position: u64| {
        let index = shard.index() + position * shard.count();
        let todo = kept.binary_search(&index).is_err();
        todo.then(|| run_one(sweep, &folder, index, stop)).flatten()
    };
    super::on_threads(runs, options.jobs, stop, work, |batch| {
        let lines: Vec<(u128, String)> = batch
            .iter()
            .map(|d| (d.spent.mtime_ns, d.row.line()))
            .collect();
        if let Err(e) = journal.append(&lines) {
            stop.store(true, Ordering::SeqCst);
            error.get_or_insert(e);
            return;
        }
        for (done, (_, line)) in batch.into_iter().zip(lines) {
            tally.add(&done, line);
        }
        progress(&tally.progress);
    });
    if let Some(e) = error {
        return Err(e);
    }
    tally.finish(&folder, options.shard, stop)
}

/// The lines held for the catalogue and the counts, as the runs come in.
struct Tally {
    held: BTreeMap<u64, String>,
    progress: Progress,
    kept: u64,
    record_seconds: f64,
    verify_seconds: f64,
}

impl Tally {
    fn add(&mut self, done: &Done, line: String) {
        self.record_seconds += done.spent.record_seconds;
        self.verify_seconds += done.spent.verify_seconds;
        self.progress.done += 1;
        let row = &done.row;
        if let (Some(failure), None) = (row.failure, &self.progress.first_failure) {
            let why = if row.reason.starts_with(failure.name()) {
                row.reason.clone()
            } else {
                format!("{}: {}", failure.name(), row.reason)
            };
            self.progress.first_failure = Some((row.index, why));
        }
        self.progress.failed += u64::from(row.status == RunStatus::Failed);
        self.held.insert(done.row.index, line);
    }

    /// Writes the catalogue (or the shard's part) in index order and, for a whole sweep, `sweep.json`.
    fn finish(
        self,
        folder: &Folder,
        shard: Shard,
        stop: &AtomicBool,
    ) -> Result<SweepOutcome, SweepError> {
        let lines = self.held.values();
        let (runs, rows) = (self.progress.runs, self.held.len() as u64);
        let failed = self.progress.failed;
        let counts @ [finished, _, pending] = [rows - failed, failed, runs - rows];
        let (catalogue, summary) = if shard.is_all() {
            let (catalogue, summary) = folder.write_whole(lines, counts)?;
            (catalogue, Some(summary))
        } else {
            (
                folder.write_catalogue(&folder::PART.name(shard), lines)?,
                None,
            )
        };
        Ok(SweepOutcome {
            runs,
            finished,
            failed,
            pending,
            kept: self.kept,
            done: self.progress.done,
            interrupted: stop.load(Ordering::SeqCst) && pending > 0,
            catalogue,
            summary,
            record_seconds: self.record_seconds,
            verify_seconds: self.verify_seconds,
        })
    }
}

/// The rows to keep from the journals and the runs to do. A row is kept when it holds its run's values
/// and its file is there with the size and modification time it was journalled with, or, if only the
/// time differs, with the same SHA-256; a failed row is kept unless it failed on I/O or `retry_failed`
/// is set.
fn resume(sweep: &Sweep, folder: &Folder, options: &RunOptions) -> Result<Resumed, SweepError> {
    let [status_at, failure_at, file_at, bytes_at, sha_at, verify_at] =
        ["status", "failure", "file", "bytes", "sha256", "verify"].map(|c| folder.column(c));
    let verifies = Some(sweep.settings.verify);
    let mut latest: BTreeMap<u64, JournalRow> = BTreeMap::new();
    for row in folder.journal_rows()? {
        if row.index < sweep.runs() && options.shard.takes(row.index) {
            latest.insert(row.index, row);
        }
    }
    let mut resumed = Resumed::default();
    let keys = sweep.keys().count();
    // Only the journalled runs: every other run of the shard is to do (a shard of 10⁹ runs is not
    // walked run by run before the first starts).
    for (index, row) in latest {
        let f = &row.fields;
        let Ok(status) = f[status_at].parse::<RunStatus>() else {
            continue;
        };
        let retry = status == RunStatus::Failed
            && (options.retry_failed || f[failure_at] == FailureKind::Io.name());
        // A row holds its own run's values (one of another sweep with the same keys, its journal copied
        // in, is redone).
        if f.get(1..=keys) != Some(&sweep.cells(index)[..]) {
            continue;
        }
        // And is one a run writes (a finished row without its file was kept, with nothing to check).
        let cells = [status_at, failure_at, file_at, verify_at].map(|at| f[at].as_str());
        if !consistent(cells, verifies) {
            continue;
        }
        // A row names its own run's file or none (one naming another's, an edited index, is redone).
        let own = folder.run_file_name(index);
        let file_ok = f[file_at].is_empty()
            || f[file_at] == own && {
                let path = folder.file(&f[file_at]);
                match folder::size_and_mtime(&path) {
                    Some((size, _)) if size.to_string() != f[bytes_at] => false,
                    Some((_, mtime)) if mtime == row.mtime_ns => true,
                    Some((_, mtime)) => {
                        let same = sha256_file(&path).is_ok_and(|(sha, _)| sha == f[sha_at]);
                        if same {
                            resumed.refreshed.push((mtime, crate::csv::line(f)));
                        }
                        same
                    }
                    None => false,
                }
            };
        if !retry && file_ok {
            resumed.failed += u64::from(status == RunStatus::Failed);
            resumed.held.insert(index, crate::csv::line(f));
        }
    }
    Ok(resumed)
}

/// One run: values → scene → record into a temporary file → hash → verify → move into place → row.
fn run_one(sweep: &Sweep, folder: &Folder, index: u64, stop: &AtomicBool) -> Option<Done> {
    let started = Instant::now();
    let values = sweep.values(index);
    let cells = definition::cells(&values, sweep.keys().count());
    let mut done = Done {
        row: Row::failed(index, cells, FailureKind::Scene),
        spent: Spent::default(),
    };
    let row = &mut done.row;
    let scene = values
        .map_err(RunSceneError::from)
        .and_then(|v| sweep.scene(&v));
    match scene {
        Err(e) => row.reason = e.to_string(),
        Ok(scene) => {
            let prediction = sweep.settings.predict.then(|| predict(&scene)).flatten();
            match record_and_check(sweep, folder, &scene, stop, row) {
                Ok(None) => return None,
                Ok(Some(spent)) => (row.prediction, done.spent) = (prediction, spent),
                Err(e) => (row.failure, row.reason) = (Some(FailureKind::Io), e),
            }
        }
    }
    done.row.wall_time = started.elapsed().as_secs_f64();
    Some(done)
}

/// Records `row`'s run into a temporary file, syncs, hashes and verifies it, moves it to its name and
/// judges it into `row`; `None` when a stop request interrupted it (the temporary file is deleted).
fn record_and_check(
    sweep: &Sweep,
    folder: &Folder,
    scene: &Scene,
    stop: &AtomicBool,
    row: &mut Row,
) -> Result<Option<Spent>, String> {
    let name = folder.run_file_name(row.index);
    let target = folder.file(&name);
    let io = |what: &str| {
        let what = format!("{what} `{name}`");
        move |e: std::io::Error| format!("{what}: {e}")
    };
    // Refused after the whole run otherwise (the rename fails).
    if let Some(attribute) = crate::files::Attribute::of(&target) {
        let (attribute, clear) = attribute.words();
        return Err(format!(
            "`{name}` is {attribute}, so the system lets no recording replace it: clear the attribute ({clear} {name}) and run again"
        ));
    }
    let mut temp = folder::temp_file(&target).map_err(io("creating a temporary file for"))?;
    let started = Instant::now();
    let writer = BufWriter::with_capacity(WRITE_BUFFER, temp.as_file_mut());
    let summary = record::record(scene, &sweep.record_options(), writer, stop, |_| {})
        .map_err(|e| error_chain(&e))?;
    if summary.termination == Termination::Interrupted {
        return Ok(None);
    }
    temp.as_file().sync_all().map_err(io("writing"))?;
    crate::files::make_readable(temp.as_file());
    let record_seconds = started.elapsed().as_secs_f64();
    let (sha256, _) = sha256_file(temp.path()).map_err(io("reading back"))?;
    let started = Instant::now();
    let report = sweep
        .settings
        .verify
        .then(|| verify::verify_file(temp.path(), &verify::Options::default()));
    let verify_seconds = started.elapsed().as_secs_f64();
    crate::files::absent_or_plain(&target).map_err(io("moving the recording to"))?;
    temp.persist(&target)
        .map_err(|e| io("moving the recording to")(e.error))?;
    let (_, mtime_ns) = folder::size_and_mtime(&target)
        .ok_or_else(|| format!("`{name}` vanished once moved into place"))?;
    (row.status, row.failure, row.reason) = judge(&summary, report.as_ref());
    row.recorded = Some(Recorded {
        file: name,
        sha256,
        summary,
        verify: report.as_ref().map(|r| r.verdict),
    });
    Ok(Some(Spent {
        mtime_ns,
        record_seconds,
        verify_seconds,
    }))
}

/// An error with its causes: `writing the MCAP file failed: No space left on device`.
fn error_chain(e: &dyn std::error::Error) -> String {
    let chain = std::iter::successors(Some(e), |e| e.source());
    let texts: Vec<String> = chain.map(ToString::to_string).collect();
    texts.join(": ")
}

/// Finished, or failed with the kind and reason: a numerical failure first, then a verdict other than ok.
fn judge(
    s: &RecordSummary,
    report: Option<&FileReport>,
) -> (RunStatus, Option<FailureKind>, String) {
    if let Some(f) = &s.failure {
        let reason = format!(
            "{} at t = {}: {f}",
            s.termination.name(),
            s.termination_time
        );
        return (RunStatus::Failed, Some(FailureKind::Numerical), reason);
    }
    match report {
        Some(r) if r.verdict != Verdict::Ok => {
            let mut reason = verify_reason(r);
            let expected = promise::check_list(&s.shortfalls, ", ");
            if !expected.is_empty() {
                // What record warns of before the run: a dataset's reader sees it beside the failure.
                reason.push_str(&format!(
                    "; record expected it: its settings allow more error than verify accepts in {expected} (tighten rtol/atol, or step)"
                ));
            }
            (RunStatus::Failed, Some(FailureKind::Verify), reason)
        }
        _ => (RunStatus::Finished, None, String::new()),
    }
}

/// `verify: failed: energy 1.2e-5 > 3.1e-7, ...`, or the problem of a file that cannot be verified.
fn verify_reason(r: &FileReport) -> String {
    let failing: Vec<String> = r
        .checks
        .iter()
        .filter(|c| c.status == Status::Fail)
        .map(|c| match (c.value, c.tolerance) {
            (Some(v), Some(t)) => format!("{} {v:.3e} > {t:.3e}", c.id),
            _ => c.id.to_string(),
        })
        .collect();
    let failing = (!failing.is_empty()).then(|| failing.join(", "));
    let verdict = format!("verify: {}", r.verdict.name());
    // The problem of a file that cannot be verified defers to "each check's reason": the catalogue has
    // no other place for them, so the skipped required checks' reasons (what to record) follow it.
    let cannot = r.verdict == Verdict::CannotVerify;
    let skipped: Vec<String> = (r.checks.iter())
        .filter(|c| cannot && c.status == Status::Skip && CheckId::REQUIRED.contains(&c.id))
        .map(|c| format!("{} skipped: {}", c.id, c.reason))
        .collect();
    let skipped = (!skipped.is_empty()).then(|| skipped.join("; "));
    let parts = [Some(verdict), failing, r.problem.clone(), skipped];
    parts.into_iter().flatten().collect::<Vec<_>>().join(": ")
}

/// What the quadrature predicts for a conservative scene (format.md: The catalogue, predicted_*).
fn predict(scene: &Scene) -> Option<Prediction> {
    if scene.dissipation.is_some() {
        return None;
    }
    let a = Analysis::of_scene(scene).ok()?;
    let duration = scene.run.duration;
    let lift_off = a.orbit.lift_off.map(|e| e.time).filter(|&t| t <= duration);
    let landing = match a.orbit.motion {
        Motion::FlatLanding { time, .. } if time <= duration => Some(time),
        _ => None,
    };
    let needs_more =
        a.slips() == Some(true) && (a.orbit.max_friction_ratio.is_some() || lift_off.is_some());
    let termination = match (lift_off, landing) {
        _ if needs_more => Termination::Slip,
        (Some(l), Some(f)) if f < l => Termination::FlatLanding,
        (Some(_), _) => Termination::LiftOff,
        (None, Some(_)) => Termination::FlatLanding,
        (None, None) => Termination::Completed,
    };
    let stability = a
        .steady
        .as_ref()
        .or(a.base_steady.as_ref())
        .map(|s| s.verdict.name());
    Some(Prediction {
        motion: motion_name(&a.orbit.motion),
        stability,
        termination,
    })
}
