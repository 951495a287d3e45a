//! Property tests at random bodies and states (proptest, fixed seed, 64 cases each): the exact flow
//! conserves energy (∇E · f = 0), the centre moves with the no-slip velocity, the quaternion is a unit
//! quaternion carrying the coin's normal to the lean frame's e_Z, the library's reaction and angular
//! accelerations equal the independent Newton–Euler model's, and the steady constructors are fixed points.
//! Tolerances are relative to the size of the terms that cancel (round-off of O(10) operations: 1e-13;
//! the measured worst is ~1.5e-15).

// Helpers outside #[test] functions unwrap too: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::newton_euler::NewtonEuler;
use crate::support::physics::{self, rate_unit};
use crate::support::vectors::{self, V3};
use coin_log::model::{
    centre, contact_point, orientation, reaction, Branch, Coin, CoinParams, State, Steady,
    SteadyKind, STATE_LEN,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// Round-off bound relative to the largest cancelling term.
const ROUND_OFF: f64 = 1e-13;

fn config() -> Config {
    Config {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x00c0_1d06),
        failure_persistence: None,
        ..Config::default()
    }
}

/// A random state for `p`: |θ| ≤ 1.4, any heading and spin, |ω_i| ≤ 5 √(g/a), centre within 10 a.
fn state() -> impl Strategy<Value = [f64; STATE_LEN]> {
    (
        -1.4..1.4,
        -10.0..10.0,
        -10.0..10.0,
        -5.0..5.0,
        -5.0..5.0,
        -5.0..5.0,
        -10.0..10.0,
        -10.0..10.0,
    )
        .prop_map(|(t, f, s, wx, wy, wz, x, z)| [t, f, s, wx, wy, wz, x, z])
}

fn scaled(p: &CoinParams, u: &[f64; STATE_LEN]) -> State {
    let (w, a) = (rate_unit(p), p.radius());
    State {
        theta: u[0],
        phi: u[1],
        psi: u[2],
        omega_x: u[3] * w,
        omega_y: u[4] * w,
        omega_z: u[5] * w,
        x: u[6] * a,
        z: u[7] * a,
    }
}

fn rhs(coin: &Coin, s: &State) -> [f64; STATE_LEN] {
    let mut f = [0.0; STATE_LEN];
    coin.derivative(&s.to_array(), &mut f);
    f
}

fn within(what: &str, residual: f64, scale: f64) -> Result<(), TestCaseError> {
    let relative = residual.abs() / scale;
    println!("{what}: |residual| / scale = {relative:.2e} (tolerance {ROUND_OFF:.0e})");
    prop_assert!(
        relative <= ROUND_OFF,
        "{what}: residual {residual:e}, scale {scale:e}, relative {relative:e} > {ROUND_OFF:e}"
    );
    Ok(())
}

proptest! {
    #![proptest_config(config())]

    /// dE/dt = ∂E/∂θ θ̇ + Σ ∂E/∂ω_i ω̇_i with ∂E/∂θ = −Mga sin θ, ∂E/∂ω_X = (I_X + Ma²) ω_X,
    /// ∂E/∂ω_Y = I_X ω_Y, ∂E/∂ω_Z = (I_Z + Ma²) ω_Z (physics §3), must vanish for the RHS of eqs (14)–(17).
    /// Scale: the sum of the absolute values of every product that enters.
    #[test]
    fn the_exact_flow_conserves_energy(p in physics::random_body(), u in state()) {
        let coin = Coin::new(p);
        let s = scaled(&p, &u);
        let f = rhs(&coin, &s);
        let (ma2, ix, iz) = (p.ma2(), p.inertia_x(), p.inertia_z());
        let mga = p.mass() * p.gravity() * p.radius();
        let (t, wx, wy, wz) = (s.theta, s.omega_x, s.omega_y, s.omega_z);
        let terms = [
            -mga * t.sin() * f[0],
            (ix + ma2) * wx * f[3],
            ix * wy * f[4],
            (iz + ma2) * wz * f[5],
        ];
        // The products inside ω̇ cancel too; bound them by |∂E/∂ω_i| × (sum of |terms| of ω̇_i).
        let tan = t.tan();
        let inner = [
            ((iz + ma2) * (wy * wz).abs() + ix * wy * wy * tan.abs() + mga * t.sin().abs()) * wx.abs(),
            ix * wy.abs() * ((wx * wy * tan).abs() + iz / ix * (wz * wx).abs()),
            (iz + ma2) * wz.abs() * ma2 / (iz + ma2) * (wx * wy).abs(),
        ];
        let scale: f64 = terms.iter().map(|v| v.abs()).sum::<f64>() + inner.iter().sum::<f64>() + f64::MIN_POSITIVE;
        within("dE/dt", terms.iter().sum(), scale)?;
    }

    /// The centre's velocity from the RHS, (ẋ, −a sin θ θ̇, ż), equals −ω × ρ with ρ = −a e_Y and
    /// ω = ω_X e_X + ω_Y e_Y + ω_Z e_Z from the lean frame built independently (physics §1).
    #[test]
    fn the_centre_moves_with_the_no_slip_velocity(p in physics::random_body(), u in state()) {
        let coin = Coin::new(p);
        let s = scaled(&p, &u);
        let f = rhs(&coin, &s);
        let a = p.radius();
        let v = V3::new(f[6], -a * s.theta.sin() * f[0], f[7]);
        let [_, e_y_lean, _] = vectors::lean_frame(s.theta, s.phi);
        let omega = vectors::world_omega(s.theta, s.phi, [s.omega_x, s.omega_y, s.omega_z]);
        let no_slip = -omega.cross(&(e_y_lean * -a));
        within("|v_G + omega x rho|", (v - no_slip).amax(), a * (omega.norm() + rate_unit(&p)))?;
    }

    /// |q| = 1; q rotates the body normal (0, 0, 1) to e_Z = (cos θ sin φ, −sin θ, cos θ cos φ) (eq (7)'s
    /// third row, derived from the rotations of physics §1); and the contact point is centre − a e_Y with
    /// e_Y = e_Z × (e_y × e_Z)/|e_y × e_Z| built from that rotated normal.
    #[test]
    fn the_quaternion_carries_the_normal_and_places_the_contact_point(p in physics::random_body(), u in state()) {
        let coin = Coin::new(p);
        let s = scaled(&p, &u);
        let q = orientation(&s);
        within("|q| - 1", q.norm() - 1.0, 1.0)?;
        let n = q.transform_vector(&V3::z());
        let (st, ct) = s.theta.sin_cos();
        let (sp, cp) = s.phi.sin_cos();
        within("|q e_z - e_Z|", (n - V3::new(ct * sp, -st, ct * cp)).amax(), 1.0)?;
        let [_, e_y_lean, _] = vectors::lean_frame_from_normal(&n);
        let expected = centre(&coin, &s) - e_y_lean * p.radius();
        let cp_lib = contact_point(&coin, &s);
        within("|contact - (centre - a e_Y)|", (cp_lib - expected).amax(), p.radius() * (1.0 + u[6].abs() + u[7].abs()))?;
    }

    /// At any state, the library's reaction (physics §3) equals the contact force the Newton–Euler model
    /// solves for, and its angular acceleration, carried to the world frame
    /// (ω̇ = Σ ω̇_i e_i + Ω × ω with the lean frame's rate Ω = θ̇ e_X + φ̇ e_y), equals the Newton–Euler ω̇.
    #[test]
    fn the_library_and_the_newton_euler_model_agree_at_every_state(p in physics::random_body(), u in state()) {
        let coin = Coin::new(p);
        let s = scaled(&p, &u);
        let ne = NewtonEuler::from_params(&p);
        let eval = ne.evaluate(&ne.state_from(&s));
        let r = reaction(&coin, &s).force;
        let w = rate_unit(&p);
        let omega_size = V3::new(s.omega_x, s.omega_y, s.omega_z).norm() + w;
        let tan = s.theta.tan().abs().max(1.0);
        let force_scale = p.mass() * (p.gravity() + p.radius() * omega_size * omega_size * tan);
        within("|R_library - R_Newton-Euler|", (r - eval.reaction).amax(), force_scale)?;

        let f = rhs(&coin, &s);
        let [e_x, e_y_lean, e_z] = vectors::lean_frame(s.theta, s.phi);
        let omega = vectors::world_omega(s.theta, s.phi, [s.omega_x, s.omega_y, s.omega_z]);
        let frame_rate = e_x * f[0] + V3::y() * f[1];
        let omega_dot = e_x * f[3] + e_y_lean * f[4] + e_z * f[5] + frame_rate.cross(&omega);
        within("|omega dot library - Newton-Euler|", (omega_dot - eval.omega_dot).amax(), omega_size * omega_size * tan / s.theta.cos())?;
    }

    /// Each steady constructor gives a fixed point of eqs (14)–(17): θ̇ = ω̇ = 0 to round-off (relative to
    /// the largest term of eq (14)), and the analytic φ̇, ψ̇ equal eqs (18)–(19).
    #[test]
    fn steady_constructors_give_fixed_points_of_the_equations(
        p in physics::random_body(),
        theta_magnitude in 0.01..1.5_f64,
        theta_negative in any::<bool>(),
        omega_z_natural in -5.0..5.0_f64,
        plus in any::<bool>(),
        kind_index in 0..4_usize,
    ) {
        let coin = Coin::new(p);
        let theta = if theta_negative { -theta_magnitude } else { theta_magnitude };
        let branch = if plus { Branch::Plus } else { Branch::Minus };
        let omega = omega_z_natural * rate_unit(&p);
        let kind = match kind_index {
            0 => SteadyKind::Straight { omega_z: omega },
            1 => SteadyKind::CentreFixed { theta, branch },
            2 => SteadyKind::SpinUpright { omega_y: omega },
            _ => SteadyKind::Circle { theta, omega_z: omega, branch },
        };
        let steady = Steady::new(&coin, kind).unwrap();
        let s = steady.state;
        let f = rhs(&coin, &s);
        let (ma2, ix, iz) = (p.ma2(), p.inertia_x(), p.inertia_z());
        let eq14_terms = [
            (iz + ma2) * s.omega_y * s.omega_z,
            ix * s.omega_y * s.omega_y * s.theta.tan(),
            p.mass() * p.gravity() * p.radius() * s.theta.sin(),
        ];
        let biggest = eq14_terms.iter().map(|v| v.abs()).fold(f64::MIN_POSITIVE, f64::max);
        within(&format!("{kind:?}: theta dot"), f[0], rate_unit(&p))?;
        within(&format!("{kind:?}: (I_X + Ma^2) omega_X dot"), (ix + ma2) * f[3], biggest)?;
        within(&format!("{kind:?}: omega_Y dot, omega_Z dot"), f[4].abs().max(f[5].abs()), rate_unit(&p).powi(2))?;
        within("phi dot", f[1] - steady.phi_dot, steady.phi_dot.abs().max(rate_unit(&p)))?;
        within("psi dot", f[2] - steady.psi_dot, steady.psi_dot.abs().max(rate_unit(&p)))?;
    }
}

/// Negative control for the energy property: with the sign of I_X ω_Y² tan θ in eq (14) flipped, ∇E · f is
/// of the order of its terms, not of round-off.
#[test]
fn a_flipped_sign_in_eq_14_breaks_energy_conservation() {
    let p = physics::unit_disk();
    let coin = Coin::new(p);
    let s = State {
        theta: 0.4,
        omega_x: 0.35,
        omega_y: -0.6,
        omega_z: 2.2,
        ..State::default()
    };
    let f = rhs(&coin, &s);
    let (ma2, ix) = (p.ma2(), p.inertia_x());
    // ω̇_X changes by 2 I_X ω_Y² tan θ / (I_X + Ma²) when the sign flips.
    let wrong_wx_dot = f[3] + 2.0 * ix * s.omega_y * s.omega_y * s.theta.tan() / (ix + ma2);
    let terms = |wx_dot: f64| {
        -p.mass() * p.gravity() * p.radius() * s.theta.sin() * f[0]
            + (ix + ma2) * s.omega_x * wx_dot
            + ix * s.omega_y * f[4]
            + (p.inertia_z() + ma2) * s.omega_z * f[5]
    };
    let (right, wrong) = (terms(f[3]), terms(wrong_wx_dot));
    println!(
        "dE/dt with eq (14): {right:.3e}; with the flipped sign: {wrong:.3e} (must exceed 1e-3)"
    );
    assert!(right.abs() < 1e-15 && wrong.abs() > 1e-3);
}
