//! Quantities derived from a state (NOTES §1, §3): centre, contact point, quaternion, energy, reaction.

use super::equations::Coin;
use super::state::State;

/// A point or vector in the world frame (y up, NOTES §1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Vec3 {
    /// x component.
    pub x: f64,
    /// y component (up).
    pub y: f64,
    /// z component.
    pub z: f64,
}

/// A unit quaternion, components named like Foxglove's (`w` the scalar part).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quaternion {
    /// Vector part, x.
    pub x: f64,
    /// Vector part, y.
    pub y: f64,
    /// Vector part, z.
    pub z: f64,
    /// Scalar part.
    pub w: f64,
}

impl Quaternion {
    /// Rotation by `angle` about a unit `axis`.
    #[must_use]
    pub fn from_axis_angle(axis: [f64; 3], angle: f64) -> Self {
        let (s, c) = (0.5 * angle).sin_cos();
        Self {
            x: s * axis[0],
            y: s * axis[1],
            z: s * axis[2],
            w: c,
        }
    }

    /// Hamilton product `self · other` (apply `other` first, then `self`).
    #[must_use]
    pub fn mul(&self, o: &Self) -> Self {
        Self {
            w: self.w * o.w - self.x * o.x - self.y * o.y - self.z * o.z,
            x: self.w * o.x + self.x * o.w + self.y * o.z - self.z * o.y,
            y: self.w * o.y - self.x * o.z + self.y * o.w + self.z * o.x,
            z: self.w * o.z + self.x * o.y - self.y * o.x + self.z * o.w,
        }
    }

    /// Rotates a vector: q v q*.
    #[must_use]
    pub fn rotate(&self, v: [f64; 3]) -> [f64; 3] {
        let p = Self {
            x: v[0],
            y: v[1],
            z: v[2],
            w: 0.0,
        };
        let conj = Self {
            x: -self.x,
            y: -self.y,
            z: -self.z,
            w: self.w,
        };
        let r = self.mul(&p).mul(&conj);
        [r.x, r.y, r.z]
    }

    /// Euclidean norm (1 for a rotation).
    #[must_use]
    pub fn norm(&self) -> f64 {
        (self.x * self.x + self.y * self.y + self.z * self.z + self.w * self.w).sqrt()
    }
}

/// Orientation q = q(e_y, φ) · q(e_x, θ) · q(e_z, ψ) (NOTES §1), acting on the coin lying in the x–y plane
/// with normal +z. Computed from the unwrapped angles, so it is continuous in time and not forced to w ≥ 0.
///
/// ```
/// use coin_log::model::{orientation, State};
/// let q = orientation(&State::default());
/// assert_eq!((q.x, q.y, q.z, q.w), (0.0, 0.0, 0.0, 1.0));
/// ```
#[must_use]
pub fn orientation(s: &State) -> Quaternion {
    let (sp, cp) = (0.5 * s.phi).sin_cos();
    let (st, ct) = (0.5 * s.theta).sin_cos();
    let (ss, cs) = (0.5 * s.psi).sin_cos();
    // q(e_y, φ)·q(e_x, θ) = (cp ct, cp st, sp ct, −sp st) [w, x, y, z], then · q(e_z, ψ), expanded by hand.
    let (w1, x1, y1, z1) = (cp * ct, cp * st, sp * ct, -sp * st);
    Quaternion {
        w: w1 * cs - z1 * ss,
        x: x1 * cs + y1 * ss,
        y: y1 * cs - x1 * ss,
        z: w1 * ss + z1 * cs,
    }
}

/// Centre of the coin in the world frame: (x, a cos θ, z) (NOTES §1).
#[must_use]
pub fn centre(coin: &Coin, s: &State) -> Vec3 {
    Vec3 {
        x: s.x,
        y: coin.params().radius() * s.theta.cos(),
        z: s.z,
    }
}

/// Contact point on the table: x_c = x − a sin θ sin φ, z_c = z − a sin θ cos φ, y = 0 (NOTES §3).
#[must_use]
pub fn contact_point(coin: &Coin, s: &State) -> Vec3 {
    let a = coin.params().radius();
    let st = s.theta.sin();
    let (sp, cp) = s.phi.sin_cos();
    Vec3 {
        x: s.x - a * st * sp,
        y: 0.0,
        z: s.z - a * st * cp,
    }
}

/// Energy split into its parts [mass·length²/time²].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    /// Kinetic + potential.
    pub total: f64,
    /// ½Ma²(ω_X² + ω_Z²) + ½(I_X(ω_X² + ω_Y²) + I_Z ω_Z²).
    pub kinetic: f64,
    /// M g a cos θ.
    pub potential: f64,
}

/// Energy, NOTES §3: E = ½Ma²(ω_X² + ω_Z²) + ½(I_X(ω_X² + ω_Y²) + I_Z ω_Z²) + Mga cos θ.
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
    let potential = p.mass() * p.gravity() * p.radius() * s.theta.cos();
    Energy {
        total: kinetic + potential,
        kinetic,
        potential,
    }
}

/// The table's reaction on the coin (NOTES §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reaction {
    /// R = M dv/dt + Mg e_y, world components \[force\].
    pub force: Vec3,
    /// Friction magnitude F = √(R_x² + R_z²) (NOTES §3, corrected; §8 item 4).
    pub friction: f64,
    /// Normal force N = R_y.
    pub normal: f64,
}

/// Reaction R of the table (NOTES §3), from the state and eqs (14)–(16):
/// R_x = Ma(−(ω̇_Z − ω_X ω_Y) cos φ − (ω_X² − ω_Y ω_Z tan θ) sin θ sin φ + (ω̇_X + ω_Y ω_Z) cos θ sin φ),
/// R_y = N = Ma(−(ω_X² − ω_Y ω_Z tan θ) cos θ − (ω̇_X + ω_Y ω_Z) sin θ) + Mg,
/// R_z = Ma((ω̇_Z − ω_X ω_Y) sin φ − (ω_X² − ω_Y ω_Z tan θ) sin θ cos φ + (ω̇_X + ω_Y ω_Z) cos θ cos φ).
///
/// ```
/// use coin_log::model::{reaction, Coin, CoinParams, State};
/// // At rest upright: the table carries the weight, no friction.
/// let r = reaction(&Coin::new(CoinParams::unit_disk()), &State::default());
/// assert!((r.normal - 1.0).abs() < 1e-15 && r.friction == 0.0);
/// ```
#[must_use]
pub fn reaction(coin: &Coin, s: &State) -> Reaction {
    let p = coin.params();
    let ma = p.mass() * p.radius();
    let acc = coin.angular_acceleration(s.theta, s.omega_x, s.omega_y, s.omega_z);
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
        force: Vec3 {
            x: rx,
            y: ry,
            z: rz,
        },
        friction: rx.hypot(rz),
        normal: ry,
    }
}
