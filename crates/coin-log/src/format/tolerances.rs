//! Default tolerances of `verify`, derived from how the log was integrated (format.md: verify, Tolerances).
//! They live in the format because `record` uses them too: its summary says an event is not to be trusted
//! when the energy drift at the event is above the tolerance `verify` will judge the file by.
//!
//! Let τ = √(a/g) be the time unit, T the recorded span, Ω = max(max|ω|, 1/τ) over the run, and
//!
//!   ε = max(rtol, atol / a)                          for adaptive methods (dopri5, dop853),
//!   ε = (h Ω)^p                                      for fixed-step methods of order p with step h
//!                                                    (rk4 and gauss4: p = 4; the order of `Method`),
//!
//! the accuracy the integrator was asked for, per unit time. Only the settings the method uses count: a
//! fixed-step method ignores rtol and atol and an adaptive one the step, so they cannot loosen (or tighten)
//! the tolerances. Then
//!
//!   energy drift tolerance        = min(1e-6, max(1e-12, 100 ε (1 + T/τ)))
//!   residual tolerance            = min(1e-6, max(1e-10, 1000 ε (1 + T/τ)))   (constraint, steady)
//!   nutation tolerance            = min(1e-6, max(1e-11, 100 ε))              (relative, T and ΔΦ)
//!
//! The factor 1 + T/τ lets errors grow linearly with the run's length, as they do for non-symplectic
//! methods (the nutation tolerance has no such factor: it judges a period, an average over the run, whose
//! relative error is the integrator's relative error per unit time, ε, not its accumulation); the floors
//! are what rounding alone produces (sums of ~1e-16 errors, and finite differences that
//! divide them by the sample interval); the ceilings are the contract's: a tolerance is never looser than
//! 1e-6, whatever the integrator settings. `--energy-tol` and `--residual-tol` replace the defaults.
//! Recomputations of a stored quantity from other stored values (energy against `/coin/energy`, the
//! quaternion, contact point, height, reaction and invariants against their inputs) repeat the recorder's
//! arithmetic on the same numbers, so they are held to [`RECOMPUTE_TOLERANCE`].

use crate::integrate::{Method, MethodConfig};
use crate::model::CoinParams;

/// Unit roundoff of f64, 2⁻⁵³: what one rounding costs, relative (the limits of a scene, the rounding
/// `record` predicts).
pub const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;
/// Contract ceiling of the energy drift tolerance.
pub const ENERGY_CEILING: f64 = 1e-6;
/// Contract ceiling of the constraint (and steady) residual tolerance.
pub const RESIDUAL_CEILING: f64 = 1e-6;
/// Smallest default energy tolerance: accumulated rounding of E over long runs.
pub const ENERGY_FLOOR: f64 = 1e-12;
/// Smallest default residual tolerance: rounding of positions amplified by the finite difference.
pub const RESIDUAL_FLOOR: f64 = 1e-10;
/// Safety factor between ε(1 + T/τ) and the energy drift tolerance.
pub const ENERGY_FACTOR: f64 = 100.0;
/// Safety factor between ε(1 + T/τ) and the residual tolerance (finite differences amplify noise).
pub const RESIDUAL_FACTOR: f64 = 1000.0;
/// Contract ceiling of the nutation tolerance.
pub const NUTATION_CEILING: f64 = 1e-6;
/// Smallest default nutation tolerance: the rounding of crossing times a few ulp of t apart, averaged.
pub const NUTATION_FLOOR: f64 = 1e-11;
/// Safety factor between ε and the nutation tolerance.
pub const NUTATION_FACTOR: f64 = 100.0;
/// Relative tolerance of a stored quantity against its recomputation from other stored values: the same
/// formula on the same numbers agrees to a few ulps; 1e-12 (≈ 4500 ε_machine) leaves room for a recorder
/// that orders its arithmetic differently.
pub const RECOMPUTE_TOLERANCE: f64 = 1e-12;
/// Relative tolerance of N ≥ 0 and |F| ≤ μN, in units of Mg (rounding only).
pub const VALIDITY_TOLERANCE: f64 = 1e-12;

/// The tolerances one file is judged with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Energy drift max|E − E₀| / max(|E₀|, Mga).
    pub energy: f64,
    /// Constraint residual relative to a·max|ω|, and the steady residuals.
    pub residual: f64,
    /// Relative error of the measured nutation period and heading advance (before the quadrature's and
    /// the interpolation's shares are added).
    pub nutation: f64,
    /// The accuracy ε the defaults were derived from.
    pub epsilon: f64,
}

/// How the log was integrated, as far as the tolerances need it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunAccuracy {
    /// The integrator (`metadata.integrator`).
    pub integrator: Method,
    /// rtol (adaptive methods).
    pub rtol: f64,
    /// atol (adaptive methods).
    pub atol: f64,
    /// Fixed step h (fixed-step methods).
    pub step: f64,
    /// Radius a.
    pub radius: f64,
    /// Time unit τ.
    pub time_unit: f64,
    /// Recorded span T.
    pub span: f64,
    /// max|ω| over the run.
    pub max_omega: f64,
}

impl RunAccuracy {
    /// A run integrated by `method` on a coin of `params`, over `span` with rates up to `max_omega`.
    #[must_use]
    pub fn new(method: &MethodConfig, params: &CoinParams, span: f64, max_omega: f64) -> Self {
        Self {
            integrator: method.method,
            rtol: method.rtol,
            atol: method.atol,
            step: method.step,
            radius: params.radius(),
            time_unit: params.time_unit(),
            span,
            max_omega,
        }
    }

    /// ε of the module doc: from rtol and atol for adaptive methods, from the step alone for fixed-step
    /// ones.
    #[must_use]
    pub fn epsilon(&self) -> f64 {
        match fixed_step_order(self.integrator) {
            None => self.rtol.max(self.atol / self.radius),
            Some(p) => {
                let omega = self.max_omega.max(1.0 / self.time_unit);
                (self.step * omega).powi(p)
            }
        }
    }
}

/// Order of a fixed-step method, `None` for adaptive ones (rtol and atol then carry the accuracy).
#[must_use]
pub fn fixed_step_order(method: Method) -> Option<i32> {
    if method.is_adaptive() {
        None
    } else {
        i32::try_from(method.order()).ok()
    }
}

impl Tolerances {
    /// The default tolerances of the module doc, overridden by `energy` / `residual` when given.
    #[must_use]
    pub fn derive(run: &RunAccuracy, energy: Option<f64>, residual: Option<f64>) -> Self {
        let mut epsilon = run.epsilon();
        if !epsilon.is_finite() {
            epsilon = f64::INFINITY;
        }
        let growth = 1.0 + (run.span / run.time_unit).max(0.0);
        let clamp = |x: f64, lo: f64, hi: f64| if x.is_nan() { hi } else { x.max(lo).min(hi) };
        Self {
            energy: energy.unwrap_or_else(|| {
                clamp(
                    ENERGY_FACTOR * epsilon * growth,
                    ENERGY_FLOOR,
                    ENERGY_CEILING,
                )
            }),
            residual: residual.unwrap_or_else(|| {
                clamp(
                    RESIDUAL_FACTOR * epsilon * growth,
                    RESIDUAL_FLOOR,
                    RESIDUAL_CEILING,
                )
            }),
            nutation: clamp(NUTATION_FACTOR * epsilon, NUTATION_FLOOR, NUTATION_CEILING),
            epsilon,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn run(integrator: &str, rtol: f64, span: f64) -> RunAccuracy {
        RunAccuracy {
            integrator: integrator.parse().unwrap(),
            rtol,
            atol: 1e-12,
            step: 1e-3,
            radius: 1.0,
            time_unit: 1.0,
            span,
            max_omega: 1.0,
        }
    }

    #[test]
    fn defaults_are_never_looser_than_the_contract_ceilings() {
        let t = Tolerances::derive(&run("dop853", 1e-3, 1e4), None, None);
        assert_eq!((t.energy, t.residual), (ENERGY_CEILING, RESIDUAL_CEILING));
    }

    #[test]
    fn defaults_tighten_with_the_requested_accuracy() {
        // ε = max(rtol, atol/a) = 1e-12 (atol dominates), T/τ = 9: 100·1e-12·10 and 1000·1e-12·10.
        let t = Tolerances::derive(&run("dop853", 1e-13, 9.0), None, None);
        assert!((t.energy - 1e-9).abs() < 1e-21, "energy tol {}", t.energy);
        assert!(
            (t.residual - 1e-8).abs() < 1e-20,
            "residual tol {}",
            t.residual
        );
    }

    #[test]
    fn fixed_step_methods_count_their_step() {
        let t = Tolerances::derive(&run("rk4", 1e-14, 0.0), None, None);
        assert!((t.epsilon - 1e-12).abs() < 1e-24, "epsilon {}", t.epsilon);
    }

    /// A setting the method does not use cannot move the tolerance: rtol = 1e-3 on rk4 (step 1e-3, Ω = 1:
    /// ε = 1e-12) and a step of 1 on dop853 (ε = rtol = 1e-10) leave ε where the used settings put it.
    #[test]
    fn settings_the_method_ignores_do_not_count() {
        let rk4 = Tolerances::derive(&run("rk4", 1e-3, 0.0), None, None);
        println!(
            "rk4 with rtol 1e-3: epsilon {:e} (expected 1e-12)",
            rk4.epsilon
        );
        assert!(
            (rk4.epsilon - 1e-12).abs() < 1e-24,
            "epsilon {}",
            rk4.epsilon
        );
        let dop853 = Tolerances::derive(
            &RunAccuracy {
                step: 1.0,
                ..run("dop853", 1e-10, 0.0)
            },
            None,
            None,
        );
        println!(
            "dop853 with step 1: epsilon {:e} (expected 1e-10)",
            dop853.epsilon
        );
        assert!(
            (dop853.epsilon - 1e-10).abs() < 1e-22,
            "epsilon {}",
            dop853.epsilon
        );
    }

    #[test]
    fn flags_override_the_defaults() {
        let t = Tolerances::derive(&run("dop853", 1e-10, 1.0), Some(0.5), Some(0.25));
        assert_eq!((t.energy, t.residual), (0.5, 0.25));
    }
}
