//! How a recording ended and what it cost: the numbers of the end-of-run table (issue 5: Summary).

use crate::integrate::{Stats, StepError};
use crate::record::messages::NonFiniteField;
use crate::simulation::PhysicalEvent;
use crate::units::TimeError;
use std::fmt;

/// A numerical failure that ended a run early; the file holds the samples up to it.
#[derive(Debug, Clone, PartialEq)]
pub enum Failure {
    /// The integrator could not take a step.
    Step(StepError),
    /// A derived quantity of a sample (energy, reaction, ...) was not finite.
    Message(NonFiniteField),
    /// A sample time had no log time.
    Time(TimeError),
}

impl Failure {
    /// The contract's termination name (`step-size-underflow`, `non-finite`, ...).
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Step(StepError::StepSizeUnderflow { .. }) => "step-size-underflow",
            Self::Step(StepError::NewtonFailure { .. }) => "newton-failure",
            Self::Step(StepError::NonFinite { .. }) | Self::Message(_) | Self::Time(_) => {
                "non-finite"
            }
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Step(e) => e.fmt(f),
            Self::Message(e) => e.fmt(f),
            Self::Time(e) => e.fmt(f),
        }
    }
}

/// Why a recording stopped (the `termination` of `coin-log.result`).
#[derive(Debug, Clone, PartialEq)]
pub enum Termination {
    /// The duration was reached.
    Completed,
    /// A physical event ended the model's validity (flat landing, lift-off, slip); a normal end.
    Event(PhysicalEvent),
    /// The stop flag was raised (SIGINT).
    Interrupted,
    /// A numerical failure.
    Failed(Failure),
}

impl Termination {
    /// The contract's name: completed | flat-landing | lift-off | slip | interrupted |
    /// step-size-underflow | non-finite (| newton-failure).
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::Completed => "completed",
            Self::Event(e) => e.name(),
            Self::Interrupted => "interrupted",
            Self::Failed(f) => f.name(),
        }
    }
}

/// What a finished recording reports.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordSummary {
    /// Samples written (time points).
    pub samples: u64,
    /// Messages written, all channels.
    pub messages: u64,
    /// Size of the finished file \[bytes\].
    pub bytes: u64,
    /// Integrator work.
    pub stats: Stats,
    /// Why the run ended.
    pub termination: Termination,
    /// When it ended (the last sample's time, or the failure's).
    pub termination_time: f64,
    /// max |E − E₀| / max(|E₀|, M g a) over the samples (CONTRACT: verify).
    pub energy_drift: f64,
    /// max |C − C₀| / (|C1₀| + |C2₀|) over the samples, when C1, C2 were computed.
    pub invariant_drift: Option<f64>,
    /// For an unperturbed steady scene: max over the samples of |θ − θ*| and |ω − ω*|·√(a/g)
    /// (dimensionless), the distance from the steady motion.
    pub steady_residual: Option<f64>,
}
