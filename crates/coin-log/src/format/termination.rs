//! Why a run ended: the `termination` value of the `coin-log.result` metadata (format.md, Metadata), one
//! typed enum for the recorder that writes it, the benches that report it and `verify` that reads it.

use crate::integrate::{self, StepError};
use crate::simulation::{CoinEvents, PhysicalEvent};

coin_log_names::named_enum! {
    /// How a run ended; the name is the one written in the metadata, in the order of the format's table
    /// (format.md: Metadata records), which says what each means.
    #[allow(missing_docs)]
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub enum Termination: "termination" {
        Completed = "completed",
        FlatLanding = "flat-landing",
        LiftOff = "lift-off",
        Slip = "slip",
        Interrupted = "interrupted",
        StepSizeUnderflow = "step-size-underflow",
        NonFinite = "non-finite",
        NewtonFailure = "newton-failure",
        StepBudgetSpent = "step-budget-spent",
    }
}

impl Termination {
    /// True for the physical events that end the model's validity (a normal end of a run).
    #[must_use]
    pub fn is_event(self) -> bool {
        matches!(self, Self::FlatLanding | Self::LiftOff | Self::Slip)
    }

    /// The termination of a numerical failure of the integrator.
    #[must_use]
    pub fn of_step_error(e: &StepError) -> Self {
        match e {
            StepError::NonFinite { .. } => Self::NonFinite,
            StepError::StepSizeUnderflow { .. } => Self::StepSizeUnderflow,
            StepError::NewtonFailure { .. } => Self::NewtonFailure,
            StepError::BudgetSpent { .. } => Self::StepBudgetSpent,
        }
    }

    /// The termination of an integration of the coin (events numbered as [`CoinEvents`] numbers them).
    #[must_use]
    pub fn of_run(end: &integrate::RunEnd) -> Self {
        match end {
            integrate::RunEnd::Completed => Self::Completed,
            integrate::RunEnd::Event { index, .. } => CoinEvents::event(*index).into(),
            integrate::RunEnd::Stopped { .. } => Self::Interrupted,
            integrate::RunEnd::Failed(e) => Self::of_step_error(e),
        }
    }
}

impl From<PhysicalEvent> for Termination {
    fn from(e: PhysicalEvent) -> Self {
        match e {
            PhysicalEvent::FlatLanding => Self::FlatLanding,
            PhysicalEvent::LiftOff => Self::LiftOff,
            PhysicalEvent::Slip => Self::Slip,
        }
    }
}
