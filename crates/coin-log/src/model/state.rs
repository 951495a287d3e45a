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
