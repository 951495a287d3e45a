//! Pieces shared by the adaptive embedded pairs ([`Dopri5`](super::Dopri5), [`Dop853`](super::Dop853)):
//! the mixed error norm, the initial step guess, the step-size controller of Hairer's codes
//! (Hairer, Nørsett & Wanner, *Solving ODEs I*, 2nd ed., §II.4 and the Fortran `dopri5.f` / `dop853.f`),
//! the step bookkeeping around the stages ([`AdaptiveSteps`]), the tableau row sum and the continuous
//! extension.

use super::{all_finite, OdeSystem, StepError, StepperState};

/// Smallest step relative to |t| before a step is declared an underflow: a step with 0.1·|h| ≤ ε·|t|
/// (ε the unit round-off) no longer moves t by more than ~10 ulp, exactly the test of `dop853.f`.
const UNDERFLOW_FACTOR: f64 = 0.1;

/// Threshold of `hinit` below which ‖f₀‖ or ‖y₀‖ count as zero (HNW I, §II.4, p. 169).
const HINIT_TINY_NORM: f64 = 1e-10;
/// Fallback first step of `hinit` when ‖f₀‖ or ‖y₀‖ is tiny.
const HINIT_FALLBACK_STEP: f64 = 1e-6;
/// `hinit`'s target: the first step makes the leading error term about 1 % of the tolerance.
const HINIT_TARGET: f64 = 0.01;
/// `hinit` treats second derivatives below this as zero.
const HINIT_TINY_DERIVATIVE: f64 = 1e-15;

/// Step shrink factor after a trial step produced non-finite values.
const NON_FINITE_SHRINK: f64 = 0.1;

/// A step is stretched by up to this factor to land on `t_limit` instead of leaving a sliver
/// (`dopri5.f`, `dop853.f`).
const LAST_STEP_STRETCH: f64 = 1.01;

/// Smallest remembered error, so the Lund factor cannot explode after a zero-error step (`facold`).
const MIN_OLD_ERROR: f64 = 1e-4;

/// Step-size controller of Hairer's codes (`dopri5.f`, `dop853.f`): new step h / clamp(err^exponent /
/// err_old^β / safety, 1/max_ratio, 1/min_ratio), the ratios bounding new/old step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Controller {
    pub safety: f64,
    pub min_ratio: f64,
    pub max_ratio: f64,
    /// 1/(q+1) − c·β, c = 0.75 in `dopri5.f`, 0.2 in `dop853.f`.
    pub exponent: f64,
    /// Lund stabilisation β.
    pub beta: f64,
}

/// The last accepted step of an adaptive pair, its step size, and all that both pairs do around their
/// stages.
#[derive(Debug, Clone)]
pub(crate) struct AdaptiveSteps<const N: usize> {
    pub state: StepperState<N>,
    controller: Controller,
    rtol: f64,
    atol: f64,
    /// Cap on the step in this run: the whole span.
    h_max: f64,
    /// Next step to try.
    h: f64,
    /// The last accepted step.
    pub h_last: f64,
    /// Error of the last accepted step (`facold`).
    old_error: f64,
    /// The last attempt was rejected: do not grow the step after the next acceptance.
    rejected: bool,
}

impl<const N: usize> AdaptiveSteps<N> {
    /// Not started yet.
    pub fn new(controller: Controller, rtol: f64, atol: f64) -> Self {
        Self {
            state: StepperState::start(0.0, &[0.0; N]),
            controller,
            rtol,
            atol,
            h_max: f64::INFINITY,
            h: 0.0,
            h_last: 0.0,
            old_error: MIN_OLD_ERROR,
            rejected: false,
        }
    }

    /// Starts a run from (t0, y0) to `t_end` for a method of order `order`: resets `state` and the
    /// controller, writes f(t0, y0) into `f0` and guesses the first step (two right-hand side
    /// evaluations); [`StepError::NonFinite`] if y0 or f(t0, y0) is not finite.
    pub fn start<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        (t0, y0): (f64, &[f64; N]),
        t_end: f64,
        f0: &mut [f64; N],
        order: u32,
    ) -> Result<(), StepError> {
        self.state = StepperState::start(t0, y0);
        self.h_last = 0.0;
        self.old_error = MIN_OLD_ERROR;
        self.rejected = false;
        // `min` ignores a NaN span.
        self.h_max = f64::INFINITY.min((t_end - t0).abs());
        sys.rhs(t0, y0, f0);
        self.state.stats.rhs_evaluations += 1;
        if !(all_finite(y0) && all_finite(f0)) {
            return Err(StepError::NonFinite { t: t0 });
        }
        self.h = self.initial_step(sys, t0, y0, f0, order);
        self.state.stats.rhs_evaluations += 1;
        Ok(())
    }

    /// Initial step of HNW I, §II.4 (`hinit` in `dopri5.f`/`dop853.f`) for a method of order `order`:
    /// h₀ = 0.01·‖y₀‖/‖f₀‖, one explicit Euler step to estimate ‖y''‖, then h = min(100·h₀,
    /// (0.01/max(‖f₀‖, ‖y''‖))^(1/order), h_max). Costs one right-hand side evaluation. Returns a
    /// positive finite step.
    fn initial_step<S: OdeSystem<N>>(
        &self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
        f0: &[f64; N],
        order: u32,
    ) -> f64 {
        let mut dnf = 0.0;
        let mut dny = 0.0;
        for i in 0..N {
            let sk = self.weight(y0[i], y0[i]);
            dnf += (f0[i] / sk).powi(2);
            dny += (y0[i] / sk).powi(2);
        }
        let mut h = if dnf <= HINIT_TINY_NORM || dny <= HINIT_TINY_NORM {
            HINIT_FALLBACK_STEP
        } else {
            (dny / dnf).sqrt() * HINIT_TARGET
        };
        h = h.min(self.h_max);
        let mut y1 = [0.0; N];
        for i in 0..N {
            y1[i] = y0[i] + h * f0[i];
        }
        let mut f1 = [0.0; N];
        sys.rhs(t0 + h, &y1, &mut f1);
        let mut der2 = 0.0;
        for i in 0..N {
            let sk = self.weight(y0[i], y0[i]);
            der2 += ((f1[i] - f0[i]) / sk).powi(2);
        }
        let der2 = der2.sqrt() / h;
        let der12 = der2.abs().max(dnf.sqrt());
        let h1 = if der12 <= HINIT_TINY_DERIVATIVE {
            HINIT_FALLBACK_STEP.max(h * 1e-3)
        } else {
            (HINIT_TARGET / der12).powf(1.0 / f64::from(order))
        };
        let h = (100.0 * h).min(h1).min(self.h_max);
        if h.is_finite() && h > 0.0 {
            h
        } else {
            // f(t0 + h, y1) was not finite: start small and let the controller (and its non-finite
            // rejections) find a workable step.
            HINIT_FALLBACK_STEP.min(self.h_max)
        }
    }

    /// Per-component error weight sk = atol + rtol·max(|y₀ᵢ|, |y₁ᵢ|) (HNW I, eq. (4.10)).
    #[inline]
    pub fn weight(&self, y0: f64, y1: f64) -> f64 {
        self.atol + self.rtol * y0.abs().max(y1.abs())
    }

    /// The next trial step from `state.t` as (h, t_new), or `None` when it has reached `t_limit`. A step
    /// within 1 % of `t_limit` is stretched to end exactly there. A step that no longer advances `t`
    /// (0.1·|h| ≤ ε·|t|, or h not positive and finite) is [`StepError::NonFinite`] if non-finite trials
    /// shrank it (`non_finite`), [`StepError::StepSizeUnderflow`] otherwise.
    #[inline]
    pub fn trial(&self, t_limit: f64, non_finite: bool) -> Result<Option<(f64, f64)>, StepError> {
        let t = self.state.t;
        let remaining = t_limit - t;
        if remaining <= 0.0 {
            return Ok(None);
        }
        let h = self.h;
        if !(h > 0.0 && h.is_finite()) || UNDERFLOW_FACTOR * h <= t.abs() * f64::EPSILON {
            return Err(if non_finite {
                StepError::NonFinite { t }
            } else {
                StepError::StepSizeUnderflow { t, h }
            });
        }
        Ok(Some(if t + LAST_STEP_STRETCH * h >= t_limit {
            (remaining, t_limit)
        } else {
            (h, t + h)
        }))
    }

    /// The trial step `h` had scaled error `err` > 1, or (`None`) produced non-finite values: shrink it
    /// and count the rejection.
    #[inline]
    pub fn reject(&mut self, h: f64, err: Option<f64>) {
        self.state.stats.rejected_steps += 1;
        self.rejected = true;
        let c = &self.controller;
        self.h = err.map_or(h * NON_FINITE_SHRINK, |err| {
            h / (err.powf(c.exponent) / c.safety).min(1.0 / c.min_ratio)
        });
    }

    /// The step `h` to (t_new, y_new) was accepted with scaled error `err` ≤ 1: pick the next step and
    /// move `state` there.
    #[inline]
    pub fn accept(&mut self, h: f64, err: f64, (t_new, y_new): (f64, &[f64; N])) {
        let c = &self.controller;
        let fac11 = err.powf(c.exponent);
        let fac = fac11 / self.old_error.powf(c.beta);
        let fac = (fac / c.safety).clamp(1.0 / c.max_ratio, 1.0 / c.min_ratio);
        let mut h_new = (h / fac).min(self.h_max);
        if self.rejected {
            h_new = h_new.min(h);
        }
        self.old_error = err.max(MIN_OLD_ERROR);
        self.rejected = false;
        self.h = h_new;
        self.h_last = h;
        self.state.advance(t_new, y_new);
    }

    /// The continuous extension at `t` in the last step from its coefficients `r` (`contd5`, `contd8`):
    /// r₀ + s(r₁ + s₁(r₂ + s(r₃ + s₁·high))), s the fraction of the step, s₁ = 1 − s, `high(i, s, s1)` the
    /// higher part of component i.
    #[inline]
    pub fn interpolate(
        &self,
        r: &[[f64; N]],
        t: f64,
        out: &mut [f64; N],
        high: impl Fn(usize, f64, f64) -> f64,
    ) {
        let s = if self.h_last == 0.0 {
            0.0
        } else {
            (t - self.state.t_prev) / self.h_last
        };
        let s1 = 1.0 - s;
        for i in 0..N {
            out[i] = r[0][i] + s * (r[1][i] + s1 * (r[2][i] + s * (r[3][i] + s1 * high(i, s, s1))));
        }
    }
}

/// out = y + h·Σⱼ aⱼ·kⱼ over the non-zero entries of one tableau row.
#[inline]
pub(crate) fn combine<const N: usize>(
    y: &[f64; N],
    h: f64,
    row: &[(usize, f64)],
    k: &[[f64; N]],
    out: &mut [f64; N],
) {
    for i in 0..N {
        let mut sum = 0.0;
        for &(j, a) in row {
            sum += a * k[j][i];
        }
        out[i] = y[i] + h * sum;
    }
}

/// The first four coefficients of the continuous extension over a step `h` from (y0, f0) to (y1, f1),
/// the same in `dopri5.f` and `dop853.f` (`rcont1..4`): with the higher rows zero they are the cubic
/// Hermite interpolant.
#[inline]
pub(crate) fn cubic_dense_output<const N: usize>(
    h: f64,
    y0: &[f64; N],
    f0: &[f64; N],
    y1: &[f64; N],
    f1: &[f64; N],
    dense: &mut [[f64; N]],
) {
    for i in 0..N {
        let ydiff = y1[i] - y0[i];
        let bspl = h * f0[i] - ydiff;
        dense[0][i] = y0[i];
        dense[1][i] = ydiff;
        dense[2][i] = bspl;
        dense[3][i] = ydiff - h * f1[i] - bspl;
    }
}
