//! Proof by simulation of `analyse` (physics §9, §10), for `bench stability` and the tests: a perturbed
//! stable circle nutates at σ, a perturbed unstable circle grows at √(−σ²), and a generic motion's period
//! and heading advance per period are those of the quadrature. Every case is simulated with every
//! integrator, and the frequency, rate, period and heading advance are measured from the samples alone.
//!
//! **Measuring.** The samples are 1/64 of a nutation period apart (at most 0.01 time units); the turning
//! points of θ are the sign changes of ω_X = θ̇ between samples, located on the cubic Hermite interpolant
//! of ω_X and ω̇_X (eq (14)) to ~(hσ)⁴/384 of a period, and φ there on the cubic Hermite interpolant of φ
//! and φ̇. The period is the mean spacing of like turning points, the heading advance the mean advance of
//! φ between them. A growth rate is the least-squares slope of ln|ω_X| over a window where the
//! perturbation has outgrown the decaying mode and is still small (amplitudes 1e-9 to 1e-5 of a radian,
//! so the nonlinear terms are ≤ 1e-5 relative).

use super::stability::{suite_config, StabilityRow};
use super::BenchError;
use coin_log::analyse::Analysis;
use coin_log::integrate::{run_method, Flow, Method, MethodConfig, NoEvents, RunSettings};
use coin_log::model::nutation::Motion;
use coin_log::model::{
    energy, steady_sigma_squared, Branch, Coin, CoinParams, Inertia, Linearisation, State, Steady,
    SteadyKind,
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
/// Fixed step of rk4 and gauss4 in the nutation cases, as a fraction of a nutation period.
const FIXED_STEP_PER_PERIOD: f64 = 1.0 / 2048.0;

/// The turning points of θ measured from one run: (t, φ) of the maxima and of the minima.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TurningPoints {
    /// Maxima of θ (ω_X from + to −).
    pub maxima: Vec<(f64, f64)>,
    /// Minima of θ (ω_X from − to +).
    pub minima: Vec<(f64, f64)>,
}

impl TurningPoints {
    /// (T, ΔΦ) as the mean spacing of like turning points (maxima and minima averaged, weighted by the
    /// number of periods each spans); `None` with fewer than two periods of either kind.
    #[must_use]
    pub fn period(&self) -> Option<(f64, f64)> {
        let per_kind = |points: &[(f64, f64)]| {
            let (first, last) = (points.first()?, points.last()?);
            #[allow(clippy::cast_precision_loss)]
            let periods = (points.len() - 1) as f64;
            (periods >= 2.0).then(|| {
                (
                    (last.0 - first.0) / periods,
                    (last.1 - first.1) / periods,
                    periods,
                )
            })
        };
        let kinds: Vec<(f64, f64, f64)> = [per_kind(&self.maxima), per_kind(&self.minima)]
            .into_iter()
            .flatten()
            .collect();
        let weight: f64 = kinds.iter().map(|k| k.2).sum();
        (!kinds.is_empty()).then(|| {
            (
                kinds.iter().map(|k| k.0 * k.2).sum::<f64>() / weight,
                kinds.iter().map(|k| k.1 * k.2).sum::<f64>() / weight,
            )
        })
    }
}

/// Runs `config` from `initial` for `duration` with samples `interval` apart and collects θ's turning
/// points (module doc). Also returns the samples' largest energy drift.
#[must_use]
pub fn turning_points(
    coin: &Coin,
    initial: &State,
    config: &MethodConfig,
    duration: f64,
    interval: f64,
) -> (TurningPoints, f64) {
    let settings = RunSettings {
        t0: 0.0,
        t_end: duration,
        sample_interval: interval,
    };
    let e0 = energy(coin, initial).total;
    let scale = e0.abs().max(coin.params().energy_scale());
    let mut drift = 0.0_f64;
    let mut points = TurningPoints::default();
    let mut previous: Option<(f64, State)> = None;
    run_method(
        config,
        coin,
        &initial.to_array(),
        &settings,
        &NoEvents,
        |t, y| {
            let s = State::from_array(y);
            drift = drift.max((energy(coin, &s).total - e0).abs() / scale);
            if let Some((tp, p)) = previous {
                if p.omega_x > 0.0 && s.omega_x <= 0.0 {
                    points.maxima.push(crossing(coin, (tp, &p), (t, &s)));
                } else if p.omega_x < 0.0 && s.omega_x >= 0.0 {
                    points.minima.push(crossing(coin, (tp, &p), (t, &s)));
                }
            }
            previous = Some((t, s));
            Flow::Continue
        },
    );
    (points, drift)
}

/// The cubic Hermite interpolant of (y0, d0) at s = 0 and (y1, d1) at s = 1, derivatives per unit time,
/// samples `h` apart: value and derivative with respect to s.
fn hermite(s: f64, h: f64, (y0, d0): (f64, f64), (y1, d1): (f64, f64)) -> (f64, f64) {
    let (s2, s3) = (s * s, s * s * s);
    (
        (2.0 * s3 - 3.0 * s2 + 1.0) * y0
            + (s3 - 2.0 * s2 + s) * h * d0
            + (3.0 * s2 - 2.0 * s3) * y1
            + (s3 - s2) * h * d1,
        (6.0 * s2 - 6.0 * s) * y0
            + (3.0 * s2 - 4.0 * s + 1.0) * h * d0
            + (6.0 * s - 6.0 * s2) * y1
            + (3.0 * s2 - 2.0 * s) * h * d1,
    )
}

/// (t, φ) where ω_X crosses zero between two samples (Newton on the Hermite cubic of ω_X).
fn crossing(coin: &Coin, (ta, a): (f64, &State), (tb, b): (f64, &State)) -> (f64, f64) {
    let h = tb - ta;
    let rate = |s: &State| {
        let acc = coin.angular_acceleration(s.theta, s.omega_x, s.omega_y, s.omega_z);
        ((s.omega_x, acc.x), (s.phi, s.omega_y / s.theta.cos()))
    };
    let ((wa, phia), (wb, phib)) = (rate(a), rate(b));
    let mut x = if a.omega_x == b.omega_x {
        1.0
    } else {
        a.omega_x / (a.omega_x - b.omega_x)
    };
    for _ in 0..50 {
        let (v, dv) = hermite(x, h, wa, wb);
        if dv == 0.0 {
            break;
        }
        let next = (x - v / dv).clamp(0.0, 1.0);
        let done = (next - x).abs() <= 4.0 * f64::EPSILON;
        x = next;
        if done {
            break;
        }
    }
    (ta + x * h, hermite(x, h, phia, phib).0)
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
    let settings = RunSettings {
        t0: 0.0,
        t_end: duration,
        sample_interval: interval,
    };
    let mut points = Vec::new();
    run_method(
        config,
        coin,
        &initial.to_array(),
        &settings,
        &NoEvents,
        |t, y| {
            let s = State::from_array(y);
            let amplitude = (s.theta - base.theta).abs();
            if (GROWTH_FROM..=GROWTH_TO).contains(&amplitude) && s.omega_x != 0.0 {
                points.push((t, s.omega_x.abs().ln()));
            }
            if amplitude > GROWTH_TO {
                Flow::Stop
            } else {
                Flow::Continue
            }
        },
    );
    if points.len() < 10 {
        return None;
    }
    #[allow(clippy::cast_precision_loss)]
    let n = points.len() as f64;
    let (mt, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let cov: f64 = points.iter().map(|p| (p.0 - mt) * (p.1 - my)).sum();
    let var: f64 = points.iter().map(|p| (p.0 - mt) * (p.0 - mt)).sum();
    Some(cov / var)
}

/// A steady circle kicked along the oscillating mode of its linearisation: δω_X = σ·amplitude, which
/// excites only the pair ±iσ (the eigenvector's imaginary part is (0, σ, 0, 0), physics §9), so the
/// motion nutates about the circle itself and its frequency differs from σ by O(amplitude²).
#[must_use]
pub fn kicked(coin: &Coin, steady: &State, amplitude: f64) -> State {
    let sigma2 = steady_sigma_squared(coin, steady.theta, steady.omega_y, steady.omega_z);
    State {
        omega_x: steady.omega_x + sigma2.max(0.0).sqrt() * amplitude,
        ..*steady
    }
}

/// A steady circle displaced along the growing mode of its linearisation: the eigenvector of
/// λ = √(−σ²) is (1, λ, D, E) with D, E the entries of physics §9, so the perturbation grows like e^{λt}
/// from t = 0 without a decaying part.
#[must_use]
pub fn displaced(coin: &Coin, steady: &State, amplitude: f64) -> State {
    let l = Linearisation::at(coin, steady.theta, steady.omega_y, steady.omega_z);
    let lambda = (-l.sigma_squared()).max(0.0).sqrt();
    State {
        theta: steady.theta + amplitude,
        omega_x: steady.omega_x + lambda * amplitude,
        omega_y: steady.omega_y + l.d * amplitude,
        omega_z: steady.omega_z + l.e * amplitude,
        ..*steady
    }
}

/// The settings of one nutation case's run with `method`: the suite's tight tolerances, or a fixed step of
/// 1/2048 of the period.
fn config(method: Method, period: f64) -> MethodConfig {
    suite_config(method, period * FIXED_STEP_PER_PERIOD)
}

/// The sample interval for a motion of period `period`.
fn interval(coin: &Coin, period: f64) -> f64 {
    (period / SAMPLES_PER_PERIOD).min(LARGEST_INTERVAL * coin.params().time_unit())
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

fn row(case: &str, method: Method, cfg: &MethodConfig, quantity: &str) -> StabilityRow {
    StabilityRow {
        case: case.to_string(),
        integrator: method,
        setting: if method.is_adaptive() {
            format!("rtol {:e} atol {:e}", cfg.rtol, cfg.atol)
        } else {
            format!("h {:.3e}", cfg.step)
        },
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

fn relative(measured: Option<f64>, expected: f64) -> Option<f64> {
    Some(measured.map_or(f64::INFINITY, |m| (m - expected).abs() / expected.abs()))
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
        let period = TAU / sigma;
        let start = kicked(&coin, &steady, NUTATION_AMPLITUDE);
        for &method in Method::ALL {
            let cfg = config(method, period);
            let clock = Instant::now();
            let (points, drift) = turning_points(
                &coin,
                &start,
                &cfg,
                periods * period,
                interval(&coin, period),
            );
            let measured = points.period().map(|(t, _)| TAU / t);
            rows.push(StabilityRow {
                end_time: periods * period,
                max_error: relative(measured, sigma),
                energy_drift: drift,
                wall_seconds: clock.elapsed().as_secs_f64(),
                measured,
                expected: Some(sigma),
                ..row(
                    &format!("nutation-{name}"),
                    method,
                    &cfg,
                    "σ of a kicked circle (2π/T)",
                )
            });
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
            let cfg = config(method, TAU / lambda);
            let clock = Instant::now();
            let measured = growth_rate(&coin, &steady, &start, &cfg, duration, 0.01 / lambda);
            rows.push(StabilityRow {
                end_time: duration,
                max_error: relative(measured, lambda),
                wall_seconds: clock.elapsed().as_secs_f64(),
                measured,
                expected: Some(lambda),
                ..row(
                    &format!("growth-{name}"),
                    method,
                    &cfg,
                    "growth rate √(−σ²)",
                )
            });
        }
    }
    Ok(rows)
}

/// The generic motions of the nutation cases: the `wobble` scene's state on the thin disk, a hoop and a
/// body with explicit inertias, each in its natural units.
#[must_use]
pub fn generic_motions() -> Vec<(&'static str, Coin, State)> {
    let wobble = State {
        theta: 0.5,
        omega_x: 0.3,
        omega_y: 0.2,
        omega_z: 1.5,
        ..State::default()
    };
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
    bodies
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
        .collect()
}

/// Generic motions ([`generic_motions`]): the period and the heading advance per period measured over
/// `periods` periods against the quadrature, with every integrator (two rows each).
///
/// # Errors
/// [`BenchError::InvalidScene`] if the quadrature fails or the motion is not periodic.
pub fn generic_periods(periods: f64) -> Result<Vec<StabilityRow>, BenchError> {
    let mut rows = Vec::new();
    for (name, coin, state) in generic_motions() {
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
            let cfg = config(method, period);
            let clock = Instant::now();
            let (points, drift) = turning_points(
                &coin,
                &state,
                &cfg,
                periods * period,
                interval(&coin, period),
            );
            let wall = clock.elapsed().as_secs_f64();
            let measured = points.period();
            for (quantity, value, expected) in [
                ("period T", measured.map(|m| m.0), period),
                ("heading advance ΔΦ", measured.map(|m| m.1), precession),
            ] {
                rows.push(StabilityRow {
                    end_time: periods * period,
                    max_error: relative(value, expected),
                    energy_drift: drift,
                    wall_seconds: wall,
                    measured: value,
                    expected: Some(expected),
                    ..row(&format!("nutation-{name}"), method, &cfg, quantity)
                });
            }
        }
    }
    Ok(rows)
}
