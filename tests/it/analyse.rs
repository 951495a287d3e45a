//! `analyse` proven by simulation and by values it does not compute itself (physics §9, §10):
//!
//! - the linear theory in closed form: σ of the centre-fixed motion and of straight rolling (physics §5),
//!   the tilt of straight rolling at ω_c growing like 1 + 2t²/5;
//! - kicked stable circles nutate at σ (eq (21)), measured from a simulation to 1e-6;
//! - displaced unstable circles grow at √(−σ²), to 1e-4 in the linear regime;
//! - the period T and heading advance ΔΦ of generic motions (disk, hoop, explicit inertias) by quadrature
//!   against a tight dop853 simulation, to 1e-10; the flat-landing and lift-off times against the events
//!   of `coin-log record`; a nutation of tiny amplitude (θ̇² with a near-double root) against 2π/σ;
//! - `coin-log analyse --json` for steady circles in and out of the unstable band against the eigenvalues
//!   of the numerically differentiated right-hand side (`linearisation.rs`), not the closed form;
//! - `coin-log analyse map`: the CSV's contract columns, its verdicts against the sign of σ², and the
//!   band's edges in closed form against bisection of σ² and against the grid;
//! - `verify`'s `nutation` check: it judges a wobble, skips a steady circle, and fails a recording whose
//!   time axis is stretched by 1e-6 (negative control).
//!
//! The simulations (the benchmarks' runners) sample 1/2048 of a nutation period apart, so the quintic
//! Hermite location of the turning points (`model::turning_points`) errs by ~(2π/2048)⁶/46080/2π ≈ 3e-21 of
//! a period: far below the tolerances.

// Helpers outside #[test] functions unwrap too: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used)]

use crate::linearisation;
use crate::support::physics::check_relative;
use crate::support::record::{coin_log, record_scene};
use crate::support::writers::rewrite_with_metadata;
use coin_log::analyse::linear::{displaced, kicked, nutation_frequency, straight_tilt_linear};
use coin_log::analyse::map::{boundary, closures, edge_leans};
use coin_log::analyse::Analysis;
use coin_log::integrate::Method;
use coin_log::model::nutation::Motion;
use coin_log::model::quadrature::bisect;
use coin_log::model::{
    centre_fixed_sigma_squared, critical_spin, steady_omega_y, steady_sigma_squared,
    straight_lambda_squared, Branch, Coin, CoinParams, Inertia, State, Steady, SteadyKind,
};
use coin_log::verify::{verify_file, CheckId, Options, Status};
use coin_log_bench::nutation::{generic_motions, growth_rate, turning_points, GROWTH_START};
use coin_log_bench::stability::suite_config;
use std::f64::consts::TAU;

/// Flat margin of the scenes (format.md: scene keys, `run.flat_margin`).
const FLAT_MARGIN: f64 = 1e-4;

fn circle(coin: &Coin, theta: f64, omega_z: f64, branch: Branch) -> State {
    Steady::new(
        coin,
        SteadyKind::Circle {
            theta,
            omega_z,
            branch,
        },
    )
    .unwrap()
    .state
}

/// (T, ΔΦ) of `state` measured from a dop853 run at rtol 1e-12 over `periods` periods of length
/// `period`, sampled 1/2048 of a period apart.
fn simulated_period(coin: &Coin, state: &State, period: f64, periods: f64) -> (f64, f64) {
    let config = suite_config(Method::Dop853, period / 2048.0);
    let (points, _) = turning_points(coin, state, &config, periods * period, period / 2048.0);
    let measured = points.measure().unwrap();
    (measured.period, measured.precession)
}

#[test]
fn nutation_frequency_matches_the_closed_forms_of_notes_section_5() {
    let coin = Coin::new(CoinParams::unit_disk());
    let theta = 0.7;
    let steady = Steady::new(
        &coin,
        SteadyKind::CentreFixed {
            theta,
            branch: Branch::Plus,
        },
    )
    .unwrap();
    let sigma = nutation_frequency(&coin, &steady).unwrap();
    let expected = centre_fixed_sigma_squared(&coin, theta).sqrt();
    println!("centre-fixed σ: measured {sigma}, expected {expected}, tolerance 1e-12");
    assert!((sigma - expected).abs() <= 1e-12 * expected);
    // Straight rolling above ω_c: σ² = −λ².
    let steady = Steady::new(&coin, SteadyKind::Straight { omega_z: 1.0 }).unwrap();
    let sigma = nutation_frequency(&coin, &steady).unwrap();
    let expected = (-straight_lambda_squared(&coin, 1.0)).sqrt();
    println!("straight σ: measured {sigma}, expected {expected} (1.2649), tolerance 1e-12");
    assert!((sigma - expected).abs() <= 1e-12 * expected);
}

#[test]
fn the_linear_tilt_of_straight_rolling_at_the_critical_spin_grows_like_t_squared() {
    // The linear theory at ω_c is the thin disk's δθ₀(1 + 2t²/5) (physics §5).
    let coin = Coin::new(CoinParams::unit_disk());
    let wc = critical_spin(&coin);
    for t in [1.0, 7.0, 20.0] {
        let linear = straight_tilt_linear(&coin, wc, 1.0, t);
        assert!(
            (linear - (1.0 + 0.4 * t * t)).abs() <= 1e-7 * linear,
            "t = {t}: {linear}"
        );
    }
}

#[test]
fn kicked_stable_circles_nutate_at_sigma() {
    // The kick δω_X = σ·1e-5 shifts the frequency by O(1e-10) (amplitude²): the 1e-6 tolerance is the
    // issue's and leaves room for the integrator over 10 periods.
    let disk = Coin::new(CoinParams::unit_disk());
    let hoop = Coin::new(CoinParams::new(2.0, 0.5, 9.81, Inertia::Hoop).unwrap());
    for (label, coin, theta, omega_z, branch) in [
        ("disk circle-plus", disk, 0.3, 1.0, Branch::Plus),
        ("disk circle-minus", disk, 0.3, 1.0, Branch::Minus),
        ("disk below the band", disk, 0.2, 0.08, Branch::Plus),
        ("disk beyond the band", disk, 0.4, 0.3, Branch::Plus),
        ("hoop", hoop, 0.7, -3.0, Branch::Minus),
    ] {
        let steady = circle(&coin, theta, omega_z, branch);
        let sigma = steady_sigma_squared(&coin, theta, steady.omega_y, omega_z).sqrt();
        let start = kicked(&coin, &steady, 1e-5);
        let (period, _) = simulated_period(&coin, &start, TAU / sigma, 10.0);
        check_relative(
            &format!("{label}: σ measured as 2π/T"),
            TAU / period,
            sigma,
            1e-6,
        );
    }
}

#[test]
fn a_kicked_circle_nutating_at_the_wrong_sigma_is_caught() {
    // Negative control: the measured frequency of circle-plus against σ of a circle 1 % faster.
    let coin = Coin::new(CoinParams::unit_disk());
    let steady = circle(&coin, 0.3, 1.0, Branch::Plus);
    let wrong = circle(&coin, 0.3, 1.01, Branch::Plus);
    let sigma = steady_sigma_squared(&coin, 0.3, wrong.omega_y, 1.01).sqrt();
    let (period, _) = simulated_period(&coin, &kicked(&coin, &steady, 1e-5), TAU / sigma, 10.0);
    let error = ((TAU / period) - sigma).abs() / sigma;
    println!("σ of the wrong circle: relative error {error:e}, far above 1e-6");
    assert!(error > 1e-3, "{error:e}");
}

#[test]
fn displaced_unstable_circles_grow_at_the_root_of_minus_sigma_squared() {
    // Displaced along the growing eigenvector by 1e-10 and fitted between 1e-9 and 1e-5 of a radian, where
    // the nonlinear terms are ≤ 1e-5 relative: the 1e-4.
    let coin = Coin::new(CoinParams::unit_disk());
    for (theta, omega_z) in [(0.2, 0.3), (0.05, 0.4), (0.3, 0.35)] {
        let steady = circle(&coin, theta, omega_z, Branch::Plus);
        let lambda = (-steady_sigma_squared(&coin, theta, steady.omega_y, omega_z)).sqrt();
        let start = displaced(&coin, &steady, GROWTH_START);
        let duration = 1e5_f64.ln() / lambda + 1.0;
        let config = suite_config(Method::Dop853, 1e-3);
        let rate = growth_rate(&coin, &steady, &start, &config, duration, 0.01 / lambda).unwrap();
        check_relative(
            &format!("θ0 = {theta}, ω_Z0 = {omega_z}: growth rate"),
            rate,
            lambda,
            1e-4,
        );
    }
}

#[test]
fn the_quadratures_period_and_heading_advance_agree_with_a_tight_simulation() {
    // The "Done when" bound, 1e-10 relative: measured ~1e-15 on the disk (dop853 at rtol 1e-12 keeps the
    // phase to ~1e-13 over 20 periods).
    for (name, coin, state) in generic_motions().unwrap() {
        let orbit = Analysis::of_state(&coin, &state, FLAT_MARGIN, None, None)
            .unwrap()
            .orbit;
        let Motion::Periodic {
            period, precession, ..
        } = orbit.motion
        else {
            panic!("{name}: {:?} is not periodic", orbit.motion);
        };
        assert!(
            orbit.error <= 1e-12,
            "{name}: quadrature error {:e}",
            orbit.error
        );
        let (t, phi) = simulated_period(&coin, &state, period, 20.0);
        check_relative(&format!("{name}: period T"), t, period, 1e-10);
        check_relative(
            &format!("{name}: heading advance ΔΦ"),
            phi,
            precession,
            1e-10,
        );
    }
}

#[test]
fn a_nutation_of_tiny_amplitude_has_the_linear_period() {
    // θ̇² = f(θ) with two turning points 2e-7 apart (nearly a double root): the quadrature's period is the
    // linearisation's 2π/σ up to the O(amplitude²) shift, and not NaN or a failed bracket.
    let coin = Coin::new(CoinParams::unit_disk());
    for (theta, omega_z, branch) in [(0.3, 1.0, Branch::Plus), (0.6, -2.0, Branch::Minus)] {
        let steady = circle(&coin, theta, omega_z, branch);
        let sigma2 = steady_sigma_squared(&coin, theta, steady.omega_y, omega_z);
        let orbit = Analysis::of_state(
            &coin,
            &kicked(&coin, &steady, 1e-7),
            FLAT_MARGIN,
            None,
            None,
        )
        .unwrap()
        .orbit;
        let Motion::Periodic { period, .. } = orbit.motion else {
            panic!("{:?}", orbit.motion);
        };
        check_relative(
            &format!("θ0 = {theta}: period of a 1e-7 nutation"),
            period,
            TAU / sigma2.sqrt(),
            1e-8,
        );
        assert!(orbit.theta_max - orbit.theta_min < 1e-6);
    }
}

/// `coin-log analyse SCENE --json [ARGS]` as a JSON object.
fn analyse_json(scene: &str, args: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let mut all = vec!["analyse", scene, "--json"];
    all.extend_from_slice(args);
    let out = coin_log(dir.path(), &all);
    assert!(
        out.status.success(),
        "{all:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn the_run_settings_analyse_does_not_use_do_not_refuse_the_analysis() {
    // A spin of 1e9 was refused for its samples over the scene's duration, which analyse never takes;
    // a rate or tolerance only record refuses did the same. The analysis is the scene's without them, and
    // flat_margin, which analyse uses, is still checked.
    let plain = analyse_json("circle-plus", &[]);
    let unused = [
        "--set=run.rate=1e12",
        "--set=run.rtol=1",
        "--set=run.duration=1e300",
        "--set=run.integrator=none-such",
    ];
    assert_eq!(analyse_json("circle-plus", &unused), plain);
    let fast = [
        "--set=initial.steady={kind=\"spin-upright\",omega_y=1e9}",
        "--set=run.duration=30",
    ];
    assert_eq!(analyse_json("circle-plus", &fast)["motion"], "steady");
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &["analyse", "circle-plus", "--set=run.flat_margin=2"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`run.flat_margin` = 2"));
}

/// The termination time of `coin-log record SCENE` (from its summary line "termination ... at t = X").
fn recorded_termination(scene: &str) -> (String, f64) {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &["record", scene, "--rtol", "1e-13", "--atol", "1e-15"],
    );
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let line = text
        .lines()
        .find(|l| l.starts_with("termination"))
        .unwrap_or_else(|| panic!("no termination line in {text}"));
    let time: f64 = line.rsplit("t = ").next().unwrap().trim().parse().unwrap();
    (line.to_string(), time)
}

#[test]
fn the_flat_landing_and_lift_off_times_are_those_of_the_recorded_events() {
    // The events are located by the integrator's root finding at rtol 1e-13; the quadrature's times by
    // adaptive Gauss–Legendre at 1e-14. Agreement to 1e-8 relative leaves room for the event location.
    let topple = analyse_json("topple", &[]);
    assert_eq!(topple["motion"], "flat-landing");
    assert_eq!(topple["period"], serde_json::Value::Null);
    let (line, time) = recorded_termination("topple");
    assert!(line.contains("flat-landing"), "{line}");
    check_relative(
        "topple: flat landing time",
        topple["flat_landing_time"].as_f64().unwrap(),
        time,
        1e-8,
    );
    let lift = analyse_json("lift-off", &[]);
    assert_eq!(lift["normal_stays_positive"], false);
    assert!(lift["min_normal"].as_f64().unwrap() < 0.0);
    let (line, time) = recorded_termination("lift-off");
    assert!(line.contains("lift-off"), "{line}");
    check_relative(
        "lift-off: time N reaches 0",
        lift["lift_off_time"].as_f64().unwrap(),
        time,
        1e-8,
    );
}

#[test]
fn analyse_json_has_the_contract_fields() {
    let expect = |v: &serde_json::Value, keys: &[&str]| {
        for key in keys {
            assert!(v.get(key).is_some(), "missing {key} in {v}");
        }
    };
    let wobble = analyse_json("wobble", &[]);
    expect(
        &wobble,
        &[
            "energy",
            "c1",
            "c2",
            "theta_min",
            "theta_max",
            "period",
            "precession",
            "max_friction_ratio",
            "min_normal",
            "steady",
        ],
    );
    assert!(wobble["steady"].is_null());
    assert!(wobble["period"].as_f64().unwrap() > 0.0);
    let circle = analyse_json("circle-plus", &[]);
    assert!(circle["period"].is_null() && circle["precession"].is_null());
    let steady = &circle["steady"];
    expect(
        steady,
        &[
            "kind",
            "omega_y",
            "phi_dot",
            "psi_dot",
            "r_g",
            "r_c",
            "sigma_squared",
            "eigenvalues",
            "verdict",
        ],
    );
    assert_eq!(steady["kind"], "circle");
    assert_eq!(steady["eigenvalues"].as_array().unwrap().len(), 4);
    assert_eq!(steady["verdict"], "stable");
}

/// `base_steady` is for a scene given as a perturbed steady motion (format.md: analyse --json). The
/// `euler-disk` scene starts exactly on its centre-fixed motion, with dissipation: its state is that
/// steady motion, not a perturbation of it (it printed "perturbed from" and repeated the steady object
/// as base_steady). A perturbed one keeps its base; a perturbed one without dissipation too.
#[test]
fn a_dissipative_scene_started_on_a_steady_motion_is_not_reported_as_perturbed() {
    let disk = analyse_json("euler-disk", &[]);
    assert_eq!(disk["motion"], "steady");
    assert_eq!(disk["steady"]["kind"], "centre-fixed");
    assert!(disk["base_steady"].is_null(), "{disk}");
    let kicked = analyse_json(
        "euler-disk",
        &["--set", "initial.perturbation={ theta = 1e-3 }"],
    );
    assert_eq!(kicked["base_steady"]["kind"], "centre-fixed", "{kicked}");
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(dir.path(), &["analyse", "euler-disk"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("perturbed from"), "{text}");
}

#[test]
fn analyse_is_right_for_steady_circles_in_and_out_of_the_band() {
    // σ² from `coin-log analyse --json` against the numerical Jacobian's eigenvalues (linearisation.rs),
    // which never use eq (21): 1e-10 of the size of σ²'s terms, and the verdict by their sign.
    let coin = Coin::new(CoinParams::unit_disk());
    for (theta, omega_z, branch, verdict) in [
        (0.2, 0.3, "+", "unstable"),
        (0.05, 0.4, "+", "unstable"),
        (0.3, 0.35, "+", "unstable"),
        (0.2, 0.08, "+", "stable"),
        (0.4, 0.3, "+", "stable"),
        (0.3, 1.0, "-", "stable"),
        (0.2, 0.6, "+", "stable"),
    ] {
        let v = analyse_json(
            "circle-plus",
            &[
                "--set",
                &format!("initial.steady.theta={theta}"),
                "--set",
                &format!("initial.steady.omega_z={omega_z}"),
                "--set",
                &format!("initial.steady.branch=\"{branch}\""),
            ],
        );
        let steady = &v["steady"];
        let sigma2 = steady["sigma_squared"].as_f64().unwrap();
        let omega_y = steady["omega_y"].as_f64().unwrap();
        let values = linearisation::eigenvalues(&coin, theta, omega_y, omega_z);
        let numerical = linearisation::sigma_squared_of(&values);
        let scale = coin_log::model::Linearisation::at(&coin, theta, omega_y, omega_z).scale();
        println!("θ0 = {theta}, ω_Z0 = {omega_z} ({branch}): σ² = {sigma2:e} (analyse) vs {numerical:e} (numerical Jacobian), {verdict}");
        assert!(
            (sigma2 - numerical).abs() <= 1e-10 * scale,
            "σ² {sigma2:e} vs {numerical:e}, tolerance {:e}",
            1e-10 * scale
        );
        assert_eq!(steady["verdict"], verdict, "{v}");
        let rate = values[3].re.abs().max(values[3].im.abs());
        let eig = &steady["eigenvalues"][2];
        let analysed = eig[0].as_f64().unwrap().abs() + eig[1].as_f64().unwrap().abs();
        check_relative("the non-zero eigenvalue's size", analysed, rate, 1e-8);
    }
}

/// The ω_Z0 in [lo, hi] where σ² changes sign on `branch` at lean θ₀, by root finding on the closed form
/// σ²(θ₀, ω_Z0) (eq (21)): sign changes over `samples` equal steps, each bisected to adjacent floats. An
/// independent route to the boundary of `boundary`.
fn sign_changes(
    coin: &Coin,
    theta0: f64,
    branch: Branch,
    (lo, hi): (f64, f64),
    samples: usize,
) -> Vec<f64> {
    let sigma2 = |w: f64| {
        let wy = steady_omega_y(coin, theta0, w, branch);
        steady_sigma_squared(coin, theta0, wy, w)
    };
    let mut out = Vec::new();
    let at = |j: usize| {
        #[allow(clippy::cast_precision_loss)]
        let x = j as f64 / samples.max(1) as f64;
        lo + (hi - lo) * x
    };
    let mut previous = (at(0), sigma2(at(0)));
    for j in 1..=samples {
        let w = at(j);
        let v = sigma2(w);
        if (v < 0.0) != (previous.1 < 0.0) {
            let negative_first = previous.1 < 0.0;
            let (a, b) = bisect(|x| (sigma2(x) < 0.0) == negative_first, previous.0, w);
            out.push(0.5 * (a + b));
        }
        previous = (w, v);
    }
    out
}

#[test]
fn the_bands_edges_in_closed_form_agree_with_bisection_and_the_grid() {
    let coin = Coin::new(CoinParams::unit_disk());
    // The closure: eq (24) for the thin disk is 2.75 u² + 19.5 u − 2.25 = 0, u = tan²θ₀ (physics §9).
    let closes = closures(&coin);
    assert_eq!(closes.len(), 1, "{closes:?}");
    let u = (405f64.sqrt() - 19.5) / 5.5;
    check_relative("closure lean", closes[0].theta0, u.sqrt().atan(), 1e-14);
    check_relative("closure spin", closes[0].omega_z0, 0.342_212, 2e-6);
    // The edges at the report's leans against the sign changes of σ² along ω_Z0, found by bisection.
    let leans = edge_leans(&coin);
    assert_eq!(leans, vec![0.05, 0.1, 0.15, 0.2, 0.25, 0.3]);
    for lean in leans {
        let mut closed: Vec<f64> = boundary(&coin, lean)
            .iter()
            .filter(|b| b.omega_z0 > 0.0 && b.branch == Branch::Plus)
            .map(|b| b.omega_z0)
            .collect();
        closed.sort_by(f64::total_cmp);
        let bisected = sign_changes(&coin, lean, Branch::Plus, (1e-6, 3.0), 3000);
        assert_eq!(closed.len(), 2, "θ0 = {lean}: {closed:?}");
        assert_eq!(bisected.len(), 2, "θ0 = {lean}: {bisected:?}");
        for (c, b) in closed.iter().zip(&bisected) {
            check_relative(&format!("θ0 = {lean}: edge"), *b, *c, 1e-12);
        }
        // Nothing on the − branch changes sign there.
        assert!(sign_changes(&coin, lean, Branch::Minus, (1e-6, 3.0), 3000).is_empty());
    }
    // Beyond the closure no circle is unstable.
    assert!(boundary(&coin, 0.33).is_empty());
}

#[test]
fn analyse_map_writes_the_contract_csv_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "analyse",
            "map",
            "--theta",
            "0.01:0.5:50",
            "--omega-z",
            "0.01:1:40",
            "--out",
            "maps",
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("closes at θ0 = 0.325043, ω_Z0 = 0.342212"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(dir.path().join("maps/stability-map.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "theta0,omega_z0,branch,omega_y0,sigma_squared,verdict"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 50 * 40 * 2);
    let coin = Coin::new(CoinParams::unit_disk());
    let mut unstable = 0;
    for row in &rows {
        let theta: f64 = row[0].parse().unwrap();
        let omega_z: f64 = row[1].parse().unwrap();
        let sigma2: f64 = row[4].parse().unwrap();
        let verdict = if sigma2 > 0.0 {
            "stable"
        } else if sigma2 < 0.0 {
            "unstable"
        } else {
            "marginal"
        };
        assert_eq!(row[5], verdict, "{row:?}");
        if verdict == "unstable" {
            unstable += 1;
            // Every unstable cell lies in the band: + branch, below the closure, between the edges.
            assert_eq!(row[2], "+", "{row:?}");
            let edges: Vec<f64> = boundary(&coin, theta)
                .iter()
                .filter(|b| b.omega_z0 > 0.0 && b.branch == Branch::Plus)
                .map(|b| b.omega_z0)
                .collect();
            assert_eq!(edges.len(), 2, "{row:?}");
            assert!(
                edges[0].min(edges[1]) < omega_z && omega_z < edges[0].max(edges[1]),
                "{row:?} outside {edges:?}"
            );
        }
    }
    assert!(unstable > 50, "{unstable} unstable cells");
    let svg = std::fs::read_to_string(dir.path().join("maps/stability-map.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("circle-plus"));
}

#[test]
fn analyse_rejects_bad_input_with_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (vec!["analyse", "map", "--theta", "0:1"], "A:B:N"),
        (vec!["analyse", "no-such-scene"], "no-such-scene"),
        (vec!["analyse", "map", "--branch", "x"], "branch"),
        // σ² ∝ ω_Z0² overflows past ω_Z0 ≈ 1e154: refused, not written as `inf` "marginal" and `NaN`
        // "unstable" rows; the number is named in exponent form, not as 160 digits.
        (
            vec!["analyse", "map", "--omega-z", "0:1e160:3"],
            "ω_Z0 = 5e159 (+ branch) gives ω_Y0 = 0, σ² = inf: too fast",
        ),
        // B − A = −inf made every value NaN and the map ran forever.
        (
            vec!["analyse", "map", "--omega-z", "1e308:-1e308:3"],
            "B − A = -inf overflows double precision",
        ),
    ] {
        let out = coin_log(dir.path(), &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(!dir.path().join("stability-map.csv").exists());
}

#[test]
fn negative_numbers_are_values_of_the_options_that_take_them() {
    // clap read `--theta -0.5:…` and `--duration -1` as unknown flags and advised `-- -1`, which fails too.
    let dir = tempfile::tempdir().unwrap();
    let map = [
        "analyse",
        "map",
        "--theta",
        "-0.5:-0.1:3",
        "--omega-z",
        "-1:1:3",
        "--out",
        "m",
    ];
    let out = coin_log(dir.path(), &map);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("m/stability-map.csv")).unwrap();
    assert!(csv.contains("\n-0.5,-1.0,+,"), "{csv}");
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--duration", "-1", "--dry-run"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("`run.duration` = -1 is outside (0, ∞)"),
        "{stderr}"
    );
}

#[test]
fn verify_judges_the_nutation_of_a_wobble_and_skips_a_steady_circle() {
    let dir = tempfile::tempdir().unwrap();
    let wobble = verify_file(
        &record_scene(dir.path(), "wobble", &[]),
        &Options::default(),
    );
    let check = wobble.check(CheckId::Nutation).unwrap();
    println!("wobble: {check:?}");
    assert_eq!(check.status, Status::Pass, "{check:?}");
    let circle = verify_file(
        &record_scene(dir.path(), "circle-plus", &[]),
        &Options::default(),
    );
    assert_eq!(
        circle.check(CheckId::Nutation).unwrap().status,
        Status::Skip
    );
}

/// Multiplies every time of a JSON message by `factor`: the field `t` and any {sec, nsec} timestamp.
fn stretch(value: &mut serde_json::Value, factor: f64) {
    match value {
        serde_json::Value::Object(map) => {
            if let (Some(sec), Some(nsec)) = (
                map.get("sec").and_then(serde_json::Value::as_i64),
                map.get("nsec").and_then(serde_json::Value::as_i64),
            ) {
                #[allow(clippy::cast_precision_loss, clippy::cast_possible_truncation)]
                let ns = ((sec as f64 * 1e9 + nsec as f64) * factor).round() as i64;
                map.insert("sec".into(), ns.div_euclid(1_000_000_000).into());
                map.insert("nsec".into(), ns.rem_euclid(1_000_000_000).into());
                return;
            }
            for (key, v) in map.iter_mut() {
                if key == "t" {
                    *v = serde_json::json!(v.as_f64().unwrap() * factor);
                } else {
                    stretch(v, factor);
                }
            }
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(|v| stretch(v, factor)),
        _ => {}
    }
}

#[test]
fn verify_fails_a_recording_whose_clock_runs_1e_6_fast() {
    // Negative control: every time (log times, `t`, timestamps, the result's termination_time) × (1 +
    // 1e-6). The values stay on the right orbit, so energy and the invariants cannot see it, nor
    // integrity; the measured period is 1e-6 too long.
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "wobble", &[]);
    let bad = dir.path().join("stretched.mcap");
    let factor = 1.0 + 1e-6;
    let stretch_end = |name: &str, entries: &mut std::collections::BTreeMap<String, String>| {
        if let Some(t) = entries
            .get_mut("termination_time")
            .filter(|_| name != "coin-log")
        {
            *t = (t.parse::<f64>().unwrap() * factor).to_string();
        }
    };
    rewrite_with_metadata(&good, &bad, &stretch_end, |e| {
        let mut v: serde_json::Value = serde_json::from_slice(e.data).unwrap();
        stretch(&mut v, factor);
        #[allow(
            clippy::cast_precision_loss,
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss
        )]
        let lt = match v.get("t").and_then(serde_json::Value::as_f64) {
            Some(t) => (t * 1e9).round() as u64,
            None => (*e.log_time as f64 * factor).round() as u64,
        };
        *e.log_time = lt;
        *e.data = serde_json::to_vec(&v).unwrap();
    });
    let r = verify_file(&bad, &Options::default());
    for c in &r.checks {
        println!(
            "{:<12} {:?} {:?} {:?}",
            c.id.to_string(),
            c.status,
            c.value,
            c.tolerance
        );
    }
    let c = r.check(CheckId::Nutation).unwrap();
    assert_eq!(c.status, Status::Fail, "{c:?}");
    let value = c.value.unwrap();
    assert!(
        (5e-7..=2e-6).contains(&value),
        "nutation: measured {value:e}, expected ~1e-6 (tolerance {:?})",
        c.tolerance
    );
    for id in [CheckId::Integrity, CheckId::Energy, CheckId::Invariants] {
        assert_eq!(r.check(id).unwrap().status, Status::Pass, "{id}");
    }
    assert_eq!(r.exit_code, 1);
}

/// `analyse map` checks its --out folder and files before any work, as every command does (it computed
/// the whole grid first: 1.2 s and 0.8 GB at the largest, then refused `--out /dev/null`); a grid that
/// fails after the check leaves no file, nor the folder it created.
#[test]
fn analyse_map_checks_its_outputs_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("taken")).unwrap();
    std::os::unix::fs::symlink("/etc/passwd", d.join("taken/stability-map.svg")).unwrap();
    // A grid the work refuses (σ² overflows): the outputs must be refused before it is reached.
    let failing = ["analyse", "map", "--omega-z", "1e300:1e301:3", "--out"];
    for (out, needle) in [
        ("/dev/null", "`/dev/null` is not a folder"),
        ("taken", "stability-map.svg` is a symbolic link"),
    ] {
        let mut args = failing.to_vec();
        args.push(out);
        let output = coin_log(d, &args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{stderr}");
        assert!(stderr.contains(needle), "{out}: {stderr}");
    }
    // Negative control: a folder it may write lets the work run, and its error leaves nothing behind.
    let mut args = failing.to_vec();
    args.push("fresh/map");
    let output = coin_log(d, &args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("σ² = inf: too fast"), "{stderr}");
    assert!(!d.join("fresh").exists(), "the created folder is removed");
    let mut left: Vec<_> = std::fs::read_dir(d.join("taken"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["stability-map.svg"], "only the link");
}

/// Straight rolling at ω_c = 1/√3 (thin disk) has σ² = 0 in exact arithmetic; in floating point `analyse`
/// prints σ² = 1.8e-16 and calls it `marginal` (zero to rounding, 64 ulp of the size of its terms). The
/// contract said `marginal` only for σ² = 0 and "σ² > 0 is stable", contradicting the object it printed;
/// it now states the rounding rule.
#[test]
fn a_marginal_verdict_with_a_nonzero_sigma_squared_is_the_rounding_rule_the_contract_states() {
    let dir = tempfile::tempdir().unwrap();
    let omega_c = format!("initial.steady.omega_z={:?}", 1.0 / 3f64.sqrt());
    let out = coin_log(
        dir.path(),
        &["analyse", "straight", "--json", "--set", &omega_c],
    );
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let steady = &v["steady"];
    assert_eq!(steady["verdict"], "marginal", "{steady}");
    let s2 = steady["sigma_squared"].as_f64().unwrap();
    assert!(s2 != 0.0 && s2.abs() < 1e-14, "{s2:e}");
    let format = std::fs::read_to_string(crate::support::repo().join("docs/format.md")).unwrap();
    let section = &format[format.find("## analyse --json").unwrap()..];
    let section = &section[..section.find("\n## ").unwrap_or(section.len())];
    assert!(
        section.contains("zero to rounding")
            && section.contains("is marginal whatever its printed"),
        "docs/format.md, analyse --json, must state when a nonzero σ² is marginal"
    );
}

/// A kick too small for double precision at a marginal state (spin-upright at Ω² = 0.8, θ kicked by
/// 1e-25): the quadrature's own estimate of its relative error is 56, and the command warns that its
/// period and advances are not reliable (it printed them to 17 digits without a word); an ordinary
/// scene gets no warning.
#[test]
fn an_unreliable_quadrature_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "analyse",
            "spin-upright",
            "--json",
            "--set",
            "initial.steady.omega_y=0.8944271909999159",
            "--set",
            "initial.perturbation={theta=1e-25}",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let error = v["quadrature_error"].as_f64().unwrap();
    assert!(error > 1.0, "{error}");
    assert!(
        stderr.contains(
            "warning: scene `spin-upright`: the quadrature's estimated relative error is"
        ) && stderr.contains("not reliable"),
        "{stderr}"
    );
    let out = coin_log(dir.path(), &["analyse", "wobble"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Straight rolling at ω_Z = 1 (stable) tilted by θ₀ nutates between θ₀ and 2θ₀ with the period of the
/// linearisation, 4.9672941328980 (unit scales), however small θ₀ is. The turning-point search stopped
/// its bisection after 200 halvings, 1e-12 above θ₀: at θ₀ = 1e-100 it gave θ up to 3.1e-73 and a period
/// of 1.4e14, with an estimated error of 3e-11. Below ~1e-154 θ² leaves the normal doubles and the
/// quadrature loses its digits (θ₀ = 1e-200 gave a period of 0, estimated 0): the estimate now says so,
/// and analyse warns.
#[test]
fn a_tiny_tilt_nutates_with_the_linear_period_or_is_said_unreliable() {
    for theta in ["1e-20", "1e-100", "1e-150"] {
        let v = analyse_json(
            "straight",
            &[
                "--set",
                &format!("initial.theta={theta}"),
                "--set",
                "initial.omega=[0,0,1]",
            ],
        );
        let theta: f64 = theta.parse().unwrap();
        let period = v["period"].as_f64().unwrap();
        check_relative("period", period, 4.967_294_132_898, 1e-11);
        check_relative(
            "theta_max",
            v["theta_max"].as_f64().unwrap(),
            2.0 * theta,
            1e-11,
        );
        assert!(v["quadrature_error"].as_f64().unwrap() < 1e-12, "{v}");
    }
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "analyse",
            "straight",
            "--json",
            "--set",
            "initial.theta=1e-200",
            "--set",
            "initial.omega=[0,0,1]",
        ],
    );
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["quadrature_error"].as_f64(), Some(1.0), "{v}");
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("the quadrature's estimated relative error is 1.0e0"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A circle leaning almost upright has ω_Y0 ~ 1/θ₀, which overflows as surely as a fast one: the refusal
/// said "too fast or too near flat" for θ₀ = 1e-300, which is neither; it names the upright side too.
#[test]
fn a_map_too_near_upright_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "analyse",
        "map",
        "--theta",
        "1e-300:1e-299:3",
        "--omega-z",
        "0:2:3",
    ];
    let output = coin_log(dir.path(), &args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("θ0 = 1e-300"), "{stderr}");
    assert!(stderr.contains("too near upright"), "{stderr}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing written"
    );
}
