//! The slow-change approximation of a dissipating coin (physics §11.2, eqs (35)–(38)): while α = π/2 − |θ|
//! changes little in a nutation period, the motion stays near the centre-fixed family.

use crate::model::{
    centre_fixed_sigma_squared, Coin, Dissipation, DissipationError, DissipationModel, State,
};
use crate::scene::defaults;
use std::f64::consts::FRAC_PI_2;

/// α = π/2 − |θ|, the angle between the coin and the table \[rad\].
#[must_use]
pub fn alpha_of(s: &State) -> f64 {
    FRAC_PI_2 - s.theta.abs()
}

/// C of the slow-change law d(sin α)/dt = −C sin^p α, eq (37) of physics §11.2 [1/time].
fn slow_change_rate(coin: &Coin, law: &Dissipation) -> f64 {
    let p = coin.params();
    let mga = p.energy_scale();
    law.coefficient() * (mga / p.inertia_x()).powf(0.5 * law.m()) / (1.5 * mga)
}

/// T = sin^(1−p) α₀ / (|1 − p| C): the collapse time t₀ for p < 1, the decay time of
/// α₀(1 + t/T)^(1/(1−p)) for p > 1 (eq (37)) \[time\].
///
/// ```
/// use coin_log::analyse::slow_change::slow_change_time_scale;
/// use coin_log::model::{Coin, CoinParams, Dissipation, DissipationModel};
/// // Viscous (m = 2, k = 0, p = −1) on the unit disk: C = κ (Mga/I_X) / (3/2 Mga) = 8κ/3, so
/// // T = sin² α₀ / (2C) = 3 sin² α₀ / (16 κ).
/// let coin = Coin::new(CoinParams::unit_disk());
/// let law = Dissipation::preset(DissipationModel::Viscous, 1e-3).unwrap();
/// let expected = 3.0 * 0.2_f64.sin().powi(2) / 16e-3;
/// assert!((slow_change_time_scale(&coin, &law, 0.2) / expected - 1.0).abs() < 1e-14);
/// ```
#[must_use]
pub fn slow_change_time_scale(coin: &Coin, law: &Dissipation, alpha0: f64) -> f64 {
    let q = 1.0 - law.angle_exponent();
    alpha0.sin().powf(q) / (q.abs() * slow_change_rate(coin, law))
}

/// The law of `model` whose time scale from `alpha0` is `time_scale` (the inverse of
/// [`slow_change_time_scale`] in κ); fails for `power-law` (no fixed exponents) or a κ that is not valid.
pub fn coefficient_for(
    coin: &Coin,
    model: DissipationModel,
    alpha0: f64,
    time_scale: f64,
) -> Result<Dissipation, DissipationError> {
    let unit = Dissipation::preset(model, 1.0)?;
    let kappa = slow_change_time_scale(coin, &unit, alpha0) / time_scale;
    Dissipation::preset(model, kappa)
}

/// ε(α) = |α̇| / (α σ): the slow-change rate α̇ = −C sin^p α / cos α against the nutation frequency σ of the
/// centre-fixed motion at α (physics §5). The slow-change approximation needs ε ≪ 1.
fn slow_change_ratio(coin: &Coin, law: &Dissipation, alpha: f64) -> f64 {
    let rate = slow_change_rate(coin, law) * alpha.sin().powf(law.angle_exponent()) / alpha.cos();
    let sigma = centre_fixed_sigma_squared(coin, FRAC_PI_2 - alpha).sqrt();
    rate / (alpha * sigma)
}

/// The α below which ε exceeds `epsilon` (bisection in ln α between the default flat margin and `alpha0`);
/// 0 when ε stays below `epsilon` all the way (p ≥ 1/2, where the slow-change approximation improves as α
/// falls) \[rad\].
#[must_use]
pub fn breakdown_alpha(coin: &Coin, law: &Dissipation, alpha0: f64, epsilon: f64) -> f64 {
    let ratio = |a: f64| slow_change_ratio(coin, law, a);
    let mut lo = defaults::FLAT_MARGIN;
    let mut hi = alpha0;
    if ratio(lo) <= epsilon {
        return 0.0;
    }
    if ratio(hi) >= epsilon {
        return hi;
    }
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if ratio(mid) > epsilon {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}
