//! `steady`: a steady motion (NOTES §4) stays steady. At every sample the right-hand side of eqs (14)–(16)
//! must vanish, θ and ω must equal the steady values, and the circles traced by the stored centre and
//! contact point must have the radii R_G and R_C of the metadata (fitted by least squares).

use super::{fmt_num, worst, Context, Max};
use crate::model::{Branch, Coin, Steady, SteadyKind};
use crate::record::RunMetadata;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use crate::verify::tolerances::Tolerances;
use nalgebra::{Matrix3, Vector3};

/// Smallest heading range over which a circle is fitted \[rad\]: shorter arcs make the radius ill-conditioned.
const MIN_ARC: f64 = 0.5;

/// The steady motion a log's scene asks for, or why the check does not apply.
///
/// # Errors
/// A sentence saying why there is no steady motion to compare with.
pub fn plan(coin: &Coin, run: &RunMetadata) -> Result<Steady, String> {
    if run.steady_kind == "none" {
        return Err("not a steady scene (steady_kind = none)".into());
    }
    let scene: toml::Table = run
        .scene
        .parse()
        .map_err(|e| format!("the metadata's scene TOML does not parse: {e}"))?;
    let initial = scene
        .get("initial")
        .and_then(toml::Value::as_table)
        .ok_or("the metadata's scene has no [initial] table")?;
    if initial.contains_key("perturbation") {
        return Err(
            "the scene perturbs its steady motion, so it is not expected to stay steady".into(),
        );
    }
    let steady = initial
        .get("steady")
        .and_then(toml::Value::as_table)
        .ok_or("steady_kind is set but the scene has no initial.steady table")?;
    let number = |key: &str| -> Result<f64, String> {
        let v = steady
            .get(key)
            .ok_or_else(|| format!("initial.steady has no `{key}`"))?;
        v.as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .ok_or_else(|| format!("initial.steady.{key} = {v} is not a number"))
    };
    let branch = match steady.get("branch").and_then(toml::Value::as_str) {
        None | Some("+") => Branch::Plus,
        Some("-") => Branch::Minus,
        Some(other) => {
            return Err(format!(
                "initial.steady.branch = {other:?} is not \"+\" or \"-\""
            ))
        }
    };
    let kind = match run.steady_kind.as_str() {
        "straight" => SteadyKind::Straight {
            omega_z: number("omega_z")?,
        },
        "centre-fixed" => SteadyKind::CentreFixed {
            theta: number("theta")?,
            branch,
        },
        "circle" => SteadyKind::Circle {
            theta: number("theta")?,
            omega_z: number("omega_z")?,
            branch,
        },
        "spin-upright" => SteadyKind::SpinUpright {
            omega_y: number("omega_y")?,
        },
        other => return Err(format!("unknown steady_kind {other:?}")),
    };
    Steady::new(coin, kind).map_err(|e| format!("the scene's steady motion cannot be built: {e}"))
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

/// Running state of the steady check.
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
    /// Accounts for one sample.
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
        self.max_omega = self.max_omega.max(Vector3::new(w.x, w.y, w.z).norm());
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

    /// The result.
    #[must_use]
    pub fn finish(&self, ctx: &Context, tol: &Tolerances) -> CheckResult {
        let steady = match &ctx.steady {
            Ok(s) => s,
            Err(reason) => return CheckResult::skip(CheckId::Steady, reason.clone()),
        };
        if self.samples == 0 {
            return CheckResult::skip(
                CheckId::Steady,
                "no sample has both /coin/omega and /coin/angles",
            );
        }
        let p = ctx.coin.params();
        let a = p.radius();
        let omega_scale = self.max_omega.max(1.0 / p.time_unit());
        let acc_scale =
            self.max_omega * self.max_omega + p.energy_scale() / (p.inertia_x() + p.ma2());
        let mut measures = vec![
            (self.acceleration.value / acc_scale, tol.residual, "rhs"),
            (self.theta.value, tol.residual, "theta"),
            (self.omega.value / omega_scale, tol.residual, "omega"),
        ];
        let mut notes = Vec::new();
        // The metadata's steady values against those recomputed from the scene.
        let meta = [
            (ctx.run.phi_dot, Some(steady.phi_dot), omega_scale),
            (ctx.run.psi_dot, Some(steady.psi_dot), omega_scale),
            (ctx.run.r_g, steady.r_g, a),
            (ctx.run.r_c, steady.r_c, a),
        ];
        let meta_dev = meta
            .iter()
            .map(|(m, s, scale)| match (m, s) {
                (Some(m), Some(s)) => (m - s).abs() / scale,
                (None, None) => 0.0,
                _ => f64::INFINITY,
            })
            .fold(0.0, f64::max);
        measures.push((meta_dev, tol.residual, "metadata"));
        let arc = self.phi_range.map_or(0.0, |(lo, hi)| hi - lo);
        let mut radii = |fit: &CircleFit, expected: Option<f64>, name: &'static str| match expected
        {
            None => notes.push(format!("{name}: straight rolling, no circle")),
            Some(0.0) => {
                measures.push((fit.max_offset / a, tol.residual, name));
                notes.push(format!(
                    "{name}: stays within {} of its start",
                    fmt_num(fit.max_offset)
                ));
            }
            Some(_) if fit.n < 3.0 => notes.push(format!("{name}: not stored")),
            Some(_) if arc < MIN_ARC => notes.push(format!(
                "{name}: the run turns only {} rad, too little to fit a circle",
                fmt_num(arc)
            )),
            Some(r) => match fit.radius() {
                Some(fitted) => {
                    measures.push(((fitted - r).abs() / r.max(a), tol.residual, name));
                    notes.push(format!(
                        "{name}: fitted {} vs {}",
                        fmt_num(fitted),
                        fmt_num(r)
                    ));
                }
                None => notes.push(format!("{name}: the circle fit is singular")),
            },
        };
        radii(&self.centre, steady.r_g, "R_G");
        radii(&self.contact, steady.r_c, "R_C");
        let Some((value, tolerance, which)) = worst(&measures) else {
            return CheckResult::skip(CheckId::Steady, "nothing measured");
        };
        CheckResult::measured(
            CheckId::Steady,
            value,
            tolerance,
            format!(
                "{} steady motion over {} samples; worst measure {which}: |ω̇|/(|ω|² + Mga/(I_X + Ma²)) = {} (t = {}), |θ - θs| = {} rad (t = {}), |ω - ωs|/|ω| = {} (t = {}), metadata φ̇, ψ̇, R_G, R_C off by {}; {}",
                steady.kind.name(),
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
