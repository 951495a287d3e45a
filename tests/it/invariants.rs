//! C1, C2 of physics §6: the Legendre basis against an independent integration of Legendre's equation, the
//! Wronskian, conservation along simulated motions (with negative controls), and dC/dt = 0 at random states.
//!
//! The reference integrates Legendre's equation (1 − s²) y″ − 2s y′ − μ y = 0 in the variable τ = artanh s
//! (s = tanh τ, so 1 − s² = sech²τ). With the flux p = (1 − s²) y′ = dy/dτ it reads
//! dy/dτ = p, dp/dτ = μ sech²τ y: smooth everywhere, no singularity at s = 1 (τ = ∞), and θ = 1.5705 is
//! only τ ≈ 8.8. Classical RK4 at h ≈ 2.5e-4 with compensated (Kahan) accumulation, run again at h/2 and
//! Richardson-extrapolated; the difference between the two runs is printed as the reference's own error.

use crate::support::physics::wobble;
use crate::support::record::coin_log;
use coin_log::integrate::{run_method, Flow, Method, MethodConfig, RunEnd, RunSettings};
use coin_log::model::{
    energy, Chaplygin, Coin, CoinParams, Inertia, Invariants, InvariantsError, State,
};
use coin_log::simulation::CoinEvents;

use std::f64::consts::FRAC_PI_6;

const FLAT_LIMIT: f64 = 1.5705;

#[allow(clippy::unwrap_used)] // a test helper: invalid parameters are a bug in the test
fn params(inertia: Inertia) -> CoinParams {
    CoinParams::new(1.0, 1.0, 1.0, inertia).unwrap()
}

/// Unit mass and radius with μ = I_Z/(I_X (I_Z + 1)) chosen through I_X at I_Z = 1/2.
fn params_with_mu(mu: f64) -> CoinParams {
    let inertia_z = 0.5;
    params(Inertia::Explicit {
        inertia_x: inertia_z / (mu * (inertia_z + 1.0)),
        inertia_z,
    })
}

/// The parameter sets every test runs on: disk, hoop, μ < ¼ (real A, B), μ = ¼, and two μ > ¼.
fn cases() -> Vec<(&'static str, CoinParams)> {
    vec![
        ("thin disk (μ = 4/3)", params(Inertia::ThinDisk)),
        ("hoop (μ = 1)", params(Inertia::Hoop)),
        ("μ = 0.1", params_with_mu(0.1)),
        ("μ = 1/4", params_with_mu(0.25)),
        ("μ = 2.7", params_with_mu(2.7)),
        ("μ = 20", params_with_mu(20.0)),
        ("μ = 100 (MU_MAX)", params_with_mu(100.0)),
    ]
}

/// [y_e, p_e, y_o, p_o] at the given increasing τ values, by RK4 with `steps_per_unit` steps per unit τ.
fn legendre_reference(mu: f64, taus: &[f64], steps_per_unit: f64) -> Vec<[f64; 4]> {
    let rhs = |tau: f64, y: &[f64; 4]| {
        let sech2 = 1.0 / (tau.cosh() * tau.cosh());
        [y[1], mu * sech2 * y[0], y[3], mu * sech2 * y[2]]
    };
    let mut y = [1.0, 0.0, 0.0, 1.0];
    let mut carry = [0.0; 4];
    let mut tau = 0.0;
    let mut out = Vec::new();
    for &target in taus {
        let span = target - tau;
        let n = (span * steps_per_unit).ceil().max(1.0) as usize;
        let h = span / n as f64;
        for i in 0..n {
            let t = tau + i as f64 * h;
            let k1 = rhs(t, &y);
            let k2 = rhs(
                t + h / 2.0,
                &std::array::from_fn(|j| y[j] + h / 2.0 * k1[j]),
            );
            let k3 = rhs(
                t + h / 2.0,
                &std::array::from_fn(|j| y[j] + h / 2.0 * k2[j]),
            );
            let k4 = rhs(t + h, &std::array::from_fn(|j| y[j] + h * k3[j]));
            for j in 0..4 {
                // Kahan summation of the increments.
                let increment = h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]) - carry[j];
                let sum = y[j] + increment;
                carry[j] = (sum - y[j]) - increment;
                y[j] = sum;
            }
        }
        tau = target;
        out.push(y);
    }
    out
}

/// Reference values and the estimated error of the reference (Richardson between h and h/2).
fn reference(mu: f64, taus: &[f64]) -> (Vec<[f64; 4]>, f64) {
    // The solutions vary on the scale 1/√μ in τ: keep h√μ fixed beyond μ = 4.
    let steps = 4000.0 * (mu / 4.0).sqrt().max(1.0);
    let coarse = legendre_reference(mu, taus, steps);
    let fine = legendre_reference(mu, taus, 2.0 * steps);
    let mut worst = 0.0_f64;
    let values = coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| {
            std::array::from_fn(|j| {
                let v = (16.0 * f[j] - c[j]) / 15.0;
                worst = worst.max((f[j] - c[j]).abs() / 15.0 / v.abs().max(1e-300));
                v
            })
        })
        .collect();
    (values, worst)
}

fn thetas() -> Vec<f64> {
    let mut t: Vec<f64> = (0..=30).map(|i| 0.05 * f64::from(i)).collect();
    t.extend([
        1e-3,
        0.52,
        FRAC_PI_6 - 1e-9,
        FRAC_PI_6,
        FRAC_PI_6 + 1e-9,
        0.53,
        1.52,
        1.55,
        1.56,
        1.565,
        1.569,
        1.57,
        1.5704,
        FLAT_LIMIT,
    ]);
    t.sort_by(f64::total_cmp);
    t
}

fn tolerance(theta: f64) -> f64 {
    if theta.abs() <= 1.5 {
        1e-12
    } else {
        1e-9
    }
}

fn relative(measured: f64, expected: f64) -> f64 {
    if expected == 0.0 {
        measured.abs()
    } else {
        (measured - expected).abs() / expected.abs()
    }
}

#[test]
fn legendre_basis_matches_direct_integration_of_legendres_equation_up_to_theta_1_5705() {
    for (name, p) in cases() {
        let ch = Chaplygin::new(&p).unwrap();
        let thetas = thetas();
        // τ = artanh(sin θ) = asinh(tan θ), accurate near π/2.
        let taus: Vec<f64> = thetas.iter().map(|t| t.tan().asinh()).collect();
        let (refs, ref_err) = reference(ch.mu(), &taus);
        println!(
            "{name}: series terms (centre, edge) = {:?}, reference error estimate {ref_err:.1e}",
            ch.terms()
        );
        let mut worst_inner = 0.0_f64;
        let mut worst_outer = 0.0_f64;
        for (&theta, r) in thetas.iter().zip(&refs) {
            let b = ch.basis(theta);
            let cos2 = theta.cos().powi(2);
            let expected = [r[0], r[2], r[1] / cos2, r[3] / cos2];
            let measured = [b.y_even, b.y_odd, b.dy_even, b.dy_odd];
            let errors: [f64; 4] = std::array::from_fn(|j| relative(measured[j], expected[j]));
            let flux_errors = [relative(b.flux_even, r[1]), relative(b.flux_odd, r[3])];
            let worst = errors
                .iter()
                .chain(&flux_errors)
                .fold(0.0_f64, |a, &e| a.max(e));
            if theta <= 1.5 {
                worst_inner = worst_inner.max(worst);
            } else {
                worst_outer = worst_outer.max(worst);
            }
            let tol = tolerance(theta);
            assert!(
                worst < tol,
                "{name}, θ = {theta}: y_e {} vs {}, y_o {} vs {}, y_e′ {} vs {}, y_o′ {} vs {}: \
                 relative error {worst:.2e} > tolerance {tol:.0e}",
                measured[0],
                expected[0],
                measured[1],
                expected[1],
                measured[2],
                expected[2],
                measured[3],
                expected[3]
            );
        }
        println!(
            "  max relative error of y_e, y_o, y_e′, y_o′, p_e, p_o: {worst_inner:.2e} for |θ| ≤ 1.5 \
             (tolerance 1e-12), {worst_outer:.2e} for 1.5 < |θ| ≤ 1.5705 (tolerance 1e-9)"
        );
        assert!(
            ref_err < 1e-14,
            "reference itself is only good to {ref_err:.1e}"
        );
    }
}

#[test]
fn legendre_basis_at_s_matches_direct_integration_for_s_up_to_sin_1_5705() {
    for (name, p) in cases() {
        let ch = Chaplygin::new(&p).unwrap();
        let sins: Vec<f64> = thetas().iter().map(|t| t.sin()).collect();
        // τ = artanh s = ½ ln(1 + 2s/(1 − s)), with 1 − s exact for s ≥ ½.
        let taus: Vec<f64> = sins
            .iter()
            .map(|s| 0.5 * (2.0 * s / (1.0 - s)).ln_1p())
            .collect();
        let (refs, _) = reference(ch.mu(), &taus);
        let mut worst_all = 0.0_f64;
        for (&s, r) in sins.iter().zip(&refs) {
            let b = ch.basis_at_sin(s);
            let cos2 = (1.0 - s) * (1.0 + s);
            let expected = [r[0], r[2], r[1] / cos2, r[3] / cos2];
            let measured = [b.y_even, b.y_odd, b.dy_even, b.dy_odd];
            let worst = (0..4)
                .map(|j| relative(measured[j], expected[j]))
                .fold(0.0_f64, f64::max);
            worst_all = worst_all.max(worst);
            assert!(
                worst < 1e-12,
                "{name}, s = {s}: measured {measured:?} vs expected {expected:?}: \
                 relative error {worst:.2e} > tolerance 1e-12"
            );
        }
        println!(
            "{name}: max relative error over s ≤ sin(1.5705): {worst_all:.2e} (tolerance 1e-12)"
        );
    }
}

#[test]
fn even_and_odd_solutions_have_exact_symmetry() {
    let ch = Chaplygin::new(&CoinParams::unit_disk()).unwrap();
    for theta in thetas() {
        let plus = ch.basis(theta);
        let minus = ch.basis(-theta);
        assert_eq!(
            plus.y_even.to_bits(),
            minus.y_even.to_bits(),
            "y_e even at θ = {theta}"
        );
        assert_eq!(
            plus.y_odd.to_bits(),
            (-minus.y_odd).to_bits(),
            "y_o odd at θ = {theta}"
        );
        assert_eq!(
            plus.dy_even.to_bits(),
            (-minus.dy_even).to_bits(),
            "y_e′ odd at θ = {theta}"
        );
        assert_eq!(
            plus.dy_odd.to_bits(),
            minus.dy_odd.to_bits(),
            "y_o′ even at θ = {theta}"
        );
    }
}

#[test]
fn wronskian_is_one_over_cos_squared() {
    for (name, p) in cases() {
        let ch = Chaplygin::new(&p).unwrap();
        let mut worst = [0.0_f64; 2];
        let mut worst_cancellation = 0.0_f64;
        for i in 0..=15704 {
            let theta = 1e-4 * f64::from(i);
            let b = ch.basis(theta);
            // y_e y_o′ − y_o y_e′ = 1/(1 − s²), i.e. y_e p_o − y_o p_e = 1. For large μ both products grow
            // like exp(2√μ θ) and cancel; their size is then the scale of any rounding, so the error is
            // taken relative to max(1, |y_e p_o| + |y_o p_e|) (= 1 relative for μ of order 1).
            let products = [b.y_even * b.flux_odd, b.y_odd * b.flux_even];
            let wronskian = products[0] - products[1];
            let cancellation = products[0].abs() + products[1].abs();
            worst_cancellation = worst_cancellation.max(cancellation);
            let error = (wronskian - 1.0).abs() / cancellation.max(1.0);
            let slot = usize::from(theta > 1.5);
            worst[slot] = worst[slot].max(error);
            assert!(
                error < tolerance(theta),
                "{name}, θ = {theta}: (y_e y_o′ − y_o y_e′)(1 − s²) = {wronskian} vs 1 \
                 (products {products:?}): {error:.2e} > tolerance {:.0e}",
                tolerance(theta)
            );
        }
        println!(
            "{name}: Wronskian relative error {:.2e} for |θ| ≤ 1.5 (tolerance 1e-12), {:.2e} up to 1.5704 \
             (products up to {worst_cancellation:.1e})",
            worst[0], worst[1]
        );
    }
}

/// C1, C2 on a trajectory; `variant` lets the negative controls break the formula.
fn drift_along<F>(p: &CoinParams, initial: &State, t_end: f64, mut value: F) -> (f64, RunEnd, f64)
where
    F: FnMut(&[f64; 8]) -> Invariants,
{
    let coin = Coin::new(*p);
    let c0 = value(&initial.to_array());
    let scale = c0.c1.abs() + c0.c2.abs();
    let mut drift = 0.0_f64;
    let rk4 = MethodConfig {
        method: Method::Rk4,
        rtol: 0.0,
        atol: 0.0,
        step: 2e-4,
    };
    let outcome = run_method(
        &rk4,
        &coin,
        &initial.to_array(),
        &RunSettings {
            t0: 0.0,
            t_end,
            sample_interval: 0.01,
        },
        &CoinEvents::new(coin, 1e-3, None),
        |_, y| {
            let c = value(y);
            drift = drift.max((c.c1 - c0.c1).abs().max((c.c2 - c0.c2).abs()) / scale);
            Flow::Continue
        },
    );
    (drift, outcome.termination, outcome.t_last)
}

/// A motion that leans far over: θ₀ = 1.2, slow spin.
fn deep_lean() -> State {
    State {
        theta: 1.2,
        omega_x: -0.4,
        omega_y: 1.0,
        omega_z: 0.7,
        ..State::default()
    }
}

const RK4_DRIFT_TOLERANCE: f64 = 1e-11;

#[test]
fn c1_and_c2_stay_constant_along_rk4_trajectories() {
    for (name, p) in cases() {
        let ch = Chaplygin::new(&p).unwrap();
        for (motion, initial) in [("wobble", wobble()), ("deep lean", deep_lean())] {
            let (drift, termination, t_last) =
                drift_along(&p, &initial, 20.0, |y| ch.evaluate(y[0], y[4], y[5]));
            println!(
                "{name}, {motion}: rk4 h = 2e-4 to t = {t_last:.3} ({termination:?}): \
                 max|C − C0|/(|C1₀| + |C2₀|) = {drift:.2e} (tolerance {RK4_DRIFT_TOLERANCE:.0e})"
            );
            assert!(drift < RK4_DRIFT_TOLERANCE);
        }
    }
}

#[test]
fn a_mixed_up_or_wrong_mu_formula_drifts_visibly() {
    let disk = CoinParams::unit_disk();
    let ch = Chaplygin::new(&disk).unwrap();
    let hoop = Chaplygin::new(&params(Inertia::Hoop)).unwrap();
    let k = ch.k();
    let control = |name: &str, drift: f64| {
        println!("negative control {name}: drift {drift:.2e} (must exceed 1e-3)");
        assert!(drift > 1e-3, "{name} did not drift: {drift:.2e}");
    };
    // y_e in the ω_Z term, y_o in the ω_Y term.
    let (drift, ..) = drift_along(&disk, &wobble(), 20.0, |y| {
        let b = ch.basis(y[0]);
        let cos = y[0].cos();
        let c1 = cos * cos * b.dy_even * y[5] - cos * b.y_odd * y[4] / k;
        Invariants { c1, c2: c1 }
    });
    control("C1 with y_e′ in place of y_o′", drift);
    // The hoop's μ = 1 basis on a disk's motion.
    let (drift, ..) = drift_along(&disk, &wobble(), 20.0, |y| hoop.evaluate(y[0], y[4], y[5]));
    control("disk motion, hoop's μ", drift);
    // Swapping y_e and y_o *everywhere* in C1 gives −C2, which is conserved: not a negative control.
    let (drift, ..) = drift_along(&disk, &wobble(), 20.0, |y| {
        let b = ch.basis(y[0]);
        let cos = y[0].cos();
        let c1 = cos * cos * b.dy_even * y[5] - cos * b.y_even * y[4] / k;
        Invariants { c1, c2: c1 }
    });
    println!("C1 with y_e, y_e′ in place of y_o, y_o′ (= −C2, conserved): drift {drift:.2e}");
    assert!(drift < RK4_DRIFT_TOLERANCE);
}

/// Deterministic uniform numbers in [0, 1) (64-bit LCG, Knuth's MMIX constants).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn time_derivative_of_c1_and_c2_vanishes_at_random_states() {
    let mut rng = Lcg(20240611);
    for (name, p) in cases() {
        let ch = Chaplygin::new(&p).unwrap();
        let coin = Coin::new(p);
        let mut worst = 0.0_f64;
        for _ in 0..2000 {
            let theta = (2.0 * rng.next() - 1.0) * 1.55;
            let [wx, wy, wz] = [0; 3].map(|_| 4.0 * rng.next() - 2.0);
            let acc = coin.angular_acceleration(theta, wx, wy, wz);
            // ∂C/∂θ by a 6th-order central difference; y varies on the scale cos θ near flat and 1/√μ.
            let h = 1e-2 * theta.cos() / (1.0 + ch.mu()).sqrt();
            let at = |d: f64| ch.evaluate(theta + d, wy, wz);
            let d_theta = |f: fn(&Invariants) -> f64| {
                let g = |j: f64| f(&at(j * h)) - f(&at(-j * h));
                (45.0 * g(1.0) - 9.0 * g(2.0) + g(3.0)) / (60.0 * h)
            };
            // C is linear in (ω_Y, ω_Z): the partial derivatives are C at unit vectors.
            let d_wy = ch.evaluate(theta, 1.0, 0.0);
            let d_wz = ch.evaluate(theta, 0.0, 1.0);
            for (component, f) in [
                ("C1", (|c: &Invariants| c.c1) as fn(&Invariants) -> f64),
                ("C2", |c: &Invariants| c.c2),
            ] {
                let terms = [d_theta(f) * wx, f(&d_wy) * acc.y, f(&d_wz) * acc.z];
                let rate: f64 = terms.iter().sum();
                let scale: f64 = terms.iter().map(|t| t.abs()).sum();
                let error = rate.abs() / scale.max(1e-300);
                worst = worst.max(error);
                assert!(
                    error < 1e-10,
                    "{name}, θ = {theta}, ω = ({wx}, {wy}, {wz}): d{component}/dt = {rate:e} vs 0, \
                     relative to {scale:e}: {error:.2e} > 1e-10"
                );
            }
        }
        println!("{name}: max |dC/dt| / (sum of |terms|) over 2000 random states: {worst:.2e} (tolerance 1e-10)");
    }
}

#[test]
fn c1_c2_are_accurate_relative_to_their_own_size_near_flat() {
    // C from the reference basis vs the library, for random ω at θ on the grid: relative to |C1| + |C2|.
    let mut rng = Lcg(7);
    for (name, p) in cases() {
        let ch = Chaplygin::new(&p).unwrap();
        let thetas = thetas();
        let taus: Vec<f64> = thetas.iter().map(|t| t.tan().asinh()).collect();
        let (refs, _) = reference(ch.mu(), &taus);
        let mut worst = [0.0_f64; 2];
        for (&theta, r) in thetas.iter().zip(&refs) {
            for _ in 0..50 {
                let wy = 4.0 * rng.next() - 2.0;
                let wz = 4.0 * rng.next() - 2.0;
                let c = ch.evaluate(theta, wy, wz);
                let lever = theta.cos() * wy / ch.k();
                let expected = Invariants {
                    c1: r[3] * wz - r[2] * lever,
                    c2: r[0] * lever - r[1] * wz,
                };
                let error = (c.c1 - expected.c1).abs().max((c.c2 - expected.c2).abs())
                    / (expected.c1.abs() + expected.c2.abs());
                let slot = usize::from(theta > 1.5);
                worst[slot] = worst[slot].max(error);
                assert!(
                    error < tolerance(theta),
                    "{name}, θ = {theta}: C = {c:?} vs {expected:?}: {error:.2e} > {:.0e}",
                    tolerance(theta)
                );
            }
        }
        println!(
            "{name}: C1, C2 error / (|C1| + |C2|): {:.2e} for |θ| ≤ 1.5 (tolerance 1e-12), {:.2e} up to 1.5705 (tolerance 1e-9)",
            worst[0], worst[1]
        );
    }
}

#[test]
fn basis_is_continuous_across_the_split_and_keeps_its_wronskian_for_random_bodies() {
    let mut rng = Lcg(99);
    let mut worst_jump = 0.0_f64;
    let mut worst_wronskian = 0.0_f64;
    for _ in 0..200 {
        // μ log-uniform in [1e-6, MU_MAX].
        let mu = 1e-6 * (1e8_f64).powf(rng.next());
        let ch = Chaplygin::new(&params_with_mu(mu)).unwrap();
        // The two expansions one ulp either side of the split agree.
        let split = ch.split_sin();
        let below = ch.basis_at_sin(split);
        let above = ch.basis_at_sin(f64::from_bits(split.to_bits() + 1));
        let pairs = [
            (below.y_even, above.y_even),
            (below.y_odd, above.y_odd),
            (below.flux_even, above.flux_even),
            (below.flux_odd, above.flux_odd),
        ];
        for (b, a) in pairs {
            let jump = (a - b).abs() / b.abs();
            worst_jump = worst_jump.max(jump);
            assert!(
                jump < 1e-13,
                "μ = {mu}: {b} below the split, {a} above: jump {jump:.2e} > 1e-13"
            );
        }
        for _ in 0..50 {
            let theta = rng.next() * FLAT_LIMIT;
            let b = ch.basis(theta);
            let products = [b.y_even * b.flux_odd, b.y_odd * b.flux_even];
            let error = (products[0] - products[1] - 1.0).abs()
                / (products[0].abs() + products[1].abs()).max(1.0);
            worst_wronskian = worst_wronskian.max(error);
            assert!(
                error < 1e-13,
                "μ = {mu}, θ = {theta}: Wronskian error {error:.2e} > 1e-13"
            );
        }
    }
    println!(
        "200 random μ in [1e-6, 100]: max relative jump across the split {worst_jump:.2e} (tolerance 1e-13), \
         max Wronskian error {worst_wronskian:.2e} (tolerance 1e-13)"
    );
}

/// Issue 4: E, C1, C2 drift ≤ 1e-11 over 100 time units on the wobble with dop853 at rtol 1e-12.
const DOP853_DRIFT_TOLERANCE: f64 = 1e-11;

#[test]
fn energy_c1_and_c2_drift_below_1e_11_over_100_time_units_with_dop853_at_rtol_1e_12() {
    // The bound is for the wobble; the deep lean (not in the issue) gets 1e-10: its energy drift
    // measured 1.2e-11 at these tolerances.
    let cases = [
        (
            "thin disk",
            params(Inertia::ThinDisk),
            wobble(),
            DOP853_DRIFT_TOLERANCE,
        ),
        (
            "hoop",
            params(Inertia::Hoop),
            wobble(),
            DOP853_DRIFT_TOLERANCE,
        ),
        (
            "μ = 0.1",
            params_with_mu(0.1),
            wobble(),
            DOP853_DRIFT_TOLERANCE,
        ),
        (
            "μ = 2.7",
            params_with_mu(2.7),
            wobble(),
            DOP853_DRIFT_TOLERANCE,
        ),
        (
            "thin disk, deep lean",
            params(Inertia::ThinDisk),
            deep_lean(),
            1e-10,
        ),
    ];
    for (name, p, initial, bound) in cases {
        let coin = Coin::new(p);
        let ch = Chaplygin::new(&p).unwrap();
        let e0 = energy(&coin, &initial).total;
        let c0 = ch.of_state(&initial);
        // Contract definitions: max|E − E₀| / max(|E₀|, Mga), max|C − C₀| / (|C1₀| + |C2₀|).
        let energy_scale = e0.abs().max(p.energy_scale());
        let c_scale = c0.c1.abs() + c0.c2.abs();
        let (mut energy_drift, mut c1_drift, mut c2_drift) = (0.0_f64, 0.0_f64, 0.0_f64);
        let config = MethodConfig {
            method: Method::Dop853,
            rtol: 1e-12,
            atol: 1e-12,
            step: 0.0,
        };
        let outcome = run_method(
            &config,
            &coin,
            &initial.to_array(),
            &RunSettings {
                t0: 0.0,
                t_end: 100.0,
                sample_interval: 0.01,
            },
            &CoinEvents::new(coin, 1e-3, None),
            |_, y| {
                let state = State::from_array(y);
                energy_drift =
                    energy_drift.max((energy(&coin, &state).total - e0).abs() / energy_scale);
                let c = ch.of_state(&state);
                c1_drift = c1_drift.max((c.c1 - c0.c1).abs() / c_scale);
                c2_drift = c2_drift.max((c.c2 - c0.c2).abs() / c_scale);
                Flow::Continue
            },
        );
        println!(
            "{name}: dop853 rtol = atol = 1e-12 to t = {:.3} ({:?}, {} steps): drift E {energy_drift:.2e}, \
             C1 {c1_drift:.2e}, C2 {c2_drift:.2e} (tolerance {bound:.0e})",
            outcome.t_last, outcome.termination, outcome.stats.steps
        );
        assert!(
            matches!(outcome.termination, RunEnd::Completed),
            "{name} did not complete"
        );
        for (quantity, drift) in [("E", energy_drift), ("C1", c1_drift), ("C2", c2_drift)] {
            assert!(
                drift <= bound,
                "{name}: {quantity} drift {drift:.2e} > {bound:.0e}"
            );
        }
    }
}

#[test]
fn thin_disk_has_mu_four_thirds_and_k_three_halves() {
    let ch = Chaplygin::new(&CoinParams::unit_disk()).unwrap();
    assert!((ch.mu() - 4.0 / 3.0).abs() < 1e-15);
    assert!((ch.k() - 1.5).abs() < 1e-15);
    println!("terms (centre, edge) = {:?}", ch.terms());
}

#[test]
fn mu_beyond_the_limit_is_refused_with_its_value() {
    let p = params(Inertia::Explicit {
        inertia_x: 1e-3,
        inertia_z: 1.0,
    });
    let err = Chaplygin::new(&p).unwrap_err();
    assert!(matches!(err, InvariantsError::MuTooLarge { .. }));
    assert!(err.to_string().contains("500"));
}

/// A coin released with a tiny spin has tiny C₀ but falls at rates of order √(g/a), which the
/// integrator's error on C follows: `wobble` with ω_Z = 1e-8 erred on C by 1e-13, a drift of 1.7e-5
/// relative to |C1₀| + |C2₀| (format.md's definition), and verify failed the file record had promised to
/// pass. The tolerance is widened by √(g/a)/(|C1₀| + |C2₀|); a tight --energy-tol still fails it.
#[test]
fn a_coin_released_with_a_tiny_spin_is_judged_against_the_natural_rate() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.mcap");
    let p = path.to_str().unwrap();
    let set = "initial.omega=[0.0,0.0,1e-8]";
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--set", set, "-o", p, "--json"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        summary["expected_to_fail"],
        serde_json::json!([]),
        "{summary}"
    );
    let verify = coin_log(dir.path(), &["verify", p]);
    let text = String::from_utf8_lossy(&verify.stdout);
    assert_eq!(verify.status.code(), Some(0), "{text}");
    assert!(
        text.contains("the energy tolerance × √(g/a)/(|C1_0| + |C2_0|)"),
        "{text}"
    );
    // Negative control: 1e-20 widened by ~1e8 is far below the drift.
    let tight = coin_log(
        dir.path(),
        &["verify", p, "--energy-tol", "1e-20", "--json"],
    );
    let json: serde_json::Value = serde_json::from_slice(&tight.stdout).unwrap();
    let checks = json["files"][0]["checks"].as_array().unwrap();
    let invariants = checks.iter().find(|c| c["id"] == "invariants").unwrap();
    assert_eq!(invariants["status"], "fail", "{invariants}");
}
