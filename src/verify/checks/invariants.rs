//! `invariants`: the Chaplygin–Appell integrals C1, C2 (NOTES §6) recomputed from the stored θ, ω_Y, ω_Z;
//! drift = max|C − C₀| / (|C1₀| + |C2₀|) (CONTRACT), and agreement with `/coin/invariants` when stored.

use super::{fmt_num, worst, Max};
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use crate::verify::tolerances::{Tolerances, RECOMPUTE_TOLERANCE};

/// Running state of the invariants check, given a way to evaluate (C1, C2) from (θ, ω_Y, ω_Z).
#[derive(Debug, Default, Clone)]
pub struct InvariantsCheck {
    c0: Option<(f64, f64)>,
    drift: Max,
    agreement: Max,
    samples: u64,
    stored: u64,
}

impl InvariantsCheck {
    /// Accounts for one sample; `evaluate` gives (C1, C2) or `None` where it cannot (e.g. |θ| too close to
    /// π/2 for the series).
    pub fn observe(&mut self, s: &Sample, evaluate: impl Fn(f64, f64, f64) -> Option<(f64, f64)>) {
        let (Some(w), Some(a)) = (s.omega, s.angles) else {
            return;
        };
        let Some((c1, c2)) = evaluate(a.theta, w.y, w.z) else {
            return;
        };
        let (c10, c20) = *self.c0.get_or_insert((c1, c2));
        self.samples += 1;
        self.drift
            .offer((c1 - c10).abs().max((c2 - c20).abs()), s.t);
        if let Some(m) = s.invariants {
            self.stored += 1;
            self.agreement
                .offer((m.c1 - c1).abs().max((m.c2 - c2).abs()), s.t);
        }
    }

    /// The result; `missing` is why the check cannot run at all (e.g. no C1, C2 in this build).
    #[must_use]
    pub fn finish(&self, tol: &Tolerances, missing: Option<&str>) -> CheckResult {
        if let Some(reason) = missing {
            return CheckResult::skip(CheckId::Invariants, reason);
        }
        let Some((c10, c20)) = self.c0 else {
            return CheckResult::skip(
                CheckId::Invariants,
                "no sample has both /coin/omega and /coin/angles, so C1, C2 cannot be recomputed",
            );
        };
        let scale = c10.abs() + c20.abs();
        if scale == 0.0 {
            return CheckResult::skip(
                CheckId::Invariants,
                "C1 = C2 = 0 at the start (ω_Y = ω_Z = 0): the relative drift is undefined",
            );
        }
        let drift = self.drift.value / scale;
        let agreement = self.agreement.value / scale;
        let mut measures = vec![(drift, tol.energy, "drift")];
        if self.stored > 0 {
            measures.push((agreement, RECOMPUTE_TOLERANCE, "agreement"));
        }
        let Some((value, tolerance, which)) = worst(&measures) else {
            return CheckResult::skip(CheckId::Invariants, "nothing measured");
        };
        CheckResult::measured(
            CheckId::Invariants,
            value,
            tolerance,
            format!(
                "{which} is the worst measure: drift max|C - C0|/(|C1_0| + |C2_0|) = {} over {} samples (worst at t = {}, tolerance {}, the energy tolerance); /coin/invariants {}",
                fmt_num(drift),
                self.samples,
                fmt_num(self.drift.t),
                fmt_num(tol.energy),
                if self.stored > 0 {
                    format!("differs from the recomputed C by {} (tolerance {})", fmt_num(agreement), fmt_num(RECOMPUTE_TOLERANCE))
                } else {
                    "not stored".into()
                }
            ),
        )
    }
}
