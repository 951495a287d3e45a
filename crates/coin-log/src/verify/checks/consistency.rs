//! `consistency`: the stored channels agree with each other (format.md: verify, Checks, lists each pair and
//! its scale). Each is a recomputation from stored numbers, held to the recomputation tolerance.

use super::{fmt_num, worst, Context, Max};
use crate::format::messages::{drift_eps, friction_ratio};
use crate::format::tolerances::RECOMPUTE_TOLERANCE;
use crate::model::orientation;
use crate::scene::Scene;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use nalgebra::Quaternion;

#[derive(Debug, Default, Clone)]
pub struct ConsistencyCheck {
    quaternion: Max,
    norm: Max,
    contact: Max,
    height: Max,
    reaction: Max,
    counts: [u64; 4],
    /// The fields added since the first version: φ̇, friction ratio, energy change, drift in units of ε.
    added: [Max; 4],
    added_counts: [u64; 4],
    /// The first stored total energy (E₀ of `change`).
    energy0: Option<f64>,
    /// The sample at t = 0 against the initial state of the stored scene, when both are there.
    initial: Option<f64>,
}

/// Labels of the added-field measures.
const ADDED: [&str; 4] = ["phi_dot", "friction_ratio", "energy change", "drift_eps"];

impl ConsistencyCheck {
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
        self.observe_added(s, ctx);
        if s.t == 0.0 && self.initial.is_none() {
            self.initial = ctx
                .scene
                .as_ref()
                .ok()
                .and_then(|scene| initial_offset(s, scene));
        }
    }

    /// The fields added since the first version, each against its recomputation from other stored fields,
    /// relative to the quantity's natural scale.
    fn observe_added(&mut self, s: &Sample, ctx: &Context) {
        let p = ctx.coin.params();
        if let (Some(phi_dot), Some(ang), Some(w)) =
            (s.angles.and_then(|m| m.phi_dot), s.angles, s.omega)
        {
            let expected = w.y / ang.theta.cos();
            // Scale: the heading rate itself, or √(g/a) for a coin that barely turns.
            let scale = expected.abs().max((p.gravity() / p.radius()).sqrt());
            self.added[0].offer((phi_dot - expected).abs() / scale, s.t);
            self.added_counts[0] += 1;
        }
        if let Some(r) = s.reaction {
            if let Some(ratio) = r.friction_ratio {
                let expected = friction_ratio(r.friction, r.normal, p.mass(), p.gravity());
                self.added[1].offer((ratio - expected).abs() / expected.abs().max(1.0), s.t);
                self.added_counts[1] += 1;
            }
        }
        if let Some(e) = s.energy {
            let e0 = *self.energy0.get_or_insert(e.total);
            if let Some(change) = e.change {
                // Scale: that of the energy drift, max(|E₀|, Mga).
                let scale = e0.abs().max(p.energy_scale());
                self.added[2].offer((change - (e.total - e0)).abs() / scale, s.t);
                self.added_counts[2] += 1;
            }
            if let Some(d) = e.drift_eps {
                // Scale: the drift itself in units of ε, or 1 (one ε of relative drift).
                let expected = drift_eps(e.total, e0, p.energy_scale());
                self.added[3].offer((d - expected).abs() / expected.abs().max(1.0), s.t);
                self.added_counts[3] += 1;
            }
        }
    }

    #[must_use]
    pub fn finish(&self) -> CheckResult {
        let (c, q, n) = (self.counts, &self.quaternion, &self.norm);
        let (h, k, r) = (&self.height, &self.contact, &self.reaction);
        // (samples, value, time of the worst, label, what the reason calls it)
        let mut entries = vec![
            (c[0], q.value, Some(q.t), "quaternion", "q vs angles"),
            (c[0], n.value, None, "quaternion norm", "| |q| - 1 |"),
            (c[1], h.value, Some(h.t), "height", "|y - a cos θ|/a"),
            (c[2], k.value, Some(k.t), "contact", "contact vs centre + c"),
            (c[3], r.value, Some(r.t), "reaction", "R vs recomputed"),
        ];
        for ((m, count), label) in self.added.iter().zip(self.added_counts).zip(ADDED) {
            entries.push((count, m.value, Some(m.t), label, label));
        }
        if let Some(offset) = self.initial {
            let what = "t = 0 vs the stored scene's initial state";
            entries.push((1, offset, None, "initial state", what));
        }
        entries.retain(|e| e.0 > 0);
        let measures: Vec<_> = entries
            .iter()
            .map(|e| (e.1, RECOMPUTE_TOLERANCE, e.3))
            .collect();
        let parts: Vec<String> = entries
            .iter()
            .map(|(_, value, t, _, what)| match t {
                Some(t) => format!("{what} {} (t = {})", fmt_num(*value), fmt_num(*t)),
                None => format!("{what} {}", fmt_num(*value)),
            })
            .collect();
        let Some((first, rest)) = measures.split_first() else {
            return CheckResult::skip(
                CheckId::Consistency,
                "no pair of channels to compare (needs /coin/angles with /coin/quaternion, /coin/position or /coin/reaction)",
            );
        };
        let (value, tolerance, which) = worst(*first, rest);
        CheckResult::measured(
            CheckId::Consistency,
            value,
            tolerance,
            format!("worst: {which}; {}", parts.join(", ")),
        )
    }
}

/// How far the sample at t = 0 is from the stored scene's initial state, which `record` writes as its first
/// sample: angles in radians (or their size), ω relative to max(|ω₀|, 1/τ), the centre relative to
/// max(a, |x₀|, |z₀|); `None` when the sample holds none of them.
fn initial_offset(s: &Sample, scene: &Scene) -> Option<f64> {
    let (x0, p) = (&scene.initial, &scene.params);
    let relative = |stored: f64, expected: f64, scale: f64| (stored - expected).abs() / scale;
    let mut offsets = Vec::new();
    if let Some(a) = s.angles {
        for (stored, expected) in [(a.theta, x0.theta), (a.phi, x0.phi), (a.psi, x0.psi)] {
            offsets.push(relative(stored, expected, expected.abs().max(1.0)));
        }
    }
    if let Some(w) = s.omega {
        let omega = [x0.omega_x, x0.omega_y, x0.omega_z];
        let scale = omega
            .iter()
            .fold(1.0 / p.time_unit(), |m, v| m.max(v.abs()));
        for (stored, expected) in [w.x, w.y, w.z].into_iter().zip(omega) {
            offsets.push(relative(stored, expected, scale));
        }
    }
    if let Some(c) = s.position {
        let scale = p.radius().max(x0.x.abs()).max(x0.z.abs());
        offsets.extend([relative(c.x, x0.x, scale), relative(c.z, x0.z, scale)]);
    }
    offsets.into_iter().reduce(f64::max)
}
