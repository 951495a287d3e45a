//! `coin-log verify`: judge a stored log from the file alone (format.md: verify).
//!
//! The parameters come from the file's `coin-log` metadata; the physics is recomputed from the stored
//! channels, never re-simulated. The file is read once, as a stream ([`coin_log_mcap::read`]), in memory
//! bounded by its largest record: messages are parsed into their strict types, grouped by log time into
//! samples ([`samples`]), and each check keeps running maxima and a short window ([`checks`]). Tolerances
//! follow from the recorded integrator settings ([`tolerances`]).

pub mod checks;
mod coverage;
mod file;
pub mod report;
pub mod samples;
pub mod tolerances;

pub use coverage::coverage;
pub use report::{CheckId, CheckResult, FileReport, Report, Status, Verdict};
pub use tolerances::Tolerances;

use std::path::Path;

/// Tolerance overrides (`--energy-tol`, `--residual-tol`); `None` keeps the derived defaults.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Options {
    /// Energy drift tolerance (and invariant drift).
    pub energy_tol: Option<f64>,
    /// Constraint and steady residual tolerance.
    pub residual_tol: Option<f64>,
}

/// Judges one file. Never fails: an unreadable file is a report with exit code 2 and the reason in
/// [`FileReport::problem`].
#[must_use]
pub fn verify_file(path: &Path, options: &Options) -> FileReport {
    file::verify_file(path, options)
}

/// [`verify_file`], calling `progress` with the bytes read so far (from the reading thread).
#[must_use]
pub fn verify_file_with_progress(
    path: &Path,
    options: &Options,
    progress: &(dyn Fn(u64) + Sync),
) -> FileReport {
    file::verify_file_with_progress(path, options, progress)
}

/// Judges an MCAP file held in memory, named `name` in the report (for tests and fuzzing).
#[must_use]
pub fn verify_bytes(name: &str, bytes: &[u8], options: &Options) -> FileReport {
    file::verify_bytes(name, bytes, options)
}
