//! The analysis of a steady motion: its family and branch, rates, radii, forces, and its linear
//! stability (physics §4, §9).

use crate::model::{
    eigenvalues, reaction, steady_sigma_squared, Branch, Coin, Linearisation, State, Steady,
    SteadyKind,
};

/// |σ²| within this many ulp of the size of its terms is zero to rounding: the verdict is marginal.
const MARGINAL_ULPS: f64 = 64.0;

coin_log_names::named_enum! {
    /// The linear stability of a steady motion (physics §9); the name is the `verdict` of format.md's
    /// analyse --json and of the stability map.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum Stability: "stability" {
        /// σ² > 0: small perturbations nutate at σ.
        Stable = "stable",
        /// σ² < 0: small perturbations grow like e^{√(−σ²) t}.
        Unstable = "unstable",
        /// σ² = 0 to rounding: the linear analysis does not decide (straight rolling at ω_c grows like t²).
        Marginal = "marginal",
    }
}

impl Stability {
    /// The verdict of σ², given the size of the terms it is the sum of.
    #[must_use]
    pub fn of(sigma_squared: f64, scale: f64) -> Self {
        if sigma_squared.abs() <= MARGINAL_ULPS * f64::EPSILON * scale {
            Self::Marginal
        } else if sigma_squared > 0.0 {
            Self::Stable
        } else {
            Self::Unstable
        }
    }
}

/// A steady motion, analysed (physics §4, §9): the motion `steady` (its kind, state, rates and radii),
/// N = `normal` \[force\] (= Mg on every steady motion), |F| = `friction` \[force\] (the centripetal
/// force of the centre's circle), and σ² of eq (21), `sigma_squared` [1/time²].
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names the fields without one")]
pub struct SteadyAnalysis {
    pub steady: Steady,
    pub normal: f64,
    pub friction: f64,
    pub sigma_squared: f64,
    /// The size of the terms σ² is the sum of (its rounding is a few ulp of this).
    pub sigma_scale: f64,
    /// The eigenvalues of the linearisation, (re, im) [1/time].
    pub eigenvalues: [(f64, f64); 4],
    /// Stable, unstable or marginal.
    pub verdict: Stability,
}

impl SteadyAnalysis {
    /// The analysis of the steady state `state` (ω_X = 0 on the steady family); `given` is the steady
    /// motion the scene asked for, which names the family and branch exactly.
    #[must_use]
    pub fn of_state(coin: &Coin, state: &State, given: Option<&Steady>) -> Self {
        let (theta, wy, wz) = (state.theta, state.omega_y, state.omega_z);
        let kind = given.map_or_else(|| classify(coin, state), |s| s.kind);
        let r = reaction(coin, state);
        let sigma_squared = steady_sigma_squared(coin, theta, wy, wz);
        let sigma_scale = Linearisation::at(coin, theta, wy, wz).scale();
        Self {
            steady: Steady::at(coin, kind, *state),
            normal: r.normal,
            friction: r.friction,
            sigma_squared,
            sigma_scale,
            eigenvalues: eigenvalues(sigma_squared),
            verdict: Stability::of(sigma_squared, sigma_scale),
        }
    }

    /// The nutation period 2π/σ of small perturbations, when stable.
    #[must_use]
    pub fn nutation_period(&self) -> Option<f64> {
        (self.verdict == Stability::Stable)
            .then(|| std::f64::consts::TAU / self.sigma_squared.sqrt())
    }

    /// The e-folding time 1/√(−σ²) of small perturbations, when unstable.
    #[must_use]
    pub fn e_folding_time(&self) -> Option<f64> {
        (self.verdict == Stability::Unstable).then(|| 1.0 / (-self.sigma_squared).sqrt())
    }
}

/// The steady motion a steady state is, given by its values: upright with ω_Y = 0 rolls straight,
/// upright otherwise spins in place; leaning without ω_Z rolls round its resting centre (branch by the
/// sign of ω_Y); otherwise a circle, on the root of the steady family nearest to ω_Y.
fn classify(coin: &Coin, state: &State) -> SteadyKind {
    let (theta, omega_y, omega_z) = (state.theta, state.omega_y, state.omega_z);
    if theta == 0.0 {
        return if omega_y.abs() <= omega_z.abs() {
            SteadyKind::Straight { omega_z }
        } else {
            SteadyKind::SpinUpright { omega_y }
        };
    }
    if omega_z == 0.0 {
        let branch = if omega_y >= 0.0 {
            Branch::Plus
        } else {
            Branch::Minus
        };
        return SteadyKind::CentreFixed { theta, branch };
    }
    SteadyKind::Circle {
        theta,
        omega_z,
        branch: Branch::nearest(coin, theta, omega_z, omega_y),
    }
}
