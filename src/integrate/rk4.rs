//! The classical fourth-order Runge–Kutta method (Kutta 1901; Hairer, Nørsett & Wanner, *Solving ODEs I*,
//! §II.1, Table 1.2), fixed step, with cubic Hermite dense output.

use super::{all_finite, hermite_interpolate, OdeSystem, Stats, StepError, Stepper};

/// Classical RK4 with a fixed step `h`. The last step is shortened to land on `t_limit`.
#[derive(Debug, Clone)]
pub struct Rk4<const N: usize> {
    h: f64,
    t0: f64,
    n: u64,
    t: f64,
    t_prev: f64,
    y: [f64; N],
    f: [f64; N],
    y_prev: [f64; N],
    f_prev: [f64; N],
    stats: Stats,
}

impl<const N: usize> Rk4<N> {
    /// A stepper with fixed step `h` (> 0).
    #[must_use]
    pub fn new(h: f64) -> Self {
        Self {
            h,
            t0: 0.0,
            n: 0,
            t: 0.0,
            t_prev: 0.0,
            y: [0.0; N],
            f: [0.0; N],
            y_prev: [0.0; N],
            f_prev: [0.0; N],
            stats: Stats::default(),
        }
    }
}

impl<const N: usize> Stepper<N> for Rk4<N> {
    fn init<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
        _t_end: f64,
    ) -> Result<(), StepError> {
        self.t0 = t0;
        self.n = 0;
        self.t = t0;
        self.t_prev = t0;
        self.y = *y0;
        self.y_prev = *y0;
        sys.rhs(t0, y0, &mut self.f);
        self.f_prev = self.f;
        self.stats = Stats {
            rhs_evaluations: 1,
            ..Stats::default()
        };
        if all_finite(y0) && all_finite(&self.f) {
            Ok(())
        } else {
            Err(StepError::NonFinite { t: t0 })
        }
    }

    fn step<S: OdeSystem<N>>(&mut self, sys: &S, t_limit: f64) -> Result<(), StepError> {
        // Times as t0 + n·h (not accumulated) so that fixed steps land exactly on the sample grid.
        #[allow(clippy::cast_precision_loss)]
        let mut t_new = self.t0 + (self.n + 1) as f64 * self.h;
        let mut full = true;
        if t_new > t_limit {
            t_new = t_limit;
            full = false;
        }
        let h = t_new - self.t;
        let (t, y) = (self.t, &self.y);
        let k1 = &self.f;
        let mut k2 = [0.0; N];
        let mut k3 = [0.0; N];
        let mut k4 = [0.0; N];
        let mut tmp = [0.0; N];
        for i in 0..N {
            tmp[i] = y[i] + 0.5 * h * k1[i];
        }
        sys.rhs(t + 0.5 * h, &tmp, &mut k2);
        for i in 0..N {
            tmp[i] = y[i] + 0.5 * h * k2[i];
        }
        sys.rhs(t + 0.5 * h, &tmp, &mut k3);
        for i in 0..N {
            tmp[i] = y[i] + h * k3[i];
        }
        sys.rhs(t + h, &tmp, &mut k4);
        let mut y_new = [0.0; N];
        for i in 0..N {
            y_new[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        let mut f_new = [0.0; N];
        sys.rhs(t_new, &y_new, &mut f_new);
        self.stats.rhs_evaluations += 4;
        if !(all_finite(&y_new) && all_finite(&f_new)) {
            return Err(StepError::NonFinite { t });
        }
        self.t_prev = t;
        self.y_prev = self.y;
        self.f_prev = self.f;
        self.t = t_new;
        self.y = y_new;
        self.f = f_new;
        if full {
            self.n += 1;
        }
        self.stats.steps += 1;
        Ok(())
    }

    fn t(&self) -> f64 {
        self.t
    }
    fn y(&self) -> &[f64; N] {
        &self.y
    }
    fn t_previous(&self) -> f64 {
        self.t_prev
    }
    fn interpolate(&self, t: f64, out: &mut [f64; N]) {
        hermite_interpolate(
            self.t_prev,
            self.t - self.t_prev,
            &self.y_prev,
            &self.f_prev,
            &self.y,
            &self.f,
            t,
            out,
        );
    }
    fn stats(&self) -> Stats {
        self.stats
    }
}
