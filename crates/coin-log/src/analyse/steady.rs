//! The analysis of a steady motion: its family and branch, rates, radii, forces, and its linear
//! stability (physics §4, §9).

use crate::model::{
    eigenvalues, rates_and_radii, reaction, steady_sigma_squared, Branch, Coin, Linearisation,
    State, Steady, SteadyFamily, SteadyKind,
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

/// A steady motion, analysed (physics §4, §9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyAnalysis {
    /// The family, as in the metadata's `steady_kind`.
    pub kind: SteadyFamily,
    /// The root of the steady family for circles and the sign of ω_Y for the centre-fixed motion.
    pub branch: Option<Branch>,
    /// ω_Y [rad/time].
    pub omega_y: f64,
    /// φ̇ = ω_Y / cos θ [rad/time].
    pub phi_dot: f64,
    /// ψ̇ = ω_Z + ω_Y tan θ [rad/time].
    pub psi_dot: f64,
    /// R_G \[length\]; `None` for straight rolling (infinite).
    pub r_g: Option<f64>,
    /// R_C \[length\]; `None` for straight rolling.
    pub r_c: Option<f64>,
    /// N \[force\] (= Mg on every steady motion).
    pub normal: f64,
    /// |F| \[force\], the centripetal force of the centre's circle.
    pub friction: f64,
    /// σ², eq (21) [1/time²].
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
        let (kind, branch) = given.map_or_else(|| classify(coin, state), |s| named(s.kind));
        let (phi_dot, psi_dot, r_g, r_c) = rates_and_radii(coin, kind, state);
        let r = reaction(coin, state);
        let sigma_squared = steady_sigma_squared(coin, theta, wy, wz);
        let sigma_scale = Linearisation::at(coin, theta, wy, wz).scale();
        Self {
            kind,
            branch,
            omega_y: wy,
            phi_dot,
            psi_dot,
            r_g,
            r_c,
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

/// The family and branch of a steady motion given by name.
fn named(kind: SteadyKind) -> (SteadyFamily, Option<Branch>) {
    let branch = match kind {
        SteadyKind::CentreFixed { branch, .. } | SteadyKind::Circle { branch, .. } => Some(branch),
        SteadyKind::Straight { .. } | SteadyKind::SpinUpright { .. } => None,
    };
    (kind.family(), branch)
}

/// The family and branch of a steady state given by its values: upright with ω_Y = 0 rolls straight,
/// upright otherwise spins in place; leaning without ω_Z rolls round its resting centre (branch by the
/// sign of ω_Y); otherwise a circle, on the root of the steady family nearest to ω_Y.
fn classify(coin: &Coin, state: &State) -> (SteadyFamily, Option<Branch>) {
    let (theta, wy, wz) = (state.theta, state.omega_y, state.omega_z);
    let sign = |w: f64| {
        if w >= 0.0 {
            Branch::Plus
        } else {
            Branch::Minus
        }
    };
    if theta == 0.0 {
        let kind = if wy.abs() <= wz.abs() {
            SteadyFamily::Straight
        } else {
            SteadyFamily::SpinUpright
        };
        return (kind, None);
    }
    if wz == 0.0 {
        return (SteadyFamily::CentreFixed, Some(sign(wy)));
    }
    (
        SteadyFamily::Circle,
        Some(Branch::nearest(coin, theta, wz, wy)),
    )
}
