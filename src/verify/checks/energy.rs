//! `energy`: E = ½Ma²(ω_X² + ω_Z²) + ½(I_X(ω_X² + ω_Y²) + I_Z ω_Z²) + Mga cos θ (physics §3) recomputed from
//! the stored ω and θ; drift = max|E − E₀| / max(|E₀|, Mga) (format.md); agreement of `/coin/energy` with
//! the recomputed total, kinetic and potential parts, in the same units.

use super::{fmt_num, worst, Context, Max};
use crate::model::drift::EnergyDrift;
use crate::model::energy;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use crate::verify::tolerances::{Tolerances, RECOMPUTE_TOLERANCE};

/// Running state of the energy check.
#[derive(Debug, Default, Clone)]
pub struct EnergyCheck {
    drift: Option<EnergyDrift>,
    agreement: Max,
    samples: u64,
    stored: u64,
}

impl EnergyCheck {
    /// Accounts for one sample.
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let Some(state) = s.state() else { return };
        let e = energy(&ctx.coin, &state);
        self.drift
            .get_or_insert_with(|| EnergyDrift::new(ctx.coin.params(), e.total))
            .observe(s.t, e.total);
        self.samples += 1;
        if let Some(m) = s.energy {
            self.stored += 1;
            let d = (m.total - e.total)
                .abs()
                .max((m.kinetic - e.kinetic).abs())
                .max((m.potential - e.potential).abs());
            self.agreement.offer(d, s.t);
        }
    }

    /// The result.
    #[must_use]
    pub fn finish(&self, tol: &Tolerances) -> CheckResult {
        let Some(energy_drift) = self.drift else {
            return CheckResult::skip(
                CheckId::Energy,
                "no sample has both /coin/omega and /coin/angles, so E cannot be recomputed: record the channels omega and angles",
            );
        };
        let drift = energy_drift.value();
        let agreement = self.agreement.value / energy_drift.scale();
        let mut measures = vec![(drift, tol.energy, "drift")];
        if self.stored > 0 {
            measures.push((agreement, RECOMPUTE_TOLERANCE, "agreement"));
        }
        let Some((value, tolerance, which)) = worst(&measures) else {
            return CheckResult::skip(CheckId::Energy, "nothing measured");
        };
        let stored = if self.stored > 0 {
            format!(
                "; /coin/energy differs from E recomputed by {} (worst at t = {}, tolerance {})",
                fmt_num(agreement),
                fmt_num(self.agreement.t),
                fmt_num(RECOMPUTE_TOLERANCE)
            )
        } else {
            "; no /coin/energy channel to compare".into()
        };
        CheckResult::measured(
            CheckId::Energy,
            value,
            tolerance,
            format!(
                "{which} is the worst measure: drift max|E - E0|/max(|E0|, Mga) = {} over {} samples (worst at t = {}, tolerance {}){stored}",
                fmt_num(drift),
                self.samples,
                fmt_num(energy_drift.worst_time()),
                fmt_num(tol.energy),
            ),
        )
    }
}
