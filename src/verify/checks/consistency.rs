//! `consistency`: the stored channels agree with each other. The quaternion equals q(e_y, φ)·q(e_x, θ)·
//! q(e_z, ψ) of the stored angles up to sign (physics §1) and has unit norm; the contact point is the centre
//! plus c (x_c = x − a sin θ sin φ, z_c = z − a sin θ cos φ, y_c = 0, physics §3); the centre's height is
//! a cos θ; the stored reaction equals R recomputed from the stored state (physics §3), with F = √(R_x² + R_z²)
//! and N = R_y. Each is a recomputation from stored numbers, held to the recomputation tolerance.

use super::{fmt_num, worst, Context, Max};
use crate::model::orientation;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use crate::verify::tolerances::RECOMPUTE_TOLERANCE;
use nalgebra::Quaternion;

/// Running state of the consistency check.
#[derive(Debug, Default, Clone)]
pub struct ConsistencyCheck {
    quaternion: Max,
    norm: Max,
    contact: Max,
    height: Max,
    reaction: Max,
    counts: [u64; 4],
}

impl ConsistencyCheck {
    /// Accounts for one sample.
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let p = ctx.coin.params();
        let a = p.radius();
        if let (Some(q), Some(ang)) = (s.quaternion, s.angles) {
            self.counts[0] += 1;
            let state = crate::model::State {
                theta: ang.theta,
                phi: ang.phi,
                psi: ang.psi,
                ..Default::default()
            };
            let e = orientation(&state);
            let stored = Quaternion::new(q.w, q.x, q.y, q.z);
            // Largest component difference, to q or to −q (the same rotation).
            let diff = |sign: f64| (stored.coords - e.coords * sign).amax();
            self.quaternion.offer(diff(1.0).min(diff(-1.0)), s.t);
            self.norm.offer((stored.norm() - 1.0).abs(), s.t);
        }
        if let (Some(pos), Some(ang)) = (s.position, s.angles) {
            self.counts[1] += 1;
            self.height
                .offer((pos.y - a * ang.theta.cos()).abs() / a, s.t);
            if let Some(c) = s.contact {
                let st = ang.theta.sin();
                let (sp, cp) = ang.phi.sin_cos();
                let scale = a.max(pos.x.abs()).max(pos.z.abs());
                let d = (c.x - (pos.x - a * st * sp))
                    .abs()
                    .max((c.z - (pos.z - a * st * cp)).abs())
                    .max(c.y.abs());
                self.contact.offer(d / scale, s.t);
                self.counts[2] += 1;
            }
        }
        if let (Some(r), Some(state)) = (s.reaction, s.state()) {
            self.counts[3] += 1;
            let e = ctx.dynamics.reaction(&state);
            let scale =
                p.mass() * p.gravity() + e.force.x.abs().max(e.force.y.abs()).max(e.force.z.abs());
            let d = (r.x - e.force.x)
                .abs()
                .max((r.y - e.force.y).abs())
                .max((r.z - e.force.z).abs())
                .max((r.friction - r.x.hypot(r.z)).abs())
                .max((r.normal - r.y).abs());
            self.reaction.offer(d / scale, s.t);
        }
    }

    /// The result.
    #[must_use]
    pub fn finish(&self) -> CheckResult {
        let mut measures = Vec::new();
        let mut parts = Vec::new();
        let tol = RECOMPUTE_TOLERANCE;
        if self.counts[0] > 0 {
            measures.push((self.quaternion.value, tol, "quaternion"));
            measures.push((self.norm.value, tol, "quaternion norm"));
            parts.push(format!(
                "q vs angles {} (t = {}), | |q| - 1 | {}",
                fmt_num(self.quaternion.value),
                fmt_num(self.quaternion.t),
                fmt_num(self.norm.value)
            ));
        }
        if self.counts[1] > 0 {
            measures.push((self.height.value, tol, "height"));
            parts.push(format!(
                "|y - a cos θ|/a {} (t = {})",
                fmt_num(self.height.value),
                fmt_num(self.height.t)
            ));
        }
        if self.counts[2] > 0 {
            measures.push((self.contact.value, tol, "contact"));
            parts.push(format!(
                "contact vs centre + c {} (t = {})",
                fmt_num(self.contact.value),
                fmt_num(self.contact.t)
            ));
        }
        if self.counts[3] > 0 {
            measures.push((self.reaction.value, tol, "reaction"));
            parts.push(format!(
                "R vs recomputed {} (t = {})",
                fmt_num(self.reaction.value),
                fmt_num(self.reaction.t)
            ));
        }
        let Some((value, tolerance, which)) = worst(&measures) else {
            return CheckResult::skip(
                CheckId::Consistency,
                "no pair of channels to compare (needs /coin/angles with /coin/quaternion, /coin/position or /coin/reaction)",
            );
        };
        CheckResult::measured(
            CheckId::Consistency,
            value,
            tolerance,
            format!("worst: {which}; {}", parts.join(", ")),
        )
    }
}
