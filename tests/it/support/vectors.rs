//! Vectors, quaternions and the angle → quaternion and lean-frame constructions of physics §1, built here
//! with nalgebra's own rotations (axis–angle products, rotation matrices), independently of the library's
//! hand-ordered formulas.

use nalgebra::{Quaternion, Unit, UnitQuaternion, Vector3};

/// A world-frame vector (y up, physics §1).
pub type V3 = Vector3<f64>;

/// Largest component of |a − b|.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Distance between two quaternions up to sign (q and −q are the same rotation, physics §1): the largest
/// component of q − p or of q + p, whichever is smaller.
pub fn quat_distance(p: &Quaternion<f64>, q: &Quaternion<f64>) -> f64 {
    (p - q).coords.amax().min((p + q).coords.amax())
}

/// physics §1, built from three axis–angle rotations: q = q(e_y, φ) · q(e_x, θ) · q(e_z, ψ).
pub fn quaternion_from_angles(theta: f64, phi: f64, psi: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::y_axis(), phi)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), theta)
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), psi)
}

/// The lean frame (e_X, e_Y, e_Z) from the coin's normal e_Z by the geometric definition of physics §1 and
/// §8 item 1: e_X = e_y × e_Z / |e_y × e_Z| (horizontal), e_Y = e_Z × e_X (in the coin, pointing up).
pub fn lean_frame_from_normal(e_z: &V3) -> [V3; 3] {
    let e_x = Unit::new_normalize(Vector3::y().cross(e_z)).into_inner();
    [e_x, e_z.cross(&e_x), *e_z]
}

/// The lean frame of angles (θ, φ) through the quaternion of physics §1 (its image of the body normal).
pub fn lean_frame(theta: f64, phi: f64) -> [V3; 3] {
    let q = quaternion_from_angles(theta, phi, 0.0);
    lean_frame_from_normal(&(q * Vector3::z()))
}

/// World angular velocity from lean-frame components: ω = ω_X e_X + ω_Y e_Y + ω_Z e_Z.
pub fn world_omega(theta: f64, phi: f64, omega: [f64; 3]) -> V3 {
    let [ex, ey, ez] = lean_frame(theta, phi);
    ex * omega[0] + ey * omega[1] + ez * omega[2]
}
