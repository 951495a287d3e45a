//! The rolling coin as an integrable system with its physical events (physics §7), and the entry points
//! that run a chosen method on it. This is where the coin model meets the generic integrators.
//!
//! The conservative coin ([`Coin`], 8 components) and the dissipative one ([`DissipativeCoin`], 9: the
//! dissipated work W rides along, physics §11) are separate systems; [`run_dynamics`] picks one once,
//! before the integration, so the conservative hot loop is exactly what it is without dissipation.

use crate::integrate::{
    self, run_method_bounded, Bounds, EventFunctions, Flow, MethodConfig, OdeSystem, RunOutcome,
    RunSettings, Stepper,
};
use crate::model::{
    reaction, Coin, DissipativeCoin, Dynamics, Reaction, State, DISSIPATIVE_STATE_LEN, STATE_LEN,
    WORK_INDEX,
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

/// The coin's eight state components of a dissipative state (θ, φ, ψ, ω, x, z), without W.
#[must_use]
#[inline]
pub fn coin_part(y: &[f64; DISSIPATIVE_STATE_LEN]) -> [f64; STATE_LEN] {
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
/// g_slip = (μN − F) / (Mg) (only when μ is given). Each ends the run when it crosses from > 0 to ≤ 0.
#[derive(Debug, Clone, Copy)]
pub struct CoinEvents {
    coin: Coin,
    flat_margin: f64,
    friction: Option<f64>,
}

impl CoinEvents {
    /// Events for `coin`, flat landing at |θ| = π/2 − `flat_margin`, slip when `friction` (μ) is given.
    #[must_use]
    pub fn new(coin: Coin, flat_margin: f64, friction: Option<f64>) -> Self {
        Self {
            coin,
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

impl CoinEvents {
    fn event_count(&self) -> usize {
        if self.friction.is_some() {
            3
        } else {
            2
        }
    }

    /// The event functions at state `s` with its reaction `r`.
    #[inline]
    fn evaluate_with(&self, s: &State, r: &Reaction, out: &mut [f64]) {
        out[0] = std::f64::consts::FRAC_PI_2 - self.flat_margin - s.theta.abs();
        let weight = self.coin.params().mass() * self.coin.params().gravity();
        out[1] = r.normal / weight;
        if let (Some(mu), Some(slot)) = (self.friction, out.get_mut(2)) {
            *slot = (mu * r.normal - r.friction) / weight;
        }
    }
}

impl EventFunctions<STATE_LEN> for CoinEvents {
    fn count(&self) -> usize {
        self.event_count()
    }

    fn evaluate(&self, _t: f64, y: &[f64; STATE_LEN], out: &mut [f64]) {
        let s = State::from_array(y);
        // Beyond flat the reaction formulas are meaningless; the flat event comes first there anyway.
        let r = reaction(&self.coin, &s);
        self.evaluate_with(&s, &r, out);
    }
}

/// The events of the dissipative coin: those of [`CoinEvents`], with the reaction of eqs (31)–(33)
/// (physics §11), on the 9-component state.
#[derive(Debug, Clone, Copy)]
pub struct DissipativeEvents {
    events: CoinEvents,
    coin: DissipativeCoin,
}

impl DissipativeEvents {
    /// Events for `coin`, flat landing at |θ| = π/2 − `flat_margin`, slip when `friction` (μ) is given;
    /// numbered as [`CoinEvents::event`] numbers them.
    #[must_use]
    pub fn new(coin: DissipativeCoin, flat_margin: f64, friction: Option<f64>) -> Self {
        Self {
            events: CoinEvents::new(*coin.coin(), flat_margin, friction),
            coin,
        }
    }
}

impl EventFunctions<DISSIPATIVE_STATE_LEN> for DissipativeEvents {
    fn count(&self) -> usize {
        self.events.event_count()
    }

    fn evaluate(&self, _t: f64, y: &[f64; DISSIPATIVE_STATE_LEN], out: &mut [f64]) {
        let s = State::from_array(&coin_part(y));
        let r = self.coin.reaction(&s);
        self.events.evaluate_with(&s, &r, out);
    }
}

/// Runs `config` on the scene's dynamics from `initial`, with the physical events (flat landing at
/// |θ| = π/2 − `flat_margin`, lift-off, slip when `friction` is given), calling `observe(t, y, W)` at every
/// sample: y the eight coin components, W the dissipated work (`None` for conservative dynamics), within
/// `bounds` (a step budget, a stop flag seen after every step).
///
/// The dispatch happens here, once: conservative dynamics integrate [`Coin`] itself, dissipative ones
/// [`DissipativeCoin`] with W as a ninth component starting at 0.
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
    match dynamics {
        Dynamics::Conservative(coin) => run_method_bounded(
            config,
            coin,
            &initial.to_array(),
            settings,
            bounds,
            &CoinEvents::new(*coin, flat_margin, friction),
            |t, y| observe(t, y, None),
        ),
        Dynamics::Dissipative(coin) => {
            let mut y0 = [0.0; DISSIPATIVE_STATE_LEN];
            y0[..STATE_LEN].copy_from_slice(&initial.to_array());
            run_method_bounded(
                config,
                coin,
                &y0,
                settings,
                bounds,
                &DissipativeEvents::new(*coin, flat_margin, friction),
                |t, y| observe(t, &coin_part(y), Some(y[WORK_INDEX])),
            )
        }
    }
}

/// Runs `stepper` on `coin` from `initial`, observing samples; a thin wrapper over [`integrate::run`].
pub fn simulate<M, O>(
    coin: &Coin,
    stepper: &mut M,
    initial: &State,
    settings: &RunSettings,
    events: &CoinEvents,
    observe: O,
) -> RunOutcome
where
    M: Stepper<STATE_LEN>,
    O: FnMut(f64, &[f64; STATE_LEN]) -> integrate::Flow,
{
    integrate::run(
        coin,
        stepper,
        &initial.to_array(),
        settings,
        events,
        observe,
    )
}
