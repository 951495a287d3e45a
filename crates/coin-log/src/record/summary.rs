//! How a recording ended and what it cost: the numbers of the end-of-run summary.

use crate::format::messages::NonFiniteField;
use crate::format::promise::Shortfall;
use crate::format::{Termination, TimeError};
use crate::integrate::{Stats, StepError};
use serde::{Serialize, Serializer};

/// A numerical failure that ended a run early; the file holds the samples up to it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Failure {
    /// The integrator could not take a step.
    #[error(transparent)]
    Step(StepError),
    /// A derived quantity of a sample (energy, reaction, ...) was not finite.
    #[error(transparent)]
    Message(#[from] NonFiniteField),
    /// A sample time had no log time.
    #[error(transparent)]
    Time(#[from] TimeError),
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

/// Steps beyond which raising `--max-steps` is no advice: 1e10 steps are about 2 hours of dop853 at
/// 0.65 µs a step (format.md: Limits, measured on `wobble`).
pub const SENSIBLE_STEPS: f64 = 1e10;

/// What a finished recording reports: the fields of `record --json` (format.md: record, Summary), serialized
/// flat: the integrator's counters beside the other fields, the termination by name, no failure (its
/// termination says what it was).
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordSummary {
    pub samples: u64,
    pub messages: u64,
    pub bytes: u64,
    #[serde(flatten, with = "StatsFields")]
    pub stats: Stats,
    #[serde(serialize_with = "by_name")]
    pub termination: Termination,
    pub termination_time: f64,
    /// The numerical failure that ended the run, when one did (its detail for the user).
    #[serde(skip)]
    pub failure: Option<Failure>,
    pub energy_drift: f64,
    pub invariant_drift: Option<f64>,
    pub steady_residual: Option<f64>,
    pub energy_tolerance: f64,
    pub event_trusted: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub event_doubt: Option<String>,
    pub dissipated_work: Option<f64>,
    pub termination_alpha: Option<f64>,
    /// The checks `verify` is expected to fail, and why ([`crate::format::promise`]); serialized as
    /// `expected_to_fail`, the check ids.
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

impl RecordSummary {
    /// What to do about a run that spent its step budget, from the pace it kept: the steps the whole
    /// `duration` would take at that pace, and whether raising the budget can give them. A dissipative
    /// couple strong enough makes the equations stiff, and an explicit method's step then stays near its
    /// stability limit whatever the tolerance (`euler-disk` with a viscous κ = 3e13 took 10⁶ steps for
    /// 1.3e-12 of its 2000 time units, where "raise --max-steps" was the advice). `None` unless the
    /// termination is `step-budget-spent`.
    #[must_use]
    pub fn budget_advice(&self, duration: f64, dissipative: bool) -> Option<String> {
        if self.termination != Termination::StepBudgetSpent {
            return None;
        }
        let steps = self.stats.steps as f64;
        let t = self.termination_time;
        let needed = if t > 0.0 {
            steps * (duration / t)
        } else {
            f64::INFINITY
        };
        if needed <= SENSIBLE_STEPS {
            return Some(format!(
                "at the pace so far the whole run needs about {} steps: raise --max-steps (run.max_steps) \
                 with a margin above that, or loosen --rtol/--atol",
                needed.ceil()
            ));
        }
        let why = if dissipative {
            "the dissipative couple makes the equations stiff, and an explicit method's step stays near its \
             stability limit whatever the tolerance: use a smaller body.dissipation.coefficient or a shorter \
             --duration"
        } else {
            "the motion is too fast or too near a singularity here for the integrator: use a shorter \
             --duration or a slower motion"
        };
        Some(format!(
            "at the pace so far, a mean step of {:.1e}, the whole run would need about {needed:.1e} steps, \
             more than raising --max-steps can give ({SENSIBLE_STEPS:.0e} steps take about 2 hours); {why}",
            t / steps
        ))
    }
}
