//! Linear stability of the steady motions (physics §5).

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
    let mga = p.mass() * p.gravity() * p.radius();
    (mga - p.inertia_z() * (p.inertia_z() + p.ma2()) * omega_z0 * omega_z0 / p.inertia_x())
        / (p.inertia_x() + p.ma2())
}

/// Critical spin ω_c of straight rolling: ω_c² = Mga I_X / (I_Z (I_Z + Ma²)) (physics §5); unstable while
/// |ω_Z0| < ω_c. Thin disk, unit scales: 1/√3.
#[must_use]
pub fn critical_spin(coin: &Coin) -> f64 {
    let p = coin.params();
    (p.mass() * p.gravity() * p.radius() * p.inertia_x()
        / (p.inertia_z() * (p.inertia_z() + p.ma2())))
    .sqrt()
}

/// σ² of the upright spin about the vertical diameter at rate Ω (physics §5): σ² = Ω² − Mga/(I_X + Ma²).
/// Stable iff σ² > 0; σ is the small-oscillation frequency.
#[must_use]
pub fn spin_upright_sigma_squared(coin: &Coin, omega: f64) -> f64 {
    let p = coin.params();
    omega * omega - p.mass() * p.gravity() * p.radius() / (p.inertia_x() + p.ma2())
}

/// σ² of the nutation about solution 2, centre at rest at lean θ₀ (physics §5):
/// σ² = Mga(Ma² cos θ₀ / I_X + 3 sin²θ₀ / cos θ₀)/(I_X + Ma²). Always positive: always stable.
#[must_use]
pub fn centre_fixed_sigma_squared(coin: &Coin, theta0: f64) -> f64 {
    let p = coin.params();
    let (s, c) = theta0.sin_cos();
    p.mass() * p.gravity() * p.radius() * (p.ma2() * c / p.inertia_x() + 3.0 * s * s / c)
        / (p.inertia_x() + p.ma2())
}
