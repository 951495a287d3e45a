//! What the fixed-step methods ([`Rk4`](super::Rk4), [`Gauss4`](super::Gauss4)) share: the step clock
//! t0 + n·h and the two ends of the last accepted step with their derivatives, from which the cubic
//! Hermite dense output interpolates.

use super::{all_finite, OdeSystem, StepError, StepperState};

/// Clock and last step of a fixed-step method. Only the stages differ between methods: they read the
/// start of the step (`state.t`, `state.y`, `f`), and hand the new state to [`FixedSteps::accept`].
#[derive(Debug, Clone)]
pub(crate) struct FixedSteps<const N: usize> {
    h: f64,
    /// Start of the run.
    t0: f64,
    /// Full steps taken since `t0`.
    n: u64,
    pub state: StepperState<N>,
    /// f(t, y).
    pub f: [f64; N],
    /// State at `t_prev`.
    y_prev: [f64; N],
    /// f(t_prev, y_prev).
    f_prev: [f64; N],
}

impl<const N: usize> FixedSteps<N> {
    /// Not started yet; step `h` (> 0).
    pub fn new(h: f64) -> Self {
        Self {
            h,
            t0: 0.0,
            n: 0,
            state: StepperState::start(0.0, &[0.0; N]),
            f: [0.0; N],
            y_prev: [0.0; N],
            f_prev: [0.0; N],
        }
    }

    /// Starts the clock at `t0` with state `y0`, evaluating f(t0, y0) (one right-hand side evaluation);
    /// [`StepError::NonFinite`] if y0 or f(t0, y0) is not finite.
    pub fn start<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
    ) -> Result<(), StepError> {
        self.t0 = t0;
        self.n = 0;
        self.state = StepperState::start(t0, y0);
        self.y_prev = *y0;
        sys.rhs(t0, y0, &mut self.f);
        self.state.stats.rhs_evaluations += 1;
        self.f_prev = self.f;
        if all_finite(y0) && all_finite(&self.f) {
            Ok(())
        } else {
            Err(StepError::NonFinite { t: t0 })
        }
    }

    /// End of the next step and whether it is a full one: t0 + (n + 1)·h, or `t_limit` if that comes
    /// first. Times are t0 + n·h (not accumulated) so that fixed steps land exactly on the sample grid.
    #[inline]
    pub fn next_end(&self, t_limit: f64) -> (f64, bool) {
        #[allow(clippy::cast_precision_loss)]
        let t_new = self.t0 + (self.n + 1) as f64 * self.h;
        if t_new > t_limit {
            (t_limit, false)
        } else {
            (t_new, true)
        }
    }

    /// Accepts the step to (`t_new`, `y_new`) returned by [`FixedSteps::next_end`], evaluating
    /// f(t_new, y_new) (one right-hand side evaluation, counted); [`StepError::NonFinite`] (at the start
    /// of the step, which is kept) if y_new or its derivative is not finite.
    #[inline]
    pub fn accept<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        (t_new, full): (f64, bool),
        y_new: &[f64; N],
    ) -> Result<(), StepError> {
        let mut f_new = [0.0; N];
        sys.rhs(t_new, y_new, &mut f_new);
        self.state.stats.rhs_evaluations += 1;
        if !(all_finite(y_new) && all_finite(&f_new)) {
            return Err(StepError::NonFinite { t: self.state.t });
        }
        self.y_prev = self.state.y;
        self.f_prev = self.f;
        self.state.advance(t_new, y_new);
        self.f = f_new;
        if full {
            self.n += 1;
        }
        Ok(())
    }

    /// Cubic Hermite dense output inside the last step (O(h⁴) local error, matching rk4 and gauss4).
    #[inline]
    pub fn interpolate(&self, t: f64, out: &mut [f64; N]) {
        let (t0, y0, f0) = (self.state.t_prev, &self.y_prev, &self.f_prev);
        let (y1, f1) = (&self.state.y, &self.f);
        let h = self.state.t - t0;
        let s = if h == 0.0 { 0.0 } else { (t - t0) / h };
        let s2 = s * s;
        let s3 = s2 * s;
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        for i in 0..N {
            out[i] = h00 * y0[i] + h * h10 * f0[i] + h01 * y1[i] + h * h11 * f1[i];
        }
    }
}
