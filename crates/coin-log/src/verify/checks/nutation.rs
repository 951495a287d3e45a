//! `nutation`: the nutation period T and the heading advance per period ΔΦ, measured from the stored angles
//! and angular velocity, against the quadrature of physics §10 from the first stored state. Energy and the
//! integrals C1, C2 are blind to an error of phase or timing (a recording whose clock runs 1e-6 fast keeps
//! every value on the right orbit); this check is not.
//!
//! **Measurement**, streaming with O(1) state: the turning points of θ are where ω_X = θ̇ changes sign
//! between two samples; the crossing time is the root of the quintic Hermite interpolant of ω_X with its
//! first two derivatives (ω̇_X from eq (14), ω̈_X = A ω_X + B ω̇_Y + C ω̇_Z with A, B, C the partial
//! derivatives of eq (14), physics §9), and φ there the quintic Hermite interpolant of φ with
//! φ̇ = ω_Y / cos θ and φ̈ = (ω̇_Y + ω_X ω_Y tan θ)/cos θ. T and ΔΦ are (last − first)/(count − 1) over the
//! maxima of θ, and likewise over the minima; the two are averaged, weighted by their counts.
//!
//! **Tolerance**: the integrator's share (format.md: verify, Tolerances) plus the quadrature's own error
//! estimate plus a bound on the interpolation error, 2·(h⁶σ⁵/46080)/(t_last − t_first) for samples h apart
//! and the nutation frequency σ = 2π/T (the quintic Hermite error h⁶/46080·max|ω_X⁽⁶⁾| with
//! ω_X⁽⁶⁾ ≈ σ⁶ max|ω_X|, over a slope σ max|ω_X|), times ten for harmonics. With the cubic Hermite
//! interpolant (h⁴σ³/384) the 1 kHz `high-spin` and the 10 Hz `long-horizon` recordings were too coarse to
//! judge at 1e-8; with the quintic their bounds are 2e-13 and 3e-11.

use super::{fmt_num, worst, Context};
use crate::model::nutation::{Motion, Orbit};
use crate::model::{Coin, Linearisation, State};
use crate::scene::{self, defaults};
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use crate::verify::tolerances::Tolerances;
use std::f64::consts::TAU;

/// Fewest samples per nutation period for the crossings to be interpolated.
const MIN_SAMPLES_PER_PERIOD: f64 = 8.0;
/// Safety factor on the interpolation error bound (higher harmonics of large nutations).
const INTERPOLATION_SAFETY: f64 = 10.0;
/// The interpolation bound may use at most this share of the tolerance, or the file is undersampled.
const INTERPOLATION_SHARE: f64 = 0.1;
/// Newton steps on the Hermite cubic (it converges in a handful from the linear estimate).
const NEWTON_STEPS: usize = 32;
/// Smallest θ range worth measuring \[rad\]: below it the crossings of ω_X are the integrator's noise.
const MIN_AMPLITUDE: f64 = 1e-8;

/// One sample, as the crossings need it: t, and (value, first, second derivative) of φ and of ω_X.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Point {
    t: f64,
    phi: [f64; 3],
    omega_x: [f64; 3],
}

impl Point {
    fn of(coin: &Coin, t: f64, s: &State) -> Self {
        let acc = coin.angular_acceleration(s.theta, s.omega_x, s.omega_y, s.omega_z);
        let partials = Linearisation::at(coin, s.theta, s.omega_y, s.omega_z);
        let (st, ct) = s.theta.sin_cos();
        Self {
            t,
            phi: [
                s.phi,
                s.omega_y / ct,
                (acc.y + s.omega_x * s.omega_y * st / ct) / ct,
            ],
            omega_x: [
                s.omega_x,
                acc.x,
                partials.a * s.omega_x + partials.b * acc.y + partials.c * acc.z,
            ],
        }
    }
}

/// The crossings of one kind (maxima or minima of θ): how many, and the first and last (t, φ).
#[derive(Debug, Default, Clone, Copy, PartialEq)]
struct Crossings {
    count: u64,
    first: Option<(f64, f64)>,
    last: Option<(f64, f64)>,
}

impl Crossings {
    fn add(&mut self, at: (f64, f64)) {
        self.count += 1;
        self.first.get_or_insert(at);
        self.last = Some(at);
    }

    /// (T, ΔΦ, periods) when at least two whole periods lie between the first and the last.
    fn measure(&self) -> Option<(f64, f64, f64)> {
        let (first, last) = (self.first?, self.last?);
        #[allow(clippy::cast_precision_loss)]
        let periods = self.count.checked_sub(1)? as f64;
        (periods >= 2.0).then(|| {
            (
                (last.0 - first.0) / periods,
                (last.1 - first.1) / periods,
                periods,
            )
        })
    }
}

/// Running state of the nutation check.
#[derive(Debug, Default, Clone)]
pub struct NutationCheck {
    initial: Option<State>,
    previous: Option<Point>,
    maxima: Crossings,
    minima: Crossings,
    samples: u64,
    largest_interval: f64,
}

impl NutationCheck {
    /// Accounts for one sample.
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let Some(state) = s.state() else {
            return;
        };
        self.initial.get_or_insert(state);
        self.samples += 1;
        let point = Point::of(&ctx.coin, s.t, &state);
        if let Some(p) = self.previous {
            self.largest_interval = self.largest_interval.max(point.t - p.t);
            let (before, after) = (p.omega_x[0], point.omega_x[0]);
            if before > 0.0 && after <= 0.0 {
                self.maxima.add(crossing(&p, &point));
            } else if before < 0.0 && after >= 0.0 {
                self.minima.add(crossing(&p, &point));
            }
        }
        self.previous = Some(point);
    }

    /// The result: T and ΔΦ against the quadrature, or why they cannot be compared.
    #[must_use]
    pub fn finish(&self, ctx: &Context, tol: &Tolerances) -> CheckResult {
        let skip = |reason: String| CheckResult::skip(CheckId::Nutation, reason);
        if let Some(d) = ctx.dynamics.dissipation() {
            return skip(format!(
                "the run has dissipation ({}): E, C1 and C2 change, so θ does not nutate periodically and the quadrature (physics §10) does not apply",
                d.model()
            ));
        }
        if let Some(kind) = ctx.run.steady_kind {
            return skip(format!(
                "a steady motion ({kind}) does not nutate; the steady check judges it"
            ));
        }
        let Some(initial) = self.initial else {
            return skip(
                "no sample has both /coin/omega and /coin/angles, so θ's turning points cannot be found"
                    .into(),
            );
        };
        let chaplygin = match &ctx.chaplygin {
            Ok(c) => c,
            Err(e) => return skip(e.clone()),
        };
        let orbit = match Orbit::new(&ctx.coin, chaplygin, &initial, flat_margin(ctx)) {
            Ok(o) => o,
            Err(e) => return skip(format!("the first stored state has no orbit: {e}")),
        };
        let (period, precession) = match orbit.motion {
            Motion::Periodic {
                period, precession, ..
            } => (period, precession),
            Motion::Steady => {
                return skip("the first stored state is steady: θ does not nutate".into())
            }
            Motion::FlatLanding { time, .. } => {
                return skip(format!(
                    "the quadrature says the coin lands flat at t = {}: there is no period",
                    fmt_num(time)
                ))
            }
        };
        if orbit.theta_max - orbit.theta_min < MIN_AMPLITUDE {
            return skip(format!(
                "θ nutates by {} rad only: below {MIN_AMPLITUDE:e} its turning points are the integrator's noise",
                fmt_num(orbit.theta_max - orbit.theta_min)
            ));
        }
        self.compare(&orbit, (period, precession), tol)
    }

    fn compare(
        &self,
        orbit: &Orbit,
        (period, precession): (f64, f64),
        tol: &Tolerances,
    ) -> CheckResult {
        let skip = |reason: String| CheckResult::skip(CheckId::Nutation, reason);
        let measured: Vec<(f64, f64, f64)> = [self.maxima.measure(), self.minima.measure()]
            .into_iter()
            .flatten()
            .collect();
        let weight: f64 = measured.iter().map(|m| m.2).sum();
        if measured.is_empty() {
            return skip(format!(
                "fewer than two nutation periods recorded ({} maxima and {} minima of θ; T = {} by quadrature)",
                self.maxima.count,
                self.minima.count,
                fmt_num(period)
            ));
        }
        let h = self.largest_interval;
        if h * MIN_SAMPLES_PER_PERIOD > period {
            return skip(format!(
                "undersampled: samples {} apart, fewer than {MIN_SAMPLES_PER_PERIOD} per nutation period T = {}; record with a higher --rate",
                fmt_num(h),
                fmt_num(period)
            ));
        }
        let t_measured = measured.iter().map(|m| m.0 * m.2).sum::<f64>() / weight;
        let phi_measured = measured.iter().map(|m| m.1 * m.2).sum::<f64>() / weight;
        let span = t_measured * measured.iter().map(|m| m.2).fold(0.0, f64::max);
        let sigma = TAU / period;
        let interpolation = INTERPOLATION_SAFETY * 2.0 * h.powi(6) * sigma.powi(5) / 46080.0 / span;
        if interpolation > INTERPOLATION_SHARE * tol.nutation {
            return skip(format!(
                "undersampled: interpolating the turning points between samples {} apart may be off by {} of T, more than {} of the tolerance {}; record with a higher --rate",
                fmt_num(h),
                fmt_num(interpolation),
                INTERPOLATION_SHARE,
                fmt_num(tol.nutation)
            ));
        }
        let tolerance = tol.nutation + orbit.error + interpolation;
        let t_error = (t_measured - period).abs() / period;
        let phi_error = (phi_measured - precession).abs() / precession.abs().max(1.0);
        let Some((value, _, which)) = worst(&[
            (t_error, tolerance, "period"),
            (phi_error, tolerance, "heading advance"),
        ]) else {
            return skip("nothing measured".into());
        };
        CheckResult::measured(
            CheckId::Nutation,
            value,
            tolerance,
            format!(
                "{which} is the worst measure: T = {} measured over {} periods ({} maxima, {} minima of θ) vs {} by quadrature, relative {}; ΔΦ = {} vs {} rad, off by {} (relative to max(|ΔΦ|, 1 rad)); tolerance {} + quadrature {} + interpolation {}",
                t_measured,
                fmt_num(weight),
                self.maxima.count,
                self.minima.count,
                period,
                fmt_num(t_error),
                phi_measured,
                precession,
                fmt_num(phi_error),
                fmt_num(tol.nutation),
                fmt_num(orbit.error),
                fmt_num(interpolation)
            ),
        )
    }
}

/// The flat margin of the stored scene (the default when the scene cannot be read).
fn flat_margin(ctx: &Context) -> f64 {
    scene::parse_with_sets(&ctx.run.scene, &[])
        .ok()
        .and_then(|f| f.run.and_then(|r| r.flat_margin))
        .unwrap_or(defaults::FLAT_MARGIN)
}

/// The quintic Hermite interpolant on [0, 1] of values and first and second derivatives (with respect
/// to time, samples `h` apart) at both ends: its value and its derivative with respect to s.
fn quintic(s: f64, h: f64, a: &[f64; 3], b: &[f64; 3]) -> (f64, f64) {
    let (s2, s3, s4, s5) = (s * s, s * s * s, s.powi(4), s.powi(5));
    let weights = [
        1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5,
        s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5,
        0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5,
        0.5 * s3 - s4 + 0.5 * s5,
        -4.0 * s3 + 7.0 * s4 - 3.0 * s5,
        10.0 * s3 - 15.0 * s4 + 6.0 * s5,
    ];
    let slopes = [
        -30.0 * s2 + 60.0 * s3 - 30.0 * s4,
        1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4,
        s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4,
        1.5 * s2 - 4.0 * s3 + 2.5 * s4,
        -12.0 * s2 + 28.0 * s3 - 15.0 * s4,
        30.0 * s2 - 60.0 * s3 + 30.0 * s4,
    ];
    let data = [a[0], h * a[1], h * h * a[2], h * h * b[2], h * b[1], b[0]];
    let dot = |w: &[f64; 6]| w.iter().zip(&data).map(|(w, d)| w * d).sum::<f64>();
    (dot(&weights), dot(&slopes))
}

/// (t, φ) where ω_X crosses zero between samples `a` and `b`: the root of the quintic Hermite interpolant
/// of ω_X by Newton's method from the linear estimate, kept inside the interval, and φ there by the
/// quintic Hermite interpolant of φ.
fn crossing(a: &Point, b: &Point) -> (f64, f64) {
    let h = b.t - a.t;
    let (wa, wb) = (a.omega_x[0], b.omega_x[0]);
    #[allow(clippy::float_cmp)] // exact: equal values give the linear estimate 0/0
    let mut s = if wa == wb { 1.0 } else { wa / (wa - wb) };
    for _ in 0..NEWTON_STEPS {
        let (value, slope) = quintic(s, h, &a.omega_x, &b.omega_x);
        if slope == 0.0 {
            break;
        }
        let next = (s - value / slope).clamp(0.0, 1.0);
        let done = (next - s).abs() <= 4.0 * f64::EPSILON;
        s = next;
        if done {
            break;
        }
    }
    let (phi, _) = quintic(s, h, &a.phi, &b.phi);
    (a.t + s * h, phi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crossing_of_a_sine_is_found_to_the_quintic_hermite_accuracy() {
        // ω_X = cos t crosses zero (downwards) at π/2; φ = t + sin t.
        let point = |t: f64| Point {
            t,
            phi: [t + t.sin(), 1.0 + t.cos(), -t.sin()],
            omega_x: [t.cos(), -t.sin(), -t.cos()],
        };
        for h in [0.1, 0.3] {
            let (t, phi) = crossing(&point(1.5), &point(1.5 + h));
            let bound = h.powi(6) / 46080.0;
            let half_pi = std::f64::consts::FRAC_PI_2;
            println!(
                "h = {h}: crossing at {t:.17} (π/2), error {:e}, bound {bound:e}",
                t - half_pi
            );
            assert!((t - half_pi).abs() < bound);
            assert!((phi - (t + t.sin())).abs() < 2.0 * bound);
        }
    }
}
