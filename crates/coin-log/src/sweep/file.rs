//! The sweep file as written (format.md: Sweep files): serde structs that mirror the TOML, every table
//! refusing unknown keys. Numbers whose kind the validation judges (bounds, counts) are kept as TOML
//! values, so that a wrong one is a [`Problem`](crate::scene::Problem) among all the others rather than
//! serde's lone message.

use serde::Deserialize;

/// A sweep file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// One line saying what the sweep is for.
    pub description: Option<String>,
    /// A built-in scene name, or the path of a scene file relative to the sweep file.
    pub base: String,
    /// Fixed edits: dotted scene key → value, as `--set` names them.
    #[serde(default)]
    pub set: toml::Table,
    /// Grid axes, combined as a product (the last varying fastest), zipped by a shared `zip` name.
    #[serde(default)]
    pub axis: Vec<AxisFile>,
    /// Random draws.
    pub random: Option<RandomFile>,
    /// The sweep's own settings.
    pub output: Option<OutputFile>,
}

/// One `[[axis]]`: a key and exactly one of `values`, `linspace`, `logspace`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisFile {
    /// Dotted scene key.
    pub key: String,
    /// The values, any TOML values.
    pub values: Option<Vec<toml::Value>>,
    /// `[first, last, n]`.
    pub linspace: Option<Vec<toml::Value>>,
    /// `[first_exp, last_exp, n]`, base 10.
    pub logspace: Option<Vec<toml::Value>>,
    /// Axes with the same name vary together (equal lengths).
    pub zip: Option<String>,
}

/// `[random]`: a seed, how many draws per grid point, and the draws.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomFile {
    /// The generator's seed, 0 … 2⁶³ − 1.
    pub seed: toml::Value,
    /// Runs per grid point (≥ 1).
    pub count: toml::Value,
    /// `[[random.draw]]`.
    #[serde(default)]
    pub draw: Vec<DrawFile>,
}

/// One `[[random.draw]]`: a key and exactly one distribution.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrawFile {
    /// Dotted scene key.
    pub key: String,
    /// `[lo, hi]`.
    pub uniform: Option<Vec<toml::Value>>,
    /// `[lo, hi]`, 0 < lo.
    pub log_uniform: Option<Vec<toml::Value>>,
    /// `{ mean, std, min, max }`.
    pub normal: Option<NormalFile>,
    /// Values to choose from, any TOML values.
    pub choice: Option<Vec<toml::Value>>,
}

/// `normal = { mean, std, min, max }`; the bounds are optional.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalFile {
    /// Mean.
    pub mean: toml::Value,
    /// Standard deviation, > 0.
    pub std: toml::Value,
    /// Lower bound (draws below are redrawn).
    pub min: Option<toml::Value>,
    /// Upper bound.
    pub max: Option<toml::Value>,
}

/// `[output]`: how every run is written.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputFile {
    /// The channels to record (as `record.channels`; default the scene's).
    pub channels: Option<Vec<String>>,
    /// `json` (default) or `protobuf`.
    pub encoding: Option<String>,
    /// `zstd` (default), `lz4` or `none`.
    pub compression: Option<String>,
    /// Verify each file after recording it (default true).
    pub verify: Option<bool>,
    /// Fill the catalogue's `predicted_*` columns by `analyse`'s quadrature (default true; about 1.7 ms
    /// a run on the development machine).
    pub predict: Option<bool>,
}
