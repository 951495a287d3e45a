//! Default tolerances of `verify`, derived from how the log was integrated (format.md: verify, Tolerances,
//! where the formulas are explained). They live in the format because `record` uses them too. With
//! τ = √(a/g), T the span, Ω = max(max|ω|, 1/τ):
//!
//!   ε = max(rtol, atol / a)      adaptive methods;   ε = (h Ω)^p   fixed-step methods of order p
//!   energy drift tolerance       = min(1e-6, max(1e-12, 100 ε (1 + T/τ)))
//!   residual tolerance           = min(1e-6, max(1e-10, 1000 ε (1 + T/τ)))   (constraint, steady)
//!   nutation tolerance           = min(1e-6, max(1e-11, 100 ε))              (relative, T and ΔΦ)
//!
//! The factors are safety margins, the floors what rounding alone produces, the ceilings the contract's.

use crate::integrate::{Method, MethodConfig};
use crate::model::CoinParams;

/// Unit roundoff of f64, 2⁻⁵³: what one rounding costs, relative (the limits of a scene, the rounding
/// `record` predicts).
pub const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;
/// Relative tolerance of a stored quantity against its recomputation from other stored values: the same
/// formula on the same numbers agrees to a few ulps; 1e-12 (≈ 4500 ε_machine) leaves room for a recorder
/// that orders its arithmetic differently.
pub const RECOMPUTE_TOLERANCE: f64 = 1e-12;
/// Relative tolerance of N ≥ 0 and |F| ≤ μN, in units of Mg (rounding only).
pub const VALIDITY_TOLERANCE: f64 = 1e-12;
/// Fewest samples per nutation period for verify's `nutation` check to interpolate the crossings; record's
/// prediction names the check only above it.
pub const MIN_SAMPLES_PER_PERIOD: f64 = 8.0;

/// The tolerances one file is judged with, and the ε they were derived from (the module doc's formulas).
#[allow(missing_docs)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    pub energy: f64,
    pub residual: f64,
    pub nutation: f64,
    pub epsilon: f64,
}

/// How the log was integrated, as far as the tolerances need it: the symbols of the module doc's formulas
/// (h = `step`, a = `radius`, τ = `time_unit`, T = `span`, max|ω| = `max_omega`).
#[allow(missing_docs)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunAccuracy {
    pub integrator: Method,
    pub rtol: f64,
    pub atol: f64,
    pub step: f64,
    pub radius: f64,
    pub time_unit: f64,
    pub span: f64,
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
            energy: energy.unwrap_or_else(|| clamp(100.0 * epsilon * growth, 1e-12, 1e-6)),
            residual: residual.unwrap_or_else(|| clamp(1000.0 * epsilon * growth, 1e-10, 1e-6)),
            nutation: clamp(100.0 * epsilon, 1e-11, 1e-6),
            epsilon,
        }
    }
}
