//! A validated sweep (format.md: Sweep files), and what a run's index alone gives: its values, scene and
//! file name.

use super::catalogue::cell;
use super::error::SweepError;
use super::file::SweepFile;
use super::random::{Distribution, Drawn, OutOfBounds, GENERATOR};
use super::validate;
use crate::files::{self, InputKind};
use crate::format::Encoding;
use crate::record::foxglove::PROTOBUF_MAX_SECONDS;
use crate::record::RecordOptions;
use crate::scene::{self, Scene, SceneError};
use coin_log_mcap::Compression;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// The most runs a sweep may have: far more than any disk holds, few enough that an index fits the
/// file names and the catalogue comfortably.
pub const MAX_RUNS: u64 = 1_000_000_000;

/// The most values the axes may give together, each expanded in memory and listed in `sweep.json`: one
/// axis of 10⁶ values peaks at 120 MB and 0.5 s to start, one of 10⁹ asked for 32 GB (measured).
pub const MAX_AXIS_VALUES: u64 = 1_000_000;

/// One grid axis, its values expanded; `zip` names the group it varies with.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Axis {
    pub key: String,
    pub values: Vec<toml::Value>,
    pub zip: Option<String>,
}

/// One random draw; `choices` holds a `choice` draw's values (empty otherwise).
#[derive(Debug, Clone, PartialEq)]
pub struct Draw {
    pub key: String,
    pub distribution: Distribution,
    pub choices: Vec<toml::Value>,
}

/// `[random]`, validated: `count` runs per grid point.
#[derive(Debug, Clone, PartialEq)]
pub struct Random {
    pub seed: u64,
    pub count: u64,
    pub draws: Vec<Draw>,
}

/// `[output]`, validated, with the defaults filled in; `channels` is `None` for the scenes' own lists.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Settings {
    pub channels: Option<Vec<String>>,
    #[serde(serialize_with = "by_name")]
    pub encoding: Encoding,
    #[serde(serialize_with = "by_name")]
    pub compression: Compression,
    pub verify: bool,
    pub predict: bool,
}

fn by_name<T: coin_log_names::Named, S: serde::Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(v.name())
}

/// A sweep, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    pub(crate) description: String,
    pub(crate) base: String,
    /// The base scene as a table, before any edit.
    pub(crate) base_table: toml::Table,
    /// The fixed edits, in the order applied (sorted by key: a table before the keys inside it).
    pub(crate) set: Vec<(String, toml::Value)>,
    pub(crate) axes: Vec<Axis>,
    /// The grid's dimensions, slowest first: each a lone axis or a zip group (indexes into `axes`), at
    /// the place of its first axis.
    pub(crate) dimensions: Vec<Vec<usize>>,
    pub(crate) random: Option<Random>,
    /// How runs are written.
    pub settings: Settings,
}

/// Why a run has no scene: a draw found nothing within its bounds, its values give no valid scene, or
/// one longer than a Protobuf timestamp of Foxglove's schemas holds.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunSceneError {
    #[error(transparent)]
    Draw(#[from] OutOfBounds),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(
        "run.duration = {0} is longer than {PROTOBUF_MAX_SECONDS} time units, the most Foxglove's Protobuf \
         timestamps hold: set output.encoding = \"json\", or shorten run.duration"
    )]
    TooLongForProtobuf(f64),
}

impl Sweep {
    /// Reads and validates the sweep file at `path` (every problem at once); a base scene file is found
    /// relative to it.
    pub fn load(path: &Path) -> Result<Self, SweepError> {
        let text = files::read_toml(path, InputKind::Sweep).map_err(|source| SweepError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let folder = path.parent().unwrap_or_else(|| Path::new("."));
        Self::parse(&text, folder, &path.display().to_string())
    }

    /// Validates sweep-file text; `folder` is where a base scene path starts from, `label` names the
    /// file in errors.
    pub fn parse(text: &str, folder: &Path, label: &str) -> Result<Self, SweepError> {
        let file = toml::from_str(text).map_err(|e| SweepError::Parse {
            label: label.to_string(),
            message: scene::toml_message(&e),
        })?;
        validate::sweep(file, folder).map_err(|problems| SweepError::Invalid {
            label: label.to_string(),
            problems: Box::new(problems),
        })
    }

    /// Each dimension's length, slowest first.
    pub(super) fn lengths(&self) -> impl DoubleEndedIterator<Item = u64> + ExactSizeIterator + '_ {
        self.dimensions
            .iter()
            .map(|d| self.axes[d[0]].values.len() as u64)
    }

    /// Runs per grid point: `random.count`, or 1.
    pub(super) fn per_point(&self) -> u64 {
        self.random.as_ref().map_or(1, |r| r.count)
    }

    /// How many runs: grid points × `random.count`.
    #[must_use]
    pub fn runs(&self) -> u64 {
        self.lengths().product::<u64>() * self.per_point()
    }

    /// The swept keys, each a catalogue column: the axes, then the draws, in the file's order.
    pub fn keys(&self) -> impl Iterator<Item = &str> {
        let draws = self.random.iter().flat_map(|r| &r.draws);
        self.axes
            .iter()
            .map(|a| a.key.as_str())
            .chain(draws.map(|d| d.key.as_str()))
    }

    /// The swept keys' values of run `index` (< [`runs`](Self::runs)), in the order of
    /// [`keys`](Self::keys): grid point ⌊index / count⌋ (its coordinates with the last dimension varying
    /// fastest), then the draws of run `index`; an error when a bounded normal draw finds nothing.
    pub fn values(&self, index: u64) -> Result<Vec<toml::Value>, OutOfBounds> {
        let mut point = index / self.per_point();
        let mut values = vec![toml::Value::Boolean(false); self.axes.len()];
        for (dimension, len) in self.dimensions.iter().zip(self.lengths()).rev() {
            // point % len < len, a length of a Vec: it fits usize.
            let at = usize::try_from(point % len).unwrap_or(0);
            point /= len;
            for &axis in dimension {
                values[axis] = self.axes[axis].values[at].clone();
            }
        }
        if let Some(r) = &self.random {
            for (j, draw) in r.draws.iter().enumerate() {
                values.push(match draw.distribution.draw(r.seed, index, j as u64)? {
                    Drawn::Number(x) => toml::Value::Float(x),
                    Drawn::Choice(k) => draw.choices[k].clone(),
                });
            }
        }
        Ok(values)
    }

    /// The catalogue's cells of the swept keys of run `index`, as its row holds them: each value as
    /// [`cell`] writes it, or every cell empty when a bounded draw found no value.
    pub(super) fn cells(&self, index: u64) -> Vec<String> {
        cells(&self.values(index), self.keys().count())
    }

    /// The sweep a folder's plan describes (its `sweep` object, [`description_json`](Self::description_json),
    /// read back as a sweep file whose base is the plan's resolved base scene), so that `collect` knows
    /// each run's values; `None` when the plan does not give back a sweep of the plan's identity (a
    /// value JSON cannot hold, such as NaN, which it writes as null) or draws with another generator.
    pub(super) fn from_plan(plan: &serde_json::Value) -> Option<Self> {
        let mut described = plan.get("sweep")?.clone();
        let object = described.as_object_mut()?;
        let base: toml::Table = toml::from_str(object.remove("base_scene")?.as_str()?).ok()?;
        // The sweep file's names for what the description calls `axes` and `draws`.
        let axes = object.remove("axes")?;
        object.insert("axis".into(), axes);
        if let Some(random) = object.get_mut("random").and_then(|r| r.as_object_mut()) {
            // Draws of another generator are not this one's (a sweep file has no such key).
            (random.remove("generator")? == GENERATOR).then_some(())?;
            let draws = random.remove("draws")?;
            random.insert("draw".into(), draws);
        }
        let file: SweepFile = serde_json::from_value(described).ok()?;
        let sweep = validate::with_base(file, base).ok()?;
        (plan.get("identity")?.as_str()? == sweep.identity()).then_some(sweep)
    }

    /// The resolved, validated scene of a run with these values, exactly as `coin-log record` resolves
    /// the same scene file: the base, then `set`, then the values, then `output.channels` as
    /// `record.channels`.
    pub fn scene(&self, values: &[toml::Value]) -> Result<Scene, RunSceneError> {
        let mut table = self.base_table.clone();
        for (key, value) in &self.set {
            scene::set_value(&mut table, key, value.clone())?;
        }
        for (key, value) in self.keys().zip(values) {
            scene::set_value(&mut table, key, value.clone())?;
        }
        if let Some(channels) = &self.settings.channels {
            scene::set_value(&mut table, CHANNELS_KEY, channels.clone().into())?;
        }
        let file = scene::file_from_table(table)?;
        let scene = Scene::from_file(&file)?;
        if self.settings.encoding == Encoding::Protobuf && scene.run.duration > PROTOBUF_MAX_SECONDS
        {
            return Err(RunSceneError::TooLongForProtobuf(scene.run.duration));
        }
        Ok(scene)
    }

    pub(super) fn record_options(&self) -> RecordOptions {
        RecordOptions {
            compression: self.settings.compression,
            encoding: self.settings.encoding,
        }
    }

    /// Digits of the largest index: the width run indexes are zero-padded to in file names.
    pub(super) fn index_width(&self) -> usize {
        self.runs().saturating_sub(1).to_string().len()
    }

    /// The sweep as resolved, the `sweep` object of `sweep.json` (format.md: sweep.json): what the
    /// identity hashes.
    pub(super) fn description_json(&self) -> serde_json::Value {
        let bound = |x: f64| x.is_finite().then_some(x);
        let draw = |d: &Draw| match d.distribution {
            Distribution::Uniform { lo, hi } => {
                serde_json::json!({"key": d.key, "uniform": [lo, hi]})
            }
            Distribution::LogUniform { lo, hi } => {
                serde_json::json!({"key": d.key, "log_uniform": [lo, hi]})
            }
            Distribution::Normal {
                mean,
                std,
                min,
                max,
            } => serde_json::json!({"key": d.key,
                "normal": {"mean": mean, "std": std, "min": bound(min), "max": bound(max)}}),
            Distribution::Choice { .. } => serde_json::json!({"key": d.key, "choice": d.choices}),
        };
        let random = self.random.as_ref().map(|r| {
            let draws: Vec<_> = r.draws.iter().map(draw).collect();
            serde_json::json!({"generator": GENERATOR, "seed": r.seed, "count": r.count, "draws": draws})
        });
        let set: BTreeMap<&str, &toml::Value> =
            self.set.iter().map(|(k, v)| (k.as_str(), v)).collect();
        serde_json::json!({
            "description": self.description,
            "base": self.base,
            "base_scene": toml::to_string(&self.base_table).unwrap_or_default(),
            "set": set,
            "axes": self.axes,
            "random": random,
            "output": self.settings,
        })
    }

    /// SHA-256 (hex) of the compact JSON of [`description_json`](Self::description_json): two sweeps
    /// with the same identity make the same runs.
    pub(super) fn identity(&self) -> String {
        super::hash::sha256_hex(self.description_json().to_string().as_bytes())
    }
}

/// The catalogue's cells of a run's swept values ([`Sweep::values`]); `keys` empty cells when a
/// bounded draw found no value.
pub(super) fn cells(values: &Result<Vec<toml::Value>, OutOfBounds>, keys: usize) -> Vec<String> {
    match values {
        Ok(values) => values.iter().map(cell).collect(),
        Err(_) => vec![String::new(); keys],
    }
}

/// The scene key `output.channels` sets.
pub(super) const CHANNELS_KEY: &str = "record.channels";

#[cfg(test)]
mod tests {
    use super::Sweep;

    /// The identity of a sweep with every part (set, zipped and spaced axes, each distribution, output)
    /// is pinned: a changed identity would refuse to resume every existing sweep folder.
    #[test]
    fn the_identity_of_a_fixed_sweep_is_pinned() {
        let text = r#"
description = "pinned"
base = "wobble"
set = { "run.duration" = 2.0 }
[[axis]]
key = "initial.theta"
linspace = [0.1, 0.3, 3]
zip = "a"
[[axis]]
key = "body.mass"
values = [1.0, 2, 3.5]
zip = "a"
[[axis]]
key = "run.rate"
logspace = [1, 2, 2]
[random]
seed = 7
count = 2
[[random.draw]]
key = "body.friction"
uniform = [0.5, 1.0]
[[random.draw]]
key = "body.radius"
log_uniform = [0.1, 10]
[[random.draw]]
key = "body.gravity"
normal = { mean = 1.0, std = 0.1, min = 0.5 }
[[random.draw]]
key = "run.integrator"
choice = ["rk4", "dop853"]
[output]
channels = ["omega", "angles"]
encoding = "protobuf"
compression = "lz4"
verify = false
"#;
        let parse = |text| Sweep::parse(text, std::path::Path::new("."), "pinned.toml").unwrap();
        let (full, bare) = (parse(text), parse("base = \"wobble\""));
        // A plan gives back its sweep (collect's values), every form of it; one with a value JSON cannot
        // hold (NaN, written as null) gives none, never another sweep.
        for sweep in [&full, &bare] {
            let plan = serde_json::json!({"identity": sweep.identity(), "sweep": sweep.description_json()});
            assert_eq!(Sweep::from_plan(&plan).as_ref(), Some(sweep));
            let mut other = plan.clone();
            other["identity"] = "0".repeat(64).into();
            assert_eq!(Sweep::from_plan(&other), None);
        }
        // A plan of generator 1's draws (no generator named) gives no sweep of this generator's.
        let mut old =
            serde_json::json!({"identity": full.identity(), "sweep": full.description_json()});
        old["sweep"]["random"]
            .as_object_mut()
            .unwrap()
            .remove("generator");
        assert_eq!(Sweep::from_plan(&old), None);
        let nan =
            parse("base = \"wobble\"\n[[axis]]\nkey = \"initial.theta\"\nvalues = [nan, 0.5]");
        let plan = serde_json::json!({"identity": nan.identity(), "sweep": nan.description_json()});
        assert_eq!(Sweep::from_plan(&plan), None);
        assert_eq!(
            full.identity(),
            "158dca438908767017ae46cec088c76e674fa32a2b3e8dd3ab489895c0754ddc"
        );
        assert_eq!(
            bare.identity(),
            "4f6db358526d76d6a7535fc24ea1bc8c826c6d112e71195f10acd01fe5d80011"
        );
    }
}
