//! The scene file exactly as written: each field is the key of its name, as format.md (Scene files, Keys)
//! describes it. Every table refuses unknown keys, every optional key is an `Option`, names (shape,
//! integrator, channels, steady kind) stay strings so that validation can report every bad one at once
//! with its key, value and allowed values.

use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::marker::PhantomData;

/// A scene file: `description`, `[body]`, `[initial]`, `[run]`, `[record]`.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    #[serde(deserialize_with = "table")]
    pub body: BodyFile,
    #[serde(deserialize_with = "table")]
    pub initial: InitialFile,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub run: Option<RunFile>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub record: Option<RecordFile>,
}

/// `[body]`: M, a, g, the inertia (a shape or both moments), μ and the display thickness.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyFile {
    pub mass: f64,
    pub radius: f64,
    pub gravity: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_x: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_z: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub dissipation: Option<DissipationFile>,
}

/// `dissipation = { model = ..., coefficient = ..., m = ..., k = ... }`: the couple −P ω/|ω|² with
/// P = κ |φ̇|^m (sin α)^(−k) (physics §11).
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DissipationFile {
    pub model: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coefficient: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k: Option<f64>,
}

/// `[initial]`: an explicit state (θ and ω, optionally φ, ψ, x, z) or a steady motion, plus an optional kick.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InitialFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theta: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<Vec<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phi: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub psi: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
    #[serde(
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub steady: Option<SteadyFile>,
    #[serde(
        skip_serializing_if = "Option::is_none",
        deserialize_with = "optional_table"
    )]
    pub perturbation: Option<PerturbationFile>,
}

/// `steady = { kind = ..., ... }`.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteadyFile {
    pub kind: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub omega_y: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub omega_z: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub branch: Option<String>,
}

/// `perturbation = { theta = ..., omega = [...] }`: added to the initial state.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PerturbationFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theta: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<Vec<f64>>,
}

/// `[run]`: every key optional, defaults in [`super::defaults`].
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RunFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duration: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flat_margin: Option<f64>,
}

/// `[record]`.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RecordFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub channels: Option<Vec<String>>,
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
