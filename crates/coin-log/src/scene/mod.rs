//! What to simulate (format.md: Scene files): [`SceneFile`] mirrors the TOML exactly, [`Scene`] is the
//! validated, resolved scene that reaches the recorder. Loading goes: text or preset → TOML table →
//! `--set` edits ([`apply_set`]) → [`SceneFile`] → flags ([`FlagOverrides`]) → [`resolve`], which reports
//! every problem at once.

mod file;
pub mod limits;
mod notes;
mod overrides;
pub mod presets;
mod problems;
mod readable;
mod validate;

pub use file::{
    BodyFile, DissipationFile, InitialFile, PerturbationFile, RecordFile, RunFile, SceneFile,
    SteadyFile,
};
pub use notes::{compact, Note};
pub use overrides::{apply_set, set_value, FlagOverrides};
pub(crate) use overrides::{dotted, other_form};
pub(crate) use problems::ProblemCollector;
pub use problems::{Problem, SceneProblems};
pub use readable::{readable_toml, Short};
pub use validate::{DESCRIPTION_MAX_CHARS, UNEXPLAINED};

use crate::format::{Channel, RunMetadata, FORMAT_VERSION};
use crate::integrate::MethodConfig;
use crate::model::{Coin, CoinParams, Dissipation, Dynamics, Inertia, State, Steady};

/// Defaults of the optional scene keys, each the key of its name (format.md: Keys).
#[allow(missing_docs)]
pub mod defaults {
    pub const RATE: f64 = 100.0;
    pub const INTEGRATOR: &str = "dop853";
    /// Relative tolerance: close to what dop853 can deliver in double precision over tens of time units.
    pub const RTOL: f64 = 1e-10;
    /// Absolute tolerance: two digits below RTOL so that components through zero do not starve the step.
    pub const ATOL: f64 = 1e-12;
    pub const STEP: f64 = 1e-3;
    /// Most integrator steps of a run (format.md: Limits): about 15 s of rk4 and a minute of dop853 (0.15
    /// and 0.65 µs a step), 10⁴ times what the longest built-in scene takes with dop853.
    pub const MAX_STEPS: u64 = 100_000_000;
    /// Flat-landing margin \[rad\]: tan θ ≈ 1e4 there, still well inside double precision.
    pub const FLAT_MARGIN: f64 = 1e-4;
    /// Display thickness, a fraction of the radius (a 500-yen coin is 1.8 mm thick for 13.25 mm radius).
    pub const THICKNESS: f64 = 0.05;
    pub const BRANCH: crate::model::Branch = crate::model::Branch::Plus;
}

/// Largest number of samples a scene may ask for (duration × rate): 10¹¹, far beyond any disk.
pub const MAX_SAMPLES: f64 = 1e11;

/// Why a scene could not be loaded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// The TOML does not parse or does not fit the scene's keys and types (serde's message, alone).
    #[error("{0}")]
    Parse(String),
    /// A `--set KEY=VALUE` (`arg`, as given) that cannot be applied, and why.
    #[allow(missing_docs)]
    #[error("`--set {arg}`: {reason}")]
    Set { arg: String, reason: String },
    /// Values out of range, missing or contradictory; every problem found (at least one).
    #[error("{0}")]
    Invalid(SceneProblems),
}

/// How the initial state was specified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InitialSpec {
    /// θ and ω given.
    Explicit,
    /// Solved from a steady motion (physics §4).
    Steady(Steady),
}

/// Duration, sampling and integration settings: the `[run]` keys of their names, validated (format.md:
/// Keys).
#[allow(missing_docs)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunConfig {
    pub duration: f64,
    pub rate: f64,
    /// Method with the settings it uses: rtol and atol for adaptive methods (step 0), the step actually
    /// used for fixed-step ones, rounded down to divide 1/rate (rtol and atol 0).
    pub method: MethodConfig,
    pub flat_margin: f64,
    pub max_steps: u64,
}

impl RunConfig {
    /// Distance between samples, 1/rate \[time\].
    #[must_use]
    pub fn sample_interval(&self) -> f64 {
        1.0 / self.rate
    }
}

/// A validated scene: everything the recorder needs, nothing left to check; a field without a doc is the
/// key (or table) of its name (format.md: Keys), resolved.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub description: String,
    /// M, a, g, I_X, I_Z.
    pub params: CoinParams,
    /// How the inertia was given (kept to write the scene back).
    pub inertia: Inertia,
    pub friction: Option<f64>,
    pub thickness: f64,
    pub dissipation: Option<Dissipation>,
    /// The state at t = 0, perturbation included.
    pub initial: State,
    /// The state before the perturbation (the explicit state or the steady motion, with φ, ψ, x, z).
    pub base: State,
    pub spec: InitialSpec,
    /// The perturbation (θ, ω_X, ω_Y, ω_Z) added to the initial state; zeros when none.
    pub perturbation: [f64; 4],
    pub run: RunConfig,
    /// Channels to record, in the contract's order, each once.
    pub channels: Vec<Channel>,
}

impl Scene {
    /// Validates and resolves a scene file: [`SceneError::Invalid`] names every bad, missing or
    /// contradictory key.
    pub fn from_file(file: &SceneFile) -> Result<Self, SceneError> {
        validate::scene_from_file(file, &[])
    }

    /// The coin (precomputed right-hand side).
    #[must_use]
    pub fn coin(&self) -> Coin {
        Coin::new(self.params)
    }

    /// The coin with its dissipation, if any: the equations the scene integrates (physics §2, §11).
    #[must_use]
    pub fn dynamics(&self) -> Dynamics {
        Dynamics::new(self.coin(), self.dissipation)
    }

    /// The steady motion the scene starts on, when it was given as one, not perturbed and without
    /// dissipation: then the whole run should stay on it (the `steady_kind` of the metadata). A dissipative
    /// couple moves the coin off every steady motion (physics §11), so a dissipative scene has none.
    #[must_use]
    pub fn unperturbed_steady(&self) -> Option<&Steady> {
        match &self.spec {
            InitialSpec::Steady(s)
                if self.perturbation.iter().all(|&p| p == 0.0) && self.dissipation.is_none() =>
            {
                Some(s)
            }
            _ => None,
        }
    }

    /// True when `channel` is recorded.
    #[must_use]
    pub fn records(&self, channel: Channel) -> bool {
        self.channels.contains(&channel)
    }

    /// The resolved scene as a file: every default written out, so it reads back to the same scene.
    #[must_use]
    pub fn to_file(&self) -> SceneFile {
        validate::file_from_scene(self)
    }

    /// The resolved scene as TOML text (the `scene` key of the `coin-log` metadata).
    #[must_use]
    pub fn to_toml(&self) -> String {
        to_toml(&self.to_file())
    }

    /// The `coin-log` metadata record of a run of this scene: what `record` writes, and what `verify`
    /// holds a file's record against, rebuilt from the scene the record stores.
    #[must_use]
    pub fn run_metadata(&self) -> RunMetadata {
        let p = &self.params;
        let steady = self.unperturbed_steady();
        RunMetadata {
            format_version: FORMAT_VERSION.to_string(),
            tool_version: env!("CARGO_PKG_VERSION").to_string(),
            scene: self.to_toml(),
            mass: p.mass(),
            radius: p.radius(),
            gravity: p.gravity(),
            inertia_x: p.inertia_x(),
            inertia_z: p.inertia_z(),
            friction: self.friction,
            time_unit: p.time_unit(),
            integrator: self.run.method.method,
            rtol: self.run.method.rtol,
            atol: self.run.method.atol,
            step: self.run.method.step,
            rate: self.run.rate,
            steady_kind: steady.map(|s| s.kind.family()),
            phi_dot: steady.map(|s| s.phi_dot),
            psi_dot: steady.map(|s| s.psi_dot),
            r_g: steady.and_then(|s| s.r_g),
            r_c: steady.and_then(|s| s.r_c),
            dissipation: self.dissipation,
        }
    }
}

/// A scene file as TOML text.
#[must_use]
pub fn to_toml(file: &SceneFile) -> String {
    // Serialising plain structs of numbers, strings and arrays cannot fail; an empty string would only
    // make the result refuse to parse back, which the tests check.
    toml::to_string(file).unwrap_or_default()
}

/// Parses scene TOML text and applies `--set` edits, giving the raw file (not yet validated).
pub fn parse_with_sets(text: &str, sets: &[String]) -> Result<SceneFile, SceneError> {
    let error = |e: toml::de::Error| SceneError::Parse(toml_message(&e));
    if sets.is_empty() {
        // Straight from the text: serde's message then points at the line.
        return toml::from_str(text).map_err(error);
    }
    with_sets(toml::from_str(text).map_err(error)?, sets)
}

/// A TOML parse error's message, trimmed, each quoted line cut to [`crate::files::SHOWN_CHARS`] characters
/// (serde's message quotes the offending line, however long).
pub(crate) fn toml_message(e: &toml::de::Error) -> String {
    let text = e.to_string();
    if text.trim() == "recursion limit" {
        // The reader's whole message for a key of too many dotted parts: no line, no key.
        return "a key or table header has too many dotted parts (the TOML reader stops at 80): a scene's \
                keys have at most three, like `initial.steady.kind`"
            .into();
    }
    let lines = text
        .trim()
        .lines()
        .map(|line| crate::files::cut(line, crate::files::SHOWN_CHARS));
    lines.collect::<Vec<_>>().join("\n")
}

/// A preset (or any file) with `--set` edits applied.
pub fn file_with_sets(file: &SceneFile, sets: &[String]) -> Result<SceneFile, SceneError> {
    if sets.is_empty() {
        return Ok(file.clone());
    }
    let table =
        toml::Table::try_from(file).map_err(|e| SceneError::Parse(e.to_string().trim().into()))?;
    with_sets(table, sets)
}

fn with_sets(mut table: toml::Table, sets: &[String]) -> Result<SceneFile, SceneError> {
    for set in sets {
        apply_set(&mut table, set)?;
    }
    file_from_table(table).map_err(|e| overrides::explain_bare_strings(e, sets))
}

/// A scene table (after edits) as a raw scene file, not yet validated (serde's message on one line).
pub fn file_from_table(table: toml::Table) -> Result<SceneFile, SceneError> {
    toml::Value::Table(table)
        .try_into::<SceneFile>()
        .map_err(|e| {
            let message = e.to_string().trim().replace('\n', " ");
            // Cut as a TOML error's lines are: an unknown `--set` key is quoted whole.
            SceneError::Parse(
                crate::files::cut(&message, 2 * crate::files::SHOWN_CHARS).into_owned(),
            )
        })
}

/// Resolves a raw file with command-line flags on top into a validated scene; problems caused by a flag
/// name the flag.
pub fn resolve(file: &SceneFile, flags: &FlagOverrides) -> Result<Scene, SceneError> {
    resolve_with_notes(file, flags).map(|(scene, _)| scene)
}

/// [`resolve`], with what resolving did to what was asked: the settings the integrator ignores and a
/// fixed step rounded to the sampling grid, for the user to be told.
pub fn resolve_with_notes(
    file: &SceneFile,
    flags: &FlagOverrides,
) -> Result<(Scene, Vec<Note>), SceneError> {
    let (file, provenance) = flags.apply(file);
    let scene = validate::scene_from_file(&file, &provenance)?;
    let notes = notes::notes(&scene, &file, &provenance);
    Ok((scene, notes))
}
