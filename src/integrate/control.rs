//! Pieces shared by the adaptive embedded pairs ([`Dopri5`](super::Dopri5), [`Dop853`](super::Dop853)):
//! the mixed error norm, the initial step guess and the step-size controller of Hairer's codes
//! (Hairer, Nørsett & Wanner, *Solving ODEs I*, 2nd ed., §II.4 and the Fortran `dopri5.f` / `dop853.f`).

use super::OdeSystem;

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
