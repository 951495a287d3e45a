//! The sweep file as written (format.md: Sweep files), every table refusing unknown keys. Numbers whose
//! kind the validation judges (bounds, counts) stay TOML values, so that a wrong one is a
//! [`Problem`](crate::scene::Problem) among all the others rather than serde's lone message.

use serde::Deserialize;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    pub description: Option<String>,
    /// A built-in scene name, or the path of a scene file relative to the sweep file.
    pub base: String,
    /// Fixed edits: dotted scene key → value, as `--set` names them.
    #[serde(default)]
    pub set: toml::Table,
    #[serde(default)]
    pub axis: Vec<AxisFile>,
    pub random: Option<RandomFile>,
    pub output: Option<OutputFile>,
}

/// One `[[axis]]`: a key and exactly one of `values`, `linspace`, `logspace`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisFile {
    pub key: String,
    pub values: Option<Vec<toml::Value>>,
    pub linspace: Option<Vec<toml::Value>>,
    pub logspace: Option<Vec<toml::Value>>,
    pub zip: Option<String>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomFile {
    pub seed: toml::Value,
    pub count: toml::Value,
    #[serde(default)]
    pub draw: Vec<DrawFile>,
}

/// One `[[random.draw]]`: a key and exactly one distribution.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrawFile {
    pub key: String,
    pub uniform: Option<Vec<toml::Value>>,
    pub log_uniform: Option<Vec<toml::Value>>,
    pub normal: Option<NormalFile>,
    pub choice: Option<Vec<toml::Value>>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalFile {
    pub mean: toml::Value,
    pub std: toml::Value,
    pub min: Option<toml::Value>,
    pub max: Option<toml::Value>,
}

/// `[output]`: how every run is written. `predict` costs about 1.7 ms a run on the development machine.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputFile {
    pub channels: Option<Vec<String>>,
    pub encoding: Option<String>,
    pub compression: Option<String>,
    pub verify: Option<bool>,
    pub predict: Option<bool>,
}
