//! What a motion will do, without simulating it (format.md: analyse): the linear stability of a steady
//! motion (physics §9), the nutation of any motion by quadrature (physics §10), and the stability map of
//! the steady circles ([`map`]).
//!
//! The library returns values; `coin-log analyse` prints them and writes the map's files.

pub mod linear;
pub mod map;
mod plot;
pub mod slow_change;
mod steady;
pub mod steady_path;

pub use steady::{Stability, SteadyAnalysis};

use crate::model::nutation::{Motion, NutationError, Orbit};
use crate::model::{Chaplygin, Coin, InvariantsError, State, Steady};
use crate::scene::{InitialSpec, Scene};
use serde_json::json;
use thiserror::Error;

/// Why a motion cannot be analysed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AnalyseError {
    /// C1, C2 cannot be evaluated for the body (physics §6).
    #[error(transparent)]
    Invariants(#[from] InvariantsError),
    /// The state is not a rolling coin.
    #[error(transparent)]
    Nutation(#[from] NutationError),
}

/// The analysis of one initial `state` (the scene's) of the body `coin`, with the scene's μ, `friction`,
/// if given.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names the fields without one")]
pub struct Analysis {
    pub coin: Coin,
    pub state: State,
    /// The motion by quadrature: E, C1, C2, θ range, period and heading advance, N and |F|/N.
    pub orbit: Orbit,
    /// The steady motion the state is, analysed; `None` when it is not steady.
    pub steady: Option<SteadyAnalysis>,
    /// The steady motion a perturbed steady scene starts from, analysed (its σ is the nutation
    /// frequency of small perturbations); `None` otherwise.
    pub base_steady: Option<SteadyAnalysis>,
    pub friction: Option<f64>,
}

impl Analysis {
    /// The analysis of a scene's initial state (the scene's flat margin and μ apply); fails when C1, C2
    /// cannot be evaluated for the body.
    pub fn of_scene(scene: &Scene) -> Result<Self, AnalyseError> {
        // The state is the steady motion when nothing perturbs it; a dissipative couple (which makes
        // `unperturbed_steady` none, since the run leaves it) does not perturb the initial state.
        let unperturbed = scene.perturbation.iter().all(|&p| p == 0.0);
        let (given, base) = match &scene.spec {
            InitialSpec::Steady(s) if unperturbed => (Some(s), None),
            InitialSpec::Steady(s) => (None, Some(s)),
            InitialSpec::Explicit => (None, None),
        };
        let mut analysis = Self::of_state(
            &scene.coin(),
            &scene.initial,
            scene.run.flat_margin,
            scene.friction,
            given,
        )?;
        analysis.base_steady =
            base.map(|s| SteadyAnalysis::of_state(&analysis.coin, &s.state, Some(s)));
        Ok(analysis)
    }

    /// The analysis of `state`; `given` is the steady motion the state is known to be (then it is
    /// analysed as steady whatever rounding says); fails when C1, C2 cannot be evaluated for the body or
    /// the state is not rolling.
    pub fn of_state(
        coin: &Coin,
        state: &State,
        flat_margin: f64,
        friction: Option<f64>,
        given: Option<&Steady>,
    ) -> Result<Self, AnalyseError> {
        let chaplygin = Chaplygin::new(coin.params())?;
        let orbit = if given.is_some() {
            Orbit::steady(coin, &chaplygin, state)
        } else {
            Orbit::new(coin, &chaplygin, state, flat_margin)?
        };
        let steady =
            (orbit.motion == Motion::Steady).then(|| SteadyAnalysis::of_state(coin, state, given));
        Ok(Self {
            coin: *coin,
            state: *state,
            orbit,
            steady,
            base_steady: None,
            friction,
        })
    }

    /// With μ given: whether the motion needs more friction than μ (|F| > μN somewhere, or N reaching 0,
    /// where |F|/N is unbounded).
    #[must_use]
    pub fn slips(&self) -> Option<bool> {
        self.friction.map(|mu| {
            self.orbit
                .max_friction_ratio
                .is_none_or(|ratio| ratio.value > mu)
        })
    }

    /// The object of `coin-log analyse --json` (format.md: analyse --json): the contract's keys, then
    /// the extensions.
    #[must_use]
    pub fn json(&self) -> serde_json::Value {
        let o = &self.orbit;
        let (period, precession, spin_advance, flat_landing_time) = match o.motion {
            Motion::Periodic {
                period,
                precession,
                spin_advance,
            } => (Some(period), Some(precession), Some(spin_advance), None),
            Motion::FlatLanding { time, .. } => (None, None, None, Some(time)),
            Motion::Steady => (None, None, None, None),
        };
        json!({
            "energy": o.energy,
            "c1": o.c1,
            "c2": o.c2,
            "theta_min": o.theta_min,
            "theta_max": o.theta_max,
            "period": period,
            "precession": precession,
            "max_friction_ratio": o.max_friction_ratio.map(|e| e.value),
            "min_normal": o.min_normal.value,
            "steady": self.steady.as_ref().map(steady_json),
            "motion": motion_name(&o.motion),
            "spin_advance": spin_advance,
            "flat_landing_time": flat_landing_time,
            "lift_off_time": o.lift_off.map(|e| e.time),
            "lift_off_theta": o.lift_off.map(|e| e.theta),
            "normal_stays_positive": o.min_normal.value > 0.0,
            "friction": self.friction,
            "slips": self.slips(),
            "quadrature_error": o.error,
            "base_steady": self.base_steady.as_ref().map(steady_json),
        })
    }
}

/// `steady`, `nutation` or `flat-landing`.
#[must_use]
pub fn motion_name(motion: &Motion) -> &'static str {
    match motion {
        Motion::Steady => "steady",
        Motion::Periodic { .. } => "nutation",
        Motion::FlatLanding { .. } => "flat-landing",
    }
}

/// The contract's `steady` object, then the extensions.
fn steady_json(s: &SteadyAnalysis) -> serde_json::Value {
    // +0.0 for the zero eigenvalues and parts (JSON would show −0.0 as "-0.0").
    let clean = |x: f64| if x == 0.0 { 0.0 } else { x };
    let eigenvalues: Vec<[f64; 2]> = s
        .eigenvalues
        .iter()
        .map(|&(re, im)| [clean(re), clean(im)])
        .collect();
    let steady = &s.steady;
    json!({
        "kind": steady.kind.family().name(),
        "omega_y": steady.state.omega_y,
        "phi_dot": steady.phi_dot,
        "psi_dot": steady.psi_dot,
        "r_g": steady.r_g,
        "r_c": steady.r_c,
        "sigma_squared": s.sigma_squared,
        "eigenvalues": eigenvalues,
        "verdict": s.verdict.name(),
        "branch": steady.kind.branch().map(crate::model::Branch::name),
        "normal": s.normal,
        "friction": s.friction,
        "nutation_period": s.nutation_period(),
        "e_folding_time": s.e_folding_time(),
    })
}
