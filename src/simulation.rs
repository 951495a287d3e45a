//! The rolling coin as an integrable system with its physical events (physics §7), and the one entry point
//! that runs a chosen method on it. This is where the coin model meets the generic integrators.

use crate::integrate::{self, EventFunctions, OdeSystem, RunOutcome, RunSettings, Stepper};
use crate::model::{reaction, Coin, State, STATE_LEN};

impl OdeSystem<STATE_LEN> for Coin {
    #[inline]
    fn rhs(&self, _t: f64, y: &[f64; STATE_LEN], dydt: &mut [f64; STATE_LEN]) {
        self.derivative(y, dydt);
    }
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

impl EventFunctions<STATE_LEN> for CoinEvents {
    fn count(&self) -> usize {
        if self.friction.is_some() {
            3
        } else {
            2
        }
    }

    fn evaluate(&self, _t: f64, y: &[f64; STATE_LEN], out: &mut [f64]) {
        let s = State::from_array(y);
        out[0] = std::f64::consts::FRAC_PI_2 - self.flat_margin - s.theta.abs();
        let weight = self.coin.params().mass() * self.coin.params().gravity();
        // Beyond flat the reaction formulas are meaningless; the flat event comes first there anyway.
        let r = reaction(&self.coin, &s);
        out[1] = r.normal / weight;
        if let (Some(mu), Some(slot)) = (self.friction, out.get_mut(2)) {
            *slot = (mu * r.normal - r.friction) / weight;
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
