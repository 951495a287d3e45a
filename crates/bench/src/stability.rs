//! The hard-case suite (`bench stability`; physics §5, §7): every case run with every integrator,
//! each reporting how the run ended, its error, energy drift and time, plus the case's own measurement
//! against its expectation:
//! - fast spin (ω_Z = 50, 500 on a steady circle at tilt 0.2, nudged): the largest stable fixed step of
//!   rk4 and gauss4 by bisection, as h·σ with σ the nutation frequency;
//! - near flat (θ = 1.5, 1.56, 1.5705): centre-fixed steady motion, and kicked towards flat (tan θ in the
//!   thousands);
//! - flat landing (θ₀ = 0.6) and lift-off (θ₀ = 0.2) of a coin released without spin, against the
//!   quadrature of the energy integral;
//! - marginal stability of straight rolling at ω_c(1 ± 1e-3) and ω_c, against the linear theory (t² growth
//!   at ω_c);
//! - long horizon on a wobbling motion: energy drift against time;
//! - scale invariance: M, a, g over 1e-3 … 1e3, disk and hoop, against the unit-scale run;
//!
//! The suite's rows, horizons and settings are here too; [`super::nutation`] adds the cases that prove
//! `analyse` and [`super::suite`] runs them all. Horizons are options ([`SuiteOptions`]) so that the tests
//! run the same cases shorter.

use super::case::{
    natural_scales, reference_trajectory_with, run_sampled_with, termination_name, Trajectory,
};
use super::presets::bench_case;
use super::{
    default_config, energy_drift, reference_trajectory, state_error, BenchCase, BenchError,
    DEFAULT_FLAT_MARGIN,
};
use coin_log::analyse::linear::{nutation_frequency, straight_tilt_linear};
use coin_log::analyse::Analysis;
use coin_log::integrate::{run_method, Flow, Method, MethodConfig, RunEnd, RunSettings};
use coin_log::model::fit::log_log_slope;
use coin_log::model::nutation::Motion;
use coin_log::model::{
    energy, Branch, Coin, CoinParams, Inertia, State, Steady, SteadyKind, STATE_LEN,
};
use std::f64::consts::{FRAC_PI_2, TAU};
use std::time::Instant;

/// Stability criterion of the fast-spin bisection: energy drift below 1e-2.
pub const STABLE_ENERGY_DRIFT: f64 = 1e-2;
/// Relative width to which the largest stable step is bisected.
const BISECTION_WIDTH: f64 = 1e-3;
/// Lean of the fast-spin circles \[rad\].
const FAST_SPIN_TILT: f64 = 0.2;
/// Nudge of the fast-spin cases: a nutation whose peak angular acceleration σ²δθ is this fraction of
/// g/a, so the motion wobbles (the step limit is that of a real nutation, not of round-off growing from
/// an exact fixed point) while N stays near Mg (a larger nutation at ω_Z = 500 lifts the coin off).
const FAST_SPIN_NUDGE: f64 = 1e-3;
/// Kick of the near-flat cases: the nutation amplitude as a fraction of the distance to the flat event.
const NEAR_FLAT_KICK: f64 = 0.5;
/// Relative perturbation of the spin in the marginal-stability cases.
pub const MARGINAL_OFFSET: f64 = 1e-3;
/// Initial tilt of the marginal-stability cases \[rad\]: small enough for the linear theory (relative
/// nonlinear terms ~ δθ² ≈ 1e-7 at t = 30), large enough to be far above the integration error.
const MARGINAL_TILT: f64 = 1e-6;
/// Adaptive tolerances of the suite's tight runs (event location to 1e-9 needs them).
const TIGHT_RTOL: f64 = 1e-12;
/// See [`TIGHT_RTOL`].
const TIGHT_ATOL: f64 = 1e-14;

/// Horizons of the suite; the bench uses [`SuiteOptions::full`], the tests [`SuiteOptions::quick`].
#[derive(Debug, Clone, PartialEq)]
pub struct SuiteOptions {
    /// Nutation periods of the fast-spin stability runs (100).
    pub nutation_periods: f64,
    /// Nutation periods of the near-flat runs.
    pub near_flat_periods: f64,
    /// Horizon of the marginal-stability runs [natural time units].
    pub marginal_horizon: f64,
    /// Horizon of the long run (10⁴) and the checkpoints at which its drift is reported.
    pub long_horizon: f64,
    /// Horizon of the scale-invariance runs [natural time units].
    pub scale_horizon: f64,
    /// Nutation periods of the analyse cases (kicked circles, generic motions; [`super::nutation`]).
    pub analyse_periods: f64,
}

impl SuiteOptions {
    /// The bench's horizons.
    #[must_use]
    pub fn full() -> Self {
        Self {
            nutation_periods: 100.0,
            near_flat_periods: 20.0,
            marginal_horizon: 30.0,
            long_horizon: 1e4,
            scale_horizon: 10.0,
            analyse_periods: 20.0,
        }
    }

    /// Shorter horizons for tests: 100 nutation periods still, long horizon 10³, marginal 20.
    #[must_use]
    pub fn quick() -> Self {
        Self {
            nutation_periods: 100.0,
            near_flat_periods: 10.0,
            marginal_horizon: 20.0,
            long_horizon: 1e3,
            scale_horizon: 5.0,
            analyse_periods: 10.0,
        }
    }
}

/// One line of the suite's report.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityRow {
    /// Case name, e.g. `fast-spin-50`.
    pub case: String,
    /// Integrator.
    pub integrator: Method,
    /// Its settings, in words (`rtol 1e-12 atol 1e-14`, `h 1e-3`).
    pub setting: String,
    /// How the run ended (`completed`, `flat-landing`, `lift-off`, ...).
    pub termination: String,
    /// Time of the last sample.
    pub end_time: f64,
    /// Max state error against the case's reference, when it has one.
    pub max_error: Option<f64>,
    /// Energy drift, format.md definition.
    pub energy_drift: f64,
    /// Wall time \[s\].
    pub wall_seconds: f64,
    /// What the case measures (`event time`, `largest stable h·σ`, ...).
    pub quantity: String,
    /// Its measured value.
    pub measured: Option<f64>,
    /// The expected value, when there is one.
    pub expected: Option<f64>,
}

impl StabilityRow {
    /// The row of `case` run with `config`, measuring `quantity`; the run's figures are filled in by the
    /// caller (until then: completed at t = 0, nothing measured).
    #[must_use]
    pub fn new(case: &str, config: &MethodConfig, quantity: &str) -> Self {
        Self {
            case: case.to_string(),
            integrator: config.method,
            setting: describe(config),
            termination: "completed".into(),
            end_time: 0.0,
            max_error: None,
            energy_drift: 0.0,
            wall_seconds: 0.0,
            quantity: quantity.to_string(),
            measured: None,
            expected: None,
        }
    }
}

/// Settings of a method in the suite: tight tolerances for adaptive methods, `step` for fixed ones.
#[must_use]
pub fn suite_config(method: Method, step: f64) -> MethodConfig {
    MethodConfig {
        method,
        rtol: TIGHT_RTOL,
        atol: TIGHT_ATOL,
        step,
    }
}

fn describe(config: &MethodConfig) -> String {
    if config.method.is_adaptive() {
        format!("rtol {:e} atol {:e}", config.rtol, config.atol)
    } else {
        format!("h {:.3e}", config.step)
    }
}

fn unit_disk() -> Coin {
    Coin::new(CoinParams::unit_disk())
}

/// Runs one configuration on a case and makes its row (error against `reference` when given).
fn row_for(
    case_name: &str,
    config: &MethodConfig,
    case: &BenchCase,
    settings: &RunSettings,
    reference: Option<&super::Reference>,
) -> (StabilityRow, Trajectory) {
    let mut run = Trajectory::default();
    let start = Instant::now();
    run_sampled_with(config, case, settings, &mut run);
    let wall_seconds = start.elapsed().as_secs_f64();
    let row = StabilityRow {
        termination: run.termination_name(),
        end_time: run.outcome.as_ref().map_or(0.0, |o| o.t_last),
        max_error: reference.map(|r| state_error(case, &run, r)),
        energy_drift: energy_drift(&case.coin, &run.states),
        wall_seconds,
        ..StabilityRow::new(case_name, config, "")
    };
    (row, run)
}

// ---------------------------------------------------------------------------------------------------------
// Fast spin

/// The fast-spin case: the steady circle at tilt 0.2 and spin `omega_z`, nudged to a nutation of
/// peak angular acceleration 1e-3 g/a, for `periods` nutation periods, and its σ.
///
/// # Errors
/// [`BenchError::InvalidScene`] if the steady motion cannot be built or is unstable.
pub fn fast_spin_case(omega_z: f64, periods: f64) -> Result<(BenchCase, f64), BenchError> {
    let coin = unit_disk();
    let name = format!("fast-spin-{omega_z}");
    let invalid = |reason: String| BenchError::InvalidScene {
        scene: name.clone(),
        reason,
    };
    let steady = Steady::new(
        &coin,
        SteadyKind::Circle {
            theta: FAST_SPIN_TILT,
            omega_z,
            branch: Branch::Plus,
        },
    )
    .map_err(|e| invalid(e.to_string()))?;
    let sigma = nutation_frequency(&coin, &steady)
        .ok_or_else(|| invalid("the steady circle is unstable".into()))?;
    let mut initial = steady.state;
    let p = coin.params();
    // δθ = nudge·(g/a)/σ², so δω_X = σ δθ.
    initial.omega_x += FAST_SPIN_NUDGE * p.gravity() / p.radius() / sigma;
    Ok((
        BenchCase::conservative(&name, coin, initial, periods * TAU / sigma),
        sigma,
    ))
}

/// Whether `method` at fixed step `h` is stable on `case`: the run completes and its energy drift (on
/// samples 20 per nutation period) stays below [`STABLE_ENERGY_DRIFT`].
#[must_use]
pub fn is_stable(method: Method, h: f64, case: &BenchCase, sigma: f64) -> bool {
    let settings = RunSettings {
        t0: 0.0,
        t_end: case.duration,
        sample_interval: TAU / sigma / 20.0,
    };
    let mut run = Trajectory::default();
    run_sampled_with(&suite_config(method, h), case, &settings, &mut run);
    run.completed() && energy_drift(&case.coin, &run.states) < STABLE_ENERGY_DRIFT
}

/// The largest stable fixed step (bisected in log h between 1e-2/σ and min(100/σ, duration/4)), or the
/// upper end if that is stable too. Returns (h, whether the upper end was reached).
#[must_use]
pub fn largest_stable_step(method: Method, case: &BenchCase, sigma: f64) -> (f64, bool) {
    let mut lo = 1e-2 / sigma;
    let mut hi = (100.0 / sigma).min(case.duration / 4.0);
    if is_stable(method, hi, case, sigma) {
        return (hi, true);
    }
    if !is_stable(method, lo, case, sigma) {
        return (0.0, false);
    }
    while hi / lo > 1.0 + BISECTION_WIDTH {
        let mid = (lo * hi).sqrt();
        if is_stable(method, mid, case, sigma) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, false)
}

/// Fast spin at `omega_z`: every integrator at tight settings (fixed step 0.05/σ), then the largest stable
/// step of each fixed-step method, reported as h·σ.
///
/// # Errors
/// [`BenchError`] if the case or its reference cannot be built.
pub fn fast_spin(omega_z: f64, options: &SuiteOptions) -> Result<Vec<StabilityRow>, BenchError> {
    let (case, sigma) = fast_spin_case(omega_z, options.nutation_periods)?;
    let settings = RunSettings {
        sample_interval: TAU / sigma / 20.0,
        ..case.settings()
    };
    let reference = reference_trajectory_with(&case, &settings)?;
    let mut rows = Vec::new();
    for &method in Method::ALL {
        let config = suite_config(method, 0.05 / sigma);
        let (mut row, _) = row_for(&case.name, &config, &case, &settings, Some(&reference));
        row.quantity = "nutation σ".into();
        row.measured = Some(sigma);
        rows.push(row);
    }
    for &method in Method::ALL.iter().filter(|m| !m.is_adaptive()) {
        let start = Instant::now();
        let (h, capped) = largest_stable_step(method, &case, sigma);
        // h = 0: not even the smallest step searched is stable; the row shows that run.
        let config = suite_config(method, if h > 0.0 { h } else { 1e-2 / sigma });
        let (mut row, _) = row_for(&case.name, &config, &case, &settings, None);
        row.wall_seconds = start.elapsed().as_secs_f64();
        row.quantity = if capped {
            "largest stable h·σ (≥, search cap)".into()
        } else {
            "largest stable h·σ".into()
        };
        row.measured = Some(h * sigma);
        row.expected = (method.name() == "rk4").then_some(RK4_STABILITY_LIMIT);
        rows.push(row);
    }
    Ok(rows)
}

/// rk4's stability limit on the imaginary axis, 2√2 (Hairer & Wanner II, §IV.2): the expected h·σ.
pub const RK4_STABILITY_LIMIT: f64 = 2.0 * std::f64::consts::SQRT_2;

// ---------------------------------------------------------------------------------------------------------
// Near flat

/// Near flat at lean `theta`: the centre-fixed steady motion (analytic reference) and the same kicked in
/// ω_X so that the nutation reaches half-way to the flat event (dop853 reference), each for `periods`
/// nutation periods with every integrator (fixed step 0.02/σ).
///
/// # Errors
/// [`BenchError`] if the steady motion or the reference cannot be built.
pub fn near_flat(theta: f64, options: &SuiteOptions) -> Result<Vec<StabilityRow>, BenchError> {
    let coin = unit_disk();
    let steady = Steady::new(
        &coin,
        SteadyKind::CentreFixed {
            theta,
            branch: Branch::Plus,
        },
    )
    .map_err(|e| BenchError::InvalidScene {
        scene: format!("near-flat-{theta}"),
        reason: e.to_string(),
    })?;
    let sigma = nutation_frequency(&coin, &steady).unwrap_or(1.0);
    let gap = FRAC_PI_2 - DEFAULT_FLAT_MARGIN - theta;
    let steady_case = BenchCase {
        steady: Some(steady),
        ..BenchCase::conservative(
            &format!("near-flat-{theta}-steady"),
            coin,
            steady.state,
            options.near_flat_periods * TAU / sigma,
        )
    };
    let mut kicked = steady_case.clone();
    kicked.name = format!("near-flat-{theta}-kicked");
    kicked.steady = None;
    kicked.initial.omega_x += NEAR_FLAT_KICK * gap * sigma;
    let mut rows = Vec::new();
    for case in [&steady_case, &kicked] {
        let reference = reference_trajectory(case)?;
        for &method in Method::ALL {
            let config = suite_config(method, 0.02 / sigma);
            let (mut row, run) = row_for(
                &case.name,
                &config,
                case,
                &case.settings(),
                Some(&reference),
            );
            row.quantity = "max tan θ".into();
            row.measured = run
                .states
                .iter()
                .map(|y| y[0].tan().abs())
                .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
            rows.push(row);
        }
    }
    Ok(rows)
}

// ---------------------------------------------------------------------------------------------------------
// Flat landing and lift-off

/// A coin released at rest at lean `theta0`: the event the quadrature of `analyse` expects (lift-off if N
/// reaches 0 first, else the flat landing at π/2 − flat_margin) and its time; every integrator locates it
/// (fixed step 1e-3).
///
/// # Errors
/// [`BenchError::InvalidScene`] if the quadrature fails or expects neither event (never for these).
pub fn release(theta0: f64, case_name: &str) -> Result<Vec<StabilityRow>, BenchError> {
    let coin = unit_disk();
    let initial = State {
        theta: theta0,
        ..State::default()
    };
    let invalid = |reason: String| BenchError::InvalidScene {
        scene: case_name.to_string(),
        reason,
    };
    let orbit = Analysis::of_state(&coin, &initial, DEFAULT_FLAT_MARGIN, None, None)
        .map_err(|e| invalid(e.to_string()))?
        .orbit;
    let (expected_event, expected_time) = match (orbit.lift_off, orbit.motion) {
        (Some(lift_off), _) => ("lift-off", lift_off.time),
        (None, Motion::FlatLanding { time, .. }) => ("flat-landing", time),
        (None, motion) => return Err(invalid(format!("the quadrature expects {motion:?}"))),
    };
    let case = BenchCase::conservative(case_name, coin, initial, 4.0 * expected_time + 1.0);
    Ok(Method::ALL
        .iter()
        .map(|&method| {
            let config = suite_config(method, 1e-3);
            let (mut row, run) = row_for(case_name, &config, &case, &case.settings(), None);
            let located = match run.outcome.as_ref().map(|o| &o.termination) {
                Some(RunEnd::Event { t, .. }) => Some(*t),
                _ => None,
            };
            row.quantity = format!("{expected_event} time");
            row.measured = located;
            row.expected = Some(expected_time);
            row.max_error = Some(located.map_or(f64::INFINITY, |t| (t - expected_time).abs()));
            row
        })
        .collect())
}

// ---------------------------------------------------------------------------------------------------------
// Marginal stability

/// Straight rolling at ω_c(1 + `offset`) from a tilt of 1e-6 for `horizon` time units: the largest
/// relative deviation of θ from [`straight_tilt_linear`] over the samples, every integrator (fixed step
/// 1e-2).
#[must_use]
pub fn marginal(offset: f64, horizon: f64) -> Vec<StabilityRow> {
    let coin = unit_disk();
    let omega = coin_log::model::critical_spin(&coin) * (1.0 + offset);
    let initial = State {
        theta: MARGINAL_TILT,
        omega_z: omega,
        ..State::default()
    };
    let case = BenchCase::conservative(&format!("marginal-wc{offset:+e}"), coin, initial, horizon);
    Method::ALL
        .iter()
        .map(|&method| {
            let config = suite_config(method, 1e-2);
            let (mut row, run) = row_for(&case.name, &config, &case, &case.settings(), None);
            let deviation = run
                .times
                .iter()
                .zip(&run.states)
                .map(|(t, y)| {
                    let linear = straight_tilt_linear(&coin, omega, MARGINAL_TILT, *t);
                    ((y[0] - linear) / linear).abs()
                })
                .fold(0.0, f64::max);
            let last = run.states.last().map_or(0.0, |y| y[0]);
            row.max_error = Some(deviation);
            row.quantity = "θ(T)/θ₀".into();
            row.measured = Some(last / MARGINAL_TILT);
            row.expected = Some(
                straight_tilt_linear(&coin, omega, MARGINAL_TILT, row.end_time) / MARGINAL_TILT,
            );
            row
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------------------
// Long horizon

/// Energy drift of one long run, reported at checkpoints.
#[derive(Debug, Clone, PartialEq)]
pub struct DriftHistory {
    /// The method and its settings.
    pub config: MethodConfig,
    /// (t, max relative energy error over [0, t]) at each checkpoint reached.
    pub checkpoints: Vec<(f64, f64)>,
    /// How the run ended.
    pub termination: String,
    /// Wall time \[s\].
    pub wall_seconds: f64,
}

/// Runs `config` on the `wobble` scene's motion to `horizon`, streaming the energy error (samples every
/// 0.1 time units, nothing stored) and recording its running maximum at t = 10, 100, 1000, ... and at the
/// horizon.
///
/// # Errors
/// [`BenchError`] if the `wobble` scene does not validate (a bug).
pub fn drift_history(config: &MethodConfig, horizon: f64) -> Result<DriftHistory, BenchError> {
    let BenchCase { coin, initial, .. } = bench_case("wobble")?;
    let e0 = energy(&coin, &initial).total;
    let scale = e0.abs().max(coin.params().energy_scale());
    let mut checkpoints = Vec::new();
    let mut next = 10.0_f64.min(horizon);
    let mut worst = 0.0_f64;
    let settings = RunSettings {
        t0: 0.0,
        t_end: horizon,
        sample_interval: 0.1,
    };
    let events = coin_log::simulation::CoinEvents::new(coin, DEFAULT_FLAT_MARGIN, None);
    let start = Instant::now();
    let outcome = run_method(
        config,
        &coin,
        &initial.to_array(),
        &settings,
        &events,
        |t, y: &[f64; STATE_LEN]| {
            let d = (energy(&coin, &State::from_array(y)).total - e0).abs() / scale;
            worst = worst.max(if d.is_nan() { f64::INFINITY } else { d });
            if t >= next * (1.0 - 1e-12) {
                checkpoints.push((t, worst));
                next = (next * 10.0).min(horizon);
                if t >= horizon {
                    next = f64::INFINITY;
                }
            }
            Flow::Continue
        },
    );
    Ok(DriftHistory {
        config: *config,
        checkpoints,
        termination: termination_name(&outcome.termination),
        wall_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Fixed step of the long-horizon runs: large enough that the truncation error of the energy (≈ 1e-8 for
/// gauss4) stands above round-off, so a drift, or its absence, is visible.
pub const LONG_HORIZON_STEP: f64 = 0.1;

/// Settings of the long-horizon runs: contract defaults for adaptive methods, [`LONG_HORIZON_STEP`] for
/// fixed ones.
#[must_use]
pub fn long_horizon_config(method: Method) -> MethodConfig {
    MethodConfig {
        step: LONG_HORIZON_STEP,
        ..default_config(method, 1.0)
    }
}

/// The long-horizon case: every integrator on the wobble to `horizon`, one row per checkpoint, and the
/// growth exponent of the drift (slope of log drift against log t: ≈ 1 for a linear drift, ≈ 0 bounded).
///
/// # Errors
/// As [`drift_history`].
pub fn long_horizon(horizon: f64) -> Result<Vec<StabilityRow>, BenchError> {
    let mut rows = Vec::new();
    for &method in Method::ALL {
        let history = drift_history(&long_horizon_config(method), horizon)?;
        let growth = log_log_slope(&history.checkpoints);
        for &(t, drift) in &history.checkpoints {
            rows.push(StabilityRow {
                termination: history.termination.clone(),
                end_time: t,
                energy_drift: drift,
                wall_seconds: history.wall_seconds,
                measured: growth,
                ..StabilityRow::new("long-horizon", &history.config, "drift growth exponent")
            });
        }
    }
    Ok(rows)
}

// ---------------------------------------------------------------------------------------------------------
// Scale invariance

/// The (M, a, g) triples of the scale-invariance case.
pub const SCALES: &[(f64, f64, f64)] = &[
    (1e-3, 1.0, 1.0),
    (1e3, 1.0, 1.0),
    (1.0, 1e-3, 1.0),
    (1.0, 1e3, 1.0),
    (1.0, 1.0, 1e-3),
    (1.0, 1.0, 1e3),
    (1e3, 1e-3, 1e3),
    (1e-3, 1e3, 1e-3),
];

/// The state made dimensionless ([`natural_scales`]): angles as they are, ω·√(a/g), x/a, z/a.
#[must_use]
pub fn dimensionless(coin: &Coin, y: &[f64; STATE_LEN]) -> [f64; STATE_LEN] {
    let scale = natural_scales(coin);
    std::array::from_fn(|i| y[i] * scale[i])
}

/// The `wobble` scene's motion on a coin of (M, a, g, shape), scaled: ω by √(g/a), horizon and step by √(a/g).
///
/// # Errors
/// [`BenchError::InvalidScene`] for non-positive parameters.
pub fn scaled_wobble(
    (mass, radius, gravity): (f64, f64, f64),
    inertia: Inertia,
    horizon: f64,
) -> Result<BenchCase, BenchError> {
    let params =
        CoinParams::new(mass, radius, gravity, inertia).map_err(|e| BenchError::InvalidScene {
            scene: "scale".into(),
            reason: format!("{e:?}"),
        })?;
    let t = params.time_unit();
    let mut initial = bench_case("wobble")?.initial;
    initial.omega_x /= t;
    initial.omega_y /= t;
    initial.omega_z /= t;
    Ok(BenchCase::conservative(
        &format!("scale-M{mass:e}-a{radius:e}-g{gravity:e}"),
        Coin::new(params),
        initial,
        horizon * t,
    ))
}

/// Largest dimensionless difference between the wobble at scale `scale` and at unit scale, same shape,
/// with `method` (adaptive: rtol 1e-13, atol 1e-15 times the scale of each run's state; fixed: h = 1e-3
/// natural units), sampled 100 times per natural time unit.
///
/// # Errors
/// [`BenchError::InvalidScene`] for non-positive parameters.
pub fn scale_difference(
    method: Method,
    scale: (f64, f64, f64),
    inertia: Inertia,
    horizon: f64,
) -> Result<(f64, Trajectory), BenchError> {
    let unit = scaled_wobble((1.0, 1.0, 1.0), inertia, horizon)?;
    let scaled = scaled_wobble(scale, inertia, horizon)?;
    let config_for = |case: &BenchCase| MethodConfig {
        method,
        rtol: 1e-13,
        // The smallest state scale of the run (ω ~ 1/T, lengths ~ a) times 1e-15: pure relative control.
        atol: 1e-15 * case.coin.params().radius().min(1.0 / case.time_unit()),
        step: 1e-3 * case.time_unit(),
    };
    let mut a = Trajectory::default();
    let mut b = Trajectory::default();
    run_sampled_with(&config_for(&unit), &unit, &unit.settings(), &mut a);
    run_sampled_with(&config_for(&scaled), &scaled, &scaled.settings(), &mut b);
    let worst = dimensionless_difference((&unit, &a), (&scaled, &b));
    Ok((worst, b))
}

/// Largest difference between two sampled runs in the natural units of their own bodies
/// ([`dimensionless`]), sample by sample; infinite when the sample counts differ or a value is NaN.
#[must_use]
pub fn dimensionless_difference(
    (case_a, a): (&BenchCase, &Trajectory),
    (case_b, b): (&BenchCase, &Trajectory),
) -> f64 {
    if a.states.len() != b.states.len() {
        return f64::INFINITY;
    }
    a.states
        .iter()
        .zip(&b.states)
        .map(|(ya, yb)| {
            let (da, db) = (
                dimensionless(&case_a.coin, ya),
                dimensionless(&case_b.coin, yb),
            );
            da.iter()
                .zip(&db)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max)
        })
        .fold(
            0.0,
            |m: f64, d: f64| if d.is_nan() { f64::INFINITY } else { m.max(d) },
        )
}

/// Scale invariance: for disk and hoop and every integrator, the worst agreement over [`SCALES`].
///
/// # Errors
/// [`BenchError::InvalidScene`] (never for the built-in scales).
pub fn scale_invariance(horizon: f64) -> Result<Vec<StabilityRow>, BenchError> {
    let mut rows = Vec::new();
    for (shape, inertia) in [("disk", Inertia::ThinDisk), ("hoop", Inertia::Hoop)] {
        for &method in Method::ALL {
            let start = Instant::now();
            let mut worst = (0.0_f64, SCALES[0]);
            let mut drift = 0.0_f64;
            let mut termination = String::from("completed");
            for &scale in SCALES {
                let (d, run) = scale_difference(method, scale, inertia, horizon)?;
                if d > worst.0 || d.is_nan() {
                    worst = (d, scale);
                }
                let coin = Coin::new(CoinParams::new(scale.0, scale.1, scale.2, inertia).map_err(
                    |e| BenchError::InvalidScene {
                        scene: "scale".into(),
                        reason: format!("{e:?}"),
                    },
                )?);
                drift = drift.max(energy_drift(&coin, &run.states));
                if !run.completed() {
                    termination = run.termination_name();
                }
            }
            rows.push(StabilityRow {
                case: format!("scale-invariance-{shape}"),
                integrator: method,
                setting: format!(
                    "worst at M={:e} a={:e} g={:e}",
                    worst.1 .0, worst.1 .1, worst.1 .2
                ),
                termination,
                end_time: horizon,
                max_error: Some(worst.0),
                energy_drift: drift,
                wall_seconds: start.elapsed().as_secs_f64(),
                quantity: "max dimensionless difference".into(),
                measured: Some(worst.0),
                expected: Some(0.0),
            });
        }
    }
    Ok(rows)
}
