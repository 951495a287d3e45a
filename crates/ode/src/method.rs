//! The user-facing choice of integrator (format.md: record) and the one dispatch from it to a stepper.

use super::driver::{run, EventFunctions, Flow, RunOutcome, RunSettings};
use super::{Dop853, Dopri5, Gauss4, OdeSystem, Rk4};
use std::fmt;
use std::str::FromStr;

/// An integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Method {
    /// Classical fourth-order Runge–Kutta, fixed step.
    Rk4,
    /// Dormand–Prince 5(4), adaptive, 4th-order dense output.
    Dopri5,
    /// Dormand–Prince 8(5,3), adaptive, 7th-order dense output. The default.
    #[default]
    Dop853,
    /// 2-stage Gauss–Legendre (order 4, symmetric, implicit), fixed step.
    Gauss4,
}

impl Method {
    /// Every method.
    pub const ALL: &'static [Method] =
        &[Method::Rk4, Method::Dopri5, Method::Dop853, Method::Gauss4];

    /// Name in scene files and `--integrator`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Rk4 => "rk4",
            Self::Dopri5 => "dopri5",
            Self::Dop853 => "dop853",
            Self::Gauss4 => "gauss4",
        }
    }

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

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown integrator name, with the valid ones.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown integrator `{name}`; valid integrators: {valid}")]
pub struct UnknownMethod {
    /// What was given.
    pub name: String,
    /// Comma-separated valid names.
    pub valid: String,
}

impl FromStr for Method {
    type Err = UnknownMethod;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .iter()
            .copied()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownMethod {
                name: s.to_string(),
                valid: Self::ALL
                    .iter()
                    .map(|m| m.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }
}

/// A method with its settings: tolerances for adaptive methods, the step for fixed-step ones.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodConfig {
    /// The method.
    pub method: Method,
    /// Relative tolerance (adaptive methods).
    pub rtol: f64,
    /// Absolute tolerance (adaptive methods).
    pub atol: f64,
    /// Step (fixed-step methods).
    pub step: f64,
}

/// Runs `config.method` on `sys` from `y0`; see [`run`].
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
    match config.method {
        Method::Rk4 => run(
            sys,
            &mut Rk4::new(config.step),
            y0,
            settings,
            events,
            observe,
        ),
        Method::Gauss4 => run(
            sys,
            &mut Gauss4::new(config.step),
            y0,
            settings,
            events,
            observe,
        ),
        Method::Dopri5 => run(
            sys,
            &mut Dopri5::new(config.rtol, config.atol),
            y0,
            settings,
            events,
            observe,
        ),
        Method::Dop853 => run(
            sys,
            &mut Dop853::new(config.rtol, config.atol),
            y0,
            settings,
            events,
            observe,
        ),
    }
}
