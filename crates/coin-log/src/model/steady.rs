//! Steady motions (physics §4) and their analytic properties.

use super::equations::Coin;
use super::state::State;
use thiserror::Error;

coin_log_names::named_enum! {
    /// Which root of the steady family's quadratic in ω_Y (physics §4.3); the name is the one of scene files.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub enum Branch: "branch" {
        /// ω_Y = (−B + √D) / (2A): for θ, ω_Z > 0 the large, outer circle of the note.
        Plus = "+",
        /// ω_Y = (−B − √D) / (2A).
        Minus = "-",
    }
}

impl Branch {
    /// The root of the steady family at (θ, ω_Z) nearest to `omega_y` (+ on a tie).
    #[must_use]
    pub fn nearest(coin: &Coin, theta: f64, omega_z: f64, omega_y: f64) -> Self {
        let distance = |b: Self| (steady_omega_y(coin, theta, omega_z, b) - omega_y).abs();
        if distance(Self::Plus) <= distance(Self::Minus) {
            Self::Plus
        } else {
            Self::Minus
        }
    }
}

coin_log_names::named_enum! {
    /// The four families of steady motion by name: the `kind` of a scene's `initial.steady` and the
    /// `steady_kind` of a recording's metadata (physics §4, §5).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub enum SteadyFamily: "steady kind" {
        /// Upright, rolling straight.
        Straight = "straight",
        /// Centre at rest, the coin rolling round it.
        CentreFixed = "centre-fixed",
        /// Circular rolling.
        Circle = "circle",
        /// Spinning upright in place about the vertical diameter.
        SpinUpright = "spin-upright",
    }
}

/// A steady motion to build, from its lean `theta` \[rad\] (0 < |θ| < π/2), its spin about the normal
/// `omega_z` or its rate Ω = `omega_y` [rad/time], and the `branch`: the root of the steady quadratic, or
/// for the centre-fixed motion the sign of ω_Y (`Plus` gives ω_Y > 0).
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the enum's doc names each field")]
pub enum SteadyKind {
    /// Upright, rolling straight: θ = ω_X = ω_Y = 0, ω_Z constant (physics §4.1).
    Straight { omega_z: f64 },
    /// Centre at rest, the coin rolling round it: ω_Z = 0, ω_Y² = Mga cos θ / I_X (physics §4.2).
    CentreFixed { theta: f64, branch: Branch },
    /// Circular rolling on either branch (physics §4.3).
    Circle {
        theta: f64,
        omega_z: f64,
        branch: Branch,
    },
    /// Spinning upright in place about the vertical diameter: θ = 0, ω_Z = 0, ω_Y = Ω (physics §5).
    SpinUpright { omega_y: f64 },
}

impl SteadyKind {
    /// The family of this motion.
    #[must_use]
    pub fn family(&self) -> SteadyFamily {
        match self {
            Self::Straight { .. } => SteadyFamily::Straight,
            Self::CentreFixed { .. } => SteadyFamily::CentreFixed,
            Self::Circle { .. } => SteadyFamily::Circle,
            Self::SpinUpright { .. } => SteadyFamily::SpinUpright,
        }
    }

    /// The root of the steady family for circles and the sign of ω_Y for the centre-fixed motion.
    #[must_use]
    pub fn branch(&self) -> Option<Branch> {
        match *self {
            Self::CentreFixed { branch, .. } | Self::Circle { branch, .. } => Some(branch),
            Self::Straight { .. } | Self::SpinUpright { .. } => None,
        }
    }
}

/// A steady motion that cannot be built, with the reason and the allowed range.
#[derive(Debug, Clone, PartialEq, Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum SteadyError {
    /// θ outside the open interval where the motion exists.
    #[error("steady `{kind}`: theta = {theta} is outside the allowed range {range}")]
    Theta {
        kind: &'static str,
        theta: f64,
        range: &'static str,
    },
    /// A non-finite rate.
    #[error("steady `{kind}`: `{name}` = {value} must be a finite number")]
    NotFinite {
        kind: &'static str,
        name: &'static str,
        value: f64,
    },
}

/// A steady motion: its initial state and analytic properties (physics §4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steady {
    /// What was asked for.
    pub kind: SteadyKind,
    /// Initial state at t = 0 (φ = ψ = x = z = 0).
    pub state: State,
    /// Heading rate φ̇ = ω_Y / cos θ, eq (18) [rad/time].
    pub phi_dot: f64,
    /// Spin rate ψ̇ = ω_Z + ω_Y tan θ, eq (19) [rad/time].
    pub psi_dot: f64,
    /// Radius of the circle traced by the centre \[length\]; `None` for straight rolling (infinite).
    pub r_g: Option<f64>,
    /// Radius of the circle traced by the contact point \[length\]; `None` for straight rolling.
    pub r_c: Option<f64>,
}

/// ω_Y on the steady family for given θ and ω_Z (physics §4): the root of
/// I_X tan θ ω_Y² + (I_Z + Ma²) ω_Z ω_Y − Mga sin θ = 0 on `branch`, computed without cancellation.
/// Requires tan θ ≠ 0.
#[must_use]
pub fn steady_omega_y(coin: &Coin, theta: f64, omega_z: f64, branch: Branch) -> f64 {
    let p = coin.params();
    let qa = p.inertia_x() * theta.tan();
    let qb = (p.inertia_z() + p.ma2()) * omega_z;
    let qc = -p.energy_scale() * theta.sin();
    // D = B² − 4AC ≥ 0 always, since A·C = −I_X Mga tan θ sin θ ≤ 0.
    let root_d = (qb * qb - 4.0 * qa * qc).sqrt();
    // Stable quadratic formula: q = −½(B + sgn(B)√D); roots q/A and C/q. The root (−B + √D)/(2A) is q/A
    // when B < 0 and C/q when B ≥ 0.
    let sign_b = if qb < 0.0 { -1.0 } else { 1.0 };
    let q = -0.5 * (qb + sign_b * root_d);
    let plus_is_q_over_a = qb < 0.0;
    let big = q / qa;
    let small = if q == 0.0 { 0.0 } else { qc / q };
    match (branch, plus_is_q_over_a) {
        (Branch::Plus, true) | (Branch::Minus, false) => big,
        (Branch::Plus, false) | (Branch::Minus, true) => small,
    }
}

fn check_finite(kind: &'static str, name: &'static str, value: f64) -> Result<(), SteadyError> {
    let error = SteadyError::NotFinite { kind, name, value };
    value.is_finite().then_some(()).ok_or(error)
}

fn check_lean(kind: &'static str, theta: f64) -> Result<(), SteadyError> {
    let ok = theta.is_finite() && theta != 0.0 && theta.abs() < std::f64::consts::FRAC_PI_2;
    ok.then_some(()).ok_or(SteadyError::Theta {
        kind,
        theta,
        range: "0 < |theta| < pi/2 (a leaning coin; use `straight` for theta = 0)",
    })
}

impl Steady {
    /// Builds the steady motion `kind` for `coin`; fails when θ is outside the range where the motion
    /// exists, or a rate is not finite.
    ///
    /// ```
    /// use coin_log::model::{Branch, Coin, CoinParams, Steady, SteadyKind};
    /// let coin = Coin::new(CoinParams::unit_disk());
    /// let s = Steady::new(&coin, SteadyKind::Circle { theta: 0.3, omega_z: 1.0, branch: Branch::Plus }).unwrap();
    /// assert!((s.r_g.unwrap() - 4.897855).abs() < 1e-6); // physics §4 example
    /// ```
    pub fn new(coin: &Coin, kind: SteadyKind) -> Result<Self, SteadyError> {
        let p = coin.params();
        let name = kind.family().name();
        let (theta, omega_y, omega_z) = match kind {
            SteadyKind::Straight { omega_z } => {
                check_finite(name, "omega_z", omega_z)?;
                (0.0, 0.0, omega_z)
            }
            SteadyKind::SpinUpright { omega_y } => {
                check_finite(name, "omega_y", omega_y)?;
                (0.0, omega_y, 0.0)
            }
            SteadyKind::CentreFixed { theta, branch } => {
                check_lean(name, theta)?;
                let magnitude = (p.energy_scale() * theta.cos() / p.inertia_x()).sqrt();
                let sign = if branch == Branch::Plus { 1.0 } else { -1.0 };
                (theta, sign * magnitude, 0.0)
            }
            SteadyKind::Circle {
                theta,
                omega_z,
                branch,
            } => {
                check_lean(name, theta)?;
                check_finite(name, "omega_z", omega_z)?;
                (theta, steady_omega_y(coin, theta, omega_z, branch), omega_z)
            }
        };
        let state = State {
            theta,
            omega_y,
            omega_z,
            ..State::default()
        };
        Ok(Self::at(coin, kind, state))
    }

    /// The steady motion `kind` at `state` (ω_X = 0 on the steady family), with its rates and its radii
    /// R_G = a|ω_Z cos θ / ω_Y|, R_C = a|ω_Z cos θ / ω_Y + sin θ| (physics §4.3; 0 for the upright spin).
    #[must_use]
    pub(crate) fn at(coin: &Coin, kind: SteadyKind, state: State) -> Self {
        let (wy, wz) = (state.omega_y, state.omega_z);
        let a = coin.params().radius();
        let (st, ct) = state.theta.sin_cos();
        let (r_g, r_c) = match kind.family() {
            SteadyFamily::Straight => (None, None),
            SteadyFamily::SpinUpright => (Some(0.0), Some(0.0)),
            SteadyFamily::CentreFixed | SteadyFamily::Circle => {
                let signed = wz * ct / wy;
                (Some(a * signed.abs()), Some(a * (signed + st).abs()))
            }
        };
        Self {
            kind,
            state,
            phi_dot: wy / ct,
            psi_dot: wz + wy * st / ct,
            r_g,
            r_c,
        }
    }
}
