//! σ² of the steady motions (physics §9, eq (21)) against values that do not come from it: the eigenvalues
//! of the numerically differentiated right-hand side (nalgebra's Schur decomposition of a 4 × 4 Jacobian
//! built by central differences of `Coin::angular_acceleration`), at hundreds of random steady states of
//! random bodies; the special cases of physics §5, written independently in `model::stability`; and the
//! hand-derived thin-disk numbers of physics §5.
//!
//! **The numerical Jacobian.** Columns ω_X, ω_Y, ω_Z: eqs (14)–(16) are polynomials of degree ≤ 2 in each
//! ω component, so the central difference is exact up to rounding for any step; the step is the size of
//! the state's rates (√(g/a) + |ω|), which makes the rounding ~ε of the entries. Column θ: tan θ, sin θ are
//! not polynomials, so a 9-point (eighth-order) central difference with step h = 0.01·(π/2 − |θ|), a
//! hundredth of the distance d to the singularity of tan θ: truncation h⁸ f⁽⁹⁾/630 ~ 9!/630·(0.01)⁸ ≈ 6e-14 of
//! the entry (f⁽⁹⁾ ~ 9!/d¹⁰ for an entry ~ 1/d²), rounding ~2ε/0.01 ≈ 4e-14. (The sixth-order stencil's
//! truncation, 7!/140·(0.01)⁶ ≈ 4e-11, was measured to exceed 1e-10 of |σ²| at |σ²| = S/100.)
//!
//! **Scaling the error.** σ² = −(A + BD + CE) is a sum of terms that may cancel (near the stability
//! boundary they do, exactly); no computation of σ² from rounded inputs, numerical or closed-form, is
//! better than a few ulp of the size of those terms, S = |A| + |BD| + |CE| (`Linearisation::scale`). The
//! error is therefore measured relative to S, which is max(|σ²|, S) since |σ²| ≤ S; away from the
//! boundary (|σ²| ≥ S/100) it is also measured relative to |σ²| itself.

// Helpers outside #[test] functions unwrap too: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::physics::{self, rate_unit};
use coin_log::model::{
    centre_fixed_sigma_squared, spin_upright_sigma_squared, steady_omega_y, steady_sigma_squared,
    straight_lambda_squared, Branch, Coin, CoinParams, Inertia, Linearisation, Steady, SteadyKind,
};
use nalgebra::{Complex, Matrix4, Schur};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use std::cell::Cell;

/// Required agreement of σ² with the numerical Jacobian's eigenvalues, relative to S (module doc).
const AGREEMENT: f64 = 1e-10;
/// Required size of the two zero eigenvalues, relative to √S: the double zero is semisimple (its
/// eigenvectors span the family's tangent plane, physics §9), so it moves by about the entries' error,
/// not its square root; measured 7e-14.
const ZERO: f64 = 1e-9;
/// Most Schur (QR) iterations per attempt: a 4 × 4 matrix converges in a few dozen.
const SCHUR_ITERATIONS: usize = 10_000;

fn config() -> Config {
    Config {
        cases: 400,
        rng_seed: RngSeed::Fixed(0x5167_a002),
        failure_persistence: None,
        ..Config::default()
    }
}

/// (θ̇, ω̇_X, ω̇_Y, ω̇_Z) of the reduced system at x = (θ, ω_X, ω_Y, ω_Z).
fn reduced(coin: &Coin, x: &[f64; 4]) -> [f64; 4] {
    let a = coin.angular_acceleration(x[0], x[1], x[2], x[3]);
    [x[1], a.x, a.y, a.z]
}

/// The numerical Jacobian of the module doc at x.
fn numerical_jacobian(coin: &Coin, x: &[f64; 4]) -> Matrix4<f64> {
    let rates = rate_unit(coin.params()) + x[1].abs() + x[2].abs() + x[3].abs();
    let mut j = Matrix4::zeros();
    for column in 0..4 {
        let at = |offset: f64| {
            let mut y = *x;
            y[column] += offset;
            reduced(coin, &y)
        };
        let derivative: [f64; 4] = if column == 0 {
            // Eighth-order central difference:
            // (f₋₄/280 − 4f₋₃/105 + f₋₂/5 − 4f₋₁/5 + 4f₁/5 − f₂/5 + 4f₃/105 − f₄/280)/h.
            let h = 0.01 * (std::f64::consts::FRAC_PI_2 - x[0].abs());
            let weights = [
                (-4.0, 1.0 / 280.0),
                (-3.0, -4.0 / 105.0),
                (-2.0, 1.0 / 5.0),
                (-1.0, -4.0 / 5.0),
                (1.0, 4.0 / 5.0),
                (2.0, -1.0 / 5.0),
                (3.0, 4.0 / 105.0),
                (4.0, -1.0 / 280.0),
            ];
            let f: Vec<(f64, [f64; 4])> = weights.iter().map(|&(k, w)| (w, at(k * h))).collect();
            std::array::from_fn(|i| f.iter().map(|(w, v)| w * v[i]).sum::<f64>() / h)
        } else {
            let (plus, minus) = (at(rates), at(-rates));
            std::array::from_fn(|i| (plus[i] - minus[i]) / (2.0 * rates))
        };
        for (row, d) in derivative.iter().enumerate() {
            j[(row, column)] = *d;
        }
    }
    j
}

/// The eigenvalues of the numerical Jacobian at the steady state (θ, 0, ω_Y, ω_Z), by magnitude.
///
/// nalgebra's `complex_eigenvalues` runs its Schur (Francis QR) iteration without a bound, and on these
/// matrices (a double zero eigenvalue, a pattern of exact zeros) it never converges: the property test
/// hung, and `Schur::try_new` returns `None` at any deflation threshold from ε to 1024 ε. Shifting the
/// matrix by c·I, with c the size of its eigenvalues (√ of the terms of σ², taken from the numerical
/// entries), breaks the pattern: the shifted matrix converges in a few dozen iterations, and its
/// eigenvalues minus c are J's, up to a rounding of ~ε·c. Other shifts are tried if one fails.
pub fn eigenvalues(coin: &Coin, theta: f64, omega_y: f64, omega_z: f64) -> Vec<Complex<f64>> {
    let j = numerical_jacobian(coin, &[theta, 0.0, omega_y, omega_z]);
    let size =
        (j[(1, 0)].abs() + (j[(1, 2)] * j[(2, 1)]).abs() + (j[(1, 3)] * j[(3, 1)]).abs()).sqrt();
    let (shift, schur) = [1.0, -0.7, 2.3, -3.1]
        .iter()
        .find_map(|k| {
            let c = k * size;
            Schur::try_new(j + Matrix4::identity() * c, f64::EPSILON, SCHUR_ITERATIONS)
                .map(|s| (c, s))
        })
        .unwrap_or_else(|| {
            panic!("the Schur iteration did not converge at θ0 = {theta}, ω_Y0 = {omega_y}, ω_Z0 = {omega_z}: J = {j}")
        });
    let mut values: Vec<Complex<f64>> = schur
        .complex_eigenvalues()
        .iter()
        .map(|v| v - shift)
        .collect();
    values.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    values
}

/// σ² from the eigenvalues: the product of the non-zero pair ±√(−σ²) is σ² (iσ · (−iσ) = σ², λ · (−λ) = −λ²).
pub fn sigma_squared_of(values: &[Complex<f64>]) -> f64 {
    (values[2] * values[3]).re
}

/// A random body: a thin disk, a hoop, or explicit inertias between a tenth and twice M a² (I_Z ≤ 2 I_X,
/// like every rigid body), with M, a, g over two decades.
fn body() -> impl Strategy<Value = CoinParams> {
    (0.1..10.0, 0.1..5.0, 0.5..20.0, 0..4_u8, 0.1..1.0, 0.05..1.0).prop_map(
        |(m, a, g, shape, kx, kz_fraction): (f64, f64, f64, u8, f64, f64)| {
            let ma2 = m * a * a;
            let inertia = match shape {
                0 => Inertia::ThinDisk,
                1 => Inertia::Hoop,
                _ => Inertia::Explicit {
                    inertia_x: kx * ma2,
                    inertia_z: 2.0 * kx * kz_fraction * ma2,
                },
            };
            CoinParams::new(m, a, g, inertia).unwrap()
        },
    )
}

/// A random steady circle: |θ₀| in [0.01, 1.4] of either sign, ω_Z0 up to 4 √(g/a) of either sign, either
/// branch; (θ₀, ω_Z0 in units of √(g/a), branch).
fn circle() -> impl Strategy<Value = (f64, f64, Branch)> {
    (0.01..1.4, any::<bool>(), -4.0..4.0, any::<bool>()).prop_map(
        |(t, negative, w, plus): (f64, bool, f64, bool)| {
            let theta = if negative { -t } else { t };
            let branch = if plus { Branch::Plus } else { Branch::Minus };
            (theta, w, branch)
        },
    )
}

#[test]
fn sigma_squared_is_the_numerical_jacobians_eigenvalue_product_at_random_steady_states() {
    let worst = Cell::new((0.0_f64, 0.0_f64, 0.0_f64));
    let near_boundary = Cell::new(0_u32);
    proptest!(config(), |(p in body(), (theta, w, branch) in circle())| {
        let coin = Coin::new(p);
        let omega_z = w * rate_unit(&p);
        let omega_y = steady_omega_y(&coin, theta, omega_z, branch);
        let closed = steady_sigma_squared(&coin, theta, omega_y, omega_z);
        let scale = Linearisation::at(&coin, theta, omega_y, omega_z).scale();
        let values = eigenvalues(&coin, theta, omega_y, omega_z);
        let numerical = sigma_squared_of(&values);
        let error = (numerical - closed).abs() / scale;
        let zero = values[1].norm() / scale.sqrt();
        let plain = (numerical - closed).abs() / closed.abs();
        prop_assert!(
            error <= AGREEMENT,
            "θ0 = {theta}, ω_Z0 = {omega_z}, {branch} branch, body {p:?}: σ² = {closed:e} (closed form) vs {numerical:e} (eigenvalues {values:?}); |difference|/S = {error:e} > {AGREEMENT:e} (S = {scale:e})"
        );
        if closed.abs() >= 1e-2 * scale {
            prop_assert!(plain <= AGREEMENT, "relative to |σ²|: {plain:e} > {AGREEMENT:e}");
            prop_assert!(zero <= ZERO, "the zero eigenvalues {:?}, {:?}: |λ|/√S = {zero:e} > {ZERO:e}", values[0], values[1]);
            let w = worst.get();
            worst.set((w.0, w.1.max(plain), w.2.max(zero)));
        } else {
            near_boundary.set(near_boundary.get() + 1);
        }
        let w = worst.get();
        worst.set((w.0.max(error), w.1, w.2));
    });
    let (worst, near_boundary) = (worst.get(), near_boundary.get());
    println!(
        "400 random steady circles: worst |Δσ²|/S = {:.2e}, worst |Δσ²|/|σ²| (|σ²| ≥ S/100) = {:.2e}, worst zero eigenvalue |λ|/√S = {:.2e}; {near_boundary} cases with |σ²| < S/100 (tolerances {AGREEMENT:e}, {AGREEMENT:e}, {ZERO:e})",
        worst.0, worst.1, worst.2
    );
}

#[test]
fn the_numerical_jacobian_sees_a_wrong_sign_in_the_closed_form() {
    // Negative control: σ² with the sign of its ω_Y ω_Z term flipped misses the eigenvalues by far more
    // than the tolerance at a generic circle.
    let coin = Coin::new(CoinParams::unit_disk());
    let (theta, omega_z) = (0.3, 1.0);
    let omega_y = steady_omega_y(&coin, theta, omega_z, Branch::Plus);
    let p = coin.params();
    let wrong = ((p.inertia_x() * (1.0 + 2.0 * theta.sin().powi(2)) / theta.cos().powi(2)
        + p.ma2())
        * omega_y
        * omega_y
        - (3.0 * p.inertia_z() + p.ma2()) * theta.tan() * omega_y * omega_z
        + p.inertia_z() * (p.inertia_z() + p.ma2()) / p.inertia_x() * omega_z * omega_z
        - theta.cos())
        / (p.inertia_x() + p.ma2());
    let numerical = sigma_squared_of(&eigenvalues(&coin, theta, omega_y, omega_z));
    let scale = Linearisation::at(&coin, theta, omega_y, omega_z).scale();
    let error = (numerical - wrong).abs() / scale;
    println!("wrong sign: |Δσ²|/S = {error:.3e}, far above {AGREEMENT:e}");
    assert!(error > 1e3 * AGREEMENT);
}

#[test]
fn sigma_squared_reduces_to_the_special_cases_of_physics_section_5() {
    for (label, p) in [
        ("unit disk", physics::unit_disk()),
        ("unit hoop", physics::unit_hoop()),
        ("general", physics::general()),
    ] {
        let coin = Coin::new(p);
        let w = rate_unit(&p);
        for omega in [0.3 * w, w, 2.5 * w] {
            // Straight rolling: σ² = −λ².
            physics::check(
                &format!("{label}: straight rolling at ω_Z0 = {omega}"),
                steady_sigma_squared(&coin, 0.0, 0.0, omega),
                -straight_lambda_squared(&coin, omega),
                1e-14 * w * w,
            );
            // Spinning upright at Ω: σ² = Ω² − Mga/(I_X + Ma²).
            physics::check(
                &format!("{label}: upright spin at Ω = {omega}"),
                steady_sigma_squared(&coin, 0.0, omega, 0.0),
                spin_upright_sigma_squared(&coin, omega),
                1e-14 * w * w,
            );
        }
        for theta in [0.1, 0.5, 1.2] {
            let s = Steady::new(
                &coin,
                SteadyKind::CentreFixed {
                    theta,
                    branch: Branch::Plus,
                },
            )
            .unwrap();
            physics::check_relative(
                &format!("{label}: centre at rest, θ0 = {theta}"),
                steady_sigma_squared(&coin, theta, s.state.omega_y, 0.0),
                centre_fixed_sigma_squared(&coin, theta),
                1e-14,
            );
        }
    }
}

#[test]
fn sigma_squared_gives_the_hand_derived_thin_disk_numbers() {
    // physics §5, thin disk at unit scales, derived by hand there: straight rolling λ² = (4/5)(1 − 3ω²);
    // the upright spin at Ω = 2: σ² = 4 − 4/5 = 3.2; the centre at rest at θ0 = 0.5: σ = 1.8539
    // and σ²/φ̇² = (3 + sin²α)/5 with α = π/2 − θ0.
    let coin = Coin::new(CoinParams::unit_disk());
    physics::check(
        "straight, ω_Z0 = 0.4",
        steady_sigma_squared(&coin, 0.0, 0.0, 0.4),
        -0.8 * (1.0 - 3.0 * 0.16),
        1e-15,
    );
    physics::check(
        "upright spin, Ω = 2",
        steady_sigma_squared(&coin, 0.0, 2.0, 0.0),
        3.2,
        1e-15,
    );
    let theta: f64 = 0.5;
    let s = Steady::new(
        &coin,
        SteadyKind::CentreFixed {
            theta,
            branch: Branch::Plus,
        },
    )
    .unwrap();
    let sigma2 = steady_sigma_squared(&coin, theta, s.state.omega_y, 0.0);
    physics::check("centre at rest, θ0 = 0.5: σ", sigma2.sqrt(), 1.8539, 5e-5);
    let alpha = std::f64::consts::FRAC_PI_2 - theta;
    physics::check_relative(
        "centre at rest, θ0 = 0.5: σ²/φ̇²",
        sigma2 / s.phi_dot.powi(2),
        (3.0 + alpha.sin().powi(2)) / 5.0,
        1e-14,
    );
}

#[test]
fn the_analytic_jacobian_is_the_numerical_one() {
    // model::Linearisation's entries A … E against the finite differences, at a generic circle of the
    // general body: each entry to 1e-10 of the largest entry of its row.
    let p = physics::general();
    let coin = Coin::new(p);
    let (theta, omega_z) = (0.7, 1.3 * rate_unit(&p));
    let omega_y = steady_omega_y(&coin, theta, omega_z, Branch::Minus);
    let l = Linearisation::at(&coin, theta, omega_y, omega_z);
    // The pattern of model::Linearisation's doc: rows θ̇, ω̇_X, ω̇_Y, ω̇_Z.
    #[rustfmt::skip]
    let analytic = Matrix4::new(
        0.0, 1.0, 0.0, 0.0,
        l.a, 0.0, l.b, l.c,
        0.0, l.d, 0.0, 0.0,
        0.0, l.e, 0.0, 0.0,
    );
    let numerical = numerical_jacobian(&coin, &[theta, 0.0, omega_y, omega_z]);
    for row in 0..4 {
        let size = (0..4).map(|c| analytic[(row, c)].abs()).fold(0.0, f64::max);
        for column in 0..4 {
            physics::check(
                &format!("J[{row}][{column}]"),
                numerical[(row, column)],
                analytic[(row, column)],
                1e-10 * size,
            );
        }
    }
}
