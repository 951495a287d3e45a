//! The one conversion from simulation time to MCAP nanoseconds (format.md: log_time = round(t·10⁹)).

use thiserror::Error;

/// A simulation time that has no MCAP timestamp.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[error("time t = {t} cannot be a log time: it must be finite, >= 0 and below 1.8e10 time units")]
pub struct TimeError {
    /// The offending time.
    pub t: f64,
}

/// Largest t whose nanoseconds fit in a u64 with margin.
const MAX_TIME: f64 = 1.8e10;

/// log_time = round(t·10⁹) ns, checked: t finite, ≥ 0, and small enough for a u64 ([`TimeError`] for a
/// NaN, negative or too large t).
///
/// ```
/// assert_eq!(coin_log::format::log_time(1.5).unwrap(), 1_500_000_000);
/// assert_eq!(coin_log::format::log_time(0.01).unwrap(), 10_000_000);
/// assert!(coin_log::format::log_time(-1.0).is_err());
/// ```
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
pub fn log_time(t: f64) -> Result<u64, TimeError> {
    if t.is_finite() && (0.0..MAX_TIME).contains(&t) {
        Ok((t * 1e9).round() as u64)
    } else {
        Err(TimeError { t })
    }
}
