//! Small vector and quaternion algebra written here (not the library's), and the angle → quaternion and
//! lean-frame constructions of physics §1 done independently of the library.

/// A world-frame vector (y up, physics §1).
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
/// Distance between two quaternions up to sign (q and −q are the same rotation, physics §1).
pub fn quat_distance(p: Quat, q: Quat) -> f64 {
    let minus: Vec<f64> = q.iter().map(|v| -v).collect();
    max_diff(&p, &q).min(max_diff(&p, &minus))
}

/// physics §1, built here from three axis–angle quaternions: q = q(e_y, φ) · q(e_x, θ) · q(e_z, ψ).
pub fn quaternion_from_angles(theta: f64, phi: f64, psi: f64) -> Quat {
    quat_mul(
        quat_axis_angle([0.0, 1.0, 0.0], phi),
        quat_mul(
            quat_axis_angle([1.0, 0.0, 0.0], theta),
            quat_axis_angle([0.0, 0.0, 1.0], psi),
        ),
    )
}

/// The lean frame (e_X, e_Y, e_Z) from the coin's normal e_Z by the geometric definition of physics §1 and
/// §8 item 1: e_X = e_y × e_Z / |e_y × e_Z| (horizontal), e_Y = e_Z × e_X (in the coin, pointing up).
pub fn lean_frame_from_normal(e_z: V3) -> [V3; 3] {
    let u = cross([0.0, 1.0, 0.0], e_z);
    let e_x = scale(1.0 / norm(u), u);
    [e_x, cross(e_z, e_x), e_z]
}

/// The lean frame of angles (θ, φ) through the quaternion of physics §1 (its image of the body normal).
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
