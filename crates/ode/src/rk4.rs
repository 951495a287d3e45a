//! The classical fourth-order Runge–Kutta method (Kutta 1901; Hairer, Nørsett & Wanner, *Solving ODEs I*,
//! §II.1, Table 1.2), fixed step, with cubic Hermite dense output.

use super::fixed::FixedSteps;
use super::{OdeSystem, StepError, Stepper, StepperState};

/// Classical RK4 with a fixed step `h`. The last step is shortened to land on `t_limit`.
#[derive(Debug, Clone)]
pub struct Rk4<const N: usize> {
    steps: FixedSteps<N>,
}

impl<const N: usize> Rk4<N> {
    /// A stepper with fixed step `h` (> 0).
    #[must_use]
    pub fn new(h: f64) -> Self {
        Self {
            steps: FixedSteps::new(h),
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
        self.steps.start(sys, t0, y0)
    }

    fn step<S: OdeSystem<N>>(&mut self, sys: &S, t_limit: f64) -> Result<(), StepError> {
        let end = self.steps.next_end(t_limit);
        let (t, y, k1) = (self.steps.state.t, &self.steps.state.y, &self.steps.f);
        let h = end.0 - t;
        let stage = |dt: f64, k_previous: &[f64; N], k: &mut [f64; N]| {
            let mut y_stage = [0.0; N];
            for i in 0..N {
                y_stage[i] = y[i] + dt * k_previous[i];
            }
            sys.rhs(t + dt, &y_stage, k);
        };
        let mut k2 = [0.0; N];
        let mut k3 = [0.0; N];
        let mut k4 = [0.0; N];
        stage(0.5 * h, k1, &mut k2);
        stage(0.5 * h, &k2, &mut k3);
        stage(h, &k3, &mut k4);
        let mut y_new = [0.0; N];
        for i in 0..N {
            y_new[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        self.steps.state.stats.rhs_evaluations += 3;
        self.steps.accept(sys, end, &y_new)
    }

    fn state(&self) -> &StepperState<N> {
        &self.steps.state
    }
    fn interpolate(&self, t: f64, out: &mut [f64; N]) {
        self.steps.interpolate(t, out);
    }
}
