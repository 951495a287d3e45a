//! `constraint`: the coin rolls without slipping. The centre's velocity is taken from the stored positions
//! by an 8th-order central finite difference over 9 equally spaced samples and compared with the rolling
//! constraint's v = a(−ω_Z e_X + ω_X e_Z) from the stored ω and angles (physics §2):
//! ẋ = a(−ω_Z cos φ + ω_X cos θ sin φ), ż = a(ω_Z sin φ + ω_X cos θ cos φ), ẏ = −a ω_X sin θ.
//! The residual is max|v_fd − v| / (a max|ω|).
//!
//! The difference's truncation error is h⁸ x⁽⁹⁾/630; positions move with the heading rate φ̇ and the rates
//! in ω, so with Ω = max(|ω|, |φ̇|) over the window it is about (hΩ)⁸/630 relative to the velocity. Windows
//! where 4 (hΩ)⁸/630 exceeds a tenth of the tolerance are not resolved by the sampling and are left out (and
//! counted); if none is resolved the check is skipped and says so.

use super::{fmt_num, Max};
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;
use crate::verify::tolerances::Tolerances;
use nalgebra::Vector3;

/// Central difference weights for f′(0)·h at offsets 1..4 (antisymmetric), 8th order.
const WEIGHTS: [f64; 4] = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
/// Window length.
const WINDOW: usize = 9;
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

/// Running state of the constraint check.
#[derive(Debug, Clone)]
pub struct ConstraintCheck {
    window: [Entry; WINDOW],
    len: usize,
    max_omega: f64,
    buckets: [Bucket; DECADES + 1],
    samples: u64,
    irregular: u64,
    min_h: f64,
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
        }
    }
}

impl ConstraintCheck {
    /// Accounts for one sample.
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
        let omega = Vector3::new(w.x, w.y, w.z).norm();
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
        let residual = d / h - centre.velocity;
        let rate = win.iter().map(|e| e.rate).fold(0.0, f64::max);
        let truncation = TRUNCATION_SAFETY * (h * rate).powi(8) / 630.0;
        let decade = if truncation > 0.0 {
            (-truncation.log10()).floor().clamp(0.0, DECADES as f64) as usize
        } else {
            DECADES
        };
        let bucket = &mut self.buckets[decade];
        bucket.windows += 1;
        bucket.residual.offer(residual.norm(), centre.t);
    }

    /// The result.
    #[must_use]
    pub fn finish(&self, a: f64, tol: &Tolerances) -> CheckResult {
        if self.samples < WINDOW as u64 {
            return CheckResult::skip(
                CheckId::Constraint,
                format!(
                    "needs {WINDOW} consecutive samples with /coin/position, /coin/omega and /coin/angles; found {}",
                    self.samples
                ),
            );
        }
        // Bucket d holds windows with truncation in (10^-(d+1), 10^-d]; resolved when 10^-d ≤ tol/10.
        let limit = tol.residual * RESOLVED_FRACTION;
        let mut used = 0;
        let mut skipped = 0;
        let mut residual = Max::default();
        for (d, b) in self.buckets.iter().enumerate() {
            let upper = 10f64.powi(-(d as i32));
            if upper <= limit || d == DECADES {
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
                    "the sampling does not resolve the motion: at h = {} the finite difference's truncation error (h·max(|ω|, |φ̇|))^8/630 exceeds a tenth of the tolerance {} in all {skipped} windows; record at a higher --rate",
                    fmt_num(self.min_h),
                    fmt_num(tol.residual)
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
