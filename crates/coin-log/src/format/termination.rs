//! Why a run ended: the `termination` value of the `coin-log.result` metadata (format.md, Metadata), one
//! typed enum for the recorder that writes it, the benches that report it and `verify` that reads it.

use crate::integrate::{self, StepError};
use crate::simulation::{CoinEvents, PhysicalEvent};
use std::fmt;
use std::str::FromStr;

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Termination {
    /// The duration was reached.
    Completed,
    /// |θ| reached π/2 − flat_margin: the coin lands flat (physics §7).
    FlatLanding,
    /// N reached 0: the coin would leave the table.
    LiftOff,
    /// |F| reached μN: the coin would slip.
    Slip,
    /// The user stopped the run (SIGINT, SIGTERM, SIGHUP).
    Interrupted,
    /// The adaptive step size fell below what floating point resolves.
    StepSizeUnderflow,
    /// The state or a derived quantity became NaN or infinite.
    NonFinite,
    /// The implicit stage equations did not converge.
    NewtonFailure,
}

impl Termination {
    /// Every value, in the order of the format's table.
    pub const ALL: [Termination; 8] = [
        Self::Completed,
        Self::FlatLanding,
        Self::LiftOff,
        Self::Slip,
        Self::Interrupted,
        Self::StepSizeUnderflow,
        Self::NonFinite,
        Self::NewtonFailure,
    ];

    /// The name written in the metadata.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Completed => "completed",
            Self::FlatLanding => "flat-landing",
            Self::LiftOff => "lift-off",
            Self::Slip => "slip",
            Self::Interrupted => "interrupted",
            Self::StepSizeUnderflow => "step-size-underflow",
            Self::NonFinite => "non-finite",
            Self::NewtonFailure => "newton-failure",
        }
    }

    /// True for the physical events that end the model's validity (a normal end of a run).
    #[must_use]
    pub fn is_event(self) -> bool {
        matches!(self, Self::FlatLanding | Self::LiftOff | Self::Slip)
    }

    /// True for numerical failures (the file holds the samples up to the failure).
    #[must_use]
    pub fn is_failure(self) -> bool {
        matches!(
            self,
            Self::StepSizeUnderflow | Self::NonFinite | Self::NewtonFailure
        )
    }

    /// The termination of a numerical failure of the integrator.
    #[must_use]
    pub fn of_step_error(e: &StepError) -> Self {
        match e {
            StepError::NonFinite { .. } => Self::NonFinite,
            StepError::StepSizeUnderflow { .. } => Self::StepSizeUnderflow,
            StepError::NewtonFailure { .. } => Self::NewtonFailure,
        }
    }

    /// The termination of an integration of the coin (events numbered as [`CoinEvents`] numbers them).
    #[must_use]
    pub fn of_run(end: &integrate::Termination) -> Self {
        match end {
            integrate::Termination::Completed => Self::Completed,
            integrate::Termination::Event { index, .. } => CoinEvents::event(*index).into(),
            integrate::Termination::Stopped { .. } => Self::Interrupted,
            integrate::Termination::Failed(e) => Self::of_step_error(e),
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

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A `termination` value this tool does not know.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown termination `{0}`; known: completed, flat-landing, lift-off, slip, interrupted, step-size-underflow, non-finite, newton-failure")]
pub struct UnknownTermination(pub String);

impl FromStr for Termination {
    type Err = UnknownTermination;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|t| t.name() == s)
            .ok_or_else(|| UnknownTermination(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for t in Termination::ALL {
            assert_eq!(t.name().parse::<Termination>(), Ok(t));
            assert_eq!(t.to_string(), t.name());
        }
        assert!("finished".parse::<Termination>().is_err());
        assert_eq!(Termination::ALL.iter().filter(|t| t.is_event()).count(), 3);
    }

    #[test]
    fn events_map_to_their_termination() {
        for (index, expected) in [
            (0, Termination::FlatLanding),
            (1, Termination::LiftOff),
            (2, Termination::Slip),
        ] {
            let end = integrate::Termination::Event { index, t: 1.0 };
            assert_eq!(Termination::of_run(&end), expected);
        }
    }
}
