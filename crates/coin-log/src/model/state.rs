//! The state of the rolling coin (physics §1): angles, lean-frame angular velocity and centre position.

/// Number of state components.
pub const STATE_LEN: usize = 8;

/// The coin's state, in the order the integrators see it ([`State::to_array`]):
/// θ, φ, ψ, ω_X, ω_Y, ω_Z, x, z.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    /// Lean θ \[rad\]: 0 is upright, ±π/2 lying flat.
    pub theta: f64,
    /// Heading φ \[rad\], rotation about the world's vertical y axis (unwrapped).
    pub phi: f64,
    /// Spin ψ \[rad\], rotation about the coin's normal (unwrapped).
    pub psi: f64,
    /// ω_X [rad/time]: angular velocity about the horizontal lean-frame axis X.
    pub omega_x: f64,
    /// ω_Y [rad/time]: angular velocity about the in-plane, upward lean-frame axis Y.
    pub omega_y: f64,
    /// ω_Z [rad/time]: angular velocity about the coin's normal Z.
    pub omega_z: f64,
    /// Centre x coordinate on the table plane \[length\].
    pub x: f64,
    /// Centre z coordinate on the table plane \[length\].
    pub z: f64,
}

impl State {
    /// The state as the integrator's vector.
    #[must_use]
    pub fn to_array(&self) -> [f64; STATE_LEN] {
        [
            self.theta,
            self.phi,
            self.psi,
            self.omega_x,
            self.omega_y,
            self.omega_z,
            self.x,
            self.z,
        ]
    }

    /// The state from the integrator's vector.
    #[must_use]
    pub fn from_array(y: &[f64; STATE_LEN]) -> Self {
        Self {
            theta: y[0],
            phi: y[1],
            psi: y[2],
            omega_x: y[3],
            omega_y: y[4],
            omega_z: y[5],
            x: y[6],
            z: y[7],
        }
    }

    /// True when every component is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.to_array().iter().all(|v| v.is_finite())
    }
}

/// Time derivative of a [`State`], same order.
pub type StateRate = [f64; STATE_LEN];

/// Below this, x² + y² + z² may have lost digits to subnormal rounding (or be 0 for a nonzero vector):
/// squares of components under 1e-154 underflow. 2⁻¹⁰²²/2⁻⁵² ≈ 1e-292 keeps that loss below one rounding.
const SQUARES_FLOOR: f64 = f64::MIN_POSITIVE / f64::EPSILON;

/// |(x, y, z)| without underflow or overflow: √(x² + y² + z²) as the callers always formed it wherever
/// that sum is a normal number (the same bits), and the scaled `hypot` where the squares would underflow
/// or overflow. A coin at rest at θ₀ = 1e-200 has |ω| ~ 1e-198, whose square is 0 in double precision;
/// `verify` then judged "ω = 0 throughout" (physics §12 follows θ₀ down to 1e-300).
#[must_use]
#[inline]
pub fn magnitude(x: f64, y: f64, z: f64) -> f64 {
    let squares = x * x + y * y + z * z;
    if squares >= SQUARES_FLOOR && squares.is_finite() {
        squares.sqrt()
    } else {
        x.hypot(y).hypot(z)
    }
}

#[cfg(test)]
mod tests {
    use super::magnitude;

    #[test]
    fn magnitude_keeps_the_sums_bits_and_survives_underflow_and_overflow() {
        for (x, y, z) in [(3.0f64, 4.0, 12.0), (0.1, -0.7, 1e-9), (1e150, 2e150, 0.0)] {
            let old = (x * x + y * y + z * z).sqrt();
            assert_eq!(magnitude(x, y, z).to_bits(), old.to_bits());
        }
        // Negative controls: the squares give 0 and ∞.
        assert_eq!((1e-200f64 * 1e-200 * 2.0).sqrt(), 0.0);
        assert!((magnitude(1e-200, 0.0, 1e-200) / 1.414_213_562_373_095e-200 - 1.0).abs() < 1e-15);
        assert!((magnitude(1e200, -1e200, 0.0) / 1.414_213_562_373_095e200 - 1.0).abs() < 1e-15);
        assert_eq!(magnitude(0.0, 0.0, 5e-324), 5e-324);
    }
}
