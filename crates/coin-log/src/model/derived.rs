//! Quantities derived from a state (physics §1, §3): centre, contact point, quaternion, energy, reaction.

use super::equations::{AngularAcceleration, Coin};
use super::state::State;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Orientation q = q(e_y, φ) · q(e_x, θ) · q(e_z, ψ) (physics §1: spin ψ about z, then lean θ about x, then
/// heading φ about y; rotation matrix eq (7)), a dimensionless unit quaternion acting on the coin lying in
/// the x–y plane with normal +z (world frame, y up). From the unwrapped angles: continuous in time, not
/// forced to w ≥ 0. Its components (i, j, k, w) are Foxglove's (x, y, z, w).
///
/// ```
/// use coin_log::model::{orientation, State};
/// let q = orientation(&State::default());
/// assert_eq!((q.i, q.j, q.k, q.w), (0.0, 0.0, 0.0, 1.0));
/// ```
#[must_use]
pub fn orientation(s: &State) -> UnitQuaternion<f64> {
    let (sp, cp) = (0.5 * s.phi).sin_cos();
    let (st, ct) = (0.5 * s.theta).sin_cos();
    let (ss, cs) = (0.5 * s.psi).sin_cos();
    // q(e_y, φ)·q(e_x, θ) = (cp ct, cp st, sp ct, −sp st) [w, x, y, z], then · q(e_z, ψ), expanded by hand.
    let (w1, x1, y1, z1) = (cp * ct, cp * st, sp * ct, -sp * st);
    let w = w1 * cs - z1 * ss;
    let x = x1 * cs + y1 * ss;
    let y = y1 * cs - x1 * ss;
    let z = w1 * ss + z1 * cs;
    // Not renormalised: the recorded components keep these exact operations (datasets compare bytes).
    UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z))
}

/// Centre of the coin in the world frame: (x, a cos θ, z) \[length\] (physics §1).
#[must_use]
pub fn centre(coin: &Coin, s: &State) -> Vector3<f64> {
    Vector3::new(s.x, coin.params().radius() * s.theta.cos(), s.z)
}

/// Contact point on the table: x_c = x − a sin θ sin φ, z_c = z − a sin θ cos φ, y = 0 \[length\]
/// (physics §3).
#[must_use]
pub fn contact_point(coin: &Coin, s: &State) -> Vector3<f64> {
    let a = coin.params().radius();
    let st = s.theta.sin();
    let (sp, cp) = s.phi.sin_cos();
    Vector3::new(s.x - a * st * sp, 0.0, s.z - a * st * cp)
}

/// Energy split into its `kinetic` and `potential` parts and their `total` [mass·length²/time²]
/// ([`energy`] gives the formulas).
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct Energy {
    pub total: f64,
    pub kinetic: f64,
    pub potential: f64,
}

/// Energy, physics §3: E = ½Ma²(ω_X² + ω_Z²) + ½(I_X(ω_X² + ω_Y²) + I_Z ω_Z²) + Mga cos θ.
///
/// ```
/// use coin_log::model::{energy, Coin, CoinParams, State};
/// // Upright unit disk rolling straight at ω_Z = 1: ½·1 + ½·½ = ¾ kinetic, potential 1.
/// let e = energy(&Coin::new(CoinParams::unit_disk()), &State { omega_z: 1.0, ..State::default() });
/// assert!((e.kinetic - 0.75).abs() < 1e-15 && (e.total - 1.75).abs() < 1e-15);
/// ```
#[must_use]
pub fn energy(coin: &Coin, s: &State) -> Energy {
    let p = coin.params();
    let (wx2, wy2, wz2) = (
        s.omega_x * s.omega_x,
        s.omega_y * s.omega_y,
        s.omega_z * s.omega_z,
    );
    let kinetic =
        0.5 * p.ma2() * (wx2 + wz2) + 0.5 * (p.inertia_x() * (wx2 + wy2) + p.inertia_z() * wz2);
    let potential = p.energy_scale() * s.theta.cos();
    Energy {
        total: kinetic + potential,
        kinetic,
        potential,
    }
}

/// The table's reaction on the coin (physics §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reaction {
    /// R = M dv/dt + Mg e_y, world components (y up) \[force\].
    pub force: Vector3<f64>,
    /// Friction magnitude F = √(R_x² + R_z²) (physics §3, corrected; §8 item 4).
    pub friction: f64,
    /// Normal force N = R_y.
    pub normal: f64,
}

/// Reaction R of the table in world components (physics §3), with ω̇ from eqs (14)–(16).
///
/// ```
/// use coin_log::model::{reaction, Coin, CoinParams, State};
/// // At rest upright: the table carries the weight, no friction.
/// let r = reaction(&Coin::new(CoinParams::unit_disk()), &State::default());
/// assert!((r.normal - 1.0).abs() < 1e-15 && r.friction == 0.0);
/// ```
#[must_use]
pub fn reaction(coin: &Coin, s: &State) -> Reaction {
    let acc = coin.angular_acceleration(s.theta, s.omega_x, s.omega_y, s.omega_z);
    reaction_with(coin, s, acc)
}

/// The reaction of physics §3 for given angular accelerations (ω̇_X, ω̇_Y, ω̇_Z): those of eqs (14)–(16)
/// ([`reaction`]), or of eqs (31)–(33) with a dissipative couple (physics §11).
#[must_use]
pub(super) fn reaction_with(coin: &Coin, s: &State, acc: AngularAcceleration) -> Reaction {
    let p = coin.params();
    let ma = p.mass() * p.radius();
    let (st, ct) = s.theta.sin_cos();
    let (sp, cp) = s.phi.sin_cos();
    let tan_t = st / ct;
    let along_z = acc.z - s.omega_x * s.omega_y; // ω̇_Z − ω_X ω_Y
    let radial = s.omega_x * s.omega_x - s.omega_y * s.omega_z * tan_t; // ω_X² − ω_Y ω_Z tan θ
    let tangential = acc.x + s.omega_y * s.omega_z; // ω̇_X + ω_Y ω_Z
    let rx = ma * (-along_z * cp - radial * st * sp + tangential * ct * sp);
    let ry = ma * (-radial * ct - tangential * st) + p.mass() * p.gravity();
    let rz = ma * (along_z * sp - radial * st * cp + tangential * ct * cp);
    Reaction {
        force: Vector3::new(rx, ry, rz),
        friction: rx.hypot(rz),
        normal: ry,
    }
}
