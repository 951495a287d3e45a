//! `coin-log verify`: prints each file's checks as a table (or the contract's JSON) and maps the worst
//! verdict to the exit code.

use super::progress::FileProgress;
use super::rss::peak_rss_bytes;
use super::Outcome;
use coin_log::files::input::check;
use coin_log::files::{escaped, shown, InputKind};
use coin_log::verify::{self, FileReport, Options, Report, Verdict};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What `coin-log verify --help` adds after the options: the checks, the tolerance formula, exit codes.
const AFTER_HELP: &str = "\
Re-reads each log knowing nothing but the file: the body parameters come from its `coin-log` metadata
(found through the summary's metadata index wherever it sits, so files rewritten by other MCAP writers
verify too), the physics is recomputed from the stored channels (never re-simulated). Checks: integrity,
energy, invariants, steady, constraint, consistency, validity, nutation (period and heading advance per
nutation period against the quadrature); each reports its measured value, tolerance and pass/fail, or skip
with the reason it could not run.

Default tolerances, from the recorded integrator settings: with tau = sqrt(a/g), T the recorded span,
W = max(max|omega|, 1/tau) and eps = max(rtol, atol/a) for adaptive methods, or for fixed-step methods
of order p with step h (rk4, gauss4: p = 4) eps = (h W)^p (only the settings the method uses count):
  energy (and invariant) drift:   min(1e-6, max(1e-12, 100 eps (1 + T/tau))); the invariant one
                                  times max(1, sqrt(g/a)/(|C1_0| + |C2_0|))
  constraint and steady residual: min(1e-6, max(1e-10, 1000 eps (1 + T/tau)))
  nutation period and advance:    min(1e-6, max(1e-11, 100 eps)), plus the quadrature's and the
                                  interpolation's error estimates and the turning points' timing
                                  2 delta/(A sigma span), delta = 0.1 eps (1 + T/tau) W, A = max|omega_X|
Stored values recomputed from other stored values (energy, invariants, quaternion, contact, height,
reaction) must agree to 1e-12 relative; N >= 0 and |F| <= mu N are held to 1e-12 Mg.

Verdict per file, and exit codes:
  ok             every check that ran passed, and the required ones ran                  exit 0
  FAILED         a check failed                                                          exit 1
  CANNOT VERIFY  no check failed, but energy, or both constraint and steady, could not
                 run (channels not recorded, or a rate that does not resolve the motion) exit 1
  UNUSABLE       unreadable, truncated, corrupt, not MCAP or not a coin-log file         exit 2
Usage errors exit 2. With several files, the worst code (2 > 1 > 0). Why a file is unusable or cannot be
verified is printed once, on stderr (`error: FILE: reason`), and is the `problem` of its --json object.";

/// Arguments of `coin-log verify` (the checks and tolerance formula are in `AFTER_HELP`).
#[derive(Debug, clap::Args)]
#[command(after_help = AFTER_HELP)]
pub struct VerifyArgs {
    /// MCAP files written by `coin-log record`.
    #[arg(required = true, value_name = "FILE")]
    files: Vec<PathBuf>,
    /// Print `{"files": [{"path", "exit_code", "verdict", "problem", "checks": [{"id", "status", "value",
    /// "tolerance", "reason"}], "peak_rss_bytes"}]}`.
    #[arg(long)]
    json: bool,
    /// Energy (and invariant) drift tolerance, replacing the default derived from rtol/atol.
    #[arg(long, value_name = "X", value_parser = positive)]
    energy_tol: Option<f64>,
    /// Constraint and steady residual tolerance, replacing the default derived from rtol/atol.
    #[arg(long, value_name = "X", value_parser = positive)]
    residual_tol: Option<f64>,
}

fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("`{s}` is not a finite number > 0")),
    }
}

/// Runs `coin-log verify`.
pub fn run(args: VerifyArgs) -> anyhow::Result<Outcome> {
    let options = Options {
        energy_tol: args.energy_tol,
        residual_tol: args.residual_tol,
    };
    // One file at a time, so that each file's report carries the process's peak RSS after it.
    let mut report = Report { files: Vec::new() };
    let mut peaks = Vec::new();
    for path in &args.files {
        report.files.push(verify_with_progress(path, &options));
        peaks.push(peak_rss_bytes());
    }
    // The reason a file is unusable or cannot be verified goes to stderr, once, in both modes: stdout
    // stays the report alone (a table, or JSON that carries the reason as `problem`), and the line reads
    // like every other command's errors.
    for file in &report.files {
        if let Some(problem) = &file.problem {
            errln!("error: {}: {problem}", escaped(&file.path));
        }
    }
    if args.json {
        let files = report.files.iter().zip(peaks);
        let files = files.map(|(report, peak_rss_bytes)| FileJson {
            report,
            peak_rss_bytes,
        });
        super::output::json(&Json {
            files: files.collect(),
        })?;
    } else {
        out!("{}", table(&report));
        if report.files.len() > 1 {
            outln!("{}", total(&report));
        }
    }
    Ok(match report.exit_code() {
        0 => Outcome::Success,
        1 => Outcome::Failure,
        _ => Outcome::Unusable,
    })
}

/// Judges one file with a progress bar on stderr (a terminal only, after a second); a path that is not a
/// regular file is unusable without being opened (files::input).
fn verify_with_progress(path: &Path, options: &Options) -> FileReport {
    let len = match check(path, InputKind::Mcap) {
        Ok(meta) => meta.len(),
        Err(e) => return FileReport::unusable(path.display().to_string(), e.to_string()),
    };
    let progress = FileProgress::new(&shown(path), len);
    let report = verify::verify_file_with_progress(path, options, &|b| progress.update(b));
    progress.finish();
    report
}

/// The one-line total of several files: `N files: x ok, y failed, z unusable`.
fn total(report: &Report) -> String {
    let count = |v: Verdict| report.files.iter().filter(|f| f.verdict == v).count();
    format!(
        "{} files: {} ok, {} failed, {} cannot verify, {} unusable",
        report.files.len(),
        count(Verdict::Ok),
        count(Verdict::Failed),
        count(Verdict::CannotVerify),
        count(Verdict::Unusable)
    )
}

/// The contract's JSON plus `peak_rss_bytes` in each file object: the process's peak resident set size
/// (VmHWM) once that file was judged, `null` where the system does not report it.
#[derive(Serialize)]
struct Json<'a> {
    files: Vec<FileJson<'a>>,
}

#[derive(Serialize)]
struct FileJson<'a> {
    #[serde(flatten)]
    report: &'a FileReport,
    peak_rss_bytes: Option<u64>,
}

fn number(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), |v| format!("{v:.3e}"))
}

fn file_table(f: &FileReport, out: &mut String) {
    out.push_str(&format!(
        "{}: {} (exit {})\n",
        escaped(&f.path),
        f.verdict.label(),
        f.exit_code
    ));
    if f.checks.is_empty() {
        return;
    }
    out.push_str(&format!(
        "  {:<12} {:<6} {:>10} {:>10}  {}\n",
        "check", "status", "value", "tolerance", "reason"
    ));
    for c in &f.checks {
        out.push_str(&format!(
            "  {:<12} {:<6} {:>10} {:>10}  {}\n",
            c.id.name(),
            c.status.to_string(),
            number(c.value),
            number(c.tolerance),
            c.reason
        ));
    }
}

fn table(report: &Report) -> String {
    let mut out = String::new();
    for f in &report.files {
        file_table(f, &mut out);
    }
    out
}
