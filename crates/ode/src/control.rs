//! Pieces shared by the adaptive embedded pairs ([`Dopri5`](super::Dopri5), [`Dop853`](super::Dop853)):
//! the mixed error norm, the initial step guess, the step-size controller of Hairer's codes
//! (Hairer, Nørsett & Wanner, *Solving ODEs I*, 2nd ed., §II.4 and the Fortran `dopri5.f` / `dop853.f`),
//! the step bookkeeping around the stages ([`StepSize`]), the tableau row sum and the cubic part of
//! the continuous extension.

use super::{OdeSystem, Stats, StepError};

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

/// Per-component error weight sk = atol + rtol·max(|y₀ᵢ|, |y₁ᵢ|) (HNW I, eq. (4.10)).
#[inline]
pub(crate) fn weight(rtol: f64, atol: f64, y0: f64, y1: f64) -> f64 {
    atol + rtol * y0.abs().max(y1.abs())
}

/// True when `h` is too small to advance `t`: 0.1·|h| ≤ ε·|t|, or h is not a positive finite number.
#[inline]
pub(crate) fn step_underflows(t: f64, h: f64) -> bool {
    !(h > 0.0 && h.is_finite()) || UNDERFLOW_FACTOR * h <= t.abs() * f64::EPSILON
}

/// Step-size controller parameters of Hairer's codes: new step h·min(1/fac_min, max(1/fac_max,
/// err^expo / err_old^β / safety)) with expo = 1/(q+1) − 0.75·β·(stabilisation) as in `dopri5.f`/`dop853.f`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Controller {
    /// Safety factor (0.9 in both codes).
    pub safety: f64,
    /// Smallest ratio new/old step (0.2 dopri5, 0.333 dop853).
    pub min_ratio: f64,
    /// Largest ratio new/old step (10 dopri5, 6 dop853).
    pub max_ratio: f64,
    /// Exponent applied to the current error, 1/(q+1) − (stabilisation)·β.
    pub exponent: f64,
    /// Lund stabilisation β (0.04 dopri5, 0 dop853).
    pub beta: f64,
}

/// Smallest remembered error, so the Lund factor cannot explode after a zero-error step (`facold`).
const MIN_OLD_ERROR: f64 = 1e-4;

/// State of the controller between steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ControllerState {
    /// Error of the last accepted step (`facold`).
    pub old_error: f64,
    /// The last attempt was rejected: do not grow the step after the next acceptance.
    pub rejected: bool,
}

impl Default for ControllerState {
    fn default() -> Self {
        Self {
            old_error: MIN_OLD_ERROR,
            rejected: false,
        }
    }
}

impl Controller {
    /// New step after an accepted step of size `h` with scaled error `err` (≤ 1).
    pub fn accepted(&self, state: &mut ControllerState, h: f64, err: f64, h_max: f64) -> f64 {
        let fac11 = err.powf(self.exponent);
        let fac = fac11 / state.old_error.powf(self.beta);
        let fac = (fac / self.safety).clamp(1.0 / self.max_ratio, 1.0 / self.min_ratio);
        let mut h_new = (h / fac).min(h_max);
        if state.rejected {
            h_new = h_new.min(h);
        }
        state.old_error = err.max(MIN_OLD_ERROR);
        state.rejected = false;
        h_new
    }

    /// New step after a rejected step of size `h` with scaled error `err` (> 1).
    pub fn rejected(&self, state: &mut ControllerState, h: f64, err: f64) -> f64 {
        let fac11 = err.powf(self.exponent);
        state.rejected = true;
        h / (fac11 / self.safety).min(1.0 / self.min_ratio)
    }
}

/// Initial step of HNW I, §II.4 (`hinit` in `dopri5.f`/`dop853.f`) for a method of order `order`:
/// h₀ = 0.01·‖y₀‖/‖f₀‖, one explicit Euler step to estimate ‖y''‖, then h = min(100·h₀, (0.01/max(‖f₀‖,
/// ‖y''‖))^(1/order), h_max). Costs one right-hand side evaluation. Returns a positive finite step.
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_step<const N: usize, S: OdeSystem<N>>(
    sys: &S,
    t0: f64,
    y0: &[f64; N],
    f0: &[f64; N],
    order: i32,
    rtol: f64,
    atol: f64,
    h_max: f64,
) -> f64 {
    let mut dnf = 0.0;
    let mut dny = 0.0;
    for i in 0..N {
        let sk = weight(rtol, atol, y0[i], y0[i]);
        dnf += (f0[i] / sk).powi(2);
        dny += (y0[i] / sk).powi(2);
    }
    let mut h = if dnf <= HINIT_TINY_NORM || dny <= HINIT_TINY_NORM {
        HINIT_FALLBACK_STEP
    } else {
        (dny / dnf).sqrt() * HINIT_TARGET
    };
    h = h.min(h_max);
    let mut y1 = [0.0; N];
    for i in 0..N {
        y1[i] = y0[i] + h * f0[i];
    }
    let mut f1 = [0.0; N];
    sys.rhs(t0 + h, &y1, &mut f1);
    let mut der2 = 0.0;
    for i in 0..N {
        let sk = weight(rtol, atol, y0[i], y0[i]);
        der2 += ((f1[i] - f0[i]) / sk).powi(2);
    }
    let der2 = der2.sqrt() / h;
    let der12 = der2.abs().max(dnf.sqrt());
    let h1 = if der12 <= HINIT_TINY_DERIVATIVE {
        HINIT_FALLBACK_STEP.max(h * 1e-3)
    } else {
        (HINIT_TARGET / der12).powf(1.0 / f64::from(order))
    };
    let h = (100.0 * h).min(h1).min(h_max);
    if h.is_finite() && h > 0.0 {
        h
    } else {
        // f(t0 + h, y1) was not finite: start small and let the controller (and its non-finite
        // rejections) find a workable step.
        HINIT_FALLBACK_STEP.min(h_max)
    }
}

/// The step size of an adaptive pair between steps, and what both pairs do around their stages: the
/// trial step towards `t_limit`, the underflow test, and the new step after a rejection or an acceptance.
#[derive(Debug, Clone)]
pub(crate) struct StepSize {
    controller: Controller,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Cap on the step set by the user, if any.
    max_step: Option<f64>,
    /// Cap on the step in this run: `max_step` or the whole span.
    h_max: f64,
    /// Next step to try.
    h: f64,
    control: ControllerState,
}

impl StepSize {
    /// Not started yet.
    pub fn new(controller: Controller, rtol: f64, atol: f64) -> Self {
        Self {
            controller,
            rtol,
            atol,
            max_step: None,
            h_max: f64::INFINITY,
            h: 0.0,
            control: ControllerState::default(),
        }
    }

    /// Caps the step size (default: the whole span t_end − t0).
    pub fn set_max_step(&mut self, max_step: f64) {
        self.max_step = Some(max_step);
    }

    /// Resets the controller for a run from `t0` to `t_end`.
    pub fn start(&mut self, t0: f64, t_end: f64) {
        self.control = ControllerState::default();
        self.h_max = self
            .max_step
            .unwrap_or(f64::INFINITY)
            .min((t_end - t0).abs());
    }

    /// Sets the first step by [`initial_step`] for a method of order `order` (one right-hand side
    /// evaluation).
    pub fn guess_first_step<const N: usize, S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
        f0: &[f64; N],
        order: i32,
    ) {
        self.h = initial_step(sys, t0, y0, f0, order, self.rtol, self.atol, self.h_max);
    }

    /// The next trial step from `t` as (h, t_new), or `None` when `t` has reached `t_limit`. A step
    /// within 1 % of `t_limit` is stretched to end exactly there.
    ///
    /// # Errors
    /// When the step no longer advances `t`: [`StepError::NonFinite`] if non-finite trials shrank it
    /// (`non_finite`), [`StepError::StepSizeUnderflow`] otherwise.
    #[inline]
    pub fn trial(
        &self,
        t: f64,
        t_limit: f64,
        non_finite: bool,
    ) -> Result<Option<(f64, f64)>, StepError> {
        let remaining = t_limit - t;
        if remaining <= 0.0 {
            return Ok(None);
        }
        if step_underflows(t, self.h) {
            return Err(if non_finite {
                StepError::NonFinite { t }
            } else {
                StepError::StepSizeUnderflow { t, h: self.h }
            });
        }
        Ok(Some(if t + LAST_STEP_STRETCH * self.h >= t_limit {
            (remaining, t_limit)
        } else {
            (self.h, t + self.h)
        }))
    }

    /// The trial step `h` produced non-finite values: shrink it and count the rejection.
    #[inline]
    pub fn reject_non_finite(&mut self, h: f64, stats: &mut Stats) {
        stats.rejected_steps += 1;
        self.control.rejected = true;
        self.h = h * NON_FINITE_SHRINK;
    }

    /// The trial step `h` had scaled error `err` > 1: the controller shrinks it; count the rejection.
    #[inline]
    pub fn reject(&mut self, h: f64, err: f64, stats: &mut Stats) {
        stats.rejected_steps += 1;
        self.h = self.controller.rejected(&mut self.control, h, err);
    }

    /// The step `h` was accepted with scaled error `err` ≤ 1: the controller picks the next one.
    #[inline]
    pub fn accept(&mut self, h: f64, err: f64) {
        self.h = self
            .controller
            .accepted(&mut self.control, h, err, self.h_max);
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

/// Where `t` lies in the step of size `h` starting at `t_start`, as a fraction (0 for an empty step).
#[inline]
pub(crate) fn step_fraction(t: f64, t_start: f64, h: f64) -> f64 {
    if h == 0.0 {
        0.0
    } else {
        (t - t_start) / h
    }
}
