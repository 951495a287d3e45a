//! How a recording ended and what it cost: the numbers of the end-of-run summary.

use crate::format::messages::NonFiniteField;
use crate::format::promise::Shortfall;
use crate::format::{Termination, TimeError};
use crate::integrate::{Stats, StepError};
use serde::{Serialize, Serializer};
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
    /// The termination this failure is recorded as.
    #[must_use]
    pub fn termination(&self) -> Termination {
        match self {
            Self::Step(e) => Termination::of_step_error(e),
            Self::Message(_) | Self::Time(_) => Termination::NonFinite,
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

/// What a finished recording reports. Serialized flat, as `record --json` prints it (format.md: record,
/// Summary): the integrator's counters beside the other fields, the termination by name, no failure (its
/// termination says what it was).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordSummary {
    /// Samples written (time points).
    pub samples: u64,
    /// Messages written, all channels.
    pub messages: u64,
    /// Size of the finished file \[bytes\].
    pub bytes: u64,
    /// Integrator work.
    #[serde(flatten, with = "StatsFields")]
    pub stats: Stats,
    /// Why the run ended.
    #[serde(serialize_with = "by_name")]
    pub termination: Termination,
    /// When it ended (the last sample's time, or the failure's).
    pub termination_time: f64,
    /// The numerical failure that ended the run, when one did (its detail for the user).
    #[serde(skip)]
    pub failure: Option<Failure>,
    /// Energy drift over the samples ([`EnergyDrift`](crate::model::drift::EnergyDrift)); with
    /// dissipation, the drift of E + W.
    pub energy_drift: f64,
    /// Invariant drift over the samples, when C1, C2 were computed
    /// ([`InvariantDrift`](crate::model::drift::InvariantDrift)).
    pub invariant_drift: Option<f64>,
    /// For an unperturbed steady scene: max over the samples of |θ − θ*| and |ω − ω*|·√(a/g)
    /// (dimensionless), the distance from the steady motion.
    pub steady_residual: Option<f64>,
    /// The energy drift tolerance `verify` derives for this file from its integrator settings, span and
    /// max|ω| ([`crate::format::tolerances`]).
    pub energy_tolerance: f64,
    /// For a run ended by a physical event (flat landing, lift-off, slip): whether the energy drift at the
    /// event is within [`energy_tolerance`](Self::energy_tolerance). When it is not, the integration had
    /// already gone wrong and the event may be an artefact of it, not physics. `None` without an event.
    pub event_trusted: Option<bool>,
    /// Why the event is not to be trusted when the energy drift does not say it: a departure from
    /// upright too small to represent ([`crate::simulation::departure_doubt`]). Absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub event_doubt: Option<String>,
    /// With dissipation: the work W dissipated by the end of the run \[energy\] (physics §11); the energy
    /// drift is then that of the balance E + W.
    pub dissipated_work: Option<f64>,
    /// With dissipation: α = π/2 − |θ| at the last sample, how flat the coin was when the run ended.
    pub termination_alpha: Option<f64>,
    /// The checks `verify` is expected to fail with its default tolerances, and why
    /// ([`crate::format::promise`]); serialized as `expected_to_fail`, the check ids. Empty: `verify` is
    /// expected to accept the file.
    #[serde(rename = "expected_to_fail", serialize_with = "check_ids")]
    pub shortfalls: Vec<Shortfall>,
}

fn check_ids<S: Serializer>(shortfalls: &[Shortfall], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(shortfalls.iter().flat_map(|f| f.checks.iter()))
}

/// [`Stats`]'s fields, for the summary's JSON (the stepper crate knows no serde).
#[derive(Serialize)]
#[serde(remote = "Stats")]
struct StatsFields {
    steps: u64,
    rhs_evaluations: u64,
    rejected_steps: u64,
}

fn by_name<S: Serializer>(termination: &Termination, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(termination)
}
