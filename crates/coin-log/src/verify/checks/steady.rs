//! `steady`: a steady motion (physics §4) stays steady. At every sample the right-hand side of eqs (14)–(16)
//! must vanish, θ and ω must equal the steady values, and the circles traced by the stored centre and
//! contact point must have the radii R_G and R_C of the metadata (fitted by least squares).

use super::{fmt_num, worst, Context, Max};
use crate::format::tolerances::Tolerances;
use crate::format::RunMetadata;
use crate::model::{magnitude, Coin, Steady};
use crate::scene::Scene;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use nalgebra::{Matrix3, Vector3};

/// Smallest heading range over which a circle is fitted \[rad\]: shorter arcs make the radius ill-conditioned.
const MIN_ARC: f64 = 0.5;

/// The steady motion a log's scene asks for, or why the check does not apply. The stored scene (`scene`,
/// read by the same typed parser and validation as `record` uses) names it; the motion is rebuilt for the
/// metadata's body.
pub fn plan(
    coin: &Coin,
    run: &RunMetadata,
    scene: &Result<Scene, String>,
) -> Result<Steady, String> {
    if let Some(d) = &run.dissipation {
        return Err(format!(
            "the run has dissipation ({}, κ = {}): a dissipative couple moves the coin off every steady motion (physics §11)",
            d.model(),
            fmt_num(d.coefficient())
        ));
    }
    let Some(family) = run.steady_kind else {
        return Err("not a steady scene (steady_kind = none)".into());
    };
    let scene = scene.as_ref().map_err(Clone::clone)?;
    let steady = scene.unperturbed_steady().ok_or(
        "the scene perturbs its steady motion (or has none), so it is not expected to stay steady",
    )?;
    if steady.kind.family() != family {
        return Err(format!(
            "the metadata says steady_kind = {family}, but its scene's steady motion is {}",
            steady.kind.family()
        ));
    }
    Steady::new(coin, steady.kind)
        .map_err(|e| format!("the scene's steady motion cannot be built: {e}"))
}

/// Streaming least-squares circle fit (Kåsa), in coordinates shifted to the first point.
#[derive(Debug, Default, Clone, Copy)]
struct CircleFit {
    origin: Option<(f64, f64)>,
    n: f64,
    su: f64,
    sv: f64,
    suu: f64,
    svv: f64,
    suv: f64,
    suuu: f64,
    svvv: f64,
    suvv: f64,
    suuv: f64,
    max_offset: f64,
}

impl CircleFit {
    fn add(&mut self, x: f64, z: f64) {
        let (x0, z0) = *self.origin.get_or_insert((x, z));
        let (u, v) = (x - x0, z - z0);
        self.n += 1.0;
        self.su += u;
        self.sv += v;
        self.suu += u * u;
        self.svv += v * v;
        self.suv += u * v;
        self.suuu += u * u * u;
        self.svvv += v * v * v;
        self.suvv += u * v * v;
        self.suuv += u * u * v;
        self.max_offset = self.max_offset.max(u.hypot(v));
    }

    /// The fitted radius, if the system is solvable. The circle u² + v² + D u + E v + F = 0 that minimises
    /// Σ(u² + v² + D u + E v + F)² solves the normal equations
    /// [Σu² Σuv Σu; Σuv Σv² Σv; Σu Σv n]·(D, E, F) = −(Σu³ + Σuv², Σu²v + Σv³, Σu² + Σv²),
    /// and its radius is √((D² + E²)/4 − F). `None` when the matrix is singular (collinear points), the
    /// solution is not finite, or the radius² comes out negative.
    fn radius(&self) -> Option<f64> {
        #[rustfmt::skip]
        let m = Matrix3::new(
            self.suu, self.suv, self.su,
            self.suv, self.svv, self.sv,
            self.su, self.sv, self.n,
        );
        let r = -Vector3::new(
            self.suuu + self.suvv,
            self.suuv + self.svvv,
            self.suu + self.svv,
        );
        let sol = m
            .lu()
            .solve(&r)
            .filter(|s| s.iter().all(|v| v.is_finite()))?;
        let (dd, ee, ff) = (sol.x, sol.y, sol.z);
        let r2 = 0.25 * (dd * dd + ee * ee) - ff;
        (r2 >= 0.0).then(|| r2.sqrt())
    }
}

#[derive(Debug, Default, Clone)]
pub struct SteadyCheck {
    acceleration: Max,
    theta: Max,
    omega: Max,
    max_omega: f64,
    samples: u64,
    centre: CircleFit,
    contact: CircleFit,
    phi_range: Option<(f64, f64)>,
}

impl SteadyCheck {
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let Ok(steady) = &ctx.steady else { return };
        let (Some(w), Some(a)) = (s.omega, s.angles) else {
            return;
        };
        self.samples += 1;
        let acc = ctx.coin.angular_acceleration(a.theta, w.x, w.y, w.z);
        self.acceleration
            .offer(acc.x.abs().max(acc.y.abs()).max(acc.z.abs()), s.t);
        self.theta.offer((a.theta - steady.state.theta).abs(), s.t);
        let e = &steady.state;
        self.omega.offer(
            (w.x - e.omega_x)
                .abs()
                .max((w.y - e.omega_y).abs())
                .max((w.z - e.omega_z).abs()),
            s.t,
        );
        self.max_omega = self.max_omega.max(magnitude(w.x, w.y, w.z));
        let (lo, hi) = self.phi_range.get_or_insert((a.phi, a.phi));
        *lo = lo.min(a.phi);
        *hi = hi.max(a.phi);
        if let Some(p) = s.position {
            self.centre.add(p.x, p.z);
        }
        if let Some(c) = s.contact {
            self.contact.add(c.x, c.z);
        }
    }

    #[must_use]
    pub fn finish(&self, ctx: &Context, tol: &Tolerances) -> CheckResult {
        let steady = match &ctx.steady {
            Ok(s) => s,
            Err(reason) => return CheckResult::skip(CheckId::Steady, reason.clone()),
        };
        if self.samples == 0 {
            return CheckResult::skip(
                CheckId::Steady,
                "no sample has both /coin/omega and /coin/angles: record the channels omega and angles",
            );
        }
        let p = ctx.coin.params();
        let a = p.radius();
        let omega_scale = self.max_omega.max(1.0 / p.time_unit());
        let acc_scale = self.max_omega * self.max_omega + p.topple_rate_squared();
        let rhs = (self.acceleration.value / acc_scale, tol.residual, "rhs");
        let meta_dev = metadata_deviation(ctx, steady, omega_scale);
        let mut measures = vec![
            (self.theta.value, tol.residual, "theta"),
            (self.omega.value / omega_scale, tol.residual, "omega"),
            (meta_dev, tol.residual, "metadata"),
        ];
        let mut notes = Vec::new();
        let arc = self.phi_range.map_or(0.0, |(lo, hi)| hi - lo);
        for (fit, expected, name) in [
            (&self.centre, steady.r_g, "R_G"),
            (&self.contact, steady.r_c, "R_C"),
        ] {
            let (measure, note) = radius_measure(fit, expected, arc, a);
            measures.extend(measure.map(|m| (m, tol.residual, name)));
            notes.push(format!("{name}: {note}"));
        }
        let (value, tolerance, which) = worst(rhs, &measures);
        CheckResult::measured(
            CheckId::Steady,
            value,
            tolerance,
            format!(
                "{} steady motion over {} samples; worst measure {which}: |ω̇|/(|ω|² + Mga/(I_X + Ma²)) = {} (t = {}), |θ - θs| = {} rad (t = {}), |ω - ωs|/|ω| = {} (t = {}), metadata φ̇, ψ̇, R_G, R_C off by {}; {}",
                steady.kind.family().name(),
                self.samples,
                fmt_num(self.acceleration.value / acc_scale),
                fmt_num(self.acceleration.t),
                fmt_num(self.theta.value),
                fmt_num(self.theta.t),
                fmt_num(self.omega.value / omega_scale),
                fmt_num(self.omega.t),
                fmt_num(meta_dev),
                notes.join(", "),
            ),
        )
    }
}

/// The largest deviation of the metadata's steady values (φ̇, ψ̇, R_G, R_C) from those recomputed from
/// the scene, rates relative to `omega_scale` and radii to a; infinite when one is stored and the other
/// is not.
fn metadata_deviation(ctx: &Context, steady: &Steady, omega_scale: f64) -> f64 {
    let a = ctx.coin.params().radius();
    let pairs = [
        (ctx.run.phi_dot, Some(steady.phi_dot), omega_scale),
        (ctx.run.psi_dot, Some(steady.psi_dot), omega_scale),
        (ctx.run.r_g, steady.r_g, a),
        (ctx.run.r_c, steady.r_c, a),
    ];
    pairs
        .iter()
        .map(|(m, s, scale)| match (m, s) {
            (Some(m), Some(s)) => (m - s).abs() / scale,
            (None, None) => 0.0,
            _ => f64::INFINITY,
        })
        .fold(0.0, f64::max)
}

/// How well a traced circle fits the expected radius: the relative misfit (if one can be measured) and a
/// note saying what was found. A radius of 0 means the point stays put; `None` means straight rolling.
fn radius_measure(
    fit: &CircleFit,
    expected: Option<f64>,
    arc: f64,
    a: f64,
) -> (Option<f64>, String) {
    match expected {
        None => (None, "straight rolling, no circle".into()),
        Some(0.0) => (
            Some(fit.max_offset / a),
            format!("stays within {} of its start", fmt_num(fit.max_offset)),
        ),
        Some(_) if fit.n < 3.0 => (None, "not stored".into()),
        Some(_) if arc < MIN_ARC => (
            None,
            format!(
                "the run turns only {} rad, too little to fit a circle",
                fmt_num(arc)
            ),
        ),
        Some(r) => match fit.radius() {
            Some(fitted) => (
                Some((fitted - r).abs() / r.max(a)),
                format!("fitted {} vs {}", fmt_num(fitted), fmt_num(r)),
            ),
            None => (None, "the circle fit is singular".into()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fit(points: impl IntoIterator<Item = (f64, f64)>) -> CircleFit {
        let mut f = CircleFit::default();
        for (x, z) in points {
            f.add(x, z);
        }
        f
    }

    #[test]
    fn the_circle_fit_recovers_the_radius_of_points_on_an_arc() {
        // 50 points over 1 rad of a circle of radius 3.7 centred at (12, −5): the normal equations hold
        // exactly for the true circle, so the fit is exact up to round-off of the sums.
        let (r, cx, cz) = (3.7, 12.0, -5.0);
        let f = fit((0..50).map(|k| {
            let a = 0.3 + f64::from(k) * 0.02;
            (cx + r * a.cos(), cz + r * a.sin())
        }));
        let got = f.radius().unwrap();
        println!("fitted radius {got}, expected {r}, tolerance 1e-9 relative");
        assert!((got - r).abs() <= 1e-9 * r);
    }

    #[test]
    fn collinear_or_too_few_points_have_no_circle() {
        // Negative controls: the matrix of the normal equations is singular (exactly, in these sums).
        let line = fit((0..20).map(|k| (f64::from(k), 2.0 * f64::from(k))));
        assert_eq!(line.radius(), None);
        let two = fit([(0.0, 0.0), (1.0, 1.0)]);
        assert_eq!(two.radius(), None);
        assert_eq!(CircleFit::default().radius(), None);
    }
}
