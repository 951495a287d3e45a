//! `invariants`: the Chaplygin–Appell integrals C1, C2 (physics §6) recomputed from the stored θ, ω_Y, ω_Z;
//! drift = max|C − C₀| / (|C1₀| + |C2₀|) (format.md), and agreement with `/coin/invariants` when stored.

use super::{fmt_num, worst, Context, Max};
use crate::format::tolerances::{Tolerances, RECOMPUTE_TOLERANCE};
use crate::model::drift::InvariantDrift;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;

#[derive(Debug, Default, Clone)]
pub struct InvariantsCheck {
    drift: Option<InvariantDrift>,
    agreement: Max,
    samples: u64,
    stored: u64,
}

impl InvariantsCheck {
    /// Accounts for one sample, when C1, C2 can be evaluated for the run's parameters.
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let (Some(w), Some(a), Ok(chaplygin)) = (s.omega, s.angles, &ctx.chaplygin) else {
            return;
        };
        let c = chaplygin.evaluate(a.theta, w.y, w.z);
        let (c1, c2) = (c.c1, c.c2);
        self.drift
            .get_or_insert_with(|| InvariantDrift::new(ctx.coin.params(), c1, c2))
            .observe(s.t, c1, c2);
        self.samples += 1;
        if let Some(m) = s.invariants {
            self.stored += 1;
            self.agreement
                .offer((m.c1 - c1).abs().max((m.c2 - c2).abs()), s.t);
        }
    }

    /// The result. It does not run when C1, C2 cannot be evaluated for the body. With dissipation,
    /// which changes C1, C2 (physics §11), only the stored `/coin/invariants` are judged, against C1, C2
    /// of the stored state, and the check is skipped when they are not stored.
    #[must_use]
    pub fn finish(&self, tol: &Tolerances, ctx: &Context) -> CheckResult {
        if let Some(d) = ctx.dynamics.dissipation() {
            let run = format!(
                "the run has dissipation ({}, κ = {}): C1, C2 are not conserved by the dissipative couple (physics §11)",
                d.model(),
                fmt_num(d.coefficient())
            );
            let instead = "the energy check judges E + W = E0 instead";
            return match (self.drift, &ctx.chaplygin) {
                (Some(drift), Ok(_)) if self.stored > 0 => {
                    let agreement = self.agreement.value / drift.scale;
                    CheckResult::measured(
                        CheckId::Invariants,
                        agreement,
                        RECOMPUTE_TOLERANCE,
                        format!(
                            "{run}, so their drift is not judged ({instead}); /coin/invariants differs from C recomputed from the stored state by {} (worst at t = {}, tolerance {}) over {} samples",
                            fmt_num(agreement),
                            fmt_num(self.agreement.t),
                            fmt_num(RECOMPUTE_TOLERANCE),
                            self.stored
                        ),
                    )
                }
                _ => CheckResult::skip(CheckId::Invariants, format!("{run}; {instead}")),
            };
        }
        if let Err(e) = &ctx.chaplygin {
            return CheckResult::skip(CheckId::Invariants, e.clone());
        }
        let Some(invariant_drift) = self.drift else {
            return CheckResult::skip(
                CheckId::Invariants,
                "no sample has both /coin/omega and /coin/angles, so C1, C2 cannot be recomputed",
            );
        };
        let drift = invariant_drift.value();
        let agreement = self.agreement.value / invariant_drift.scale;
        let scale = if invariant_drift.natural_scale() {
            "√(g/a), since C1_0 = C2_0 = 0"
        } else {
            "|C1_0| + |C2_0|"
        };
        // The integrator errs on C by its tolerance times the rates that make C up, of order √(g/a) for a
        // coin falling or wobbling however small C₀ is: relative to a C₀ below that, the energy tolerance
        // is widened by √(g/a)/(|C1₀| + |C2₀|) (`wobble` with ω_Z = 1e-8 erred on C by 1e-13, a drift of
        // 1.7e-5, and failed the pass record had promised).
        let natural = 1.0 / ctx.coin.params().time_unit();
        let widened = (natural / invariant_drift.scale).max(1.0);
        let drift_tol = tol.energy * widened;
        let mut drift_tol_said = format!("{}, the energy tolerance", fmt_num(drift_tol));
        if widened > 1.0 {
            drift_tol_said += &format!(" × √(g/a)/(|C1_0| + |C2_0|) = {}", fmt_num(widened));
        }
        let agreed = (self.stored > 0).then_some((agreement, RECOMPUTE_TOLERANCE, "agreement"));
        let (value, tolerance, which) = worst((drift, drift_tol, "drift"), agreed.as_slice());
        CheckResult::measured(
            CheckId::Invariants,
            value,
            tolerance,
            format!(
                "{which} is the worst measure: drift max|C - C0|/({scale}) = {} over {} samples (worst at t = {}, tolerance {drift_tol_said}); /coin/invariants {}",
                fmt_num(drift),
                self.samples,
                fmt_num(invariant_drift.worst_time()),
                if self.stored > 0 {
                    format!("differs from the recomputed C by {} (tolerance {})", fmt_num(agreement), fmt_num(RECOMPUTE_TOLERANCE))
                } else {
                    "not stored".into()
                }
            ),
        )
    }
}
