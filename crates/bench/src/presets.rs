//! Bench cases from scenes: the built-in scenes of [`coin_log::scene::presets`] by name, or any validated
//! [`Scene`] (a `.toml` file read by the CLI).

use super::{BenchCase, BenchError};
use coin_log::scene::{self, presets, Scene};

/// Scenes `bench precision` runs when none are given: a generic wobble, a steady circle (analytic
/// reference) and a fast spin.
pub const DEFAULT_PRECISION_SCENES: &[&str] = &["wobble", "circle-plus", "high-spin"];

impl BenchCase {
    /// The bench case of a validated scene: its coin, initial state, duration, flat margin and friction;
    /// the analytic reference when it starts on an unperturbed steady motion.
    #[must_use]
    pub fn from_scene(name: &str, scene: &Scene) -> Self {
        Self {
            name: name.to_string(),
            coin: scene.coin(),
            initial: scene.initial,
            steady: scene.unperturbed_steady().copied(),
            duration: scene.run.duration,
            flat_margin: scene.run.flat_margin,
            friction: scene.friction,
            dissipation: scene.dissipation,
        }
    }
}

/// The bench case of a built-in scene.
///
/// # Errors
/// [`BenchError::UnknownScene`] for a name that is not a built-in; [`BenchError::InvalidScene`] if the
/// preset does not validate (a bug: presets are tested to).
pub fn bench_case(name: &str) -> Result<BenchCase, BenchError> {
    let file = presets::preset(name).ok_or_else(|| BenchError::UnknownScene {
        name: name.to_string(),
        valid: presets::NAMES.join(", "),
    })?;
    let scene = Scene::from_file(&file).map_err(|e| BenchError::InvalidScene {
        scene: name.to_string(),
        reason: e.to_string(),
    })?;
    Ok(BenchCase::from_scene(name, &scene))
}

/// The bench case of a scene file's text, named `name` (the file stem).
///
/// # Errors
/// [`BenchError::InvalidScene`] with every problem the scene validation found.
pub fn bench_case_from_toml(name: &str, text: &str) -> Result<BenchCase, BenchError> {
    let invalid = |e: scene::SceneError| BenchError::InvalidScene {
        scene: name.to_string(),
        reason: e.to_string(),
    };
    let file = scene::parse_with_sets(text, &[]).map_err(invalid)?;
    let scene = Scene::from_file(&file).map_err(invalid)?;
    Ok(BenchCase::from_scene(name, &scene))
}
