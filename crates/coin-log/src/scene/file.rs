//! The scene file exactly as written (format.md: Scene files): every table refuses unknown keys, every
//! optional key is an `Option`, names (shape, integrator, channels, steady kind) stay strings so that
//! validation can report every bad one at once with its key, value and allowed values.

use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::marker::PhantomData;

/// A scene file: `description`, `[body]`, `[initial]`, `[run]`, `[record]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// One line saying what the scene shows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// The coin.
    #[serde(deserialize_with = "table")]
    pub body: BodyFile,
    /// The initial state.
    #[serde(deserialize_with = "table")]
    pub initial: InitialFile,
    /// Duration, sampling and integrator.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub run: Option<RunFile>,
    /// What to record.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub record: Option<RecordFile>,
}

/// `[body]`: M, a, g, the inertia (a shape or both moments), μ and the display thickness.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyFile {
    /// M > 0 \[mass\].
    pub mass: f64,
    /// a > 0 \[length\].
    pub radius: f64,
    /// g > 0 [length/time²].
    pub gravity: f64,
    /// `thin-disk` or `hoop`; or give both `inertia_x` and `inertia_z` instead.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<String>,
    /// I_X, moment about a diameter [mass·length²].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_x: Option<f64>,
    /// I_Z, moment about the symmetry axis [mass·length²].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_z: Option<f64>,
    /// μ: with it, |F| > μN ends the run (slip).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// Display thickness, as a fraction of a (default 0.05).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// A dissipative couple (physics §11).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub dissipation: Option<DissipationFile>,
}

/// `dissipation = { model = ..., coefficient = ..., m = ..., k = ... }`: the couple −P ω/|ω|² with
/// P = κ |φ̇|^m (sin α)^(−k) (physics §11).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DissipationFile {
    /// `moffatt`, `air-drag`, `viscous`, `rolling`, `pivoting` or `power-law`.
    pub model: String,
    /// κ ≥ 0, in the scene's units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coefficient: Option<f64>,
    /// m ≥ 1 (`power-law` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub m: Option<f64>,
    /// k (`power-law` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k: Option<f64>,
}

/// `[initial]`: an explicit state (θ and ω, optionally φ, ψ, x, z) or a steady motion, plus an optional kick.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InitialFile {
    /// θ \[rad\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theta: Option<f64>,
    /// (ω_X, ω_Y, ω_Z) in the lean frame [rad/time].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<Vec<f64>>,
    /// φ \[rad\] (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phi: Option<f64>,
    /// ψ \[rad\] (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub psi: Option<f64>,
    /// Centre x \[length\] (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    /// Centre z \[length\] (default 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
    /// A steady motion (physics §4) whose ω the solver fills in.
    #[serde(
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub steady: Option<SteadyFile>,
    /// A kick added to the initial state of either form.
    #[serde(
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub perturbation: Option<PerturbationFile>,
}

/// `steady = { kind = ..., ... }`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteadyFile {
    /// `straight`, `centre-fixed`, `circle` or `spin-upright`.
    pub kind: String,
    /// θ \[rad\] (`centre-fixed`, `circle`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta: Option<f64>,
    /// ω_Y [rad/time] (`spin-upright`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub omega_y: Option<f64>,
    /// ω_Z [rad/time] (`straight`, `circle`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub omega_z: Option<f64>,
    /// `+` or `-` (`centre-fixed`, `circle`; default `+`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub branch: Option<String>,
}

/// `perturbation = { theta = ..., omega = [...] }`: added to the initial state.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PerturbationFile {
    /// Added to θ \[rad\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theta: Option<f64>,
    /// Added to (ω_X, ω_Y, ω_Z) [rad/time].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<Vec<f64>>,
}

/// `[run]`: every key optional, defaults in [`super::defaults`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RunFile {
    /// Duration \[time\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    /// Samples per time unit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
    /// Integrator name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    /// Relative tolerance (adaptive methods).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// Absolute tolerance (adaptive methods).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    /// Step (fixed-step methods) \[time\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
    /// Most integrator steps (format.md: Limits).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<u64>,
    /// The run ends at |θ| ≥ π/2 − flat_margin \[rad\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flat_margin: Option<f64>,
}

/// `[record]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RecordFile {
    /// Channel names.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub channels: Option<Vec<String>>,
    /// `true` adds the `rerun` channel (the coin, table and track for Rerun) to the channels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rerun: Option<bool>,
}

/// A table, and only a table: serde's derived structs also take an array, read as their fields in order,
/// so `perturbation = [1]` was a kick of θ by 1 rad and `body = [1.0, 1.0, 1.0, "thin-disk"]` a body.
fn table<'de, D: Deserializer<'de>, T: Deserialize<'de>>(deserializer: D) -> Result<T, D::Error> {
    struct Table<T>(PhantomData<T>);
    impl<'de, T: Deserialize<'de>> Visitor<'de> for Table<T> {
        type Value = T;
        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a table")
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
            T::deserialize(de::value::MapAccessDeserializer::new(map))
        }
    }
    deserializer.deserialize_map(Table(PhantomData))
}

/// [`table`] for an optional key (its absence is `None` by `#[serde(default)]`).
fn optional_table<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
    deserializer: D,
) -> Result<Option<T>, D::Error> {
    table(deserializer).map(Some)
}
