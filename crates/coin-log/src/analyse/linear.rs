//! What the linear theory of the steady motions predicts (physics §5, §9): the nutation frequency of small
//! perturbations, the states that excite one mode of the linearisation only, and the tilt of straight
//! rolling started from a small tilt at rest.

use crate::model::{
    steady_sigma_squared, straight_lambda_squared, Coin, Linearisation, State, Steady,
};

/// The nutation frequency σ of small perturbations of a steady motion (physics §9, eq (21)); `None` when
/// σ² ≤ 0 (an unstable steady motion) [1/time].
///
/// ```
/// use coin_log::analyse::linear::nutation_frequency;
/// use coin_log::model::{straight_lambda_squared, Coin, CoinParams, Steady, SteadyKind};
/// let coin = Coin::new(CoinParams::unit_disk());
/// // Straight rolling above ω_c: σ² = −λ² = 4/5 (3 ω_Z0² − 1) = 1.6 at ω_Z0 = 1.
/// let steady = Steady::new(&coin, SteadyKind::Straight { omega_z: 1.0 }).unwrap();
/// assert!((nutation_frequency(&coin, &steady).unwrap() - 1.6_f64.sqrt()).abs() < 1e-15);
/// ```
#[must_use]
pub fn nutation_frequency(coin: &Coin, steady: &Steady) -> Option<f64> {
    let s = &steady.state;
    let sigma2 = steady_sigma_squared(coin, s.theta, s.omega_y, s.omega_z);
    (sigma2 > 0.0).then(|| sigma2.sqrt())
}

/// A steady motion `steady` kicked along the oscillating mode of its linearisation (physics §9):
/// δω_X = σ·amplitude, so the motion nutates about the steady motion itself, by `amplitude` \[rad\] in θ,
/// and its frequency differs from σ by O(amplitude²).
#[must_use]
pub fn kicked(coin: &Coin, steady: &State, amplitude: f64) -> State {
    let sigma2 = steady_sigma_squared(coin, steady.theta, steady.omega_y, steady.omega_z);
    State {
        omega_x: steady.omega_x + sigma2.max(0.0).sqrt() * amplitude,
        ..*steady
    }
}

/// A steady motion `steady` displaced by `amplitude` \[rad\] in θ along the eigenvector (1, λ, D, E) of
/// λ = √(−σ²) (physics §9), so the perturbation grows like e^{λt} from t = 0 without a decaying part.
#[must_use]
pub fn displaced(coin: &Coin, steady: &State, amplitude: f64) -> State {
    let l = Linearisation::at(coin, steady.theta, steady.omega_y, steady.omega_z);
    let lambda = (-l.sigma_squared()).max(0.0).sqrt();
    State {
        theta: steady.theta + amplitude,
        omega_x: steady.omega_x + lambda * amplitude,
        omega_y: steady.omega_y + l.d * amplitude,
        omega_z: steady.omega_z + l.e * amplitude,
        ..*steady
    }
}

/// θ(t) of straight rolling at spin Ω = `omega_z0` from a small tilt θ₀ = `theta0` at rest, by the linear
/// theory (physics §5): with G = Mga/(I_X + Ma²) and λ² = [`straight_lambda_squared`],
/// θ̈ = λ²θ + (G − λ²)θ₀, so θ(t) = θ₀(1 + G(cosh λt − 1)/λ²), with (1 − cos σt)/σ² for λ² = −σ² < 0 and
/// t²/2 at λ² = 0 \[rad\].
///
/// ```
/// use coin_log::analyse::linear::straight_tilt_linear;
/// use coin_log::model::{critical_spin, Coin, CoinParams};
/// let coin = Coin::new(CoinParams::unit_disk());
/// // At ω_c the thin disk's tilt grows like θ₀(1 + 2t²/5): 41 θ₀ at t = 10.
/// let theta = straight_tilt_linear(&coin, critical_spin(&coin), 1e-6, 10.0);
/// assert!((theta / 1e-6 - 41.0).abs() < 1e-6);
/// ```
#[must_use]
pub fn straight_tilt_linear(coin: &Coin, omega_z0: f64, theta0: f64, t: f64) -> f64 {
    let p = coin.params();
    let g = p.topple_rate_squared();
    let l2 = straight_lambda_squared(coin, omega_z0);
    let growth = if l2.abs() * t * t < 1e-8 {
        // Series: t²/2 + λ²t⁴/24 (the closed forms cancel here).
        0.5 * t * t + l2 * t.powi(4) / 24.0
    } else if l2 > 0.0 {
        let l = l2.sqrt();
        ((l * t).cosh() - 1.0) / l2
    } else {
        let s = (-l2).sqrt();
        (1.0 - (s * t).cos()) / (-l2)
    };
    theta0 * (1.0 + g * growth)
}
