//! The rolling coin as an integrable system with its physical events (physics §7), and the entry points
//! that run a chosen method on it. This is where the coin model meets the generic integrators.
//!
//! The conservative coin ([`Coin`], 8 components) and the dissipative one ([`DissipativeCoin`], 9: the
//! dissipated work W rides along, physics §11) are separate systems; [`run_dynamics`] picks one once,
//! before the integration, so the conservative hot loop is exactly what it is without dissipation.

use crate::integrate::{
    run_method_bounded, Bounds, EventFunctions, Flow, MethodConfig, OdeSystem, RunOutcome,
    RunSettings,
};
use crate::model::{
    Coin, DissipativeCoin, Dynamics, State, DISSIPATIVE_STATE_LEN, STATE_LEN, WORK_INDEX,
};

impl OdeSystem<STATE_LEN> for Coin {
    #[inline]
    fn rhs(&self, _t: f64, y: &[f64; STATE_LEN], dydt: &mut [f64; STATE_LEN]) {
        self.derivative(y, dydt);
    }
}

impl OdeSystem<DISSIPATIVE_STATE_LEN> for DissipativeCoin {
    #[inline]
    fn rhs(
        &self,
        _t: f64,
        y: &[f64; DISSIPATIVE_STATE_LEN],
        dydt: &mut [f64; DISSIPATIVE_STATE_LEN],
    ) {
        self.derivative(y, dydt);
    }
}

/// The coin's eight state components (θ, φ, ψ, ω, x, z) of a state, without W.
#[inline]
fn coin_part<const N: usize>(y: &[f64; N]) -> [f64; STATE_LEN] {
    let mut out = [0.0; STATE_LEN];
    out.copy_from_slice(&y[..STATE_LEN]);
    out
}

/// A physical event that ends a run because the rolling model stops being valid (physics §7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhysicalEvent {
    /// |θ| reached π/2 − flat_margin: the coin lands flat.
    FlatLanding,
    /// N reached 0: the coin would leave the table.
    LiftOff,
    /// |F| reached μN: the coin would slip.
    Slip,
}

/// Event functions of the coin: g_flat = π/2 − flat_margin − |θ|, g_lift = N / (Mg),
/// g_slip = (μN − F) / (Mg) (only when μ is given), with the reaction of the dynamics (eqs (31)–(33)
/// with dissipation, physics §11). Each ends the run when it crosses from > 0 to ≤ 0. They watch the
/// 8-component state of [`Coin`] and the 9-component one of [`DissipativeCoin`] alike.
#[derive(Debug, Clone, Copy)]
pub struct CoinEvents {
    dynamics: Dynamics,
    flat_margin: f64,
    friction: Option<f64>,
}

impl CoinEvents {
    /// Events for `dynamics`: flat landing at |θ| = π/2 − `flat_margin`, slip when `friction` (μ) is given.
    #[must_use]
    pub fn new(dynamics: impl Into<Dynamics>, flat_margin: f64, friction: Option<f64>) -> Self {
        Self {
            dynamics: dynamics.into(),
            flat_margin,
            friction,
        }
    }

    /// Which physical event the index reported by the driver stands for.
    #[must_use]
    pub fn event(index: usize) -> PhysicalEvent {
        match index {
            0 => PhysicalEvent::FlatLanding,
            1 => PhysicalEvent::LiftOff,
            _ => PhysicalEvent::Slip,
        }
    }
}

impl<const N: usize> EventFunctions<N> for CoinEvents {
    fn count(&self) -> usize {
        2 + usize::from(self.friction.is_some())
    }

    #[inline]
    fn evaluate(&self, _t: f64, y: &[f64; N], out: &mut [f64]) {
        let s = State::from_array(&coin_part(y));
        out[0] = std::f64::consts::FRAC_PI_2 - self.flat_margin - s.theta.abs();
        // Beyond flat the reaction formulas are meaningless; the flat event comes first there anyway.
        let r = self.dynamics.reaction(&s);
        let params = self.dynamics.coin().params();
        let weight = params.mass() * params.gravity();
        out[1] = r.normal / weight;
        if let (Some(mu), Some(slot)) = (self.friction, out.get_mut(2)) {
            *slot = (mu * r.normal - r.friction) / weight;
        }
    }
}

/// Runs `config` on `dynamics` from `initial` within `bounds`, until one of the [`CoinEvents`] of
/// `flat_margin` and `friction`, calling `observe(t, y, W)` at every sample: y the eight coin components, W
/// the dissipated work (from 0; `None` for conservative dynamics).
#[allow(
    clippy::too_many_arguments,
    reason = "what to integrate, how, for how long, within which bounds, until which events: each its own"
)]
pub fn run_dynamics<O>(
    config: &MethodConfig,
    dynamics: &Dynamics,
    initial: &State,
    settings: &RunSettings,
    bounds: &Bounds<'_>,
    flat_margin: f64,
    friction: Option<f64>,
    mut observe: O,
) -> RunOutcome
where
    O: FnMut(f64, &[f64; STATE_LEN], Option<f64>) -> Flow,
{
    let config = &MethodConfig {
        atol: working_atol(config, dynamics.coin(), initial),
        ..*config
    };
    let events = CoinEvents::new(*dynamics, flat_margin, friction);
    match dynamics {
        Dynamics::Conservative(coin) => run_method_bounded(
            config,
            coin,
            &initial.to_array(),
            settings,
            bounds,
            &events,
            |t, y| observe(t, y, None),
        ),
        Dynamics::Dissipative(coin) => {
            let mut y0 = [0.0; DISSIPATIVE_STATE_LEN];
            y0[..STATE_LEN].copy_from_slice(&initial.to_array());
            run_method_bounded(config, coin, &y0, settings, bounds, &events, |t, y| {
                observe(t, &coin_part(y), Some(y[WORK_INDEX]))
            })
        }
    }
}

/// The departure d = max(|θ|, τ|ω_X|) of `state` from upright (θ = 0, θ̇ = 0, whatever the spin), τ the
/// time unit: the size of the state that grows away from the unstable upright (physics §5, §12).
fn upright_departure(coin: &Coin, state: &State) -> f64 {
    state
        .theta
        .abs()
        .max(coin.params().time_unit() * state.omega_x.abs())
}

/// The absolute tolerance the integration works to (physics §12, "Integration"): the scene's atol, but at
/// most rtol·d for a departure d > 0 from upright, floored at the smallest subnormal so that no weight is 0.
#[must_use]
pub fn working_atol(config: &MethodConfig, coin: &Coin, initial: &State) -> f64 {
    let d = upright_departure(coin, initial);
    if d > 0.0 && config.rtol * d < config.atol {
        (config.rtol * d).max(f64::from_bits(1))
    } else {
        config.atol
    }
}

/// Why an event time from `initial` is not to be trusted whatever the energy drift says, if it is not: a
/// departure from upright below 2.2e-308 is subnormal and carries fewer than 53 bits (physics §12).
#[must_use]
pub fn departure_doubt(coin: &Coin, initial: &State) -> Option<String> {
    let d = upright_departure(coin, initial);
    (d > 0.0 && d < f64::MIN_POSITIVE).then(|| {
        format!(
            "the departure from upright max(|θ|, τ|ω_X|) = {d:e} is below 2.2e-308, the smallest \
             normal number: it carries fewer than 53 bits, so the escape time ln(C/d)/λ cannot be \
             integrated to the tolerance; start at least 2.2e-308 from upright"
        )
    })
}
