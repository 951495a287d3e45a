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

/// log_time = round(t·10⁹) ns, checked: t finite, ≥ 0, and small enough for a u64.
///
/// ```
/// assert_eq!(coin_log::format::log_time(1.5).unwrap(), 1_500_000_000);
/// assert_eq!(coin_log::format::log_time(0.01).unwrap(), 10_000_000);
/// assert!(coin_log::format::log_time(-1.0).is_err());
/// ```
///
/// # Errors
/// [`TimeError`] for a NaN, negative or too large t.
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
pub fn log_time(t: f64) -> Result<u64, TimeError> {
    if t.is_finite() && (0.0..MAX_TIME).contains(&t) {
        Ok((t * 1e9).round() as u64)
    } else {
        Err(TimeError { t })
    }
}

#[cfg(test)]
mod tests {
    use super::log_time;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(11), ..ProptestConfig::default() })]

        /// Whole nanoseconds below 2^50 ns (1.1e6 time units, far beyond any run) convert exactly: there
        /// the two roundings of t = ns/1e9 and t·1e9 stay below half a nanosecond.
        #[test]
        fn whole_nanoseconds_convert_exactly(ns in 0u64..(1u64 << 50)) {
            #[allow(clippy::cast_precision_loss)]
            let t = ns as f64 / 1e9;
            prop_assert_eq!(log_time(t).unwrap(), ns);
        }

        /// The conversion never decreases: t1 ≤ t2 gives log_time(t1) ≤ log_time(t2).
        #[test]
        fn the_conversion_is_monotone(a in 0.0f64..1.8e10, b in 0.0f64..1.8e10) {
            let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
            prop_assert!(log_time(lo).unwrap() <= log_time(hi).unwrap());
        }
    }

    #[test]
    fn non_finite_negative_and_huge_times_are_refused() {
        for t in [f64::NAN, f64::INFINITY, -1e-12, -1.0, 1.8e10, 1e300] {
            assert!(log_time(t).is_err(), "{t}");
        }
    }
}
