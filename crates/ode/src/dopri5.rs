//! DOPRI5: the explicit embedded Runge–Kutta pair 5(4) of Dormand & Prince (J. Comp. Appl. Math. 6, 1980,
//! 19–26) with the step-size control, Lund (PI) stabilisation, initial step and 4th-order continuous
//! extension of Hairer's `dopri5.f` (Hairer, Nørsett & Wanner, *Solving ODEs I*, 2nd ed., §II.4–II.6,
//! Table 5.2 and the dense output of §II.6, eq. (6.12)).

use super::control::{combine, cubic_dense_output, AdaptiveSteps, Controller};
use super::{all_finite, Method, OdeSystem, StepError, Stepper, StepperState};

/// Nodes cᵢ (HNW I, Table 5.2).
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];

/// Rows of the Runge–Kutta matrix as (stage index, aᵢⱼ); row 6 is the 5th-order solution b (FSAL).
const A: [&[(usize, f64)]; 7] = [
    &[],
    &[(0, 1.0 / 5.0)],
    &[(0, 3.0 / 40.0), (1, 9.0 / 40.0)],
    &[(0, 44.0 / 45.0), (1, -56.0 / 15.0), (2, 32.0 / 9.0)],
    &[
        (0, 19372.0 / 6561.0),
        (1, -25360.0 / 2187.0),
        (2, 64448.0 / 6561.0),
        (3, -212.0 / 729.0),
    ],
    &[
        (0, 9017.0 / 3168.0),
        (1, -355.0 / 33.0),
        (2, 46732.0 / 5247.0),
        (3, 49.0 / 176.0),
        (4, -5103.0 / 18656.0),
    ],
    &[
        (0, 35.0 / 384.0),
        (2, 500.0 / 1113.0),
        (3, 125.0 / 192.0),
        (4, -2187.0 / 6784.0),
        (5, 11.0 / 84.0),
    ],
];

/// Error estimator b − b̂ (5th minus 4th order), over stages 1..7 (`e1..e7` of `dopri5.f`).
const E: [(usize, f64); 6] = [
    (0, 71.0 / 57600.0),
    (2, -71.0 / 16695.0),
    (3, 71.0 / 1920.0),
    (4, -17253.0 / 339200.0),
    (5, 22.0 / 525.0),
    (6, -1.0 / 40.0),
];

/// Dense output coefficients `d1..d7` of `dopri5.f` (Shampine's 4th-order continuous extension).
const D: [(usize, f64); 6] = [
    (0, -12715105075.0 / 11282082432.0),
    (2, 87487479700.0 / 32700410799.0),
    (3, -10690763975.0 / 1880347072.0),
    (4, 701980252875.0 / 199316789632.0),
    (5, -1453857185.0 / 822651844.0),
    (6, 69997945.0 / 29380423.0),
];

/// Step controller of `dopri5.f`: safety 0.9, step ratio in [0.2, 10], β = 0.04, exponent 1/5 − 0.75β.
const CONTROLLER: Controller = Controller {
    safety: 0.9,
    min_ratio: 0.2,
    max_ratio: 10.0,
    exponent: 0.2 - 0.04 * 0.75,
    beta: 0.04,
};

/// The Dormand–Prince 5(4) pair with error control and 4th-order dense output.
#[derive(Debug, Clone)]
pub struct Dopri5<const N: usize> {
    steps: AdaptiveSteps<N>,
    /// f(t, y), the FSAL stage.
    f: [f64; N],
    /// Coefficients r₁..r₅ of the continuous extension over the last step (`rcont` of `dopri5.f`).
    dense: [[f64; N]; 5],
}

impl<const N: usize> Dopri5<N> {
    /// A stepper keeping the local error per step below atol + rtol·|y| (in Hairer's RMS norm).
    #[must_use]
    pub fn new(rtol: f64, atol: f64) -> Self {
        Self {
            steps: AdaptiveSteps::new(CONTROLLER, rtol, atol),
            f: [0.0; N],
            dense: [[0.0; N]; 5],
        }
    }
}

impl<const N: usize> Stepper<N> for Dopri5<N> {
    fn init<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
        t_end: f64,
    ) -> Result<(), StepError> {
        self.dense = [[0.0; N]; 5];
        self.dense[0] = *y0;
        self.steps
            .start(sys, (t0, y0), t_end, &mut self.f, Method::Dopri5.order())
    }

    fn step<S: OdeSystem<N>>(&mut self, sys: &S, t_limit: f64) -> Result<(), StepError> {
        let mut k = [[0.0; N]; 7];
        let mut y_stage = [0.0; N];
        let mut non_finite = false;
        let y = self.steps.state.y;
        loop {
            let Some((h, t_new)) = self.steps.trial(t_limit, non_finite)? else {
                return Ok(());
            };

            k[0] = self.f;
            for s in 1..7 {
                combine(&y, h, A[s], &k, &mut y_stage);
                let t_stage = if s == 6 {
                    t_new
                } else {
                    self.steps.state.t + C[s] * h
                };
                sys.rhs(t_stage, &y_stage, &mut k[s]);
            }
            // y_stage now holds the 5th-order solution at t_new, k[6] = f(t_new, y_new) (FSAL).
            self.steps.state.stats.rhs_evaluations += 6;

            let mut err = 0.0;
            for i in 0..N {
                let sk = self.steps.weight(y[i], y_stage[i]);
                let e: f64 = E.iter().map(|&(j, e)| e * k[j][i]).sum();
                err += (h * e / sk).powi(2);
            }
            #[allow(clippy::cast_precision_loss)]
            let err = (err / N as f64).sqrt();

            if !err.is_finite() || !all_finite(&y_stage) || !all_finite(&k[6]) {
                non_finite = true;
                self.steps.reject(h, None);
                continue;
            }
            if err > 1.0 {
                self.steps.reject(h, Some(err));
                continue;
            }

            // Accepted: continuous extension (dopri5.f, after label 'dense output').
            cubic_dense_output(h, &y, &k[0], &y_stage, &k[6], &mut self.dense);
            for (i, r4) in self.dense[4].iter_mut().enumerate() {
                *r4 = h * D.iter().map(|&(j, d)| d * k[j][i]).sum::<f64>();
            }
            self.steps.accept(h, err, (t_new, &y_stage));
            self.f = k[6];
            return Ok(());
        }
    }

    fn state(&self) -> &StepperState<N> {
        &self.steps.state
    }
    fn interpolate(&self, t: f64, out: &mut [f64; N]) {
        let r = &self.dense;
        self.steps.interpolate(r, t, out, |i, _, _| r[4][i]);
    }
}
