//! The hard-case suite of `bench stability` as tests, one per case, each with an assertion on
//! what the case measures. Horizons are those of `SuiteOptions::quick()`: the same 100 nutation periods
//! for the fast-spin step limits, 10 nutation periods near flat (bench: 20), 20 time units of marginal
//! rolling (bench: 30), a long horizon of 10³ (bench: 10⁴) and 5 time units of scale invariance (bench: 10).
//! Every run of every case must end completed or at a physical event, never with NaN or a numerical failure.
//! (The physics they are judged against is tested on its own: `analyse.rs`, `events.rs`.)

use coin_log::integrate::Method;
use coin_log::model::Inertia;
use coin_log_bench::nutation::{generic_periods, stable_circles, unstable_circles};
use coin_log_bench::stability::{dimensionless_difference, scaled_wobble};
use coin_log_bench::stability::{
    drift_history, fast_spin, long_horizon_config, marginal, near_flat, release, scale_difference,
    StabilityRow, SuiteOptions, RK4_STABILITY_LIMIT, SCALES,
};
use coin_log_bench::{default_config, run_sampled, Trajectory};

fn assert_honest_ending(rows: &[StabilityRow], allowed: &[&str]) {
    for r in rows {
        assert!(
            allowed.contains(&r.termination.as_str()),
            "{} with {}: ended `{}`, allowed {allowed:?}",
            r.case,
            r.integrator,
            r.termination
        );
        assert!(r.energy_drift.is_finite(), "{r:?}");
        assert!(r.measured.is_none_or(f64::is_finite), "{r:?}");
    }
}

#[test]
fn fast_spin_step_limit_of_rk4_is_its_imaginary_axis_bound_and_gauss4_stays_stable() {
    for omega_z in [50.0, 500.0] {
        let rows = fast_spin(omega_z, &SuiteOptions::quick()).unwrap();
        assert_honest_ending(&rows, &["completed"]);
        for r in rows.iter().filter(|r| r.quantity == "nutation σ") {
            println!(
                "ω_Z = {omega_z}, {}: state error {:e} (≤ 1e-8)",
                r.integrator,
                r.max_error.unwrap()
            );
            assert!(r.max_error.unwrap() <= 1e-8, "{r:?}");
        }
        let limit = |m: Method| {
            rows.iter()
                .find(|r| r.integrator == m && r.quantity.starts_with("largest stable"))
                .and_then(|r| r.measured)
                .unwrap()
        };
        let rk4 = limit(Method::Rk4);
        println!("ω_Z = {omega_z}: rk4 largest stable h·σ {rk4:.4}, expected 2√2 = {RK4_STABILITY_LIMIT:.4} ± 3%");
        assert!((rk4 / RK4_STABILITY_LIMIT - 1.0).abs() <= 0.03);
        let gauss4 = limit(Method::Gauss4);
        println!(
            "ω_Z = {omega_z}: gauss4 largest stable h·σ {gauss4:.4} (A-stable: ≥ 10 expected)"
        );
        assert!(gauss4 >= 10.0);
    }
}

#[test]
fn near_flat_motions_are_integrated_or_end_at_the_flat_landing() {
    let options = SuiteOptions::quick();
    for theta in [1.5, 1.56, 1.5705] {
        let rows = near_flat(theta, &options).unwrap();
        assert_honest_ending(&rows, &["completed", "flat-landing"]);
        for r in rows.iter().filter(|r| r.integrator == Method::Dop853) {
            let error = r.max_error.unwrap();
            println!(
                "{}: dop853 state error {error:e} (≤ 1e-8), max tan θ {:.0}",
                r.case,
                r.measured.unwrap()
            );
            assert!(error <= 1e-8, "{r:?}");
        }
    }
    let rows = near_flat(1.5705, &options).unwrap();
    let kicked_tan = rows
        .iter()
        .filter(|r| r.case.ends_with("kicked"))
        .filter_map(|r| r.measured)
        .fold(0.0, f64::max);
    println!("θ = 1.5705 kicked: max tan θ {kicked_tan:.0} (in the thousands)");
    assert!(kicked_tan >= 1000.0);
}

#[test]
fn flat_landing_and_lift_off_are_located_to_1e_9_against_the_quadrature() {
    for (theta0, name) in [(0.6, "flat-landing"), (0.2, "lift-off")] {
        let rows = release(theta0, name).unwrap();
        assert_honest_ending(&rows, &[name]);
        for r in &rows {
            let (t, expected) = (r.measured.unwrap(), r.expected.unwrap());
            println!("θ₀ = {theta0} {}: {name} at {t:.13}, quadrature {expected:.13}, |Δt| {:e} (≤ 1e-9)", r.integrator, (t - expected).abs());
            assert!((t - expected).abs() <= 1e-9);
        }
    }
}

#[test]
fn straight_rolling_at_the_critical_spin_grows_like_t_squared() {
    // Against the linear theory, which at ω_c is the thin disk's δθ₀(1 + 2t²/5) (analyse.rs tests that).
    let horizon = SuiteOptions::quick().marginal_horizon;
    let mut finals = Vec::new();
    for offset in [1e-3, 0.0, -1e-3] {
        let rows = marginal(offset, horizon);
        assert_honest_ending(&rows, &["completed"]);
        for r in &rows {
            let deviation = r.max_error.unwrap();
            println!("ω_c(1{offset:+e}) {}: θ(T)/θ₀ {:.6} vs linear {:.6}, max relative deviation {deviation:e} (≤ 1e-4)", r.integrator, r.measured.unwrap(), r.expected.unwrap());
            assert!(deviation <= 1e-4);
        }
        finals.push(rows[0].measured.unwrap());
    }
    // Negative control: the three spins are told apart, and in the right order (stable grows least).
    println!("θ(T)/θ₀ at ω_c(1 + 1e-3), ω_c, ω_c(1 − 1e-3): {finals:?}");
    assert!(finals[0] < finals[1] && finals[1] < finals[2]);
    assert!(finals[2] / finals[0] > 1.0 + 1e-3);
}

#[test]
fn gauss4_energy_error_stays_bounded_while_rk4_drifts() {
    let horizon = SuiteOptions::quick().long_horizon;
    let drift_at = |m: Method, t: f64| {
        let history = drift_history(&long_horizon_config(m), horizon).unwrap();
        assert_eq!(history.termination, "completed");
        history
            .checkpoints
            .iter()
            .find(|(tc, _)| (tc - t).abs() < 1e-6)
            .map(|(_, d)| *d)
            .unwrap()
    };
    let (g100, g1000) = (
        drift_at(Method::Gauss4, 100.0),
        drift_at(Method::Gauss4, horizon),
    );
    println!(
        "gauss4 energy drift: {g100:e} at t ≤ 100, {g1000:e} at t ≤ {horizon} (bounded: ratio ≤ 2)"
    );
    assert!(
        g100 >= 1e-10,
        "gauss4's error must stand above round-off for the test to mean something"
    );
    assert!(g1000 <= 2.0 * g100);
    let (r100, r1000) = (drift_at(Method::Rk4, 100.0), drift_at(Method::Rk4, horizon));
    println!("rk4 (control) energy drift: {r100:e} at t ≤ 100, {r1000:e} at t ≤ {horizon} (drifts: ratio ≥ 5)");
    assert!(r1000 >= 5.0 * r100);
}

#[test]
fn scaled_coins_agree_with_the_unit_coin_to_1e_10() {
    let horizon = SuiteOptions::quick().scale_horizon;
    for inertia in [Inertia::ThinDisk, Inertia::Hoop] {
        for &method in Method::ALL {
            for &scale in SCALES {
                let (difference, run) = scale_difference(method, scale, inertia, horizon).unwrap();
                assert!(
                    run.completed(),
                    "{method} {scale:?}: {}",
                    run.termination_name()
                );
                assert!(
                    difference <= 1e-10,
                    "{inertia:?} {method} at (M, a, g) = {scale:?}: dimensionless difference {difference:e} > 1e-10"
                );
            }
        }
    }
    // Negative control: a coin of radius 4 whose spin is NOT rescaled by √(g/a) is a different motion.
    let unit = scaled_wobble((1.0, 1.0, 1.0), Inertia::ThinDisk, horizon).unwrap();
    let mut wrong = scaled_wobble((1.0, 4.0, 1.0), Inertia::ThinDisk, horizon).unwrap();
    let t = wrong.time_unit();
    wrong.initial.omega_x *= t;
    wrong.initial.omega_y *= t;
    wrong.initial.omega_z *= t;
    let config = default_config(Method::Dop853, 1.0);
    let (mut a, mut b) = (Trajectory::default(), Trajectory::default());
    run_sampled(&config, &unit, &mut a);
    run_sampled(&config, &wrong, &mut b);
    let difference = dimensionless_difference((&unit, &a), (&wrong, &b));
    println!("control: a = 4 without rescaling the spin differs by {difference:e} (≥ 1e-3)");
    assert!(difference >= 1e-3);
}

#[test]
fn the_analyse_rows_confirm_sigma_growth_and_the_quadrature_with_every_integrator() {
    // The rows `bench stability` adds for `analyse` (bench::nutation), over 10 periods: σ of kicked
    // circles to 1e-6, growth rates to 1e-4, T and ΔΦ of generic motions to 1e-9 (the bounds),
    // with every integrator (rk4 and gauss4 at 2048 steps per period: (2π/2048)⁴ ≈ 1e-10).
    let mut rows = stable_circles(10.0).unwrap();
    rows.extend(unstable_circles().unwrap());
    rows.extend(generic_periods(10.0).unwrap());
    assert_honest_ending(&rows, &["completed"]);
    assert_eq!(rows.len(), 4 * 4 + 2 * 4 + 3 * 4 * 2);
    for r in &rows {
        let bound = if r.case.starts_with("growth") {
            1e-4
        } else if r.case.starts_with("nutation-circle") || r.case.contains("band") {
            1e-6
        } else {
            1e-9
        };
        let error = r.max_error.unwrap();
        println!(
            "{:<28} {:<8} {:<28} measured {:?} expected {:?} relative error {error:.2e} (bound {bound:e}), {:.3} s",
            r.case, r.integrator.to_string(), r.quantity, r.measured, r.expected, r.wall_seconds
        );
        assert!(
            error <= bound,
            "{r:?}: relative error {error:e} > {bound:e}"
        );
    }
}
