//! The steady motions of physics §4 stay steady when integrated: θ and ω stay constant, φ and ψ advance at
//! the analytic rates, the centre stays on the circle of radius R_G about `circle_centre` and the contact
//! point on the circle of radius R_C (or, rolling straight, on the analytic line), over 20 time units
//! with rk4 at h = 1e-3 natural time units. Tolerance 1e-9 relative to the natural scales (a, √(g/a),
//! radians): rk4's truncation error on these smooth periodic motions is ~1e-12, so 1e-9 is tight enough
//! to catch any error in the steady relations (which would show as an O(1e-3..1) drift).

// Helpers outside #[test] functions unwrap too: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::physics::{self, rate_unit};
use crate::support::vectors;
use coin_log::model::{
    centre, contact_point, reaction, Branch, Coin, CoinParams, State, Steady, SteadyKind,
};

/// Natural time units of the run.
const DURATION: f64 = 20.0;
/// rk4 step in natural time units.
const STEP_NATURAL: f64 = 1e-3;
/// Allowed deviation from the steady motion (scaled, see the module doc).
const STEADY: f64 = 1e-9;

/// Centre of the circle traced by the coin's centre, in the table plane (x, z), for a motion that starts
/// from `start` (any φ₀, x₀, z₀): C = p₀ + (a ω_Z / φ̇)(sin φ₀, cos φ₀). `None` when φ̇ = 0.
fn circle_centre(steady: &Steady, coin: &Coin, start: &State) -> Option<(f64, f64)> {
    if steady.phi_dot == 0.0 {
        return None;
    }
    let scale = coin.params().radius() * start.omega_z / steady.phi_dot;
    let (sp, cp) = start.phi.sin_cos();
    Some((start.x + scale * sp, start.z + scale * cp))
}

/// Integrates `kind` from a shifted start (φ₀ = 0.7, x₀ = a, z₀ = −2a, to exercise `circle_centre`)
/// and returns the steady description for further checks.
fn stays_steady(label: &str, p: &CoinParams, kind: SteadyKind) -> Steady {
    let coin = Coin::new(*p);
    let steady = Steady::new(&coin, kind).unwrap();
    let (a, w) = (p.radius(), rate_unit(p));
    let start = State {
        phi: 0.7,
        x: a,
        z: -2.0 * a,
        ..steady.state
    };
    let h = STEP_NATURAL * p.time_unit();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let steps = (DURATION / STEP_NATURAL).round() as usize;
    let traj = physics::rk4_trajectory(&coin, &start.to_array(), h, steps, 10);
    let centre_of_circle = circle_centre(&steady, &coin, &start);
    let (mut d_theta, mut d_omega, mut d_angles, mut d_centre, mut d_contact) =
        (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    for (t, y) in &traj {
        let s = State::from_array(y);
        d_theta = d_theta.max((s.theta - start.theta).abs());
        d_omega = d_omega.max(
            vectors::max_diff(
                &[s.omega_x, s.omega_y, s.omega_z],
                &[start.omega_x, start.omega_y, start.omega_z],
            ) / w,
        );
        // φ and ψ grow linearly; relative to the angle turned (at least one radian).
        let phi_err = (s.phi - (start.phi + steady.phi_dot * t)).abs();
        let psi_err = (s.psi - (start.psi + steady.psi_dot * t)).abs();
        let turned = (steady.phi_dot * t)
            .abs()
            .max((steady.psi_dot * t).abs())
            .max(1.0);
        d_angles = d_angles.max(phi_err.max(psi_err) / turned);
        let c = centre(&coin, &s);
        let cp = contact_point(&coin, &s);
        match (centre_of_circle, steady.r_g, steady.r_c) {
            (Some((cx, cz)), Some(r_g), Some(r_c)) => {
                d_centre = d_centre.max(((c.x - cx).hypot(c.z - cz) - r_g).abs() / a);
                d_contact = d_contact.max(((cp.x - cx).hypot(cp.z - cz) - r_c).abs() / a);
            }
            _ => {
                // Straight rolling (φ̇ = 0): the centre moves along (−cos φ₀, sin φ₀) at speed a ω_Z, eq ẋ, ż.
                let v = a * start.omega_z;
                let (sp, cp0) = start.phi.sin_cos();
                let expected = [start.x - v * cp0 * t, start.z + v * sp * t];
                let travelled = (v * t).abs().max(a);
                d_centre = d_centre.max(vectors::max_diff(&[c.x, c.z], &expected) / travelled);
                d_contact = d_contact.max(vectors::max_diff(&[cp.x, cp.z], &expected) / travelled);
            }
        }
    }
    physics::check(
        &format!("{label}: max |theta - theta0| [rad]"),
        d_theta,
        0.0,
        STEADY,
    );
    physics::check(
        &format!("{label}: max |omega - omega0| / sqrt(g/a)"),
        d_omega,
        0.0,
        STEADY,
    );
    physics::check(
        &format!("{label}: max |phi, psi - analytic| / angle turned"),
        d_angles,
        0.0,
        STEADY,
    );
    physics::check(
        &format!("{label}: max |centre distance - R_G| / a"),
        d_centre,
        0.0,
        STEADY,
    );
    physics::check(
        &format!("{label}: max |contact distance - R_C| / a"),
        d_contact,
        0.0,
        STEADY,
    );
    // physics §4: in every steady motion N = Mg and the friction is the centripetal force Ma|ω_Y ω_Z|/cos θ₀.
    let r = reaction(&coin, &steady.state);
    let weight = p.mass() * p.gravity();
    let s0 = steady.state;
    let centripetal = p.mass() * a * (s0.omega_y * s0.omega_z).abs() / s0.theta.cos();
    // Round-off of terms of size max(Mg, centripetal force).
    let force_scale = weight.max(centripetal);
    physics::check(
        &format!("{label}: (N - M g) / max(M g, F)"),
        (r.normal - weight) / force_scale,
        0.0,
        1e-14,
    );
    physics::check(
        &format!("{label}: (F - M a |wY wZ| / cos(theta0)) / max(M g, F)"),
        (r.friction - centripetal) / force_scale,
        0.0,
        1e-14,
    );
    steady
}

/// R_C = a |R_G/a + sgn(ω_Y ω_Z) sin θ₀| (physics §4.3), checked against the library's r_c.
fn sign_rule(label: &str, p: &CoinParams, steady: &Steady) {
    let s = steady.state;
    let a = p.radius();
    let r_g = steady.r_g.unwrap();
    let sign = (s.omega_y * s.omega_z).signum();
    let expected = a * (r_g / a + sign * s.theta.sin()).abs();
    physics::check(
        &format!("{label}: R_C / a vs |R_G/a + sgn(wY wZ) sin(theta0)| (sgn = {sign})"),
        steady.r_c.unwrap() / a,
        expected / a,
        1e-14,
    );
}

#[test]
fn straight_rolling_stays_straight() {
    let p = physics::unit_disk();
    stays_steady(
        "straight, w_Z = 1",
        &p,
        SteadyKind::Straight { omega_z: 1.0 },
    );
    stays_steady(
        "straight, w_Z = -2.5",
        &p,
        SteadyKind::Straight { omega_z: -2.5 },
    );
    let g = physics::general();
    stays_steady(
        "general, straight",
        &g,
        SteadyKind::Straight {
            omega_z: 1.5 * rate_unit(&g),
        },
    );
}

#[test]
fn the_coin_rolling_round_its_fixed_centre_stays_on_its_circle() {
    for (label, p) in [
        ("unit disk", physics::unit_disk()),
        ("general", physics::general()),
    ] {
        for branch in [Branch::Plus, Branch::Minus] {
            for theta in [0.5, -0.9] {
                let s = stays_steady(
                    &format!("{label}, centre fixed, theta {theta}, {branch:?}"),
                    &p,
                    SteadyKind::CentreFixed { theta, branch },
                );
                // R_C = a |sin θ₀| and R_G = 0 (physics §4.2).
                physics::check("R_G / a", s.r_g.unwrap() / p.radius(), 0.0, 0.0);
                physics::check(
                    "R_C / a",
                    s.r_c.unwrap() / p.radius(),
                    f64::abs(theta.sin()),
                    1e-15,
                );
            }
        }
    }
}

#[test]
fn the_notes_circle_example_has_the_stated_radii_and_stays_on_them() {
    let p = physics::unit_disk();
    let s = stays_steady(
        "circle theta 0.3, w_Z 1, +",
        &p,
        SteadyKind::Circle {
            theta: 0.3,
            omega_z: 1.0,
            branch: Branch::Plus,
        },
    );
    physics::check("R_G (physics §4 example)", s.r_g.unwrap(), 4.897855, 1e-6);
    physics::check("R_C (physics §4 example)", s.r_c.unwrap(), 5.193375, 1e-6);
    sign_rule("circle theta 0.3, w_Z 1, +", &p, &s);
}

#[test]
fn circles_on_both_branches_and_every_sign_stay_steady_and_follow_the_contact_radius_sign_rule() {
    for (label, p) in [
        ("unit disk", physics::unit_disk()),
        ("general", physics::general()),
    ] {
        let w = rate_unit(&p);
        for (theta, omega_z) in [
            (0.3, 1.0),
            (0.3, -1.0),
            (-0.3, 1.0),
            (-0.6, -2.0),
            (1.0, 0.5),
        ] {
            for branch in [Branch::Plus, Branch::Minus] {
                let name = format!("{label}, circle theta {theta}, w_Z {omega_z}, {branch:?}");
                let s = stays_steady(
                    &name,
                    &p,
                    SteadyKind::Circle {
                        theta,
                        omega_z: omega_z * w,
                        branch,
                    },
                );
                sign_rule(&name, &p, &s);
            }
        }
    }
}

#[test]
fn a_stably_spinning_upright_coin_stays_upright() {
    for (label, p) in [
        ("unit disk", physics::unit_disk()),
        ("general", physics::general()),
    ] {
        // Ω² = 4 g/a is above the stability bound Mga/(I_X + Ma²) for both bodies (physics §5).
        let omega = 2.0 * rate_unit(&p);
        let s = stays_steady(
            &format!("{label}, spin upright, Omega = 2 sqrt(g/a)"),
            &p,
            SteadyKind::SpinUpright { omega_y: omega },
        );
        physics::check("R_G", s.r_g.unwrap(), 0.0, 0.0);
    }
}

/// For general parameters the steady relation of physics §4 holds at the constructed states:
/// I_X tan θ ω_Y² + (I_Z + Ma²) ω_Z ω_Y − Mga sin θ = 0 to round-off (relative to its largest term), and
/// eq (14) then gives ω̇_X = 0.
#[test]
fn the_steady_quadratic_holds_for_general_parameters() {
    let p = physics::general();
    let coin = Coin::new(p);
    let w = rate_unit(&p);
    for (theta, omega_z) in [(0.3, 1.0), (-0.7, 0.2), (1.3, -3.0), (0.05, 4.0)] {
        for branch in [Branch::Plus, Branch::Minus] {
            let s = Steady::new(
                &coin,
                SteadyKind::Circle {
                    theta,
                    omega_z: omega_z * w,
                    branch,
                },
            )
            .unwrap()
            .state;
            let terms = [
                p.inertia_x() * theta.tan() * s.omega_y * s.omega_y,
                (p.inertia_z() + p.ma2()) * s.omega_z * s.omega_y,
                -p.mass() * p.gravity() * p.radius() * theta.sin(),
            ];
            let biggest = terms.iter().map(|t| t.abs()).fold(0.0, f64::max);
            physics::check(
                &format!("steady quadratic residual / largest term, theta {theta}, w_Z {omega_z}, {branch:?}"),
                terms.iter().sum::<f64>() / biggest,
                0.0,
                1e-14,
            );
            let acc = coin.angular_acceleration(s.theta, s.omega_x, s.omega_y, s.omega_z);
            physics::check(
                "eq (14): w_X dot (I_X + M a^2) / largest term",
                acc.x * (p.inertia_x() + p.ma2()) / biggest,
                0.0,
                1e-14,
            );
        }
    }
}
