//! `validity`: the rolling model holds. The table pushes (N ≥ 0) and, when μ is given, friction holds the
//! coin (|F| ≤ μN). A run that ended at a lift-off or slip event is judged up to that event: its last sample,
//! at the event, is where the inequality becomes an equality.

use super::{fmt_num, Context, Max};
use crate::format::tolerances::VALIDITY_TOLERANCE;
use crate::format::Termination;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;

/// One sample's margins: N/(Mg) and (|F| − μN)/(Mg).
#[derive(Debug, Clone, Copy)]
struct Margins {
    t: f64,
    normal: f64,
    slip: f64,
}

/// Running state of the validity check. The termination is only known at the end of the file (the
/// `coin-log.result` record follows the messages), so the latest sample is held back until the next one
/// arrives: it is the event sample if the run ended at an event.
#[derive(Debug, Default, Clone)]
pub struct ValidityCheck {
    min_normal: Option<(f64, f64)>,
    slip: Max,
    samples: u64,
    held: Option<Margins>,
    recomputed: bool,
}

impl ValidityCheck {
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let (normal, friction) = if let Some(r) = s.reaction {
            (r.normal, r.friction)
        } else if let Some(state) = s.state() {
            self.recomputed = true;
            let r = ctx.dynamics.reaction(&state);
            (r.normal, r.friction)
        } else {
            return;
        };
        let weight = ctx.coin.params().mass() * ctx.coin.params().gravity();
        let slip = ctx
            .run
            .friction
            .map_or(f64::NEG_INFINITY, |mu| (friction - mu * normal) / weight);
        if let Some(previous) = self.held.replace(Margins {
            t: s.t,
            normal: normal / weight,
            slip,
        }) {
            self.fold(previous);
        }
    }

    fn fold(&mut self, m: Margins) {
        self.samples += 1;
        if self
            .min_normal
            .is_none_or(|(n, _)| m.normal < n || m.normal.is_nan())
        {
            self.min_normal = Some((m.normal, m.t));
        }
        if self.samples == 1 {
            self.slip = Max {
                value: m.slip,
                t: m.t,
            };
        } else {
            self.slip.offer(m.slip, m.t);
        }
    }

    #[must_use]
    pub fn finish(&self, ctx: &Context) -> CheckResult {
        let mut this = self.clone();
        let mut judged_to = None;
        if let Some(last) = this.held.take() {
            let event = ctx.result.as_ref().filter(|r| {
                matches!(r.termination, Termination::LiftOff | Termination::Slip)
                    && last.t >= r.termination_time
            });
            match event {
                Some(r) => judged_to = Some(r.termination),
                None => this.fold(last),
            }
        }
        let Some((n_min, n_t)) = this.min_normal else {
            return CheckResult::skip(
                CheckId::Validity,
                "no /coin/reaction and no sample with ω and angles to recompute N",
            );
        };
        let lift = -n_min;
        let normal = format!("min N/(Mg) = {} (t = {})", fmt_num(n_min), fmt_num(n_t));
        let (value, mut reason) = match ctx.run.friction {
            Some(mu) => (
                lift.max(this.slip.value),
                format!(
                    "{normal}, max (|F| - μN)/(Mg) = {} (t = {}, μ = {})",
                    fmt_num(this.slip.value),
                    fmt_num(this.slip.t),
                    fmt_num(mu)
                ),
            ),
            None => (lift, format!("{normal}; no μ, friction not judged")),
        };
        reason.push_str(&format!("; {} samples", this.samples));
        if let Some(event) = judged_to {
            reason.push_str(&format!(", judged up to the recorded {event} event"));
        }
        if this.recomputed {
            reason.push_str(", N recomputed where /coin/reaction is absent");
        }
        CheckResult::measured(CheckId::Validity, value, VALIDITY_TOLERANCE, reason)
    }
}
