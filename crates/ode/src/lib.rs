//! Time stepping, generic over an [`OdeSystem`]; knows nothing about coins.
//!
//! A [`Stepper`] advances one accepted step at a time and interpolates inside the last step (dense output),
//! so that [`run`] can sample at exact output times and locate events by root finding without shortening
//! steps. Methods, one file each: [`Rk4`] and [`Gauss4`] (fixed step), [`Dopri5`] and [`Dop853`]
//! (adaptive embedded pairs with error control). All four are written here rather than taken from a crate:
//! none offers dense output at arbitrary times, event location hooks, work statistics and no per-step
//! heap allocation together, correct down to rtol 1e-13.

mod control;
mod dop853;
mod dopri5;
mod driver;
mod fixed;
mod gauss4;
mod method;
mod rk4;

pub use coin_log_names::UnknownName;
pub use dop853::Dop853;
pub use dopri5::Dopri5;
pub use driver::{
    run, samples_to_end, Bounds, EventFunctions, Flow, NoEvents, RunEnd, RunOutcome, RunSettings,
};
pub use gauss4::Gauss4;
pub use method::{run_method, run_method_bounded, Method, MethodConfig};
pub use rk4::Rk4;

use thiserror::Error;

/// A system of first-order ODEs y' = f(t, y) of fixed dimension `N`.
pub trait OdeSystem<const N: usize> {
    /// Writes f(t, y) into `dydt`. Must not allocate.
    fn rhs(&self, t: f64, y: &[f64; N], dydt: &mut [f64; N]);
}

/// Work counters of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Right-hand side evaluations, including those spent on rejected steps and on Newton iterations.
    pub rhs_evaluations: u64,
    /// Rejected steps (adaptive methods).
    pub rejected_steps: u64,
}

/// Why a step could not be taken. Every variant carries the time it happened at; its message names
/// each field.
#[derive(Debug, Clone, PartialEq, Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum StepError {
    /// The state or its derivative became NaN or infinite (`t`: the last finite state's time).
    #[error("non-finite state at t = {t}")]
    NonFinite { t: f64 },
    /// The adaptive step size fell below what the time's floating-point spacing allows.
    #[error(
        "step size underflow at t = {t} (h = {h:e}); the problem is too stiff or singular here"
    )]
    StepSizeUnderflow { t: f64, h: f64 },
    /// The run's step budget ([`Bounds::max_steps`]) was spent before its end.
    #[error("the step budget of {steps} steps was spent at t = {t}")]
    BudgetSpent { t: f64, steps: u64 },
    /// The implicit stage equations did not converge (`t`: the start of the step).
    #[error("stage equations did not converge at t = {t} (h = {h:e}, residual {residual:e} after {iterations} iterations); reduce the step")]
    NewtonFailure {
        t: f64,
        h: f64,
        iterations: u32,
        residual: f64,
    },
}

/// One integration method: takes accepted steps and interpolates within the last one.
pub trait Stepper<const N: usize> {
    /// Starts at (t0, y0) (`t_end` bounds an adaptive method's first step); [`StepError::NonFinite`] if
    /// f(t0, y0) is not finite.
    fn init<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
        t_end: f64,
    ) -> Result<(), StepError>;

    /// Takes one accepted step that ends no later than `t_limit`; after a [`StepError`] the stepper still
    /// holds the last good step.
    fn step<S: OdeSystem<N>>(&mut self, sys: &S, t_limit: f64) -> Result<(), StepError>;

    /// Where the stepper stands.
    fn state(&self) -> &StepperState<N>;
    /// Makes the full dense output of the last step available, for methods that compute it lazily
    /// (dop853's three extra stages). [`run`] calls it before the first [`Stepper::interpolate`] in a
    /// step; without it, such methods interpolate at lower order. Default: nothing to do.
    fn prepare_interpolation<S: OdeSystem<N>>(&mut self, _sys: &S) {}
    /// Dense output: the solution at `t` in [t_prev, t] of the last step, written into `out`.
    fn interpolate(&self, t: f64, out: &mut [f64; N]);
}

/// The last accepted step of a [`Stepper`], from `t_prev` to `t` (the state `y` at `t`), and the work so
/// far (`stats`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct StepperState<const N: usize> {
    pub t: f64,
    pub t_prev: f64,
    pub y: [f64; N],
    pub stats: Stats,
}

impl<const N: usize> StepperState<N> {
    /// At (t0, y0), no work done yet.
    fn start(t0: f64, y0: &[f64; N]) -> Self {
        Self {
            t: t0,
            t_prev: t0,
            y: *y0,
            stats: Stats::default(),
        }
    }

    /// Moves to the end (t_new, y_new) of an accepted step.
    #[inline]
    fn advance(&mut self, t_new: f64, y_new: &[f64; N]) {
        self.t_prev = self.t;
        self.t = t_new;
        self.y = *y_new;
        self.stats.steps += 1;
    }
}

#[inline]
pub(crate) fn all_finite<const N: usize>(y: &[f64; N]) -> bool {
    y.iter().all(|v| v.is_finite())
}
