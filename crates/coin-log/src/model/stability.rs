//! Linear stability of the steady motions: the known special cases (physics §5) and the linearisation of
//! any steady motion (physics §9).

use super::equations::Coin;

/// λ² of straight rolling at spin ω_Z0 (physics §5):
/// λ² = (Mga − I_Z(I_Z + Ma²) ω_Z0² / I_X) / (I_X + Ma²). Positive: the tilt grows like e^{λt};
/// negative: it oscillates at σ = √(−λ²).
///
/// ```
/// use coin_log::model::{straight_lambda_squared, Coin, CoinParams};
/// let coin = Coin::new(CoinParams::unit_disk());
/// // Thin disk, unit scales: λ² = 4/5 (1 − 3 ω_Z0²).
/// assert!((straight_lambda_squared(&coin, 0.4) - 0.8 * (1.0 - 3.0 * 0.16)).abs() < 1e-15);
/// ```
#[must_use]
pub fn straight_lambda_squared(coin: &Coin, omega_z0: f64) -> f64 {
    let p = coin.params();
    let mga = p.energy_scale();
    (mga - p.inertia_z() * (p.inertia_z() + p.ma2()) * omega_z0 * omega_z0 / p.inertia_x())
        / (p.inertia_x() + p.ma2())
}

/// Critical spin ω_c of straight rolling: ω_c² = Mga I_X / (I_Z (I_Z + Ma²)) (physics §5); unstable while
/// |ω_Z0| < ω_c. Thin disk, unit scales: 1/√3.
#[must_use]
pub fn critical_spin(coin: &Coin) -> f64 {
    let p = coin.params();
    (p.energy_scale() * p.inertia_x() / (p.inertia_z() * (p.inertia_z() + p.ma2()))).sqrt()
}

/// σ² of the upright spin about the vertical diameter at rate Ω (physics §5): σ² = Ω² − Mga/(I_X + Ma²).
/// Stable iff σ² > 0; σ is the small-oscillation frequency.
#[must_use]
pub fn spin_upright_sigma_squared(coin: &Coin, omega: f64) -> f64 {
    omega * omega - coin.params().topple_rate_squared()
}

/// σ² of the nutation about solution 2, centre at rest at lean θ₀ (physics §5):
/// σ² = Mga(Ma² cos θ₀ / I_X + 3 sin²θ₀ / cos θ₀)/(I_X + Ma²). Always positive: always stable.
#[must_use]
pub fn centre_fixed_sigma_squared(coin: &Coin, theta0: f64) -> f64 {
    let p = coin.params();
    let (s, c) = theta0.sin_cos();
    p.energy_scale() * (p.ma2() * c / p.inertia_x() + 3.0 * s * s / c) / (p.inertia_x() + p.ma2())
}

/// The reduced system of eqs (14)–(17) linearised about a state with ω_X = 0: the entries A … E of its
/// Jacobian in (θ, ω_X, ω_Y, ω_Z), eq (20) of physics §9, whose characteristic polynomial is
/// λ²(λ² + σ²) with σ² = −(A + BD + CE).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linearisation {
    /// ∂ω̇_X/∂θ = (Mga cos θ − I_X ω_Y² / cos²θ)/(I_X + Ma²).
    pub a: f64,
    /// ∂ω̇_X/∂ω_Y = −((I_Z + Ma²) ω_Z + 2 I_X ω_Y tan θ)/(I_X + Ma²).
    pub b: f64,
    /// ∂ω̇_X/∂ω_Z = −(I_Z + Ma²) ω_Y/(I_X + Ma²).
    pub c: f64,
    /// ∂ω̇_Y/∂ω_X = ω_Y tan θ + (I_Z/I_X) ω_Z.
    pub d: f64,
    /// ∂ω̇_Z/∂ω_X = Ma² ω_Y/(I_Z + Ma²).
    pub e: f64,
}

impl Linearisation {
    /// The entries of the Jacobian at (θ, ω_X = 0, ω_Y, ω_Z) (physics §9, eq (20)).
    #[must_use]
    pub fn at(coin: &Coin, theta: f64, omega_y: f64, omega_z: f64) -> Self {
        let p = coin.params();
        let (ix, iz, ma2) = (p.inertia_x(), p.inertia_z(), p.ma2());
        let mga = p.energy_scale();
        let (st, ct) = theta.sin_cos();
        let tan_t = st / ct;
        let lever = ix + ma2;
        Self {
            a: (mga * ct - ix * omega_y * omega_y / (ct * ct)) / lever,
            b: -((iz + ma2) * omega_z + 2.0 * ix * omega_y * tan_t) / lever,
            c: -(iz + ma2) * omega_y / lever,
            d: omega_y * tan_t + iz / ix * omega_z,
            e: ma2 * omega_y / (iz + ma2),
        }
    }

    /// σ² = −(A + BD + CE), the constant term of λ² + σ² (physics §9, eq (20)).
    #[must_use]
    pub fn sigma_squared(&self) -> f64 {
        -(self.a + self.b * self.d + self.c * self.e)
    }

    /// |A| + |BD| + |CE|: the size of the terms σ² is the sum of. Rounding leaves σ² uncertain by a few
    /// ulp of this, not of |σ²|, which is what matters near the stability boundary σ² = 0.
    #[must_use]
    pub fn scale(&self) -> f64 {
        self.a.abs() + (self.b * self.d).abs() + (self.c * self.e).abs()
    }
}

/// The roots of λ²(λ² + σ²) as (re, im) pairs: 0, 0 and ±√(−σ²) (physics §9), the pair with the positive
/// real or imaginary part first.
#[must_use]
pub fn eigenvalues(sigma_squared: f64) -> [(f64, f64); 4] {
    let root = sigma_squared.abs().sqrt();
    if sigma_squared >= 0.0 {
        [(0.0, 0.0), (0.0, 0.0), (0.0, root), (0.0, -root)]
    } else {
        [(0.0, 0.0), (0.0, 0.0), (root, 0.0), (-root, 0.0)]
    }
}

/// σ² of the steady motion at lean θ₀ with rates ω_Y0, ω_Z0 (ω_X = 0; physics §9, eq (21)).
/// σ² > 0: stable, small perturbations nutate at σ; σ² < 0: unstable, they grow like e^{√(−σ²) t}.
/// Straight rolling, the upright spin and the centre-fixed motion are its special cases (physics §5).
///
/// ```
/// use coin_log::model::{steady_sigma_squared, straight_lambda_squared, Coin, CoinParams};
/// let coin = Coin::new(CoinParams::unit_disk());
/// // Straight rolling (θ₀ = ω_Y0 = 0): σ² = −λ².
/// let s2 = steady_sigma_squared(&coin, 0.0, 0.0, 1.0);
/// assert!((s2 + straight_lambda_squared(&coin, 1.0)).abs() < 1e-15);
/// ```
#[must_use]
pub fn steady_sigma_squared(coin: &Coin, theta0: f64, omega_y0: f64, omega_z0: f64) -> f64 {
    let p = coin.params();
    let (ix, iz, ma2) = (p.inertia_x(), p.inertia_z(), p.ma2());
    let mga = p.energy_scale();
    let (s, c) = theta0.sin_cos();
    let (wy, wz) = (omega_y0, omega_z0);
    ((ix * (1.0 + 2.0 * s * s) / (c * c) + ma2) * wy * wy
        + (3.0 * iz + ma2) * (s / c) * wy * wz
        + iz * (iz + ma2) / ix * wz * wz
        - mga * c)
        / (ix + ma2)
}
