//! `constraint`: the coin rolls without slipping (format.md: verify, Checks, gives the residual, its
//! correction by Δ⁸v/630 and the windows left out). Whether the sampling resolves a window is still judged
//! by the uncorrected leading term (hΩ)⁸/630, a conservative bound on what the correction leaves, with
//! Ω = r + g + 3 min(√|Δg/h|, g) (see `difference`), not r = max(|ω|, |φ̇|) alone: a coin sinking flat from
//! θ = 1.5 doubled φ̇ every 0.05 time units, and windows judged by r alone erred 30 times beyond the
//! estimate, 2.5e-7 against a tolerance of 2e-7. Ω comes from the stored rates, not from the differences,
//! so that noise in a tampered file cannot make its windows look unresolved.

use super::{fmt_num, Max};
use crate::format::tolerances::Tolerances;
use crate::model::magnitude;
use crate::scene::limits::max_rate;
use crate::scene::MAX_SAMPLES;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use nalgebra::Vector3;

/// Central difference weights for f′(0)·h at offsets 1..4 (antisymmetric), 8th order.
const WEIGHTS: [f64; 4] = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
/// Binomial weights of the eighth central difference over the window, (−1)^k C(8, k).
const EIGHTH_DIFFERENCE: [f64; 9] = [1.0, -8.0, 28.0, -56.0, 70.0, -56.0, 28.0, -8.0, 1.0];
/// The weight of √|Δg/h| in Ω, g the rate's growth: with g alone, windows of a coin braked within a few
/// samples (φ̇ ∝ 1/(t + d)) judged resolved erred by 1.2e-6 against a tolerance of 4e-7.
const SINGULAR_GROWTH: f64 = 3.0;
/// Window length.
pub(crate) const WINDOW: usize = 9;
/// Relative spread of sample intervals accepted as equal spacing.
const SPACING_TOLERANCE: f64 = 1e-6;
/// Safety factor on the truncation estimate (hΩ)⁸/630.
const TRUNCATION_SAFETY: f64 = 4.0;
/// Truncation must stay below this fraction of the tolerance for a window to count.
const RESOLVED_FRACTION: f64 = 0.1;
/// Decades of truncation estimate tracked (1e-40 .. 1e0).
const DECADES: usize = 40;

#[derive(Debug, Clone, Copy, Default)]
struct Entry {
    t: f64,
    /// Stored centre \[length\].
    position: Vector3<f64>,
    /// Centre velocity from the rolling constraint \[length/time\].
    velocity: Vector3<f64>,
    rate: f64,
}

#[derive(Debug, Clone, Copy, Default)]
struct Bucket {
    windows: u64,
    residual: Max,
}

/// The finite difference's truncation error relative to the velocity, estimated as 4 (hΩ)⁸/630 for
/// samples h apart on a motion with rates up to Ω.
#[must_use]
pub fn truncation(h: f64, rate: f64) -> f64 {
    TRUNCATION_SAFETY * (h * rate).powi(8) / 630.0
}

/// The bucket of a truncation estimate: d holds (10^-(d+1), 10^-d], the last one everything smaller.
fn decade(truncation: f64) -> usize {
    if truncation > 0.0 {
        // Clamped to 0..=DECADES first, so the cast neither truncates nor wraps.
        (-truncation.log10()).floor().clamp(0.0, DECADES as f64) as usize
    } else {
        DECADES
    }
}

/// Whether the windows of bucket `d` are resolved at residual tolerance `tol`: 10^-d ≤ tol/10.
fn counts(d: usize, tol: f64) -> bool {
    d == DECADES || 10f64.powi(-i32::try_from(d).unwrap_or(i32::MAX)) <= tol * RESOLVED_FRACTION
}

/// Whether a window of samples h apart on a motion with rates up to Ω counts at residual tolerance
/// `tol` (the rule [`ConstraintCheck::finish`] applies).
#[must_use]
pub fn resolves(h: f64, rate: f64, tol: f64) -> bool {
    counts(decade(truncation(h, rate)), tol)
}

/// The smallest sampling rate (samples per time unit) at which windows on a motion with rates up to Ω
/// count at residual tolerance `tol`; infinite when no rate does.
#[must_use]
pub fn min_rate(rate: f64, tol: f64) -> f64 {
    let Some(d) = (0..=DECADES).find(|d| counts(*d, tol)) else {
        return f64::INFINITY;
    };
    if d == DECADES || rate == 0.0 {
        return 0.0;
    }
    // The largest truncation in bucket d is 10^-d: 4 (hΩ)⁸/630 = 10^-d.
    let largest = 10f64.powi(-i32::try_from(d).unwrap_or(i32::MAX));
    let h = (largest * 630.0 / TRUNCATION_SAFETY).powf(0.125) / rate;
    1.0 / h
}

/// Why no --rate resolves `what` over a recording of `span` when that takes `needed` samples per time unit
/// (shown as `shown`), if none does: samples are at least 1 ns apart (format.md: Keys). verify and record's
/// prediction both advise a higher rate otherwise (`wobble` spinning at ω_Z = 5e8 was told "at least
/// 2.66e9", which record refuses).
pub fn no_rate_resolves(what: &str, needed: f64, shown: &str, span: f64) -> Option<String> {
    let highest = max_rate(span).floor();
    (needed > highest).then(|| {
        format!(
            "no --rate resolves {what}: that takes at least {shown} samples per time unit, and samples 1 ns \
             apart (the log-time resolution) allow at most {highest}; slow the motion, or express the scene \
             in a shorter time unit"
        )
    })
}

/// What a rate of `needed` over `span` takes besides: a shorter --duration, where that many samples pass
/// the most a recording holds ([`MAX_SAMPLES`]), else nothing.
pub fn shorter_duration(needed: f64, span: f64) -> String {
    if needed * span > MAX_SAMPLES {
        let at_most = digits3(MAX_SAMPLES / needed, f64::floor);
        format!(
            " and shorten --duration to at most {at_most} (a recording holds at most {MAX_SAMPLES:e} \
             samples)"
        )
    } else {
        String::new()
    }
}

/// `x` rounded by `round` to 3 significant digits (`f64::ceil` for a rate that is enough).
pub fn digits3(x: f64, round: fn(f64) -> f64) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    let unit = 10f64.powf(x.abs().log10().floor() - 2.0);
    let rounded = round(x / unit) * unit;
    // The product carries the unit's rounding (72.6 came out as 72.60000000000001): the three digits
    // printed and read back are the number meant.
    format!("{rounded:.2e}").parse().unwrap_or(rounded)
}

/// What to record instead at `needed` samples per time unit, over a recording of `span`.
fn rate_advice(needed: f64, span: f64) -> String {
    let shown = fmt_num(needed);
    no_rate_resolves("it", needed, &shown, span).unwrap_or_else(|| {
        let shorter = shorter_duration(needed, span);
        format!("record at a higher --rate (at least {shown}){shorter}")
    })
}

#[derive(Debug, Clone)]
pub struct ConstraintCheck {
    window: [Entry; WINDOW],
    len: usize,
    max_omega: f64,
    buckets: [Bucket; DECADES + 1],
    samples: u64,
    irregular: u64,
    min_h: f64,
    /// The smallest rate Ω of a window: the one the sampling comes closest to resolving.
    min_rate: f64,
}

impl Default for ConstraintCheck {
    fn default() -> Self {
        Self {
            window: [Entry::default(); WINDOW],
            len: 0,
            max_omega: 0.0,
            buckets: [Bucket::default(); DECADES + 1],
            samples: 0,
            irregular: 0,
            min_h: f64::INFINITY,
            min_rate: f64::INFINITY,
        }
    }
}

impl ConstraintCheck {
    pub fn observe(&mut self, s: &Sample, a: f64) {
        let (Some(w), Some(ang), Some(p)) = (s.omega, s.angles, s.position) else {
            self.len = 0;
            return;
        };
        self.samples += 1;
        let (st, ct) = ang.theta.sin_cos();
        let (sp, cp) = ang.phi.sin_cos();
        let velocity = Vector3::new(
            a * (-w.z * cp + w.x * ct * sp),
            -a * w.x * st,
            a * (w.z * sp + w.x * ct * cp),
        );
        let omega = magnitude(w.x, w.y, w.z);
        self.max_omega = self.max_omega.max(omega);
        let entry = Entry {
            t: s.t,
            position: Vector3::new(p.x, p.y, p.z),
            velocity,
            rate: omega.max((w.y / ct).abs()),
        };
        if self.len == WINDOW {
            self.window.copy_within(1.., 0);
            self.len -= 1;
        }
        self.window[self.len] = entry;
        self.len += 1;
        if self.len == WINDOW {
            self.difference();
        }
    }

    fn difference(&mut self) {
        let win = &self.window;
        let h = (win[WINDOW - 1].t - win[0].t) / (WINDOW - 1) as f64;
        let uniform = h > 0.0
            && win
                .windows(2)
                .all(|p| ((p[1].t - p[0].t) - h).abs() <= SPACING_TOLERANCE * h);
        if !uniform {
            self.irregular += 1;
            return;
        }
        self.min_h = self.min_h.min(h);
        let centre = &win[WINDOW / 2];
        let mut d = Vector3::zeros();
        for (j, c) in WEIGHTS.iter().enumerate() {
            d += (win[WINDOW / 2 + j + 1].position - win[WINDOW / 2 - j - 1].position) * *c;
        }
        // The difference's leading error −h⁸x⁽⁹⁾/630 is taken off with the eighth central difference of
        // the constraint's own velocities, Δ⁸v = h⁸v⁽⁸⁾ + O(h¹⁰): what is left is O(h¹⁰) (on sin t at
        // h = 0.1, 1.6e-11 becomes 1e-14), so the residual is the constraint's, not the sampling's. A
        // tampered sample still shows: ω changed at the centre moves it by (1 − 70/630) of its effect.
        let mut d8 = Vector3::zeros();
        for (k, e) in win.iter().enumerate() {
            d8 += e.velocity * EIGHTH_DIFFERENCE[k];
        }
        let residual = d / h + d8 / 630.0 - centre.velocity;
        let rate = win.iter().map(|e| e.rate).fold(0.0, f64::max);
        // The rate's growth g = |Δ ln r|/h between neighbours, and how fast g itself changes: an
        // exponential (a coin leaving the upright) has a constant g and derivatives of order n growing
        // as gⁿ; near a singularity at distance d, g = 1/d grows as 1/d² and the n-th derivative as
        // n!/dⁿ⁺¹, an Ω of about (8!)^(1/8)/d ≈ 3.8/d, which g + 3 √|Δg/h| gives. A smooth wobble of
        // ln r (amplitude A, frequency ν) has g = Aν and |Δg/h| = Aν², whose root would overstate its Ω
        // for small A: the term is held to 3g, which a singularity (|Δg/h| = g²) reaches anyway.
        let mut growth = [0.0; WINDOW - 1];
        for (g, p) in growth.iter_mut().zip(win.windows(2)) {
            if p[0].rate > 0.0 && p[1].rate > 0.0 {
                *g = (p[1].rate / p[0].rate).ln().abs() / h;
            }
        }
        let steepest = growth.iter().copied().fold(0.0, f64::max);
        let bending = growth
            .windows(2)
            .map(|g| (g[1] - g[0]).abs() / h)
            .fold(0.0, f64::max);
        let rate = rate + steepest + SINGULAR_GROWTH * bending.sqrt().min(steepest);
        self.min_rate = self.min_rate.min(rate);
        let bucket = &mut self.buckets[decade(truncation(h, rate))];
        bucket.windows += 1;
        bucket
            .residual
            .offer(magnitude(residual.x, residual.y, residual.z), centre.t);
    }

    #[must_use]
    /// The result over the windows seen, `a` the radius and `span` the recorded span (for the highest
    /// rate a recording that long allows, if a higher one is needed).
    pub fn finish(&self, a: f64, tol: &Tolerances, span: f64) -> CheckResult {
        if self.samples < WINDOW as u64 {
            return CheckResult::skip(
                CheckId::Constraint,
                format!(
                    "needs {WINDOW} consecutive samples with /coin/position, /coin/omega and /coin/angles; found {}{}",
                    self.samples,
                    if self.samples == 0 {
                        ": record the channels omega, angles and position"
                    } else {
                        ""
                    }
                ),
            );
        }
        let mut used = 0;
        let mut skipped = 0;
        let mut residual = Max::default();
        for (d, b) in self.buckets.iter().enumerate() {
            if counts(d, tol.residual) {
                used += b.windows;
                residual.offer(b.residual.value, b.residual.t);
            } else {
                skipped += b.windows;
            }
        }
        if used == 0 {
            return CheckResult::skip(
                CheckId::Constraint,
                format!(
                    "the sampling does not resolve the motion: at h = {} the finite difference's truncation error 4(hΩ)^8/630, Ω = max(|ω|, |φ̇|) + its rate of change, exceeds a tenth of the tolerance {} in all {skipped} windows; {}",
                    fmt_num(self.min_h),
                    fmt_num(tol.residual),
                    rate_advice(min_rate(self.min_rate, tol.residual).ceil(), span)
                ),
            );
        }
        let scale = a * self.max_omega;
        if scale == 0.0 {
            return CheckResult::skip(
                CheckId::Constraint,
                "the coin does not move (ω = 0 throughout)",
            );
        }
        let value = residual.value / scale;
        let mut reason = format!(
            "max|v_fd - a(-ω_Z e_X + ω_X e_Z)|/(a max|ω|) = {} (worst at t = {}) over {used} windows of {WINDOW} samples, h = {}",
            fmt_num(value),
            fmt_num(residual.t),
            fmt_num(self.min_h)
        );
        if skipped > 0 {
            reason.push_str(&format!(
                "; {skipped} windows left out: the sampling does not resolve the motion there"
            ));
        }
        if self.irregular > 0 {
            reason.push_str(&format!(
                "; {} windows with unequal spacing left out",
                self.irregular
            ));
        }
        CheckResult::measured(CheckId::Constraint, value, tol.residual, reason)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rate_whose_samples_a_recording_cannot_hold_comes_with_a_shorter_duration() {
        // 5e8 per time unit over 1000 is 5e11 samples, past the 1e11 a recording holds: the advice names
        // the duration that holds them (200); over 100, 5e10 fit and the rate alone is the advice.
        assert_eq!(
            rate_advice(5e8, 1000.0),
            "record at a higher --rate (at least 5.00e8) and shorten --duration to at most 200 (a \
             recording holds at most 1e11 samples)"
        );
        assert_eq!(
            rate_advice(5e8, 100.0),
            "record at a higher --rate (at least 5.00e8)"
        );
    }

    #[test]
    fn the_eighth_difference_of_the_velocities_cancels_the_differences_leading_error() {
        // x = sin t, v = cos t at h = 0.1: the 8th-order difference errs by −h⁸ x⁽⁹⁾/630 = −1.59e-11; with
        // Δ⁸v/630 added, by O(h¹⁰). Negative control: the uncorrected error is the leading term.
        let h = 0.1;
        let x = |k: f64| (k * h).sin();
        let fd: f64 = WEIGHTS
            .iter()
            .zip(1..)
            .map(|(w, j)| w * (x(f64::from(j)) - x(-f64::from(j))))
            .sum::<f64>()
            / h;
        let d8: f64 = EIGHTH_DIFFERENCE
            .iter()
            .zip(-4..)
            .map(|(c, k)| c * (f64::from(k) * h).cos())
            .sum();
        let leading = -h.powi(8) / 630.0;
        assert!(
            ((fd - 1.0) / leading - 1.0).abs() < 0.01,
            "uncorrected {:e}",
            fd - 1.0
        );
        assert!(
            (fd + d8 / 630.0 - 1.0).abs() < 2e-14,
            "corrected {:e}",
            fd + d8 / 630.0 - 1.0
        );
    }

    #[test]
    fn the_minimum_rate_is_the_edge_of_resolution() {
        // high-spin: Ω = 50 at tolerance 1e-6. Just above the minimum rate a window counts, just below
        // it does not, and the check's own rule (resolves) agrees with the formula.
        let (omega, tol) = (50.0, 1e-6);
        let r = min_rate(omega, tol);
        println!("minimum rate {r} for Ω = {omega}, tolerance {tol}");
        assert!(resolves(1.0 / (r * 1.0001), omega, tol));
        assert!(!resolves(1.0 / (r * 0.9999), omega, tol));
        // hΩ = 0.5 (rate 100) is far from resolved; the default rate of 1000 is resolved.
        assert!(!resolves(0.01, omega, tol));
        assert!(resolves(0.001, omega, tol));
    }
}
