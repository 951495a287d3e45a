//! Proof by simulation of `analyse` (physics §9, §10), for `bench stability`: a perturbed stable circle
//! nutates at σ, a perturbed unstable circle grows at √(−σ²), and a generic motion's period and heading
//! advance per period are those of the quadrature. Every case is simulated with every integrator, and the
//! frequency, rate, period and heading advance are measured from the samples alone.
//!
//! **Measuring.** The samples are 1/64 of a nutation period apart (at most 0.01 time units); the period
//! and the heading advance are those of θ's turning points ([`TurningPoints`], located to ~(hσ)⁶/46080 of
//! a period). A growth rate is the least-squares slope of ln|ω_X| over a window where the perturbation has
//! outgrown the decaying mode and is still small (amplitudes 1e-9 to 1e-5 of a radian, so the nonlinear
//! terms are ≤ 1e-5 relative).

use super::presets::bench_case;
use super::stability::{suite_config, StabilityRow};
use super::BenchError;
use coin_log::analyse::linear::{displaced, kicked};
use coin_log::analyse::Analysis;
use coin_log::integrate::{run_method, Flow, Method, MethodConfig, NoEvents, RunSettings};
use coin_log::model::fit;
use coin_log::model::nutation::Motion;
use coin_log::model::{
    energy, steady_sigma_squared, Branch, Coin, CoinParams, Inertia, MeasuredNutation, State,
    Steady, SteadyKind, TurningPoints,
};
use std::f64::consts::TAU;
use std::time::Instant;

/// Samples per nutation period.
const SAMPLES_PER_PERIOD: f64 = 64.0;
/// Largest sample interval [natural time units].
const LARGEST_INTERVAL: f64 = 0.01;
/// Tilt amplitude of the perturbed stable circles \[rad\]: their frequency shift is O(amplitude²).
pub const NUTATION_AMPLITUDE: f64 = 1e-5;
/// Initial amplitude of the perturbed unstable circles \[rad\].
pub const GROWTH_START: f64 = 1e-10;
/// Window of the growth-rate fit: from this amplitude ...
pub const GROWTH_FROM: f64 = 1e-9;
/// ... to this one \[rad\].
pub const GROWTH_TO: f64 = 1e-5;
/// Fewest samples in the window of the growth-rate fit.
const GROWTH_POINTS: usize = 10;
/// Fixed step of rk4 and gauss4 in the nutation cases, as a fraction of a nutation period.
const FIXED_STEP_PER_PERIOD: f64 = 1.0 / 2048.0;

/// Runs `config` on `coin` from `initial` for `duration` (no events), handing `observe` the samples
/// `interval` apart.
fn run(
    coin: &Coin,
    initial: &State,
    config: &MethodConfig,
    (duration, interval): (f64, f64),
    mut observe: impl FnMut(f64, State) -> Flow,
) {
    let settings = RunSettings {
        t0: 0.0,
        t_end: duration,
        sample_interval: interval,
    };
    run_method(
        config,
        coin,
        &initial.to_array(),
        &settings,
        &NoEvents,
        |t, y| observe(t, State::from_array(y)),
    );
}

/// Runs `config` from `initial` for `duration` with samples `interval` apart and gathers θ's turning
/// points. Also returns the samples' largest energy drift.
#[must_use]
pub fn turning_points(
    coin: &Coin,
    initial: &State,
    config: &MethodConfig,
    duration: f64,
    interval: f64,
) -> (TurningPoints, f64) {
    let e0 = energy(coin, initial).total;
    let scale = e0.abs().max(coin.params().energy_scale());
    let mut drift = 0.0_f64;
    let mut points = TurningPoints::default();
    run(coin, initial, config, (duration, interval), |t, s| {
        drift = drift.max((energy(coin, &s).total - e0).abs() / scale);
        points.observe(coin, t, &s);
        Flow::Continue
    });
    (points, drift)
}

/// The least-squares slope of ln|ω_X| against t over the samples where |θ − θ₀| is between
/// [`GROWTH_FROM`] and [`GROWTH_TO`], from a run of `config` from `initial` (`None` with fewer than 10
/// such samples).
#[must_use]
pub fn growth_rate(
    coin: &Coin,
    base: &State,
    initial: &State,
    config: &MethodConfig,
    duration: f64,
    interval: f64,
) -> Option<f64> {
    let mut points = Vec::new();
    run(coin, initial, config, (duration, interval), |t, s| {
        let amplitude = (s.theta - base.theta).abs();
        if (GROWTH_FROM..=GROWTH_TO).contains(&amplitude) && s.omega_x != 0.0 {
            points.push((t, s.omega_x.abs().ln()));
        }
        if amplitude > GROWTH_TO {
            Flow::Stop
        } else {
            Flow::Continue
        }
    });
    (points.len() >= GROWTH_POINTS)
        .then(|| fit::line(&points))
        .flatten()
        .map(|l| l.slope)
}

/// One nutation case's run with `method` over `periods` periods of length `period`: the suite's tight
/// tolerances or a fixed step of 1/2048 of the period, samples 1/64 of a period apart (at most 0.01 time
/// units). Returns a row with the run's figures, and the measured T and ΔΦ.
fn measure(
    case: &str,
    coin: &Coin,
    start: &State,
    method: Method,
    (period, periods): (f64, f64),
    quantity: &str,
) -> (StabilityRow, Option<MeasuredNutation>) {
    let config = suite_config(method, period * FIXED_STEP_PER_PERIOD);
    let interval = (period / SAMPLES_PER_PERIOD).min(LARGEST_INTERVAL * coin.params().time_unit());
    let clock = Instant::now();
    let (points, drift) = turning_points(coin, start, &config, periods * period, interval);
    let row = StabilityRow {
        end_time: periods * period,
        energy_drift: drift,
        wall_seconds: clock.elapsed().as_secs_f64(),
        ..StabilityRow::new(case, &config, quantity)
    };
    (row, points.measure())
}

fn circle(coin: &Coin, theta: f64, omega_z: f64, branch: Branch) -> Result<State, BenchError> {
    Steady::new(
        coin,
        SteadyKind::Circle {
            theta,
            omega_z,
            branch,
        },
    )
    .map(|s| s.state)
    .map_err(|e| BenchError::InvalidScene {
        scene: format!("circle θ0 = {theta}, ω_Z0 = {omega_z}"),
        reason: e.to_string(),
    })
}

/// `measured` against `expected`: the row's error (relative; infinite when nothing was measured), value
/// and expectation.
fn judged(row: StabilityRow, measured: Option<f64>, expected: f64) -> StabilityRow {
    StabilityRow {
        max_error: Some(measured.map_or(f64::INFINITY, |m| (m - expected).abs() / expected.abs())),
        measured,
        expected: Some(expected),
        ..row
    }
}

/// The stable circles of the unit thin disk kicked by [`NUTATION_AMPLITUDE`]: σ measured (2π over the
/// period) against eq (21), with every integrator, over `periods` nutation periods.
///
/// # Errors
/// [`BenchError::InvalidScene`] if a circle cannot be built (never for these).
pub fn stable_circles(periods: f64) -> Result<Vec<StabilityRow>, BenchError> {
    let coin = Coin::new(CoinParams::unit_disk());
    let mut rows = Vec::new();
    for (name, theta, omega_z, branch) in [
        ("circle-plus", 0.3, 1.0, Branch::Plus),
        ("circle-minus", 0.3, 1.0, Branch::Minus),
        ("below-the-band", 0.2, 0.08, Branch::Plus),
        ("beyond-the-band", 0.4, 0.3, Branch::Plus),
    ] {
        let steady = circle(&coin, theta, omega_z, branch)?;
        let sigma = steady_sigma_squared(&coin, theta, steady.omega_y, omega_z).sqrt();
        let start = kicked(&coin, &steady, NUTATION_AMPLITUDE);
        for &method in Method::ALL {
            let (row, measured) = measure(
                &format!("nutation-{name}"),
                &coin,
                &start,
                method,
                (TAU / sigma, periods),
                "σ of a kicked circle (2π/T)",
            );
            rows.push(judged(row, measured.map(|m| TAU / m.period), sigma));
        }
    }
    Ok(rows)
}

/// Unstable circles of the unit thin disk inside the band, displaced by [`GROWTH_START`] along the
/// growing mode: the growth rate of ln|ω_X| against √(−σ²), with every integrator.
///
/// # Errors
/// [`BenchError::InvalidScene`] if a circle cannot be built (never for these).
pub fn unstable_circles() -> Result<Vec<StabilityRow>, BenchError> {
    let coin = Coin::new(CoinParams::unit_disk());
    let mut rows = Vec::new();
    for (name, theta, omega_z) in [("in-the-band", 0.2, 0.3), ("near-upright", 0.05, 0.4)] {
        let steady = circle(&coin, theta, omega_z, Branch::Plus)?;
        let lambda = (-steady_sigma_squared(&coin, theta, steady.omega_y, omega_z)).sqrt();
        let start = displaced(&coin, &steady, GROWTH_START);
        let duration = (GROWTH_TO / GROWTH_START).ln() / lambda + 1.0;
        for &method in Method::ALL {
            let config = suite_config(method, TAU / lambda * FIXED_STEP_PER_PERIOD);
            let clock = Instant::now();
            let measured = growth_rate(&coin, &steady, &start, &config, duration, 0.01 / lambda);
            let row = StabilityRow {
                end_time: duration,
                wall_seconds: clock.elapsed().as_secs_f64(),
                ..StabilityRow::new(&format!("growth-{name}"), &config, "growth rate √(−σ²)")
            };
            rows.push(judged(row, measured, lambda));
        }
    }
    Ok(rows)
}

/// The generic motions of the nutation cases: the `wobble` scene's state on the thin disk, a hoop and a
/// body with explicit inertias, each in its natural units.
///
/// # Errors
/// [`BenchError`] if the `wobble` scene does not validate (a bug).
pub fn generic_motions() -> Result<Vec<(&'static str, Coin, State)>, BenchError> {
    let wobble = bench_case("wobble")?.initial;
    let bodies = [
        ("disk", CoinParams::new(1.0, 1.0, 1.0, Inertia::ThinDisk)),
        ("hoop", CoinParams::new(2.0, 0.5, 9.81, Inertia::Hoop)),
        (
            "explicit",
            CoinParams::new(
                0.5,
                2.0,
                9.81,
                Inertia::Explicit {
                    inertia_x: 0.35,
                    inertia_z: 0.6,
                },
            ),
        ),
    ];
    Ok(bodies
        .into_iter()
        .filter_map(|(name, p)| p.ok().map(|p| (name, p)))
        .map(|(name, p)| {
            let w = 1.0 / p.time_unit();
            let state = State {
                omega_x: wobble.omega_x * w,
                omega_y: wobble.omega_y * w,
                omega_z: wobble.omega_z * w,
                ..wobble
            };
            (name, Coin::new(p), state)
        })
        .collect())
}

/// Generic motions ([`generic_motions`]): the period and the heading advance per period measured over
/// `periods` periods against the quadrature, with every integrator (two rows each).
///
/// # Errors
/// [`BenchError::InvalidScene`] if the quadrature fails or the motion is not periodic.
pub fn generic_periods(periods: f64) -> Result<Vec<StabilityRow>, BenchError> {
    let mut rows = Vec::new();
    for (name, coin, state) in generic_motions()? {
        let invalid = |reason: String| BenchError::InvalidScene {
            scene: format!("nutation-{name}"),
            reason,
        };
        let analysis = Analysis::of_state(
            &coin,
            &state,
            coin_log::scene::defaults::FLAT_MARGIN,
            None,
            None,
        )
        .map_err(|e| invalid(e.to_string()))?;
        let Motion::Periodic {
            period, precession, ..
        } = analysis.orbit.motion
        else {
            return Err(invalid("the motion is not periodic".into()));
        };
        for &method in Method::ALL {
            let case = format!("nutation-{name}");
            let (row, measured) = measure(&case, &coin, &state, method, (period, periods), "");
            for (quantity, value, expected) in [
                ("period T", measured.map(|m| m.period), period),
                (
                    "heading advance ΔΦ",
                    measured.map(|m| m.precession),
                    precession,
                ),
            ] {
                let row = StabilityRow {
                    quantity: quantity.to_string(),
                    ..row.clone()
                };
                rows.push(judged(row, value, expected));
            }
        }
    }
    Ok(rows)
}
