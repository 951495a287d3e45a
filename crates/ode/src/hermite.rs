//! Cubic Hermite interpolation between two points with known derivatives: the dense output of the
//! fixed-step methods (O(h⁴) local error, matching rk4 and gauss4).

/// Interpolates at `t` ∈ [t0, t0 + h] from (y0, f0) at t0 and (y1, f1) at t0 + h.
#[inline]
#[allow(clippy::too_many_arguments)] // the two end points with their derivatives, as in the formula
pub fn hermite_interpolate<const N: usize>(
    t0: f64,
    h: f64,
    y0: &[f64; N],
    f0: &[f64; N],
    y1: &[f64; N],
    f1: &[f64; N],
    t: f64,
    out: &mut [f64; N],
) {
    let s = if h == 0.0 { 0.0 } else { (t - t0) / h };
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    for i in 0..N {
        out[i] = h00 * y0[i] + h * h10 * f0[i] + h01 * y1[i] + h * h11 * f1[i];
    }
}
