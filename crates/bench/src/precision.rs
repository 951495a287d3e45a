//! Work-precision sweeps (`bench precision`): for a scene and each integrator, a sweep of
//! tolerances (adaptive methods) or steps (fixed-step methods), each point's state, energy and invariant
//! errors against a reference, its wall time (median of repeats after a warm-up) and its work counters.
//!
//! The slope of log error against log cost estimates the order: error ∝ cost^(−p) for a method of order
//! p once the step is small enough and the error is above round-off.

use super::case::{run_sampled, termination_name, Reference, ReferenceKind, Trajectory};
use super::{
    balance_drift, invariant_drift, median, reference_trajectory, state_error, BenchCase,
    BenchError,
};
use coin_log::integrate::{Method, MethodConfig};
use coin_log::model::fit::log_log_slope;
use std::time::Instant;

/// The adaptive sweep's rtol is 1e3·atol ...
const RTOL_OVER_ATOL: f64 = 1e3;
/// ... capped at 1e-3.
const RTOL_CAP: f64 = 1e-3;

/// Slopes are fitted to points with errors inside this range: above round-off and the reference's own
/// error (≈ 1e-13 on a 30-unit run), below the pre-asymptotic regime of loose tolerances.
pub const SLOPE_FIT_RANGE: (f64, f64) = (1e-12, 1e-4);

/// The error range the fixed-step sweep aims to cover, matching the adaptive sweep's.
const FIXED_ERROR_RANGE: (f64, f64) = (1e-13, 1e-5);

/// A pilot run with an error above this is taken as unstable or pre-asymptotic; its step is divided by 4.
const PILOT_ERROR_CEILING: f64 = 1e-2;
/// How many times the pilot step is divided before giving up.
const PILOT_ATTEMPTS: usize = 10;
/// Upper bound on the number of fixed steps of one sweep point (bounds the bench's cost).
const MAX_FIXED_STEPS: f64 = 4e6;
/// Largest step of a fixed sweep, relative to the pilot's: beyond it the extrapolation is not trusted.
const MAX_STEP_OVER_PILOT: f64 = 8.0;

/// How thorough a sweep is.
#[derive(Debug, Clone, PartialEq)]
pub struct PrecisionOptions {
    /// Timed repeats per point (after one warm-up run); the median is reported.
    pub repeats: usize,
    /// atol values of the adaptive sweep (rtol = min(1e3·atol, 1e-3)).
    pub adaptive_atols: Vec<f64>,
    /// Number of steps in the fixed-step sweep.
    pub fixed_points: usize,
}

impl PrecisionOptions {
    /// The full sweep: atol = 1e-6, 1e-7, ..., 1e-16 and 10 fixed steps.
    #[must_use]
    pub fn full(repeats: usize) -> Self {
        Self {
            repeats,
            adaptive_atols: (6..=16).map(|k| 10f64.powi(-k)).collect(),
            fixed_points: 10,
        }
    }

    /// A reduced sweep for tests: atol = 1e-6, 1e-8, ..., 1e-16, 5 fixed steps, one timed run.
    #[must_use]
    pub fn reduced() -> Self {
        Self {
            repeats: 1,
            adaptive_atols: (3..=8).map(|k| 10f64.powi(-2 * k)).collect(),
            fixed_points: 5,
        }
    }
}

/// One point of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct PrecisionRow {
    /// Scene name.
    pub scene: String,
    /// Integrator.
    pub integrator: Method,
    /// atol of an adaptive point (rtol = min(1e3·atol, 1e-3)); `None` for fixed-step methods.
    pub tolerance: Option<f64>,
    /// Step of a fixed-step point; `None` for adaptive methods.
    pub step: Option<f64>,
    /// Max dimensionless state difference to the reference over the samples ([`super::state_error`]).
    pub state_error: f64,
    /// Energy drift, format.md definition.
    pub energy_error: f64,
    /// C1, C2 drift, format.md definition; `None` when the invariants are not available.
    pub invariant_error: Option<f64>,
    /// Median wall time of the run \[s\].
    pub wall_seconds: f64,
    /// Right-hand side evaluations.
    pub rhs_evaluations: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// How the run ended.
    pub termination: String,
}

impl PrecisionRow {
    /// The method's settings at this point.
    #[must_use]
    pub fn config(&self) -> MethodConfig {
        let atol = self.tolerance.unwrap_or(0.0);
        MethodConfig {
            method: self.integrator,
            rtol: rtol_for(atol),
            atol,
            step: self.step.unwrap_or(0.0),
        }
    }
}

/// Measured slopes of one integrator's work-precision line.
#[derive(Debug, Clone, PartialEq)]
pub struct Slope {
    /// Integrator.
    pub integrator: Method,
    /// d log10(error) / d log10(wall time); `None` with fewer than two usable points.
    pub time: Option<f64>,
    /// d log10(error) / d log10(RHS evaluations): the same slope on a deterministic cost.
    pub work: Option<f64>,
    /// Points used in the fit.
    pub points: usize,
}

/// A scene's sweep.
#[derive(Debug, Clone)]
pub struct PrecisionReport {
    /// Scene name.
    pub scene: String,
    /// What the errors are measured against.
    pub reference: ReferenceKind,
    /// The points, integrator by integrator.
    pub rows: Vec<PrecisionRow>,
    /// One slope per integrator.
    pub slopes: Vec<Slope>,
}

/// rtol of the adaptive sweep for a given atol: min(1e3·atol, 1e-3).
#[must_use]
pub fn rtol_for(atol: f64) -> f64 {
    (RTOL_OVER_ATOL * atol).min(RTOL_CAP)
}

/// Rounds a step so that the sample interval is a whole multiple of it (h ≤ interval) or it is a whole
/// multiple of the interval (h > interval): steps then land on the sample grid.
#[must_use]
pub fn round_to_grid(step: f64, interval: f64) -> f64 {
    if step <= interval {
        interval / (interval / step).round().max(1.0)
    } else {
        interval * (step / interval).round()
    }
}

/// Slopes of one integrator's rows, fitted on the points whose error is inside [`SLOPE_FIT_RANGE`] (all
/// finite points if fewer than three are inside).
#[must_use]
pub fn slopes_of(integrator: Method, rows: &[PrecisionRow]) -> Slope {
    let mine: Vec<&PrecisionRow> = rows
        .iter()
        .filter(|r| r.integrator == integrator && r.state_error.is_finite())
        .collect();
    let inside: Vec<&PrecisionRow> = mine
        .iter()
        .copied()
        .filter(|r| r.state_error >= SLOPE_FIT_RANGE.0 && r.state_error <= SLOPE_FIT_RANGE.1)
        .collect();
    let used = if inside.len() >= 3 { inside } else { mine };
    #[allow(clippy::cast_precision_loss)]
    let work: Vec<(f64, f64)> = used
        .iter()
        .map(|r| (r.rhs_evaluations as f64, r.state_error))
        .collect();
    let time: Vec<(f64, f64)> = used
        .iter()
        .map(|r| (r.wall_seconds, r.state_error))
        .collect();
    Slope {
        integrator,
        time: log_log_slope(&time),
        work: log_log_slope(&work),
        points: used.len(),
    }
}

/// Runs `config` once as a warm-up and `repeats` more times, returning the median wall time \[s\]; the
/// samples of the last run are left in `out`.
fn timed_runs(
    config: &MethodConfig,
    case: &BenchCase,
    repeats: usize,
    out: &mut Trajectory,
) -> f64 {
    run_sampled(config, case, out);
    let times: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let start = Instant::now();
            run_sampled(config, case, out);
            start.elapsed().as_secs_f64()
        })
        .collect();
    median(&times)
}

/// Measures one sweep point.
fn measure(
    config: &MethodConfig,
    case: &BenchCase,
    reference: &Reference,
    repeats: usize,
    buffer: &mut Trajectory,
) -> PrecisionRow {
    let wall_seconds = timed_runs(config, case, repeats, buffer);
    let stats = buffer.outcome.as_ref().map(|o| o.stats).unwrap_or_default();
    PrecisionRow {
        scene: case.name.clone(),
        integrator: config.method,
        tolerance: config.method.is_adaptive().then_some(config.atol),
        step: (!config.method.is_adaptive()).then_some(config.step),
        state_error: state_error(case, buffer, reference),
        energy_error: balance_drift(&case.coin, &buffer.states, &buffer.work),
        // With dissipation C1, C2 are not conserved (physics §11): no drift to report.
        invariant_error: case
            .dissipation
            .is_none()
            .then(|| invariant_drift(&case.coin, &buffer.states))
            .flatten(),
        wall_seconds,
        rhs_evaluations: stats.rhs_evaluations,
        steps: stats.steps,
        rejected: stats.rejected_steps,
        termination: buffer
            .outcome
            .as_ref()
            .map_or_else(|| "not-run".into(), |o| termination_name(&o.termination)),
    }
}

/// The steps of a fixed-step sweep: a pilot run at the sample interval (divided by 4 until its error is
/// below 1e-2) measures the error constant, and the steps are spread geometrically so that the predicted
/// errors e ≈ e_pilot (h/h_pilot)^p span 1e-5 … 1e-13, each rounded onto the sample grid.
#[must_use]
pub fn fixed_steps(
    case: &BenchCase,
    method: Method,
    reference: &Reference,
    points: usize,
) -> Vec<f64> {
    let interval = case.settings().sample_interval;
    let order = f64::from(method.order());
    let mut buffer = Trajectory::default();
    let mut pilot = interval;
    let mut pilot_error = f64::INFINITY;
    for _ in 0..PILOT_ATTEMPTS {
        let config = MethodConfig {
            step: pilot,
            ..super::default_config(method, case.time_unit())
        };
        run_sampled(&config, case, &mut buffer);
        pilot_error = state_error(case, &buffer, reference);
        if pilot_error.is_finite() && pilot_error <= PILOT_ERROR_CEILING {
            break;
        }
        pilot /= 4.0;
    }
    let step_for = |e: f64| {
        if pilot_error > 0.0 && pilot_error.is_finite() {
            pilot * (e / pilot_error).powf(1.0 / order)
        } else {
            pilot
        }
    };
    let h_max = step_for(FIXED_ERROR_RANGE.1)
        .min(MAX_STEP_OVER_PILOT * pilot)
        .min(case.duration / 10.0);
    let h_min = step_for(FIXED_ERROR_RANGE.0)
        .max(case.duration / MAX_FIXED_STEPS)
        .min(h_max);
    let n = points.max(2);
    let mut steps: Vec<f64> = (0..n)
        .map(|i| {
            #[allow(clippy::cast_precision_loss)]
            let f = i as f64 / (n - 1) as f64;
            round_to_grid(h_max * (h_min / h_max).powf(f), interval)
        })
        .collect();
    steps.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    steps
}

/// The sweep of one scene over `methods`.
///
/// # Errors
/// [`BenchError::ReferenceFailed`] when the numerical reference cannot be computed.
pub fn precision_bench(
    case: &BenchCase,
    methods: &[Method],
    options: &PrecisionOptions,
) -> Result<PrecisionReport, BenchError> {
    let reference = reference_trajectory(case)?;
    let mut rows = Vec::new();
    let mut buffer = Trajectory::with_capacity(reference_samples(case));
    for &method in methods {
        let configs: Vec<MethodConfig> = if method.is_adaptive() {
            options
                .adaptive_atols
                .iter()
                .map(|&atol| MethodConfig {
                    method,
                    rtol: rtol_for(atol),
                    atol,
                    step: 0.0,
                })
                .collect()
        } else {
            fixed_steps(case, method, &reference, options.fixed_points)
                .into_iter()
                .map(|step| MethodConfig {
                    step,
                    ..super::default_config(method, case.time_unit())
                })
                .collect()
        };
        for config in &configs {
            rows.push(measure(
                config,
                case,
                &reference,
                options.repeats,
                &mut buffer,
            ));
        }
    }
    let slopes = methods.iter().map(|&m| slopes_of(m, &rows)).collect();
    Ok(PrecisionReport {
        scene: case.name.clone(),
        reference: reference.kind(),
        rows,
        slopes,
    })
}

/// The loosest adaptive setting of `method` among `atols` (loosest first; rtol = min(1e3·atol, 1e-3)) whose
/// state error on `case` against its reference is at most `error`, with that error: the setting at which
/// the criterion benchmarks time an integrator.
///
/// # Errors
/// [`BenchError::ReferenceFailed`] when the reference cannot be computed; [`BenchError::Inaccurate`] when
/// no setting reaches `error`.
pub fn loosest_accurate(
    case: &BenchCase,
    method: Method,
    atols: &[f64],
    error: f64,
) -> Result<(MethodConfig, f64), BenchError> {
    let reference = reference_trajectory(case)?;
    let mut run = Trajectory::default();
    let mut best = f64::INFINITY;
    for &atol in atols {
        let config = MethodConfig {
            method,
            rtol: rtol_for(atol),
            atol,
            step: 0.0,
        };
        run_sampled(&config, case, &mut run);
        let reached = state_error(case, &run, &reference);
        best = best.min(reached);
        if run.completed() && reached <= error {
            return Ok((config, reached));
        }
    }
    Err(BenchError::Inaccurate {
        scene: case.name.clone(),
        method,
        error,
        best,
    })
}

#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
fn reference_samples(case: &BenchCase) -> usize {
    let n = case.duration / case.settings().sample_interval;
    if n.is_finite() && n > 0.0 {
        n as usize + 2
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_rounded_onto_the_sample_grid() {
        let h = round_to_grid(3e-3, 1e-2);
        assert!((1e-2 / h - 3.0).abs() < 1e-12, "h = {h}");
        let h = round_to_grid(2.6e-2, 1e-2);
        assert!((h / 1e-2 - 3.0).abs() < 1e-12, "h = {h}");
    }

    #[test]
    fn rtol_is_a_thousand_times_atol_capped_at_a_thousandth() {
        assert!((rtol_for(1e-10) - 1e-7).abs() < 1e-22);
        assert!((rtol_for(1e-6) - 1e-3).abs() < 1e-18);
    }
}
