//! `coin-log verify`: judge a stored log from the file alone (format.md: verify).
//!
//! The parameters come from the file's `coin-log` metadata; the physics is recomputed from the stored
//! channels, never re-simulated. The file is read once, as a stream ([`coin_log_mcap::read`]), in memory
//! bounded by its largest record: messages are parsed into their strict types, grouped by log time into
//! samples ([`samples`]), and each check keeps running maxima and a short window ([`checks`]). Tolerances
//! follow from the recorded integrator settings ([`crate::format::tolerances`]).

pub mod checks;
mod coverage;
mod file;
pub mod report;
pub mod samples;

pub use coverage::coverage;
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
