//! The nutation of a motion measured from its samples, streaming with O(1) state, alike for verify's
//! `nutation` check (stored samples) and the benchmarks (simulated ones): θ's turning points are where
//! ω_X = θ̇ changes sign between two samples, at the root of the quintic Hermite interpolant of ω_X with
//! ω̇_X from eq (14) and ω̈_X = A ω_X + B ω̇_Y + C ω̇_Z (A, B, C its partial derivatives, physics §9: exact,
//! as eq (14) has no ω_X), φ there by that of φ with φ̇ = ω_Y / cos θ, φ̈ = (ω̇_Y + ω_X ω_Y tan θ)/cos θ.
//! T and ΔΦ are the mean spacing of like turning points.
//!
//! **Accuracy**: the interpolant errs by h⁶/46080·max|ω_X⁽⁶⁾| for samples h apart, ω_X⁽⁶⁾ ≈ σ⁶ max|ω_X|,
//! over a slope σ max|ω_X|: h⁶σ⁵/46080 in time ([`TurningPoints::interpolation_error`]). With the cubic
//! Hermite interpolant (h⁴σ³/384) the 1 kHz `high-spin` and the 10 Hz `long-horizon` recordings were too
//! coarse to judge at 1e-8; with the quintic their bounds are 2e-13 and 3e-11.

use super::equations::Coin;
use super::stability::Linearisation;
use super::state::State;
use std::f64::consts::TAU;

/// Newton steps on the Hermite quintic (it converges in a handful from the linear estimate).
const NEWTON_STEPS: usize = 32;
/// Safety factor on the interpolation error bound (higher harmonics of large nutations).
const INTERPOLATION_SAFETY: f64 = 10.0;

/// θ's turning points, gathered sample by sample ([`observe`](Self::observe)); the module doc says how.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct TurningPoints {
    previous: Option<(f64, State)>,
    maxima: Crossings,
    minima: Crossings,
    largest_interval: f64,
}

/// T and ΔΦ measured over the turning points ([`TurningPoints::measure`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredNutation {
    /// The nutation period T \[time\].
    pub period: f64,
    /// The heading advance per period ΔΦ \[rad\].
    pub precession: f64,
    /// The periods measured: those between the maxima plus those between the minima.
    pub periods: f64,
    /// The time the longer of the two kinds spans, T times its periods \[time\].
    pub span: f64,
}

impl TurningPoints {
    /// Accounts for the sample `state` at time `t` (samples in time order).
    pub fn observe(&mut self, coin: &Coin, t: f64, state: &State) {
        if let Some((tp, p)) = self.previous {
            self.largest_interval = self.largest_interval.max(t - tp);
            let ends = || (Point::of(coin, tp, &p), Point::of(coin, t, state));
            if p.omega_x > 0.0 && state.omega_x <= 0.0 {
                let (a, b) = ends();
                self.maxima.add(crossing(&a, &b));
            } else if p.omega_x < 0.0 && state.omega_x >= 0.0 {
                let (a, b) = ends();
                self.minima.add(crossing(&a, &b));
            }
        }
        self.previous = Some((t, *state));
    }

    /// Maxima of θ found (ω_X from + to −).
    #[must_use]
    pub fn maxima(&self) -> u64 {
        self.maxima.count
    }

    /// Minima of θ found (ω_X from − to +).
    #[must_use]
    pub fn minima(&self) -> u64 {
        self.minima.count
    }

    /// The largest interval between two samples \[time\].
    #[must_use]
    pub fn largest_interval(&self) -> f64 {
        self.largest_interval
    }

    /// T and ΔΦ as the mean spacing of like turning points, maxima and minima weighted by the periods each
    /// spans; `None` until either kind spans two whole periods.
    #[must_use]
    pub fn measure(&self) -> Option<MeasuredNutation> {
        let measured: Vec<(f64, f64, f64)> = [self.maxima.measure(), self.minima.measure()]
            .into_iter()
            .flatten()
            .collect();
        if measured.is_empty() {
            return None;
        }
        let periods: f64 = measured.iter().map(|m| m.2).sum();
        let period = measured.iter().map(|m| m.0 * m.2).sum::<f64>() / periods;
        Some(MeasuredNutation {
            period,
            precession: measured.iter().map(|m| m.1 * m.2).sum::<f64>() / periods,
            periods,
            span: period * measured.iter().map(|m| m.2).fold(0.0, f64::max),
        })
    }

    /// A bound on the relative error of `measured`'s T from the interpolation, for a motion of period
    /// `period`: the first and the last turning point each off by h⁶σ⁵/46080 (module doc), σ = 2π/T, over
    /// the span, times 10 for the higher harmonics of large nutations.
    #[must_use]
    pub fn interpolation_error(&self, measured: &MeasuredNutation, period: f64) -> f64 {
        let sigma = TAU / period;
        INTERPOLATION_SAFETY * 2.0 * self.largest_interval.powi(6) * sigma.powi(5)
            / 46080.0
            / measured.span
    }
}

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

    #[test]
    fn two_periods_of_each_kind_are_needed_and_like_kinds_are_averaged_by_their_periods() {
        let mut meter = TurningPoints::default();
        for (i, t) in [0.0, 2.0, 4.0].into_iter().enumerate() {
            meter.maxima.add((t, 0.5 * t));
            if i < 2 {
                meter.minima.add((t + 1.0, 0.5 * t));
            }
        }
        // Maxima: 2 periods of T = 2, ΔΦ = 1; minima: 1 period only, left out.
        let m = meter.measure().unwrap();
        assert_eq!(
            (m.period, m.precession, m.periods, m.span),
            (2.0, 1.0, 2.0, 4.0)
        );
        meter.minima.add((7.0, 3.5));
        meter.minima.add((9.0, 4.0));
        // Minima now 3 periods, T = 8/3, ΔΦ = 4/3 (3.5 + 0.5 over 3): weights 2 and 3.
        let m = meter.measure().unwrap();
        assert!((m.period - (2.0 * 2.0 + 3.0 * 8.0 / 3.0) / 5.0).abs() < 1e-15);
        assert!((m.precession - (2.0 * 1.0 + 3.0 * 4.0 / 3.0) / 5.0).abs() < 1e-15);
        assert!(TurningPoints::default().measure().is_none());
    }
}
