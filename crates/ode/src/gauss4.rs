//! The 2-stage Gauss–Legendre collocation method (Butcher 1964; Hairer, Lubich & Wanner, *Geometric
//! Numerical Integration*, 2nd ed., §II.1.3, Table 1.1 and §VIII.5–6 for solving the stage equations):
//! order 4, symmetric, symplectic, A-stable. Fixed step, landing on t0 + n·h like [`Rk4`](super::Rk4),
//! with cubic Hermite dense output.
//!
//! The stage equations Zᵢ = h·Σⱼ aᵢⱼ f(t + cⱼh, y + Zⱼ) are solved to round-off by simplified Newton
//! iterations with the matrix I − h·(A ⊗ J), J a finite-difference Jacobian. J and the LU factors are
//! kept across steps while the iteration contracts quickly, and refreshed when it slows down or the step
//! changes; the iteration starts from the previous step's collocation polynomial. Symmetry (and hence
//! the bounded energy error) needs the stage equations solved to round-off, not to a tolerance.

// Index loops over stages and components read like the formulas (Zᵢ, aᵢⱼ, J[i][j]).
#![allow(clippy::needless_range_loop)]

use super::fixed::FixedSteps;
use super::{OdeSystem, StepError, Stepper, StepperState};
use nalgebra::{DMatrix, DVector, Dyn, SMatrix, LU};

/// √3/6, the half-distance of the Gauss nodes from 1/2.
const SQRT3_6: f64 = 0.288_675_134_594_812_882_254_574_390_250_978_7;

/// √3.
const SQRT3: f64 = 1.732_050_807_568_877_293_527_446_341_505_872_4;

/// Nodes c = 1/2 ∓ √3/6.
const C: [f64; 2] = [0.5 - SQRT3_6, 0.5 + SQRT3_6];

/// Runge–Kutta matrix A = [[1/4, 1/4 − √3/6], [1/4 + √3/6, 1/4]] (weights b = [1/2, 1/2]).
const A: [[f64; 2]; 2] = [[0.25, 0.25 - SQRT3_6], [0.25 + SQRT3_6, 0.25]];

/// Most Newton iterations per attempt; with a fresh Jacobian the iteration gains several digits each
/// time, so this is only reached when the step is far too large for the problem.
const MAX_ITERATIONS: u32 = 30;

/// Round-off plateau: once the scaled correction is below this and stops decreasing, the stage values
/// are as accurate as floating point allows.
const ROUND_OFF_PLATEAU: f64 = 1e-12;

/// Extrapolate the previous step's polynomial only over at most this many of its steps.
const MAX_EXTRAPOLATION_RATIO: f64 = 2.0;

/// A contraction rate above this marks the Jacobian stale; it is recomputed at the next step.
const SLOW_CONTRACTION: f64 = 0.01;

/// Relative finite-difference increment for the Jacobian: √ε balances truncation and round-off.
const JACOBIAN_INCREMENT: f64 = 1.490_116_119_384_765_6e-8;

/// 2-stage Gauss–Legendre with a fixed step `h`. The last step is shortened to land on `t_limit`.
#[derive(Debug, Clone)]
pub struct Gauss4<const N: usize> {
    steps: FixedSteps<N>,
    /// Stage increments of the last accepted step, to extrapolate the next step's starting guess.
    z_last: [[f64; N]; 2],
    /// Step of `z_last` (0 when there is none).
    h_z_last: f64,
    /// Jacobian J ≈ ∂f/∂y.
    jacobian: SMatrix<f64, N, N>,
    jacobian_stale: bool,
    /// LU factors (partial pivoting) of I − h·(A ⊗ J), built for step `h_lu`. 2N×2N is a run-time size:
    /// a fixed-size `SMatrix` of 2N rows cannot be named for a generic `N` on stable Rust.
    lu: Option<LU<f64, Dyn, Dyn>>,
    h_lu: f64,
    /// Newton right-hand side / correction, length 2N.
    work: DVector<f64>,
}

impl<const N: usize> Gauss4<N> {
    /// A stepper with fixed step `h` (> 0).
    #[must_use]
    pub fn new(h: f64) -> Self {
        Self {
            steps: FixedSteps::new(h),
            z_last: [[0.0; N]; 2],
            h_z_last: 0.0,
            jacobian: SMatrix::zeros(),
            jacobian_stale: true,
            lu: None,
            h_lu: 0.0,
            work: DVector::zeros(2 * N),
        }
    }

    /// J ≈ ∂f/∂y at (t, y) by forward differences from the known f(t, y); N evaluations.
    fn update_jacobian<S: OdeSystem<N>>(&mut self, sys: &S) {
        let (t, y0) = (self.steps.state.t, self.steps.state.y);
        let mut y = y0;
        let mut f = [0.0; N];
        for j in 0..N {
            let delta = JACOBIAN_INCREMENT * y0[j].abs().max(1.0);
            y[j] = y0[j] + delta;
            let delta = y[j] - y0[j]; // the increment actually representable
            sys.rhs(t, &y, &mut f);
            for i in 0..N {
                self.jacobian[(i, j)] = (f[i] - self.steps.f[i]) / delta;
            }
            y[j] = y0[j];
        }
        self.steps.state.stats.rhs_evaluations += N as u64;
        self.jacobian_stale = false;
        self.h_lu = 0.0;
    }

    /// LU factors (partial pivoting) of I − h·(A ⊗ J). Returns false if the matrix is singular or the
    /// factors are not finite.
    fn factor(&mut self, h: f64) -> bool {
        self.lu = None;
        self.h_lu = 0.0;
        // Row (a, i) and column (b, j) of the Kronecker product: stage a, b and component i, j.
        let matrix = DMatrix::from_fn(2 * N, 2 * N, |r, c| {
            let (a, i, b, j) = (r / N, r % N, c / N, c % N);
            let identity = if r == c { 1.0 } else { 0.0 };
            identity - h * A[a][b] * self.jacobian[(i, j)]
        });
        if !matrix.iter().all(|v| v.is_finite()) {
            return false;
        }
        let lu = matrix.lu();
        if !lu.u().diagonal().iter().all(|&d| d != 0.0 && d.is_finite()) {
            return false;
        }
        self.lu = Some(lu);
        self.h_lu = h;
        true
    }

    /// Starting guess for the stage increments: the previous step's collocation polynomial
    /// w(s) (w(0) = 0, w(cᵢ) = Zᵢ, s in units of the previous step) extrapolated,
    /// Zᵢ ≈ w(1 + r·cᵢ) − w(1) with r = h / h_previous; explicit Euler without a previous step.
    fn initial_guess(&self, h: f64) -> [[f64; N]; 2] {
        let ratio = h / self.h_z_last;
        let extrapolate = self.h_z_last > 0.0 && ratio <= MAX_EXTRAPOLATION_RATIO;
        let w = |s: f64, i: usize| {
            self.z_last[0][i] * s * (s - C[1]) / (C[0] * (C[0] - C[1]))
                + self.z_last[1][i] * s * (s - C[0]) / (C[1] * (C[1] - C[0]))
        };
        let mut z = [[0.0; N]; 2];
        for a in 0..2 {
            for i in 0..N {
                z[a][i] = if extrapolate {
                    w(1.0 + ratio * C[a], i) - w(1.0, i)
                } else {
                    C[a] * h * self.steps.f[i]
                };
            }
        }
        z
    }

    /// One simplified Newton solve of the stage equations, improving `z` in place until it is exact to
    /// round-off. On failure returns the iteration count and the last correction norm (NaN: non-finite).
    fn newton<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        h: f64,
        z: &mut [[f64; N]; 2],
    ) -> Result<(), (u32, f64)> {
        let mut stage_f = [[0.0; N]; 2];
        let mut previous_norm = f64::INFINITY;
        let mut y_stage = [0.0; N];
        let (t, y) = (self.steps.state.t, self.steps.state.y);
        for iteration in 1..=MAX_ITERATIONS {
            for a in 0..2 {
                for i in 0..N {
                    y_stage[i] = y[i] + z[a][i];
                }
                sys.rhs(t + C[a] * h, &y_stage, &mut stage_f[a]);
            }
            self.steps.state.stats.rhs_evaluations += 2;
            for a in 0..2 {
                for i in 0..N {
                    let residual =
                        z[a][i] - h * (A[a][0] * stage_f[0][i] + A[a][1] * stage_f[1][i]);
                    self.work[a * N + i] = -residual;
                }
            }
            if !self.work.iter().all(|v| v.is_finite()) {
                return Err((iteration, f64::NAN));
            }
            // `factor` succeeded before every Newton solve, so the factors exist and are invertible.
            let solved = self
                .lu
                .as_ref()
                .is_some_and(|lu| lu.solve_mut(&mut self.work));
            if !solved {
                return Err((iteration, f64::INFINITY));
            }
            let mut norm = 0.0_f64;
            for a in 0..2 {
                for i in 0..N {
                    let dz = self.work[a * N + i];
                    z[a][i] += dz;
                    norm = norm.max(dz.abs() / y[i].abs().max(1.0));
                }
            }
            if !norm.is_finite() {
                return Err((iteration, norm));
            }
            // Converged to round-off: the correction, or the one the contraction rate predicts next,
            // is below ε; or the corrections stopped decreasing at round-off level.
            // (No rate is known after the first iteration: then only a correction below ε counts.)
            let rate = if iteration == 1 {
                1.0
            } else {
                norm / previous_norm
            };
            if norm <= f64::EPSILON
                || (rate < 1.0 && rate * norm <= f64::EPSILON)
                || (rate >= 1.0 && norm <= ROUND_OFF_PLATEAU)
            {
                return Ok(());
            }
            if rate >= 1.0 && iteration > 1 {
                return Err((iteration, norm)); // diverging above round-off
            }
            // Slow contraction far above round-off means J is out of date (near round-off the ratio of
            // successive corrections is noise and says nothing about J).
            if iteration > 1 && rate > SLOW_CONTRACTION && norm > ROUND_OFF_PLATEAU {
                self.jacobian_stale = true;
            }
            previous_norm = norm;
        }
        Err((MAX_ITERATIONS, previous_norm))
    }
}

impl<const N: usize> Stepper<N> for Gauss4<N> {
    fn init<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t0: f64,
        y0: &[f64; N],
        _t_end: f64,
    ) -> Result<(), StepError> {
        self.h_z_last = 0.0;
        self.jacobian_stale = true;
        self.h_lu = 0.0;
        self.steps.start(sys, t0, y0)
    }

    fn step<S: OdeSystem<N>>(&mut self, sys: &S, t_limit: f64) -> Result<(), StepError> {
        let end = self.steps.next_end(t_limit);
        let t = self.steps.state.t;
        let h = end.0 - t;
        // First attempt with the kept Jacobian; if it fails, once more with a fresh one.
        let z = loop {
            let fresh = self.jacobian_stale;
            if fresh {
                self.update_jacobian(sys);
            }
            #[allow(clippy::float_cmp)] // exact: the LU was built for this very step value
            let lu_current = self.h_lu == h;
            let (iterations, residual) = if !lu_current && !self.factor(h) {
                (0, f64::INFINITY)
            } else {
                let mut z = self.initial_guess(h);
                match self.newton(sys, h, &mut z) {
                    Ok(()) => break z,
                    Err(e) => e,
                }
            };
            self.jacobian_stale = true;
            // Failed with an up-to-date Jacobian: another one will not help.
            if fresh {
                return Err(if residual.is_nan() {
                    StepError::NonFinite { t }
                } else {
                    StepError::NewtonFailure {
                        t,
                        h,
                        iterations,
                        residual,
                    }
                });
            }
        };

        // y₁ = y₀ + h·Σ bᵢ f(Yᵢ) = y₀ + bᵀA⁻¹Z = y₀ + √3·(Z₂ − Z₁), from the final (round-off exact) Z
        // without two more evaluations (HLW, §VIII.6.3).
        let mut y_new = [0.0; N];
        for i in 0..N {
            y_new[i] = self.steps.state.y[i] + SQRT3 * (z[1][i] - z[0][i]);
        }
        self.steps.accept(sys, end, &y_new)?;
        self.z_last = z;
        self.h_z_last = h;
        Ok(())
    }

    fn state(&self) -> &StepperState<N> {
        &self.steps.state
    }
    fn interpolate(&self, t: f64, out: &mut [f64; N]) {
        self.steps.interpolate(t, out);
    }
}
