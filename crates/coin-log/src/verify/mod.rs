//! `coin-log verify`: judge a stored log from the file alone (format.md: verify). The physics is
//! recomputed from the stored channels with the parameters of the file's `coin-log` metadata, never
//! re-simulated, in one streaming pass in memory bounded by the largest record: messages are grouped by
//! log time into samples, and each check keeps running maxima and a short window.

mod checks;
mod coverage;
mod file;
mod report;
mod samples;

pub use coverage::{coverage, coverage_over};
pub use file::{verify_bytes, verify_file, verify_file_with_progress};
pub use report::{CheckId, CheckResult, FileReport, Report, Status, Verdict};

/// Tolerance overrides (`--energy-tol`, `--residual-tol`); `None` keeps the derived defaults.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Options {
    /// Energy drift tolerance (and invariant drift).
    pub energy_tol: Option<f64>,
    /// Constraint and steady residual tolerance.
    pub residual_tol: Option<f64>,
}
