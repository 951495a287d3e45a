//! Helpers shared by the model tests: small vector algebra written here (not the library's), the angle →
//! quaternion and lean-frame constructions of NOTES §1 done independently, a fixed-step rk4 trajectory
//! recorder, parameter sets, and the reporting helper that prints measured vs expected vs tolerance.
#![allow(dead_code)]
// each test binary uses a different subset of these helpers
// Test helpers are not #[test] functions, so clippy.toml's allow-unwrap-in-tests does not reach them; a
// failed unwrap here is a failed test, which is what we want.
#![allow(clippy::unwrap_used, clippy::expect_used)]

pub mod newton_euler;

use coin_log::integrate::{OdeSystem, Rk4, Stepper};
use coin_log::model::{CoinParams, Inertia, State};

/// A world-frame vector (y up, NOTES §1).
pub type V3 = [f64; 3];

pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub fn scale(k: f64, a: V3) -> V3 {
    [k * a[0], k * a[1], k * a[2]]
}
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
/// Largest component of |a − b|.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A quaternion, scalar first: [w, x, y, z].
pub type Quat = [f64; 4];

pub fn quat_mul(p: Quat, q: Quat) -> Quat {
    [
        p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
        p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
        p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
        p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0],
    ]
}
pub fn quat_axis_angle(axis: V3, angle: f64) -> Quat {
    let (s, c) = (0.5 * angle).sin_cos();
    [c, s * axis[0], s * axis[1], s * axis[2]]
}
/// The rotation matrix of a (normalised) quaternion; columns are the images of e_x, e_y, e_z.
pub fn quat_matrix(q: Quat) -> [[f64; 3]; 3] {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = [q[0] / n, q[1] / n, q[2] / n, q[3] / n];
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}
pub fn mat_vec(m: &[[f64; 3]; 3], v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}
pub fn column(m: &[[f64; 3]; 3], j: usize) -> V3 {
    [m[0][j], m[1][j], m[2][j]]
}
/// Distance between two quaternions up to sign (q and −q are the same rotation, NOTES §1).
pub fn quat_distance(p: Quat, q: Quat) -> f64 {
    let minus: Vec<f64> = q.iter().map(|v| -v).collect();
    max_diff(&p, &q).min(max_diff(&p, &minus))
}

/// NOTES §1, built here from three axis–angle quaternions: q = q(e_y, φ) · q(e_x, θ) · q(e_z, ψ).
pub fn quaternion_from_angles(theta: f64, phi: f64, psi: f64) -> Quat {
    quat_mul(
        quat_axis_angle([0.0, 1.0, 0.0], phi),
        quat_mul(
            quat_axis_angle([1.0, 0.0, 0.0], theta),
            quat_axis_angle([0.0, 0.0, 1.0], psi),
        ),
    )
}

/// The lean frame (e_X, e_Y, e_Z) from the coin's normal e_Z by the geometric definition of NOTES §1 and
/// §8 item 1: e_X = e_y × e_Z / |e_y × e_Z| (horizontal), e_Y = e_Z × e_X (in the coin, pointing up).
pub fn lean_frame_from_normal(e_z: V3) -> [V3; 3] {
    let u = cross([0.0, 1.0, 0.0], e_z);
    let e_x = scale(1.0 / norm(u), u);
    [e_x, cross(e_z, e_x), e_z]
}

/// The lean frame of angles (θ, φ) through the quaternion of NOTES §1 (its image of the body normal).
pub fn lean_frame(theta: f64, phi: f64) -> [V3; 3] {
    let q = quaternion_from_angles(theta, phi, 0.0);
    lean_frame_from_normal(column(&quat_matrix(q), 2))
}

/// World angular velocity from lean-frame components: ω = ω_X e_X + ω_Y e_Y + ω_Z e_Z.
pub fn world_omega(theta: f64, phi: f64, omega: V3) -> V3 {
    let [ex, ey, ez] = lean_frame(theta, phi);
    add(
        add(scale(omega[0], ex), scale(omega[1], ey)),
        scale(omega[2], ez),
    )
}

/// Unit thin disk M = a = g = 1 (the note's section 5).
pub fn unit_disk() -> CoinParams {
    CoinParams::unit_disk()
}
/// Unit hoop M = a = g = 1.
pub fn unit_hoop() -> CoinParams {
    CoinParams::new(1.0, 1.0, 1.0, Inertia::Hoop).unwrap()
}
/// The "general parameters" of issue 3: M = 0.5, a = 2, g = 9.81, with inertias that are neither a disk's
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
/// The natural rate unit √(g/a) (NOTES §2).
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
            out.push((stepper.t(), *stepper.y()));
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
