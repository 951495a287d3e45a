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

use super::vectors::{
    add, column, cross, dot, lean_frame_from_normal, mat_vec, norm, quat_matrix, quat_mul,
    quaternion_from_angles, scale, sub, world_omega, Quat, V3,
};
use coin_log::integrate::OdeSystem;
use coin_log::model::{CoinParams, State};

/// Dimension of the Newton–Euler state.
pub const NE_LEN: usize = 13;

/// Body constants of the second model.
#[derive(Debug, Clone, Copy)]
pub struct NewtonEuler {
    pub mass: f64,
    pub radius: f64,
    pub gravity: f64,
    pub inertia_x: f64,
    pub inertia_z: f64,
}

type M3 = [[f64; 3]; 3];

fn mat_mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}
fn transpose(a: &M3) -> M3 {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}
fn skew(v: V3) -> M3 {
    [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]
}
fn det(a: &M3) -> f64 {
    dot(a[0], cross(a[1], a[2]))
}
/// Solves A x = b by Cramer's rule (A is a well-conditioned 3×3 SPD matrix here).
fn solve(a: &M3, b: V3) -> V3 {
    let d = det(a);
    let mut x = [0.0; 3];
    for (j, xj) in x.iter_mut().enumerate() {
        let mut aj = *a;
        for i in 0..3 {
            aj[i][j] = b[i];
        }
        *xj = det(&aj) / d;
    }
    x
}

/// What one evaluation of the second model computes.
pub struct Evaluation {
    pub q_dot: Quat,
    pub omega_dot: V3,
    pub acceleration: V3,
    pub reaction: V3,
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
        }
    }

    /// Converts the library's state: angles → quaternion (physics §1), lean-frame ω → world ω, centre from
    /// the contact point on the table (r_G = r_P − ρ, so y_G = a e_Y·e_y), v_G from no slip (v_G = −ω × ρ).
    pub fn state_from(&self, s: &State) -> [f64; NE_LEN] {
        let q = quaternion_from_angles(s.theta, s.phi, s.psi);
        let [_, e_y_lean, _] = lean_frame_from_normal(column(&quat_matrix(q), 2));
        let omega = world_omega(s.theta, s.phi, [s.omega_x, s.omega_y, s.omega_z]);
        let rho = scale(-self.radius, e_y_lean);
        let r_g = [s.x, -rho[1], s.z];
        let v_g = scale(-1.0, cross(omega, rho));
        [
            q[0], q[1], q[2], q[3], omega[0], omega[1], omega[2], r_g[0], r_g[1], r_g[2], v_g[0],
            v_g[1], v_g[2],
        ]
    }

    pub fn quaternion(y: &[f64; NE_LEN]) -> Quat {
        [y[0], y[1], y[2], y[3]]
    }
    pub fn omega(y: &[f64; NE_LEN]) -> V3 {
        [y[4], y[5], y[6]]
    }
    pub fn centre(y: &[f64; NE_LEN]) -> V3 {
        [y[7], y[8], y[9]]
    }
    /// ρ = −a e_Y from the state's orientation.
    pub fn rho(&self, y: &[f64; NE_LEN]) -> V3 {
        let [_, e_y_lean, _] = lean_frame_from_normal(column(&quat_matrix(Self::quaternion(y)), 2));
        scale(-self.radius, e_y_lean)
    }
    /// Contact point r_P = r_G + ρ.
    pub fn contact_point(&self, y: &[f64; NE_LEN]) -> V3 {
        add(Self::centre(y), self.rho(y))
    }

    /// Solves for the contact force and the accelerations at state `y`.
    pub fn evaluate(&self, y: &[f64; NE_LEN]) -> Evaluation {
        let q = Self::quaternion(y);
        let omega = Self::omega(y);
        let rot = quat_matrix(q);
        let e_z = column(&rot, 2);
        // Lean frame and its rate, from ė_Z = ω × e_Z.
        let e_up = [0.0, 1.0, 0.0];
        let u = cross(e_up, e_z);
        let u_len = norm(u);
        let e_x = scale(1.0 / u_len, u);
        let e_y_lean = cross(e_z, e_x);
        let e_z_dot = cross(omega, e_z);
        let u_dot = cross(e_up, e_z_dot);
        let e_x_dot = sub(
            scale(1.0 / u_len, u_dot),
            scale(dot(u, u_dot) / (u_len * u_len * u_len), u),
        );
        let e_y_dot = add(cross(e_z_dot, e_x), cross(e_z, e_x_dot));
        let rho = scale(-self.radius, e_y_lean);
        let rho_dot = scale(-self.radius, e_y_dot);
        // World inertia and its inverse.
        let body = [
            [self.inertia_x, 0.0, 0.0],
            [0.0, self.inertia_x, 0.0],
            [0.0, 0.0, self.inertia_z],
        ];
        let body_inv = [
            [1.0 / self.inertia_x, 0.0, 0.0],
            [0.0, 1.0 / self.inertia_x, 0.0],
            [0.0, 0.0, 1.0 / self.inertia_z],
        ];
        let rot_t = transpose(&rot);
        let inertia = mat_mul(&rot, &mat_mul(&body, &rot_t));
        let inertia_inv = mat_mul(&rot, &mat_mul(&body_inv, &rot_t));
        let gyro = cross(omega, mat_vec(&inertia, omega)); // ω × I_w ω
                                                           // (1/M − [ρ]× I⁻¹ [ρ]×) R = g e_y − ω × ρ̇ − [ρ]× I⁻¹ (ω × I_w ω)
        let p = skew(rho);
        let pip = mat_mul(&p, &mat_mul(&inertia_inv, &p));
        let mut a = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] = -pip[i][j] + if i == j { 1.0 / self.mass } else { 0.0 };
            }
        }
        let b = sub(
            sub(scale(self.gravity, e_up), cross(omega, rho_dot)),
            mat_vec(&p, mat_vec(&inertia_inv, gyro)),
        );
        let reaction = solve(&a, b);
        let acceleration = sub(scale(1.0 / self.mass, reaction), scale(self.gravity, e_up));
        let omega_dot = mat_vec(&inertia_inv, sub(cross(rho, reaction), gyro));
        let wq = quat_mul([0.0, omega[0], omega[1], omega[2]], q);
        Evaluation {
            q_dot: [0.5 * wq[0], 0.5 * wq[1], 0.5 * wq[2], 0.5 * wq[3]],
            omega_dot,
            acceleration,
            reaction,
        }
    }
}

impl OdeSystem<NE_LEN> for NewtonEuler {
    fn rhs(&self, _t: f64, y: &[f64; NE_LEN], dydt: &mut [f64; NE_LEN]) {
        let e = self.evaluate(y);
        dydt[0..4].copy_from_slice(&e.q_dot);
        dydt[4..7].copy_from_slice(&e.omega_dot);
        dydt[7..10].copy_from_slice(&y[10..13]);
        dydt[10..13].copy_from_slice(&e.acceleration);
    }
}
