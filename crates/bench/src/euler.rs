//! Euler's disk (`bench euler`, physics §11): each dissipation preset on the toy disk of the `euler-disk`
//! scene, started on its centre-fixed motion at α₀ = 0.2, integrated until an event (lift-off, slip at the
//! scene's μ, flat landing) or, without a finite-time singularity, for a fixed time. On each run a power law
//! α = A |t₀ − t|^n is fitted (t₀ fitted too) on a window well above the breakdown of the slow-change
//! approximation, and n is compared with the prediction n = 1/(1 − p), p = −m/2 − k (eq (38)).
//!
//! **The presets are compared at equal time scale.** κ of each preset is set so that the slow-change law
//! sin^(1−p) α = sin^(1−p) α₀ − (1 − p) C t (eq (37)) has the time scale T = sin^(1−p) α₀ / (|1 − p| C)
//! of the `euler-disk` scene's Moffatt coefficient (T = t₀ ≈ 849 s there); for p < 1, T is the collapse
//! time t₀, for p > 1 (pivoting) the time in which α falls to α₀/4 (α = α₀ (1 + t/T)^(−2)).
//!
//! **The window.** The slow-change approximation holds while α changes little during a nutation period:
//! ε(α) = |α̇| / (α σ) ≪ 1, σ the nutation frequency of the centre-fixed motion at α (physics §5) and α̇ the
//! slow-change rate. The window runs from α = 0.1 (half of α₀, past the start) down to the α at which
//! ε = [`EulerOptions::epsilon`] (for p < 1/2, where ε grows as α falls), or to 1.5 times the smallest α
//! the run reached. Samples are thinned to be evenly spaced in ln α.
//!
//! **t₀.** Fitted with n and A ([`power_law`]), on both sides of the window: after it (a finite-time
//! singularity, n > 0) and before it (a power-law decay, n < 0). Extrapolating t₀ from the run's end
//! instead would bias n, since the event comes a finite time before t₀.
//!
//! The slow-change laws themselves are the library's ([`coin_log::analyse::slow_change`]).

use super::case::{run_sampled_with, Trajectory};
use super::{BenchCase, BenchError};
use coin_log::analyse::slow_change::{
    alpha_of, breakdown_alpha, coefficient_for, slow_change_time_scale,
};
use coin_log::integrate::RunSettings;
use coin_log::model::fit::{power_law, PowerLaw};
use coin_log::model::{Dissipation, DissipationModel, State};
use coin_log::scene::{presets, Scene};
use std::time::Instant;

/// The scene whose body, start, μ and Moffatt coefficient the bench uses.
pub const SCENE: &str = "euler-disk";
/// Upper end of the fit window: α = 0.1 rad, half of α₀, past the start.
pub const WINDOW_TOP: f64 = 0.1;
/// The window ends this factor above the smallest α of the run (the run's end is no slow change).
const END_MARGIN: f64 = 1.5;
/// Points of the thinned window (evenly spaced in ln α).
const WINDOW_POINTS: usize = 400;
/// Samples per run (the window's end needs a fine grid in time).
const SAMPLES: f64 = 2e5;

/// How the bench runs.
#[derive(Debug, Clone, PartialEq)]
pub struct EulerOptions {
    /// ε = |α̇|/(α σ) at the window's lower end.
    pub epsilon: f64,
    /// α at the window's upper end.
    pub top: f64,
    /// Largest share ω_Z²/|ω|² of the spin in the window (the departure from the centre-fixed family).
    pub spin_share: f64,
    /// Duration of runs without a finite-time singularity, in units of the time scale T.
    pub decay_duration: f64,
    /// The presets to run.
    pub models: Vec<DissipationModel>,
}

impl EulerOptions {
    /// Every preset; window down to ε = 1e-3; decays for 3 T.
    #[must_use]
    pub fn full() -> Self {
        Self {
            epsilon: 1e-3,
            top: WINDOW_TOP,
            spin_share: 1e-2,
            decay_duration: 3.0,
            models: DissipationModel::PRESETS.to_vec(),
        }
    }
}

coin_log_names::named_enum! {
    /// What ends the fit window at small α; its name is the one in the table and the CSV.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum WindowLimit: "window limit" {
        /// ε = |α̇|/(α σ) reached [`EulerOptions::epsilon`]: the slow-change approximation starts to fail.
        SlowChange = "slow-change",
        /// ω_Z²/|ω|² reached [`EulerOptions::spin_share`]: the motion has drifted off the centre-fixed
        /// family on which the prediction is made (the spin ω_Z picked up on the way takes a share of P).
        SpinShare = "spin-share",
        /// 1.5 times the smallest α of the run.
        RunEnd = "run-end",
    }
}

/// One preset's run and fit.
#[derive(Debug, Clone, PartialEq)]
pub struct EulerRow {
    /// The law (model, κ, m, k).
    pub dissipation: Dissipation,
    /// p = −m/2 − k.
    pub p: f64,
    /// n = 1/(1 − p) ([`Dissipation::predicted_exponent`]).
    pub predicted: f64,
    /// The fit; `None` when the window holds fewer than 10 points.
    pub fit: Option<PowerLaw>,
    /// The window: α from `alpha_window.0` to `alpha_window.1`.
    pub alpha_window: (f64, f64),
    /// What set the window's lower end.
    pub limit: WindowLimit,
    /// The window's times.
    pub time_window: (f64, f64),
    /// Points fitted.
    pub points: usize,
    /// The slow-change time scale T of the presets (eq (37)).
    pub time_scale: f64,
    /// How the run without μ ended (the scene has none): `lift-off`, `flat-landing` or `completed`.
    pub end: DiskEnd,
    /// The smallest N/(Mg) of the run without μ, and α there.
    pub lowest_normal: (f64, f64),
    /// How the same run with μ = [`SLIP_FRICTION`] ended: a `slip` when friction gives out first.
    pub with_friction: DiskEnd,
    /// The thinned samples (t, α) of the whole run, for the diagram.
    pub samples: Vec<(f64, f64)>,
    /// Wall time of the run without μ \[s\].
    pub wall_seconds: f64,
}

impl EulerRow {
    /// |n − n_predicted| / |n_predicted|; `None` without a fit.
    #[must_use]
    pub fn relative_error(&self) -> Option<f64> {
        self.fit
            .map(|f| (f.exponent - self.predicted).abs() / self.predicted.abs())
    }
}

/// The bench's setting: the `euler-disk` scene and its slow-change time scale.
#[derive(Debug, Clone)]
pub struct EulerSetting {
    /// The scene (body, start, μ, flat margin, Moffatt's κ).
    pub scene: Scene,
    /// The time scale T every preset is given (the scene's t₀).
    pub time_scale: f64,
}

impl EulerSetting {
    /// The `euler-disk` scene and the time scale of its own dissipation.
    ///
    /// # Errors
    /// [`BenchError::InvalidScene`] if the preset does not validate or has no dissipation (a bug).
    pub fn from_preset() -> Result<Self, BenchError> {
        let invalid = |reason: String| BenchError::InvalidScene {
            scene: SCENE.into(),
            reason,
        };
        let file = presets::preset(SCENE).ok_or_else(|| invalid("no such preset".into()))?;
        let scene = Scene::from_file(&file).map_err(|e| invalid(e.to_string()))?;
        let law = scene
            .dissipation
            .ok_or_else(|| invalid("the scene has no dissipation".into()))?;
        let time_scale = slow_change_time_scale(&scene.coin(), &law, alpha_of(&scene.initial));
        Ok(Self { scene, time_scale })
    }

    /// α₀ of the scene.
    #[must_use]
    pub fn alpha0(&self) -> f64 {
        alpha_of(&self.scene.initial)
    }
}

/// The friction coefficient at which the bench reports where rolling without slipping breaks down first.
pub const SLIP_FRICTION: f64 = 0.3;

/// How a run ended: its termination, time and α.
#[derive(Debug, Clone, PartialEq)]
pub struct DiskEnd {
    /// `lift-off`, `slip`, `flat-landing`, `completed`, or a failure.
    pub termination: String,
    /// When \[time\].
    pub time: f64,
    /// α = π/2 − |θ| there \[rad\].
    pub alpha: f64,
}

/// The bench case of one law on the setting.
fn model_case(
    setting: &EulerSetting,
    law: Dissipation,
    duration: f64,
    friction: Option<f64>,
) -> BenchCase {
    BenchCase {
        name: format!("{SCENE}/{}", law.model()),
        coin: setting.scene.coin(),
        initial: setting.scene.initial,
        steady: None,
        duration,
        flat_margin: setting.scene.run.flat_margin,
        friction,
        dissipation: Some(law),
    }
}

/// One run of a law: its (t, α) series, its end, the α at which the spin share ω_Z²/|ω|² first exceeds
/// the bench's limit (0 if never), and the wall time.
struct AlphaSeries {
    series: Vec<(f64, f64)>,
    end: DiskEnd,
    spin_alpha: f64,
    lowest_normal: (f64, f64),
    wall_seconds: f64,
}

/// Runs `case` with the scene's integrator settings (dop853 at the default tolerances), sampling α at
/// [`SAMPLES`] points.
fn alpha_series(setting: &EulerSetting, case: &BenchCase, spin_share: f64) -> AlphaSeries {
    let settings = RunSettings {
        t0: 0.0,
        t_end: case.duration,
        sample_interval: case.duration / SAMPLES,
    };
    let started = Instant::now();
    let mut run = Trajectory::default();
    run_sampled_with(&setting.scene.run.method, case, &settings, &mut run);
    let wall_seconds = started.elapsed().as_secs_f64();
    let series: Vec<(f64, f64)> = run
        .times
        .iter()
        .zip(&run.states)
        .map(|(t, y)| (*t, alpha_of(&State::from_array(y))))
        .collect();
    let (time, alpha) = series
        .last()
        .copied()
        .unwrap_or((0.0, alpha_of(&case.initial)));
    let end = DiskEnd {
        termination: run.termination_name(),
        time,
        alpha,
    };
    let spin_alpha = run
        .states
        .iter()
        .map(State::from_array)
        .find(|s| {
            let w2 = s.omega_x * s.omega_x + s.omega_y * s.omega_y + s.omega_z * s.omega_z;
            s.omega_z * s.omega_z > spin_share * w2
        })
        .map_or(0.0, |s| alpha_of(&s));
    AlphaSeries {
        series,
        end,
        spin_alpha,
        lowest_normal: lowest_normal(case, &run),
        wall_seconds,
    }
}

/// The smallest N/(Mg) over the samples of a run, and α there (physics §11: how close it came to lift-off).
fn lowest_normal(case: &BenchCase, run: &Trajectory) -> (f64, f64) {
    let dynamics = case.dynamics();
    let p = case.coin.params();
    let weight = p.mass() * p.gravity();
    run.states
        .iter()
        .map(|y| {
            let s = State::from_array(y);
            (dynamics.reaction(&s).normal / weight, alpha_of(&s))
        })
        .fold(
            (f64::INFINITY, 0.0),
            |low, n| if n.0 < low.0 { n } else { low },
        )
}

/// Runs one preset on the setting and fits its law; runs it again with μ = [`SLIP_FRICTION`] to see
/// whether it slips before the run's own end.
///
/// # Errors
/// [`BenchError::InvalidScene`] if the preset's law cannot be built.
pub fn run_model(
    setting: &EulerSetting,
    model: DissipationModel,
    options: &EulerOptions,
) -> Result<EulerRow, BenchError> {
    let coin = setting.scene.coin();
    let alpha0 = setting.alpha0();
    let law = coefficient_for(&coin, model, alpha0, setting.time_scale).map_err(|e| {
        BenchError::InvalidScene {
            scene: SCENE.into(),
            reason: e.to_string(),
        }
    })?;
    let p = law.angle_exponent();
    let factor = if p < 1.0 { 2.0 } else { options.decay_duration };
    let duration = setting.time_scale * factor;
    let free = alpha_series(
        setting,
        &model_case(setting, law, duration, setting.scene.friction),
        options.spin_share,
    );
    let with_friction = alpha_series(
        setting,
        &model_case(setting, law, duration, Some(SLIP_FRICTION)),
        options.spin_share,
    )
    .end;
    let series = free.series;
    let smallest = series.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
    let limits = [
        (
            breakdown_alpha(&coin, &law, alpha0, options.epsilon),
            WindowLimit::SlowChange,
        ),
        (free.spin_alpha, WindowLimit::SpinShare),
        (END_MARGIN * smallest, WindowLimit::RunEnd),
    ];
    let (bottom, limit) = limits
        .into_iter()
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((0.0, WindowLimit::RunEnd));
    let window = thin(&series, options.top, bottom);
    let fit = (window.len() >= 10).then(|| power_law(&window)).flatten();
    Ok(EulerRow {
        dissipation: law,
        p,
        predicted: law.predicted_exponent(),
        fit,
        alpha_window: (bottom, options.top),
        limit,
        time_window: (
            window.first().map_or(0.0, |w| w.0),
            window.last().map_or(0.0, |w| w.0),
        ),
        points: window.len(),
        time_scale: setting.time_scale,
        end: free.end,
        lowest_normal: free.lowest_normal,
        with_friction,
        samples: thin(&series, f64::INFINITY, 0.0),
        wall_seconds: free.wall_seconds,
    })
}

/// The samples with α in [bottom, top], thinned to about `WINDOW_POINTS` (400) evenly spaced in ln α: a
/// sample is kept when α has fallen by the spacing since the last kept one (the first sample in range is
/// kept). With `top` infinite, the whole run, thinned the same way over its own range.
#[must_use]
pub fn thin(series: &[(f64, f64)], top: f64, bottom: f64) -> Vec<(f64, f64)> {
    let inside: Vec<(f64, f64)> = series
        .iter()
        .copied()
        .filter(|(_, a)| *a <= top && *a >= bottom && *a > 0.0)
        .collect();
    let (hi, lo) = inside
        .iter()
        .fold((0.0_f64, f64::INFINITY), |(h, l), (_, a)| {
            (h.max(*a), l.min(*a))
        });
    if inside.is_empty() || hi <= lo {
        return inside;
    }
    #[allow(clippy::cast_precision_loss)]
    let spacing = (hi / lo).ln() / WINDOW_POINTS as f64;
    let mut kept: Vec<(f64, f64)> = Vec::with_capacity(WINDOW_POINTS + 1);
    for &(t, a) in &inside {
        match kept.last() {
            Some(&(_, last)) if (last / a).ln() < spacing => {}
            _ => kept.push((t, a)),
        }
    }
    kept
}

/// Every preset of `options`, in order.
///
/// # Errors
/// As [`run_model`], and [`EulerSetting::from_preset`].
pub fn euler_bench(options: &EulerOptions) -> Result<Vec<EulerRow>, BenchError> {
    let setting = EulerSetting::from_preset()?;
    options
        .models
        .iter()
        .map(|&m| run_model(&setting, m, options))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinning_keeps_evenly_spaced_logs() {
        let series: Vec<(f64, f64)> = (0..100_000)
            .map(|i| {
                let t = f64::from(i);
                (t, (-t / 1e4).exp())
            })
            .collect();
        let kept = thin(&series, 0.5, 0.01);
        assert!(
            kept.len() > WINDOW_POINTS / 2 && kept.len() <= WINDOW_POINTS + 1,
            "{}",
            kept.len()
        );
    }
}
