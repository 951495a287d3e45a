//! The whole `bench stability` suite: the hard cases of [`super::stability`], then the cases of
//! [`super::nutation`] that prove `analyse`: kicked stable circles nutate at σ, displaced unstable circles
//! grow at √(−σ²), generic motions have the quadrature's period and heading advance.

use super::nutation::{generic_periods, stable_circles, unstable_circles};
use super::stability::{
    fast_spin, long_horizon, marginal, near_flat, release, scale_invariance, StabilityRow,
    SuiteOptions, MARGINAL_OFFSET,
};
use super::BenchError;

/// Every case, in the order of the report.
///
/// # Errors
/// [`BenchError`] if a case cannot be built (never for the built-in cases).
pub fn run_suite(options: &SuiteOptions) -> Result<Vec<StabilityRow>, BenchError> {
    let mut rows = Vec::new();
    for omega_z in [50.0, 500.0] {
        rows.extend(fast_spin(omega_z, options)?);
    }
    for theta in [1.5, 1.56, 1.5705] {
        rows.extend(near_flat(theta, options)?);
    }
    rows.extend(release(0.6, "flat-landing")?);
    rows.extend(release(0.2, "lift-off")?);
    for offset in [MARGINAL_OFFSET, 0.0, -MARGINAL_OFFSET] {
        rows.extend(marginal(offset, options.marginal_horizon));
    }
    rows.extend(long_horizon(options.long_horizon)?);
    rows.extend(scale_invariance(options.scale_horizon)?);
    rows.extend(stable_circles(options.analyse_periods)?);
    rows.extend(unstable_circles()?);
    rows.extend(generic_periods(options.analyse_periods)?);
    Ok(rows)
}
