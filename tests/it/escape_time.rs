//! The escape from the unstable upright (physics §12): a coin released at rest at a tilt θ₀ lifts off at
//! t = ln(8 tan(θ_L/4)/θ₀)/λ + O(θ₀²), λ² = Mga/(I_X + Ma²), θ_L = π/3 for the thin disk (N = 0 where
//! cos θ = 1/2, events.rs). Over θ₀ = 1e-3 … 1e-300 the recorded lift-off is on that law within the
//! integrator's accuracy, every file verifies and its event is trusted, and analyse's prediction agrees
//! with the recording within analyse's stated error. The negative control integrates with the scene's
//! atol as it stands (the code before the tolerance relative to the departure) and is off the law.

// Helpers outside #[test] functions unwrap too: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::record::record_to_memory;
use coin_log::analyse::Analysis;
use coin_log::format::Termination;
use coin_log::integrate::{run_method, Flow, RunEnd, RunSettings};
use coin_log::record::RecordOptions;
use coin_log::scene::{self, presets, Scene};
use coin_log::simulation::CoinEvents;
use coin_log::verify::{verify_bytes, Options};
use std::f64::consts::PI;

/// The decades k of θ₀ = 10^-k.
const DECADES: [i32; 8] = [3, 6, 12, 25, 50, 100, 200, 300];

/// The lift-off scene released at θ₀ = 10^-k, long enough to reach the lift-off (t ≈ 2.57 k), sampled
/// at 10 per time unit (enough for verify's constraint check; the event is located in the step).
fn released(k: i32) -> Scene {
    let sets: Vec<String> = [
        format!("initial.theta=1e-{k}"),
        "run.duration=900".into(),
        "run.rate=10".into(),
    ]
    .into();
    let file = scene::file_with_sets(&presets::preset("lift-off").unwrap(), &sets).unwrap();
    Scene::from_file(&file).unwrap()
}

/// λ of the unit thin disk: √0.8.
fn lambda(scene: &Scene) -> f64 {
    scene.params.topple_rate_squared().sqrt()
}

/// The ln law without its O(θ₀²) term (below 1e-12 in time from θ₀ = 1e-6 on).
fn law(scene: &Scene, theta0: f64) -> f64 {
    ((8.0 * (PI / 12.0).tan()).ln() - theta0.ln()) / lambda(scene)
}

/// The accuracy the recording claims for an event time t: the integrator's ε = max(rtol, atol/a) per
/// time unit, accumulated over the run with the factor 100 verify's energy tolerance has
/// (format/tolerances.rs): 100 ε (1 + t/τ) τ. Measured errors are below 1e-2 of it (9e-12·t).
fn claimed_error(scene: &Scene, t: f64) -> f64 {
    let m = &scene.run.method;
    let tau = scene.params.time_unit();
    100.0 * m.rtol.max(m.atol / scene.params.radius()) * (1.0 + t / tau) * tau
}

#[test]
fn lift_off_from_near_upright_follows_the_ln_law_is_trusted_verifies_and_analyse_predicts_it() {
    let mut times = Vec::new();
    println!("θ₀ | recorded t | ln-law t | analyse t | analyse error bound");
    for k in DECADES {
        let scene = released(k);
        let theta0 = scene.initial.theta;
        let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
        assert_eq!(summary.termination, Termination::LiftOff, "θ₀ = {theta0:e}");
        let t = summary.termination_time;
        let analysis = Analysis::of_scene(&scene).unwrap();
        let predicted = analysis.orbit.lift_off.unwrap().time;
        let bound = analysis.orbit.error * predicted;
        println!(
            "1e-{k} | {t:.12} | {:.12} | {predicted:.12} | {bound:.2e}",
            law(&scene, theta0)
        );
        assert_eq!(summary.event_trusted, Some(true), "θ₀ = {theta0:e}");
        let report = verify_bytes("escape.mcap", &bytes, &Options::default());
        assert_eq!(report.exit_code, 0, "θ₀ = {theta0:e}: {report:?}");
        assert!(
            (predicted - t).abs() <= bound + claimed_error(&scene, t),
            "θ₀ = {theta0:e}: analyse {predicted} ± {bound:e}, recorded {t}"
        );
        if k >= 6 {
            assert!(
                (t - law(&scene, theta0)).abs() <= claimed_error(&scene, t),
                "θ₀ = {theta0:e}: recorded {t}, the ln law {}",
                law(&scene, theta0)
            );
            assert!(
                (predicted - law(&scene, theta0)).abs() <= bound,
                "θ₀ = {theta0:e}: analyse {predicted} ± {bound:e}, the ln law {}",
                law(&scene, theta0)
            );
        }
        times.push((k, t, lambda(&scene)));
    }
    // t(10^-j) − t(10^-k) = (j − k) ln 10 / λ: the nonlinear part is the same constant for all.
    for pair in times.windows(2) {
        let ((k, t1, l), (j, t2, _)) = (pair[0], pair[1]);
        let expected = f64::from(j - k) * 10f64.ln() / l;
        let relative = ((t2 - t1) - expected).abs() / expected;
        println!(
            "t(1e-{j}) − t(1e-{k}) = {}: relative error {relative:.1e}",
            t2 - t1
        );
        assert!(
            relative <= 1e-6,
            "1e-{k} → 1e-{j}: {} against {expected}",
            t2 - t1
        );
    }
}

/// The lift-off time of `scene` integrated with its atol as given: what `record` did before the
/// tolerance relative to the departure (or `None` when the run does not lift off).
fn lift_off_with_the_scene_atol(scene: &Scene) -> Option<f64> {
    let coin = scene.coin();
    let events = CoinEvents::new(coin, scene.run.flat_margin, scene.friction);
    let settings = RunSettings {
        t0: 0.0,
        t_end: scene.run.duration,
        sample_interval: scene.run.sample_interval(),
    };
    let outcome = run_method(
        &scene.run.method,
        &coin,
        &scene.initial.to_array(),
        &settings,
        &events,
        |_, _| Flow::Continue,
    );
    match outcome.termination {
        RunEnd::Event { t, .. } => Some(t),
        _ => None,
    }
}

#[test]
fn negative_control_the_absolute_tolerance_alone_misses_the_ln_law() {
    for k in [12, 50, 100] {
        let scene = released(k);
        let t = lift_off_with_the_scene_atol(&scene);
        let law = law(&scene, scene.initial.theta);
        println!("θ₀ = 1e-{k}: atol alone {t:?}, the ln law {law}");
        assert!(
            t.is_none_or(|t| (t - law).abs() > 1e3 * claimed_error(&scene, t)),
            "atol alone is on the law at 1e-{k}: {t:?} against {law}"
        );
    }
}

/// Below 2.2e-308 the departure is subnormal: the recording says its event is not to be trusted and why
/// (at 1e-320 it is 5e-4 late), and analyse widens its bound to cover what it computes.
#[test]
fn a_subnormal_departure_gives_an_event_marked_untrusted_with_the_reason() {
    for k in [310, 320] {
        let scene = released(k);
        let (_, summary) = record_to_memory(&scene, &RecordOptions::default());
        let law = law(&scene, scene.initial.theta);
        println!(
            "θ₀ = 1e-{k}: recorded {} ({:?}), the ln law {law}",
            summary.termination_time, summary.event_trusted
        );
        assert_eq!(summary.event_trusted, Some(false), "1e-{k}");
        assert!(
            summary
                .event_doubt
                .as_deref()
                .unwrap()
                .contains("subnormal")
                || summary.event_doubt.as_deref().unwrap().contains("2.2e-308"),
            "{:?}",
            summary.event_doubt
        );
        let orbit = Analysis::of_scene(&scene).unwrap().orbit;
        let predicted = orbit.lift_off.unwrap().time;
        assert!(
            (predicted - law).abs() <= orbit.error * predicted,
            "1e-{k}: analyse {predicted} ± {:e}, the ln law {law}",
            orbit.error * predicted
        );
    }
}
