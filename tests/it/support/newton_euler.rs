//! A second, independent model of the rolling coin, for tests only: world-frame Newton–Euler equations
//! with the contact force solved from the no-slip constraint at every evaluation.
//!
//! State (13): unit quaternion q = [w, x, y, z] (body → world, the body being the coin lying in the x–y
//! plane with normal +z, physics §1), world angular velocity ω, centre position r_G and velocity v_G.
//!
//! Derivation (first principles, nothing taken from eqs (14)–(19)):
//! - the lean frame is geometric: e_Z = Q e_z (the normal), e_X = e_y × e_Z / |e_y × e_Z|, e_Y = e_Z × e_X;
//!   the contact point is r_P = r_G + ρ with ρ = −a e_Y;
//! - Newton: M a_G = R − M g e_y; Euler about the centre: d(I_w ω)/dt = I_w ω̇ + ω × I_w ω = ρ × R with
//!   I_w = Q diag(I_X, I_X, I_Z) Qᵀ;
//! - no slip: the material point at P has zero velocity, v_G + ω × ρ = 0. Differentiated in time (ρ moves
//!   round the rim, so ρ̇ is the rate of the geometric vector, computed from ė_Z = ω × e_Z):
//!   a_G + ω̇ × ρ + ω × ρ̇ = 0;
//! - substituting a_G and ω̇ = I_w⁻¹(ρ × R − ω × I_w ω) gives a 3×3 linear system for R:
//!   (1/M · 1 − [ρ]× I_w⁻¹ [ρ]×) R = g e_y − ω × ρ̇ − [ρ]× I_w⁻¹ (ω × I_w ω),
//!   whose matrix is symmetric positive definite (−[ρ]× X [ρ]× = [ρ]×ᵀ X [ρ]× for symmetric X);
//! - kinematics: q̇ = ½ (0, ω) ⊗ q for world ω; ṙ_G = v_G.
//!
//! Only the velocity-level and position-level constraints' second derivatives are imposed, so they drift
//! with the integrator's truncation error; with rk4 at h = 1e-3 that drift is far below the tolerances.
//!
//! A dissipative couple T (physics §11), when given, is one more torque in Euler's equation:
//! I_w ω̇ + ω × I_w ω = ρ × R + T with T = −P ω/|ω|², P = κ |φ̇|^m (sin α)^(−k). Here P is built from the
//! geometry, not from the library's angles: sin α = e_Y·e_y (the coin's in-plane upward axis against the
//! vertical) and φ̇ = (ω·e_Y)/(e_Y·e_y) (ω = φ̇ e_y + θ̇ e_X + ψ̇ e_Z with e_X ⊥ e_Y and e_Z ⊥ e_Y). T enters
//! the contact-force system through ω̇: its right-hand side gains + [ρ]× I⁻¹ T. [`Dissipating`] carries the
//! dissipated work W = ∫P dt as a 14th state component.

// A test model: a matrix that is not positive definite is a failed test, with the reason.
#![allow(clippy::expect_used)]

use super::vectors::{lean_frame_from_normal, quaternion_from_angles, world_omega, V3};
use coin_log::integrate::OdeSystem;
use coin_log::model::{CoinParams, State};
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

/// Dimension of the Newton–Euler state.
pub const NE_LEN: usize = 13;

/// The couple's law P = κ |φ̇|^m (sin α)^(−k) (physics §11), as plain numbers.
#[derive(Debug, Clone, Copy)]
pub struct Couple {
    pub kappa: f64,
    pub m: f64,
    pub k: f64,
}

/// Body constants of the second model, and an optional dissipative couple.
#[derive(Debug, Clone, Copy)]
pub struct NewtonEuler {
    pub mass: f64,
    pub radius: f64,
    pub gravity: f64,
    pub inertia_x: f64,
    pub inertia_z: f64,
    pub couple: Option<Couple>,
}

/// What one evaluation of the second model computes.
pub struct Evaluation {
    pub q_dot: Quaternion<f64>,
    pub omega_dot: V3,
    pub acceleration: V3,
    pub reaction: V3,
    /// The couple's power P (0 without a couple).
    pub power: f64,
}

impl NewtonEuler {
    /// The same body as `p`, read through its plain getters only.
    pub fn from_params(p: &CoinParams) -> Self {
        Self {
            mass: p.mass(),
            radius: p.radius(),
            gravity: p.gravity(),
            inertia_x: p.inertia_x(),
            inertia_z: p.inertia_z(),
            couple: None,
        }
    }

    /// The same body with a dissipative couple.
    pub fn with_couple(self, couple: Couple) -> Self {
        Self {
            couple: Some(couple),
            ..self
        }
    }

    /// The couple T = −P ω/|ω|² and its power P at world ω, with the lean axis e_Y (physics §11).
    fn couple_torque(&self, omega: &V3, e_y_lean: &V3) -> (V3, f64) {
        let Some(c) = self.couple else {
            return (Vector3::zeros(), 0.0);
        };
        let sin_alpha = e_y_lean.dot(&Vector3::y());
        let phi_dot = omega.dot(e_y_lean) / sin_alpha;
        let power = c.kappa * phi_dot.abs().powf(c.m) * sin_alpha.powf(-c.k);
        let w2 = omega.norm_squared();
        if w2 == 0.0 {
            return (Vector3::zeros(), power);
        }
        (omega * (-power / w2), power)
    }

    /// Converts the library's state: angles → quaternion (physics §1), lean-frame ω → world ω, centre from
    /// the contact point on the table (r_G = r_P − ρ, so y_G = a e_Y·e_y), v_G from no slip (v_G = −ω × ρ).
    pub fn state_from(&self, s: &State) -> [f64; NE_LEN] {
        let q = quaternion_from_angles(s.theta, s.phi, s.psi);
        let [_, e_y_lean, _] = lean_frame_from_normal(&(q * Vector3::z()));
        let omega = world_omega(s.theta, s.phi, [s.omega_x, s.omega_y, s.omega_z]);
        let rho = e_y_lean * -self.radius;
        let r_g = Vector3::new(s.x, -rho.y, s.z);
        let v_g = -omega.cross(&rho);
        let mut y = [0.0; NE_LEN];
        y[0..4].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        y[4..7].copy_from_slice(omega.as_slice());
        y[7..10].copy_from_slice(r_g.as_slice());
        y[10..13].copy_from_slice(v_g.as_slice());
        y
    }

    /// The orientation q = [w, x, y, z] of the state (not renormalised: the integrator keeps it near unit).
    pub fn quaternion(y: &[f64; NE_LEN]) -> Quaternion<f64> {
        Quaternion::new(y[0], y[1], y[2], y[3])
    }
    pub fn omega(y: &[f64; NE_LEN]) -> V3 {
        Vector3::new(y[4], y[5], y[6])
    }
    pub fn centre(y: &[f64; NE_LEN]) -> V3 {
        Vector3::new(y[7], y[8], y[9])
    }
    /// The rotation of the state's quaternion (normalised), body → world.
    fn rotation(y: &[f64; NE_LEN]) -> Matrix3<f64> {
        UnitQuaternion::from_quaternion(Self::quaternion(y))
            .to_rotation_matrix()
            .into_inner()
    }
    /// ρ = −a e_Y from the state's orientation.
    pub fn rho(&self, y: &[f64; NE_LEN]) -> V3 {
        let [_, e_y_lean, _] = lean_frame_from_normal(&Self::rotation(y).column(2).into_owned());
        e_y_lean * -self.radius
    }
    /// Contact point r_P = r_G + ρ.
    pub fn contact_point(&self, y: &[f64; NE_LEN]) -> V3 {
        Self::centre(y) + self.rho(y)
    }

    /// Solves for the contact force and the accelerations at state `y`.
    pub fn evaluate(&self, y: &[f64; NE_LEN]) -> Evaluation {
        let omega = Self::omega(y);
        let rot = Self::rotation(y);
        let e_z: V3 = rot.column(2).into_owned();
        // Lean frame and its rate, from ė_Z = ω × e_Z.
        let e_up = Vector3::y();
        let u = e_up.cross(&e_z);
        let u_len = u.norm();
        let e_x = u / u_len;
        let e_y_lean = e_z.cross(&e_x);
        let e_z_dot = omega.cross(&e_z);
        let u_dot = e_up.cross(&e_z_dot);
        let e_x_dot = u_dot / u_len - u * (u.dot(&u_dot) / (u_len * u_len * u_len));
        let e_y_dot = e_z_dot.cross(&e_x) + e_z.cross(&e_x_dot);
        let rho = e_y_lean * -self.radius;
        let rho_dot = e_y_dot * -self.radius;
        // World inertia and its inverse: I_w = Q diag(I_X, I_X, I_Z) Qᵀ.
        let body = Matrix3::from_diagonal(&Vector3::new(
            self.inertia_x,
            self.inertia_x,
            self.inertia_z,
        ));
        let inertia = rot * body * rot.transpose();
        let inertia_inv =
            rot * body.map(|v| if v == 0.0 { 0.0 } else { 1.0 / v }) * rot.transpose();
        let gyro = omega.cross(&(inertia * omega)); // ω × I_w ω
        let (torque, power) = self.couple_torque(&omega, &e_y_lean);
        // (1/M − [ρ]× I⁻¹ [ρ]×) R = g e_y − ω × ρ̇ − [ρ]× I⁻¹ (ω × I_w ω − T); the matrix is SPD.
        let p = rho.cross_matrix();
        let a = Matrix3::identity() / self.mass - p * inertia_inv * p;
        let b = e_up * self.gravity - omega.cross(&rho_dot) - p * (inertia_inv * (gyro - torque));
        let reaction = a
            .cholesky()
            .expect("the contact-force matrix is symmetric positive definite")
            .solve(&b);
        let acceleration = reaction / self.mass - e_up * self.gravity;
        let omega_dot = inertia_inv * (rho.cross(&reaction) - gyro + torque);
        let wq = Quaternion::from_imag(omega) * Self::quaternion(y);
        Evaluation {
            q_dot: wq * 0.5,
            omega_dot,
            acceleration,
            reaction,
            power,
        }
    }

    /// The lean θ of a state, from the normal alone: e_Z·e_y = −sin θ (physics §1, eq (9)).
    pub fn lean(y: &[f64]) -> f64 {
        let q = UnitQuaternion::from_quaternion(Quaternion::new(y[0], y[1], y[2], y[3]));
        (-(q * Vector3::z()).y).asin()
    }
}

/// Dimension of the dissipating Newton–Euler state: the 13 of [`NewtonEuler`] and W.
pub const NE_DISSIPATING_LEN: usize = NE_LEN + 1;

/// The Newton–Euler model with its couple's work W = ∫P dt as a 14th component.
pub struct Dissipating(pub NewtonEuler);

impl Dissipating {
    /// The 14-component state of a library state, with W = 0.
    pub fn state_from(&self, s: &State) -> [f64; NE_DISSIPATING_LEN] {
        let mut y = [0.0; NE_DISSIPATING_LEN];
        y[..NE_LEN].copy_from_slice(&self.0.state_from(s));
        y
    }
}

impl OdeSystem<NE_DISSIPATING_LEN> for Dissipating {
    fn rhs(&self, _t: f64, y: &[f64; NE_DISSIPATING_LEN], dydt: &mut [f64; NE_DISSIPATING_LEN]) {
        let mut inner = [0.0; NE_LEN];
        inner.copy_from_slice(&y[..NE_LEN]);
        let e = self.0.evaluate(&inner);
        dydt[0..4].copy_from_slice(&[e.q_dot.w, e.q_dot.i, e.q_dot.j, e.q_dot.k]);
        dydt[4..7].copy_from_slice(e.omega_dot.as_slice());
        dydt[7..10].copy_from_slice(&y[10..13]);
        dydt[10..13].copy_from_slice(e.acceleration.as_slice());
        dydt[NE_LEN] = e.power;
    }
}

impl OdeSystem<NE_LEN> for NewtonEuler {
    fn rhs(&self, _t: f64, y: &[f64; NE_LEN], dydt: &mut [f64; NE_LEN]) {
        let e = self.evaluate(y);
        dydt[0..4].copy_from_slice(&[e.q_dot.w, e.q_dot.i, e.q_dot.j, e.q_dot.k]);
        dydt[4..7].copy_from_slice(e.omega_dot.as_slice());
        dydt[7..10].copy_from_slice(&y[10..13]);
        dydt[10..13].copy_from_slice(e.acceleration.as_slice());
    }
}
