//! The user-facing choice of integrator (format.md: record) and the one dispatch from it to a stepper.

use super::driver::{run, Bounds, EventFunctions, Flow, RunOutcome, RunSettings};
use super::{Dop853, Dopri5, Gauss4, OdeSystem, Rk4};

coin_log_names::named_enum! {
    /// An integration method; its name is the one in scene files and `--integrator`.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    pub enum Method: "integrator" {
        /// Classical fourth-order Runge–Kutta, fixed step.
        Rk4 = "rk4",
        /// Dormand–Prince 5(4), adaptive, 4th-order dense output.
        Dopri5 = "dopri5",
        /// Dormand–Prince 8(5,3), adaptive, 7th-order dense output. The default.
        #[default]
        Dop853 = "dop853",
        /// 2-stage Gauss–Legendre (order 4, symmetric, implicit), fixed step.
        Gauss4 = "gauss4",
    }
}

impl Method {
    /// True for methods with error control (rtol, atol); false for fixed-step methods (step).
    #[must_use]
    pub fn is_adaptive(self) -> bool {
        match self {
            Self::Rk4 | Self::Gauss4 => false,
            Self::Dopri5 | Self::Dop853 => true,
        }
    }

    /// Classical order of the method (of the propagated solution for the adaptive pairs).
    #[must_use]
    pub fn order(self) -> u32 {
        match self {
            Self::Rk4 | Self::Gauss4 => 4,
            Self::Dopri5 => 5,
            Self::Dop853 => 8,
        }
    }
}

/// A `method` with its settings: the tolerances `rtol` and `atol` for adaptive methods, the `step` for
/// fixed-step ones.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct MethodConfig {
    pub method: Method,
    pub rtol: f64,
    pub atol: f64,
    pub step: f64,
}

/// Runs `config.method` on `sys` from `y0`; see [`run`](super::run).
pub fn run_method<const N: usize, S, E, O>(
    config: &MethodConfig,
    sys: &S,
    y0: &[f64; N],
    settings: &RunSettings,
    events: &E,
    observe: O,
) -> RunOutcome
where
    S: OdeSystem<N>,
    E: EventFunctions<N>,
    O: FnMut(f64, &[f64; N]) -> Flow,
{
    run_method_bounded(
        config,
        sys,
        y0,
        settings,
        &Bounds::default(),
        events,
        observe,
    )
}

/// [`run_method`] within `bounds`; see [`run`](super::run).
pub fn run_method_bounded<const N: usize, S, E, O>(
    config: &MethodConfig,
    sys: &S,
    y0: &[f64; N],
    settings: &RunSettings,
    bounds: &Bounds<'_>,
    events: &E,
    observe: O,
) -> RunOutcome
where
    S: OdeSystem<N>,
    E: EventFunctions<N>,
    O: FnMut(f64, &[f64; N]) -> Flow,
{
    // One call per stepper type; a closure cannot take the stepper, whose type differs per arm.
    macro_rules! run_with {
        ($stepper:expr) => {
            run(sys, &mut $stepper, y0, settings, bounds, events, observe)
        };
    }
    match config.method {
        Method::Rk4 => run_with!(Rk4::new(config.step)),
        Method::Gauss4 => run_with!(Gauss4::new(config.step)),
        Method::Dopri5 => run_with!(Dopri5::new(config.rtol, config.atol)),
        Method::Dop853 => run_with!(Dop853::new(config.rtol, config.atol)),
    }
}
