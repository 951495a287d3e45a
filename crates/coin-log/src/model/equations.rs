//! The equations of motion of the rolling coin, eqs (14)–(19) of physics §2, plus ẋ and ż.

use super::params::CoinParams;
use super::state::{StateRate, STATE_LEN};

/// The rolling coin as an ODE system: [`CoinParams`] with the coefficients of eqs (14)–(16) precomputed,
/// so that one right-hand side evaluation is a handful of multiplications and one `sin_cos` pair per angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coin {
    params: CoinParams,
    /// (I_Z + Ma²)/(I_X + Ma²), eq (14).
    gyro_x: f64,
    /// I_X/(I_X + Ma²), eq (14).
    centrifugal_x: f64,
    /// Mga/(I_X + Ma²), eq (14).
    gravity_x: f64,
    /// I_Z/I_X, eq (15).
    ratio_zx: f64,
    /// Ma²/(I_Z + Ma²), eq (16).
    rolling_z: f64,
}

/// Angular accelerations (ω̇_X, ω̇_Y, ω̇_Z) = (`x`, `y`, `z`) [rad/time²], eqs (14)–(16).
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct AngularAcceleration {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Coin {
    /// The ODE system for these parameters.
    #[must_use]
    pub fn new(params: CoinParams) -> Self {
        let ma2 = params.ma2();
        let ix = params.inertia_x();
        let iz = params.inertia_z();
        Self {
            params,
            gyro_x: (iz + ma2) / (ix + ma2),
            centrifugal_x: ix / (ix + ma2),
            gravity_x: params.topple_rate_squared(),
            ratio_zx: iz / ix,
            rolling_z: ma2 / (iz + ma2),
        }
    }

    /// The body parameters.
    #[must_use]
    pub fn params(&self) -> &CoinParams {
        &self.params
    }

    /// Angular accelerations from eqs (14)–(16) of physics §2, given θ and ω (lean frame).
    ///
    /// ```
    /// use coin_log::model::{Coin, CoinParams};
    /// // Unit thin disk (note §5): ω̇_X = −6/5 ω_Y ω_Z − 1/5 ω_Y² tan θ + 4/5 sin θ.
    /// let coin = Coin::new(CoinParams::unit_disk());
    /// let acc = coin.angular_acceleration(0.0, 0.0, 1.0, 2.0);
    /// assert!((acc.x - (-12.0 / 5.0)).abs() < 1e-15);
    /// ```
    #[must_use]
    #[inline]
    pub fn angular_acceleration(
        &self,
        theta: f64,
        omega_x: f64,
        omega_y: f64,
        omega_z: f64,
    ) -> AngularAcceleration {
        let (sin_t, cos_t) = theta.sin_cos();
        let tan_t = sin_t / cos_t;
        self.angular_acceleration_trig(sin_t, tan_t, omega_x, omega_y, omega_z)
    }

    #[inline]
    fn angular_acceleration_trig(
        &self,
        sin_t: f64,
        tan_t: f64,
        wx: f64,
        wy: f64,
        wz: f64,
    ) -> AngularAcceleration {
        AngularAcceleration {
            x: -self.gyro_x * wy * wz - self.centrifugal_x * wy * wy * tan_t
                + self.gravity_x * sin_t,
            y: wx * wy * tan_t + self.ratio_zx * wz * wx,
            z: self.rolling_z * wx * wy,
        }
    }

    /// The right-hand side: eqs (14)–(19) and the centre's velocity (physics §2). Writes into a
    /// caller-owned buffer; no allocation.
    #[inline]
    pub fn derivative(&self, y: &[f64; STATE_LEN], dydt: &mut StateRate) {
        // Plain arrays, the steppers' interface: nalgebra's SVector measured the same (27.4–27.9 ns per
        // evaluation against 27.5–28.1 ns, `cargo bench --bench rhs`).
        let (sin_t, tan_t) = kinematics(self.params.radius(), y, dydt);
        let acc = self.angular_acceleration_trig(sin_t, tan_t, y[3], y[4], y[5]);
        dydt[3] = acc.x; // (14)
        dydt[4] = acc.y; // (15)
        dydt[5] = acc.z; // (16)
    }
}

/// The rows of the right-hand side that no couple changes, for a coin of radius `a`: eqs (17)–(19) and
/// the centre's ẋ, ż (physics §2, §11). Returns (sin θ, tan θ) for the accelerations.
#[inline]
pub(super) fn kinematics<const N: usize>(a: f64, y: &[f64; N], dydt: &mut [f64; N]) -> (f64, f64) {
    let (theta, phi, wx, wy, wz) = (y[0], y[1], y[3], y[4], y[5]);
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    let tan_t = sin_t / cos_t;
    dydt[0] = wx; // (17)
    dydt[1] = wy / cos_t; // (18)
    dydt[2] = wz + wy * tan_t; // (19)
    dydt[6] = a * (-wz * cos_p + wx * cos_t * sin_p);
    dydt[7] = a * (wz * sin_p + wx * cos_t * cos_p);
    (sin_t, tan_t)
}
