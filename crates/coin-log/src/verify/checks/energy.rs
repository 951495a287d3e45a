//! `energy`: E (physics §3) recomputed from the stored ω and θ, its drift (format.md: Drift definitions), and
//! the agreement of `/coin/energy`'s total, kinetic and potential parts with it, in the same units.
//!
//! With dissipation (physics §11) the conserved quantity is the balance E + W, W the dissipated work stored
//! in `/coin/work` (format.md: verify). Without `/coin/work` a dissipative file's energy cannot be judged.

use super::{fmt_num, worst, Context, Max};
use crate::format::tolerances::{Tolerances, RECOMPUTE_TOLERANCE};
use crate::model::drift::EnergyDrift;
use crate::model::energy;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;

#[derive(Debug, Default, Clone)]
pub struct EnergyCheck {
    drift: Option<EnergyDrift>,
    agreement: Max,
    samples: u64,
    stored: u64,
    /// Dissipative runs: samples with ω and angles but no W (they cannot enter the balance).
    without_work: u64,
    /// Dissipative runs: W at the last judged sample.
    last_work: Option<f64>,
}

impl EnergyCheck {
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let Some(state) = s.state() else { return };
        let e = energy(&ctx.coin, &state);
        let dissipative = ctx.dynamics.dissipation().is_some();
        let work = match (dissipative, s.work) {
            (false, _) => 0.0,
            (true, Some(w)) => w.dissipated,
            (true, None) => {
                self.without_work += 1;
                return;
            }
        };
        let balance = e.total + work;
        self.drift
            .get_or_insert_with(|| EnergyDrift::new(ctx.coin.params(), balance))
            .observe(s.t, balance);
        self.samples += 1;
        if dissipative {
            self.last_work = Some(work);
        }
        if let Some(m) = s.energy {
            self.stored += 1;
            let d = (m.total - e.total)
                .abs()
                .max((m.kinetic - e.kinetic).abs())
                .max((m.potential - e.potential).abs());
            self.agreement.offer(d, s.t);
        }
        if let Some(w) = s.work.filter(|_| dissipative) {
            self.stored += 1;
            self.agreement.offer((w.balance - balance).abs(), s.t);
        }
    }

    #[must_use]
    pub fn finish(&self, tol: &Tolerances, ctx: &Context) -> CheckResult {
        let Some(energy_drift) = self.drift else {
            let reason = if self.without_work > 0 {
                "the run has dissipation (physics §11) but no sample has /coin/work, so the balance E + W = E0 cannot be judged: record the work channel"
            } else {
                "no sample has both /coin/omega and /coin/angles, so E cannot be recomputed: record the channels omega and angles"
            };
            return CheckResult::skip(CheckId::Energy, reason);
        };
        let drift = energy_drift.value();
        let agreement = self.agreement.value / energy_drift.scale;
        let agreed = (self.stored > 0).then_some((agreement, RECOMPUTE_TOLERANCE, "agreement"));
        let (value, tolerance, which) = worst((drift, tol.energy, "drift"), agreed.as_slice());
        let stored = if self.stored > 0 {
            let what = if self.last_work.is_some() {
                "/coin/energy and the /coin/work balance differ from E and E + W recomputed"
            } else {
                "/coin/energy differs from E recomputed"
            };
            format!(
                "; {what} by {} (worst at t = {}, tolerance {})",
                fmt_num(agreement),
                fmt_num(self.agreement.t),
                fmt_num(RECOMPUTE_TOLERANCE)
            )
        } else {
            "; no /coin/energy channel to compare".into()
        };
        let quantity = match (ctx.dynamics.dissipation(), self.last_work) {
            (Some(d), Some(w)) => format!(
                "dissipation {} (κ = {}): drift of the balance max|E + W - E0|/max(|E0|, Mga) = {}, W = {} at the end",
                d.model(),
                fmt_num(d.coefficient()),
                fmt_num(drift),
                fmt_num(w)
            ),
            _ => format!("drift max|E - E0|/max(|E0|, Mga) = {}", fmt_num(drift)),
        };
        let mut reason = format!(
            "{which} is the worst measure: {quantity} over {} samples (worst at t = {}, tolerance {}){stored}",
            self.samples,
            fmt_num(energy_drift.worst_time()),
            fmt_num(tol.energy),
        );
        if self.without_work > 0 {
            reason += &format!(
                "; {} samples without /coin/work not judged",
                self.without_work
            );
        }
        CheckResult::measured(CheckId::Energy, value, tolerance, reason)
    }
}
