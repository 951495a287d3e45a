//! Helpers of the model tests: parameter sets, a generic wobbling state and the `wobble` scene's state,
//! fixed-step rk4 trajectories, zero crossings of a sampled signal, and the reporting check that prints
//! measured vs expected vs tolerance.
// Test helpers are not #[test] functions, so clippy.toml's allow-unwrap-in-tests does not reach them; a
// failed unwrap here is a failed test, which is what we want.
#![allow(clippy::unwrap_used)]

use coin_log::integrate::{OdeSystem, Rk4, Stepper};
use coin_log::model::{CoinParams, Inertia, State};
use coin_log::scene::{presets, Scene};
use proptest::prelude::*;

/// Unit thin disk M = a = g = 1 (the note's section 5).
pub fn unit_disk() -> CoinParams {
    CoinParams::unit_disk()
}
/// Unit hoop M = a = g = 1.
pub fn unit_hoop() -> CoinParams {
    CoinParams::new(1.0, 1.0, 1.0, Inertia::Hoop).unwrap()
}
/// The "general parameters": M = 0.5, a = 2, g = 9.81, with inertias that are neither a disk's
/// (I_X = 0.5, I_Z = 1) nor a hoop's (I_X = 1, I_Z = 2).
pub fn general() -> CoinParams {
    CoinParams::new(
        0.5,
        2.0,
        9.81,
        Inertia::Explicit {
            inertia_x: 0.35,
            inertia_z: 0.6,
        },
    )
    .unwrap()
}
/// The natural rate unit √(g/a) (physics §2).
pub fn rate_unit(p: &CoinParams) -> f64 {
    (p.gravity() / p.radius()).sqrt()
}

/// A generic wobbling state: lean 0.4, every ω component nonzero, in the body's natural rate unit.
pub fn wobbling(p: &CoinParams) -> State {
    let w = rate_unit(p);
    State {
        theta: 0.4,
        phi: 0.3,
        psi: -0.2,
        omega_x: 0.35 * w,
        omega_y: -0.6 * w,
        omega_z: 2.2 * w,
        x: 0.1 * p.radius(),
        z: -0.2 * p.radius(),
    }
}

/// The initial state of the built-in `wobble` scene (θ0 = 0.5, ω = (0.3, 0.2, 1.5), unit thin disk).
pub fn wobble() -> State {
    let file = presets::preset("wobble").unwrap();
    Scene::from_file(&file).unwrap().initial
}

/// Integrates with the library's fixed-step rk4 for `steps` steps of `h`, keeping every `every`-th state
/// (and the first): the samples fall exactly on steps, so no interpolation error enters.
pub fn rk4_trajectory<const N: usize, S: OdeSystem<N>>(
    sys: &S,
    y0: &[f64; N],
    h: f64,
    steps: usize,
    every: usize,
) -> Vec<(f64, [f64; N])> {
    let mut stepper = Rk4::<N>::new(h);
    stepper.init(sys, 0.0, y0, f64::MAX).unwrap();
    let mut out = vec![(0.0, *y0)];
    for k in 1..=steps {
        stepper.step(sys, f64::MAX).unwrap();
        if k % every == 0 {
            out.push((stepper.state().t, stepper.state().y));
        }
    }
    out
}

/// The state after `steps` rk4 steps of `h`.
pub fn rk4_final<const N: usize, S: OdeSystem<N>>(
    sys: &S,
    y0: &[f64; N],
    h: f64,
    steps: usize,
) -> [f64; N] {
    rk4_trajectory(sys, y0, h, steps, steps).last().unwrap().1
}

/// Prints `what: measured, expected, |difference| vs tolerance` and asserts |measured − expected| ≤ tol.
pub fn check(what: &str, measured: f64, expected: f64, tolerance: f64) {
    let diff = (measured - expected).abs();
    println!(
        "{what}: measured {measured:.12e}, expected {expected:.12e}, |diff| {diff:.3e} (tolerance {tolerance:.1e})"
    );
    assert!(
        diff <= tolerance,
        "{what}: measured {measured:e} vs expected {expected:e}: |diff| {diff:e} > tolerance {tolerance:e}"
    );
}

/// Like [`check`] with a relative tolerance: |measured − expected| ≤ tol · |expected|.
pub fn check_relative(what: &str, measured: f64, expected: f64, relative: f64) {
    let diff = (measured - expected).abs() / expected.abs();
    println!(
        "{what}: measured {measured:.12e}, expected {expected:.12e}, relative diff {diff:.3e} (tolerance {relative:.1e})"
    );
    assert!(
        diff <= relative,
        "{what}: measured {measured:e} vs expected {expected:e}: relative diff {diff:e} > tolerance {relative:e}"
    );
}

/// Times where the sampled signal changes sign, by linear interpolation between samples.
pub fn zero_crossings(samples: &[(f64, f64)]) -> Vec<f64> {
    samples
        .windows(2)
        .filter(|w| w[0].1 != 0.0 && w[0].1.signum() != w[1].1.signum())
        .map(|w| w[0].0 - w[0].1 * (w[1].0 - w[0].0) / (w[1].1 - w[0].1))
        .collect()
}

/// A random body for property tests: M, a, g over two decades, inertias between a tenth and twice M a²
/// (any shape, not only the thin disk or the hoop).
pub fn random_body() -> impl Strategy<Value = CoinParams> {
    (0.1..10.0, 0.1..5.0, 0.5..20.0, 0.1..1.0, 0.1..2.0).prop_map(
        |(m, a, g, kx, kz): (f64, f64, f64, f64, f64)| {
            let ma2 = m * a * a;
            CoinParams::new(
                m,
                a,
                g,
                Inertia::Explicit {
                    inertia_x: kx * ma2,
                    inertia_z: kz * ma2,
                },
            )
            .unwrap()
        },
    )
}
