//! Every formula of physics §3 against an independent computation along simulated motions:
//! energy constant; R = M dv/dt + M g e_y with dv/dt from finite differences of the centre's position;
//! F = √(R_x² + R_z²) and its closed form; N = Mg − Ma(ω_X² cos θ + ω̇_X sin θ); the quaternion equal to the
//! rotation of eq (7); the contact point's speed a|ψ̇|.

use crate::support::physics::{self, rate_unit, wobbling};
use crate::support::vectors::{self, V3};
use coin_log::model::{
    centre, contact_point, energy, orientation, reaction, Coin, CoinParams, State,
};

/// Eighth-order central difference weights for the first derivative (offsets −4..4, times 1/H).
const FD1: [f64; 9] = [
    1.0 / 280.0,
    -4.0 / 105.0,
    1.0 / 5.0,
    -4.0 / 5.0,
    0.0,
    4.0 / 5.0,
    -1.0 / 5.0,
    4.0 / 105.0,
    -1.0 / 280.0,
];
/// Eighth-order central difference weights for the second derivative (offsets −4..4, times 1/H²).
const FD2: [f64; 9] = [
    -1.0 / 560.0,
    8.0 / 315.0,
    -1.0 / 5.0,
    8.0 / 5.0,
    -205.0 / 72.0,
    8.0 / 5.0,
    -1.0 / 5.0,
    8.0 / 315.0,
    -1.0 / 560.0,
];

fn fd(weights: &[f64; 9], values: &[f64], i: usize, scale: f64) -> f64 {
    (0..9).map(|k| weights[k] * values[i + k - 4]).sum::<f64>() * scale
}

fn cases() -> [(&'static str, CoinParams); 3] {
    [
        ("unit thin disk", physics::unit_disk()),
        ("unit hoop", physics::unit_hoop()),
        ("general", physics::general()),
    ]
}

/// A trajectory of 20 natural time units sampled every `spacing` natural units (rk4, 10 steps per sample).
fn trajectory(p: &CoinParams, spacing: f64) -> (f64, Vec<State>) {
    let coin = Coin::new(*p);
    let big_h = spacing * p.time_unit();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let samples = (20.0 / spacing).round() as usize;
    let traj = physics::rk4_trajectory(
        &coin,
        &wobbling(p).to_array(),
        big_h / 10.0,
        samples * 10,
        10,
    );
    (
        big_h,
        traj.iter().map(|(_, y)| State::from_array(y)).collect(),
    )
}

/// Energy is constant along a trajectory; rk4's drift at h = 1e-3 natural units is ~1e-13 relative,
/// so 1e-11 of M g a is a tight bound that a wrong energy formula (or wrong RHS) misses by far.
#[test]
fn energy_is_constant_along_wobbling_trajectories() {
    for (label, p) in cases() {
        let coin = Coin::new(p);
        let (_, states) = trajectory(&p, 0.01);
        let e0 = energy(&coin, &states[0]).total;
        let drift = states
            .iter()
            .map(|s| (energy(&coin, s).total - e0).abs())
            .fold(0.0, f64::max);
        physics::check(
            &format!("{label}: max |E(t) - E(0)| / (M g a) over 20 time units"),
            drift / p.energy_scale(),
            0.0,
            1e-11,
        );
        // The parts add up, and the potential is M g a cos θ.
        let e = energy(&coin, &states[500]);
        physics::check(
            &format!("{label}: kinetic + potential - total"),
            e.kinetic + e.potential - e.total,
            0.0,
            1e-15 * e.total.abs(),
        );
    }
}

/// R = M dv/dt + M g e_y with the centre's acceleration from an 8th-order second difference of its
/// position (x, a cos θ, z) on a grid of 0.01 natural time units. Truncation ~H⁸ω¹⁰ and round-off
/// ~ε|x|/H² are both ≲ 1e-10 of Mg; tolerance 1e-8 of Mg.
/// On the same samples, N = Mg − Ma(ω_X² cos θ + ω̇_X sin θ) with ω̇_X differenced from ω_X, and the closed
/// form F = Ma √((ω̇_Z − ω_X ω_Y)² + (ω_X² sin θ − ω̇_X cos θ − ω_Y ω_Z / cos θ)²) with ω̇ differenced.
#[test]
fn the_reaction_equals_mass_times_the_differenced_centre_acceleration_plus_weight() {
    for (label, p) in cases() {
        let coin = Coin::new(p);
        let (big_h, states) = trajectory(&p, 0.01);
        let (m, a, g) = (p.mass(), p.radius(), p.gravity());
        let pos: [Vec<f64>; 3] = [
            states.iter().map(|s| s.x).collect(),
            states.iter().map(|s| a * s.theta.cos()).collect(),
            states.iter().map(|s| s.z).collect(),
        ];
        let wx: Vec<f64> = states.iter().map(|s| s.omega_x).collect();
        let wz: Vec<f64> = states.iter().map(|s| s.omega_z).collect();
        let (mut worst_r, mut worst_n, mut worst_f, mut worst_closed) =
            (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
        for i in (4..states.len() - 4).step_by(25) {
            let s = &states[i];
            let acc = V3::from([0, 1, 2].map(|k| fd(&FD2, &pos[k], i, 1.0 / (big_h * big_h))));
            let expected = acc * m + V3::y() * (m * g);
            let r = reaction(&coin, s);
            worst_r = worst_r.max((r.force - expected).amax());
            // N from physics §3's "equivalently" form, ω̇_X by differences.
            let wx_dot = fd(&FD1, &wx, i, 1.0 / big_h);
            let wz_dot = fd(&FD1, &wz, i, 1.0 / big_h);
            let (st, ct) = s.theta.sin_cos();
            let n_alt = m * g - m * a * (s.omega_x * s.omega_x * ct + wx_dot * st);
            worst_n = worst_n.max((r.normal - n_alt).abs());
            worst_f = worst_f.max((r.friction - r.force.x.hypot(r.force.z)).abs());
            let closed = m
                * a
                * (wz_dot - s.omega_x * s.omega_y)
                    .hypot(s.omega_x * s.omega_x * st - wx_dot * ct - s.omega_y * s.omega_z / ct);
            worst_closed = worst_closed.max((r.friction - closed).abs());
        }
        let weight = m * g;
        physics::check(
            &format!("{label}: max |R - (M dv/dt + M g e_y)| / (M g)"),
            worst_r / weight,
            0.0,
            1e-8,
        );
        physics::check(
            &format!("{label}: max |N - (Mg - Ma(wX^2 cos + wX' sin))| / (M g)"),
            worst_n / weight,
            0.0,
            1e-9,
        );
        physics::check(
            &format!("{label}: max |F - hypot(R_x, R_z)| / (M g)"),
            worst_f / weight,
            0.0,
            1e-15,
        );
        physics::check(
            &format!("{label}: max |F - closed form of physics §3| / (M g)"),
            worst_closed / weight,
            0.0,
            1e-9,
        );
    }
}

/// The centre's velocity from an 8th-order first difference of its position equals the no-slip velocity
/// −ω × ρ, ρ = −a e_Y, computed from the lean frame of physics §1 (not from the library's ẋ, ż).
#[test]
fn the_differenced_centre_velocity_is_the_no_slip_velocity() {
    for (label, p) in cases() {
        let (big_h, states) = trajectory(&p, 0.01);
        let a = p.radius();
        let pos: [Vec<f64>; 3] = [
            states.iter().map(|s| s.x).collect(),
            states.iter().map(|s| a * s.theta.cos()).collect(),
            states.iter().map(|s| s.z).collect(),
        ];
        let mut worst = 0.0_f64;
        for i in (4..states.len() - 4).step_by(25) {
            let s = &states[i];
            let v = V3::from([0, 1, 2].map(|k| fd(&FD1, &pos[k], i, 1.0 / big_h)));
            let [_, e_y_lean, _] = vectors::lean_frame(s.theta, s.phi);
            let omega = vectors::world_omega(s.theta, s.phi, [s.omega_x, s.omega_y, s.omega_z]);
            let no_slip = -omega.cross(&(e_y_lean * -a));
            worst = worst.max((v - no_slip).amax());
        }
        physics::check(
            &format!("{label}: max |dr_G/dt (differenced) + omega x rho| / (a sqrt(g/a))"),
            worst / (a * rate_unit(&p)),
            0.0,
            1e-10,
        );
    }
}

/// The contact point moves at speed a|ψ̇| (physics §3): both sides by 8th-order differences (of the contact
/// point and of ψ), so neither eq (19) nor ẋ, ż enter.
#[test]
fn the_contact_point_moves_at_speed_a_times_the_spin_rate() {
    for (label, p) in cases() {
        let coin = Coin::new(p);
        let (big_h, states) = trajectory(&p, 0.01);
        let cps: Vec<_> = states.iter().map(|s| contact_point(&coin, s)).collect();
        let (xc, zc): (Vec<f64>, Vec<f64>) = cps.iter().map(|c| (c.x, c.z)).unzip();
        let psi: Vec<f64> = states.iter().map(|s| s.psi).collect();
        let mut worst = 0.0_f64;
        for i in (4..states.len() - 4).step_by(25) {
            let speed = fd(&FD1, &xc, i, 1.0 / big_h).hypot(fd(&FD1, &zc, i, 1.0 / big_h));
            let expected = p.radius() * fd(&FD1, &psi, i, 1.0 / big_h).abs();
            worst = worst.max((speed - expected).abs());
        }
        physics::check(
            &format!("{label}: max |contact speed - a |psi dot|| / (a sqrt(g/a))"),
            worst / (p.radius() * rate_unit(&p)),
            0.0,
            1e-10,
        );
        // The contact point is on the table and a below the centre along −e_Y.
        let s = &states[777];
        let (c, cp) = (centre(&coin, s), contact_point(&coin, s));
        let [_, e_y_lean, _] = vectors::lean_frame(s.theta, s.phi);
        let expected = c - e_y_lean * p.radius();
        physics::check(
            &format!("{label}: |contact point - (centre - a e_Y)| / a"),
            (cp - expected).amax() / p.radius(),
            0.0,
            4e-15, // a few ulps of the coordinates
        );
    }
}

/// The library's quaternion equals the rotation of eq (7) followed by the spin ψ: rotating the body axes
/// gives q e_x = cos ψ e_X + sin ψ e_Y, q e_y = −sin ψ e_X + cos ψ e_Y, q e_z = e_Z, with e_X, e_Y, e_Z the
/// rows of eq (7) written out literally. Round-off only: 1e-14.
#[test]
fn the_quaternion_is_the_rotation_of_eq_7_followed_by_the_spin() {
    let angles: [f64; 7] = [-1.4, -0.7, -0.1, 0.0, 0.3, 1.1, 1.5];
    let headings: [f64; 6] = [-7.0, -2.0, 0.0, 0.4, 2.9, 13.0];
    let mut worst = 0.0_f64;
    let mut worst_norm = 0.0_f64;
    for &theta in &angles {
        for &phi in &headings {
            for &psi in &headings {
                let (st, ct) = theta.sin_cos();
                let (sp, cp) = phi.sin_cos();
                let (ss, cs) = psi.sin_cos();
                // Eq (7), row by row.
                let e_x = V3::new(cp, 0.0, -sp);
                let e_y = V3::new(st * sp, ct, st * cp);
                let e_z = V3::new(ct * sp, -st, ct * cp);
                let q = orientation(&State {
                    theta,
                    phi,
                    psi,
                    ..State::default()
                });
                let expected = [e_x * cs + e_y * ss, e_x * -ss + e_y * cs, e_z];
                for (axis, want) in [V3::x(), V3::y(), V3::z()].iter().zip(expected) {
                    worst = worst.max((q.transform_vector(axis) - want).amax());
                }
                worst_norm = worst_norm.max((q.norm() - 1.0).abs());
            }
        }
    }
    physics::check(
        "max |q e_i - eq (7) axes| over 252 angle triples",
        worst,
        0.0,
        1e-14,
    );
    physics::check("max ||q| - 1|", worst_norm, 0.0, 1e-15);
}

/// A wrong formula is caught: the note's uncorrected F (R_y in place of R_z, §8 item 4) differs from
/// √(R_x² + R_z²) by a large margin on a wobbling motion (negative control for the F check).
#[test]
fn the_uncorrected_friction_formula_of_the_note_is_rejected() {
    let p = physics::unit_disk();
    let coin = Coin::new(p);
    let s = wobbling(&p);
    let r = reaction(&coin, &s);
    let wrong = r.force.x.hypot(r.force.y);
    let diff = (wrong - r.friction).abs() / (p.mass() * p.gravity());
    println!("|F_uncorrected - F| / (M g) = {diff:.3e}, must exceed 1e-2");
    assert!(diff > 1e-2);
}
