//! The library's angle model (eqs (14)–(19)) against an independent world-frame Newton–Euler model
//! (`support::newton_euler`): both are integrated from the same physical state with rk4 and must describe
//! the same motion. A wrong sign or factor in either shows up as a disagreement of order 1, far above the
//! 1e-9 tolerance; the negative control at the end proves it by flipping one sign.

use crate::support::newton_euler::{NewtonEuler, NE_LEN};
use crate::support::physics::{self, rate_unit, wobbling};
use crate::support::vectors::{quat_distance, world_omega};
use coin_log::integrate::{
    run_method, Flow, Method, MethodConfig, NoEvents, OdeSystem, RunEnd, RunSettings,
};
use coin_log::model::{centre, contact_point, orientation, Coin, CoinParams, State, STATE_LEN};

/// Duration of the comparison [time units of the parameters].
const DURATION: f64 = 20.0;
/// rk4 step in natural time units √(a/g): the global truncation error (~h⁴ ≈ 6e-14 per natural time
/// unit times the error growth of a wobbling motion) stays well below the tolerance.
const STEP_NATURAL: f64 = 5e-4;
/// Agreement required, relative to the natural scales: positions / a, angular velocities / √(g/a), and the
/// quaternion (dimensionless). Both models are exact up to rk4's truncation error (~1e-12 per unit time),
/// so 1e-9 leaves room for error growth on a wobbling motion, and is ~1e8 below a sign error.
const AGREEMENT: f64 = 1e-9;

/// The largest scaled disagreements between an 8-state angle model and the Newton–Euler model over the
/// run, sampled 200 times: (centre, contact point, quaternion, world ω).
fn disagreement<S: OdeSystem<STATE_LEN>>(
    angle_model: &S,
    p: &CoinParams,
    method: Option<MethodConfig>,
) -> [f64; 4] {
    let coin = Coin::new(*p);
    let ne = NewtonEuler::from_params(p);
    let start = wobbling(p);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let steps = (DURATION / (STEP_NATURAL * p.time_unit())).ceil() as usize;
    #[allow(clippy::cast_precision_loss)]
    let step = DURATION / steps as f64;
    let every = steps / 200;
    let a_traj = match method {
        None => physics::rk4_trajectory(angle_model, &start.to_array(), step, steps, every),
        Some(config) => {
            let mut out = Vec::new();
            #[allow(clippy::cast_precision_loss)]
            let settings = {
                // The rk4 samples fall on multiples of `every` steps up to `steps`: end on the last one.
                let interval = step * every as f64;
                RunSettings {
                    t0: 0.0,
                    t_end: interval * (steps / every) as f64,
                    sample_interval: interval,
                }
            };
            let outcome = run_method(
                &config,
                angle_model,
                &start.to_array(),
                &settings,
                &NoEvents,
                |t, y| {
                    out.push((t, *y));
                    Flow::Continue
                },
            );
            assert_eq!(outcome.termination, RunEnd::Completed);
            out
        }
    };
    let n_traj =
        physics::rk4_trajectory::<NE_LEN, _>(&ne, &ne.state_from(&start), step, steps, every);
    assert_eq!(a_traj.len(), n_traj.len());
    let (a, w) = (p.radius(), rate_unit(p));
    let mut worst = [0.0_f64; 4];
    let mut theta_range = (f64::MAX, f64::MIN);
    for ((_, ya), (_, yn)) in a_traj.iter().zip(&n_traj) {
        let s = State::from_array(ya);
        theta_range = (theta_range.0.min(s.theta), theta_range.1.max(s.theta));
        let c = centre(&coin, &s);
        let cp = contact_point(&coin, &s);
        let q = orientation(&s);
        let omega = world_omega(s.theta, s.phi, [s.omega_x, s.omega_y, s.omega_z]);
        let d = [
            (c - NewtonEuler::centre(yn)).amax() / a,
            (cp - ne.contact_point(yn)).amax() / a,
            quat_distance(&q, &NewtonEuler::quaternion(yn)),
            (omega - NewtonEuler::omega(yn)).amax() / w,
        ];
        for (wk, dk) in worst.iter_mut().zip(d) {
            *wk = wk.max(dk);
        }
    }
    println!(
        "theta stayed in [{:.3}, {:.3}]",
        theta_range.0, theta_range.1
    );
    worst
}

fn models_agree(label: &str, p: &CoinParams) {
    models_agree_with(label, p, None);
}

/// The angle model integrated by `method` (rk4 at the fine step when `None`) against the Newton–Euler
/// model integrated by rk4.
fn models_agree_with(label: &str, p: &CoinParams, method: Option<MethodConfig>) {
    let coin = Coin::new(*p);
    let worst = disagreement(&coin, p, method);
    for (what, d) in [
        "centre / a",
        "contact point / a",
        "quaternion (up to sign)",
        "world omega / sqrt(g/a)",
    ]
    .iter()
    .zip(worst)
    {
        physics::check(
            &format!("{label}: max |angle model - Newton-Euler| of {what}"),
            d,
            0.0,
            AGREEMENT,
        );
    }
}

#[test]
fn the_angle_model_and_a_newton_euler_model_agree_for_the_thin_disk() {
    models_agree("unit thin disk", &physics::unit_disk());
}

#[test]
fn the_angle_model_and_a_newton_euler_model_agree_for_the_hoop() {
    models_agree("unit hoop", &physics::unit_hoop());
}

#[test]
fn the_angle_model_and_a_newton_euler_model_agree_for_general_parameters() {
    models_agree(
        "M = 0.5, a = 2, g = 9.81, I_X = 0.35, I_Z = 0.6",
        &physics::general(),
    );
}

#[test]
fn the_angle_model_and_a_newton_euler_model_agree_for_a_scaled_thin_disk() {
    let p = CoinParams::new(0.5, 2.0, 9.81, coin_log::model::Inertia::ThinDisk).unwrap();
    models_agree("thin disk M = 0.5, a = 2, g = 9.81", &p);
}

/// The contact force the Newton–Euler model solves for is the reaction of physics §3.
#[test]
fn the_newton_euler_contact_force_equals_the_reaction_of_notes_section_3() {
    for p in [
        physics::unit_disk(),
        physics::unit_hoop(),
        physics::general(),
    ] {
        let coin = Coin::new(p);
        let ne = NewtonEuler::from_params(&p);
        let s = wobbling(&p);
        let r_ne = ne.evaluate(&ne.state_from(&s)).reaction;
        let r = coin_log::model::reaction(&coin, &s).force;
        let weight = p.mass() * p.gravity();
        // Two algebraically different round-off paths: 1e-13 of the weight.
        physics::check(
            "max |R_library - R_Newton-Euler| / (M g)",
            (r - r_ne).amax() / weight,
            0.0,
            1e-13,
        );
    }
}

/// The library's right-hand side with one sign flipped: + I_X ω_Y² tan θ in eq (14) instead of −.
struct FlippedCoin {
    params: CoinParams,
}

impl OdeSystem<STATE_LEN> for FlippedCoin {
    fn rhs(&self, _t: f64, y: &[f64; STATE_LEN], dydt: &mut [f64; STATE_LEN]) {
        let p = &self.params;
        let (ma2, ix, iz) = (p.ma2(), p.inertia_x(), p.inertia_z());
        let mga = p.mass() * p.gravity() * p.radius();
        let [theta, phi, _psi, wx, wy, wz, _x, _z] = *y;
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let tt = st / ct;
        let a = p.radius();
        dydt[0] = wx;
        dydt[1] = wy / ct;
        dydt[2] = wz + wy * tt;
        dydt[3] = (-(iz + ma2) * wy * wz + ix * wy * wy * tt + mga * st) / (ix + ma2); // sign flipped
        dydt[4] = wx * wy * tt + iz / ix * wz * wx;
        dydt[5] = ma2 / (iz + ma2) * wx * wy;
        dydt[6] = a * (-wz * cp + wx * ct * sp);
        dydt[7] = a * (wz * sp + wx * ct * cp);
    }
}

/// Negative control: the same comparison, run on a copy of eq (14) with the I_X ω_Y² tan θ term's sign
/// flipped, must fail by orders of magnitude (here: by more than 1e4 × the tolerance).
#[test]
fn a_flipped_sign_in_eq_14_makes_the_two_models_disagree_by_orders_of_magnitude() {
    for (label, p) in [
        ("unit thin disk", physics::unit_disk()),
        ("general", physics::general()),
    ] {
        let worst = disagreement(&FlippedCoin { params: p }, &p, None);
        let biggest = worst.iter().copied().fold(0.0, f64::max);
        println!(
            "{label}, flipped sign: disagreement {biggest:.3e} (centre, contact, q, omega = {worst:?}); \
             must exceed {:.1e}",
            1e4 * AGREEMENT
        );
        assert!(
            biggest > 1e4 * AGREEMENT,
            "the negative control did not fail: {biggest:e}"
        );
    }
}

/// Issue 4: dop853 at rtol 1e-12 on the angle model agrees with the independent model to 1e-9, for the
/// thin disk, the hoop and general parameters.
#[test]
fn dop853_on_the_angle_model_agrees_with_the_newton_euler_model() {
    let config = MethodConfig {
        method: Method::Dop853,
        rtol: 1e-12,
        atol: 1e-14,
        step: 0.0,
    };
    let general = CoinParams::new(
        0.5,
        2.0,
        9.81,
        coin_log::model::Inertia::Explicit {
            inertia_x: 0.35,
            inertia_z: 0.6,
        },
    )
    .unwrap();
    for (label, p) in [
        ("dop853, thin disk", CoinParams::unit_disk()),
        (
            "dop853, hoop",
            CoinParams::new(1.0, 1.0, 1.0, coin_log::model::Inertia::Hoop).unwrap(),
        ),
        ("dop853, general parameters", general),
    ] {
        models_agree_with(label, &p, Some(config));
    }
}
