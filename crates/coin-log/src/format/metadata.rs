//! The two metadata records (format.md, Metadata): `coin-log`, written before the first message, and
//! `coin-log.result`, written when the run finishes. Numbers are shortest round-trip strings; optional values
//! are empty strings; names (integrator, steady kind, termination) are typed here and written by their
//! `Display`, read by their `FromStr`. Nothing machine- or clock-dependent goes in.

use super::Termination;
use crate::integrate::Method;
use crate::model::{Dissipation, DissipationModel, SteadyFamily};
use std::collections::BTreeMap;
use std::str::FromStr;

/// Name of the metadata record written before the first message.
pub const RUN_METADATA_NAME: &str = "coin-log";
/// Name of the metadata record written at the end.
pub const RESULT_METADATA_NAME: &str = "coin-log.result";
/// Key of α at the end of a dissipative run in the `coin-log.result` record.
pub const TERMINATION_ALPHA_KEY: &str = "termination_alpha";
/// `format_version` of this contract.
pub const FORMAT_VERSION: &str = "1";

/// A metadata record that cannot be read back.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MetadataError {
    /// A required key is absent.
    #[error("metadata `{record}` has no key `{key}`")]
    Missing {
        /// Record name.
        record: &'static str,
        /// Key.
        key: &'static str,
    },
    /// A value does not parse.
    #[error("metadata `{record}`: `{key}` = {value:?}: {reason}")]
    Invalid {
        /// Record name.
        record: &'static str,
        /// Key.
        key: &'static str,
        /// Value found.
        value: String,
        /// Why it does not parse, and what would.
        reason: String,
    },
}

/// Shortest round-trip decimal string of a number (the contract's number format).
#[must_use]
pub fn number_string(value: f64) -> String {
    ryu::Buffer::new().format(value).to_string()
}

fn optional_string(value: Option<f64>) -> String {
    value.map(number_string).unwrap_or_default()
}

/// The `coin-log` record: what was simulated and how.
#[derive(Debug, Clone, PartialEq)]
pub struct RunMetadata {
    /// `format_version` ("1").
    pub format_version: String,
    /// `tool_version`: the crate version.
    pub tool_version: String,
    /// `scene`: the resolved scene as TOML.
    pub scene: String,
    /// M.
    pub mass: f64,
    /// a.
    pub radius: f64,
    /// g.
    pub gravity: f64,
    /// I_X.
    pub inertia_x: f64,
    /// I_Z.
    pub inertia_z: f64,
    /// μ, if given.
    pub friction: Option<f64>,
    /// √(a/g).
    pub time_unit: f64,
    /// The integrator.
    pub integrator: Method,
    /// rtol.
    pub rtol: f64,
    /// atol.
    pub atol: f64,
    /// Fixed step (the value used by fixed-step methods; recorded for all).
    pub step: f64,
    /// Samples per time unit.
    pub rate: f64,
    /// The steady motion the whole run should stay on (`none` when the scene is not an unperturbed steady
    /// motion).
    pub steady_kind: Option<SteadyFamily>,
    /// Steady φ̇.
    pub phi_dot: Option<f64>,
    /// Steady ψ̇.
    pub psi_dot: Option<f64>,
    /// Steady R_G.
    pub r_g: Option<f64>,
    /// Steady R_C.
    pub r_c: Option<f64>,
    /// The dissipation law (physics §11): keys `dissipation` (the model), `dissipation_coefficient` (κ),
    /// `dissipation_m`, `dissipation_k`, written only when there is one. A file without them is
    /// conservative.
    pub dissipation: Option<Dissipation>,
}

/// The `coin-log.result` record: how the run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultMetadata {
    /// Accepted steps.
    pub steps: u64,
    /// RHS evaluations.
    pub rhs_evaluations: u64,
    /// Rejected steps.
    pub rejected_steps: u64,
    /// How the run ended.
    pub termination: Termination,
    /// Time the run ended.
    pub termination_time: f64,
    /// α = π/2 − |θ| at the last sample (`termination_alpha`), written only with dissipation: how flat
    /// the coin was when the run ended (physics §11).
    pub termination_alpha: Option<f64>,
}

fn get<'a>(
    map: &'a BTreeMap<String, String>,
    record: &'static str,
    key: &'static str,
) -> Result<&'a str, MetadataError> {
    map.get(key)
        .map(String::as_str)
        .ok_or(MetadataError::Missing { record, key })
}

fn get_f64(
    map: &BTreeMap<String, String>,
    record: &'static str,
    key: &'static str,
) -> Result<f64, MetadataError> {
    let value = get(map, record, key)?;
    value.parse::<f64>().map_err(|_| MetadataError::Invalid {
        record,
        key,
        value: value.to_string(),
        reason: "not a number".into(),
    })
}

/// A typed name: the value's `FromStr` error says what is wrong and what is allowed.
fn get_parsed<T: FromStr>(
    map: &BTreeMap<String, String>,
    record: &'static str,
    key: &'static str,
) -> Result<T, MetadataError>
where
    T::Err: std::fmt::Display,
{
    let value = get(map, record, key)?;
    value.parse::<T>().map_err(|e| MetadataError::Invalid {
        record,
        key,
        value: value.to_string(),
        reason: e.to_string(),
    })
}

/// The `steady_kind` value of no steady motion.
const NO_STEADY: &str = "none";

fn get_optional_f64(
    map: &BTreeMap<String, String>,
    record: &'static str,
    key: &'static str,
) -> Result<Option<f64>, MetadataError> {
    match get(map, record, key)? {
        "" => Ok(None),
        _ => get_f64(map, record, key).map(Some),
    }
}

fn get_u64(
    map: &BTreeMap<String, String>,
    record: &'static str,
    key: &'static str,
) -> Result<u64, MetadataError> {
    let value = get(map, record, key)?;
    value.parse::<u64>().map_err(|_| MetadataError::Invalid {
        record,
        key,
        value: value.to_string(),
        reason: "not a non-negative integer".into(),
    })
}

impl RunMetadata {
    /// The record's key/value map.
    #[must_use]
    pub fn to_map(&self) -> BTreeMap<String, String> {
        let entries = [
            ("format_version", self.format_version.clone()),
            ("tool_version", self.tool_version.clone()),
            ("scene", self.scene.clone()),
            ("mass", number_string(self.mass)),
            ("radius", number_string(self.radius)),
            ("gravity", number_string(self.gravity)),
            ("inertia_x", number_string(self.inertia_x)),
            ("inertia_z", number_string(self.inertia_z)),
            ("friction", optional_string(self.friction)),
            ("time_unit", number_string(self.time_unit)),
            ("integrator", self.integrator.to_string()),
            ("rtol", number_string(self.rtol)),
            ("atol", number_string(self.atol)),
            ("step", number_string(self.step)),
            ("rate", number_string(self.rate)),
            (
                "steady_kind",
                self.steady_kind
                    .map_or_else(|| NO_STEADY.to_string(), |k| k.to_string()),
            ),
            ("phi_dot", optional_string(self.phi_dot)),
            ("psi_dot", optional_string(self.psi_dot)),
            ("r_g", optional_string(self.r_g)),
            ("r_c", optional_string(self.r_c)),
        ];
        let mut map: BTreeMap<String, String> = entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        if let Some(d) = &self.dissipation {
            for (k, v) in [
                (DISSIPATION_KEYS[0], d.model().to_string()),
                (DISSIPATION_KEYS[1], number_string(d.coefficient())),
                (DISSIPATION_KEYS[2], number_string(d.m())),
                (DISSIPATION_KEYS[3], number_string(d.k())),
            ] {
                map.insert(k.to_string(), v);
            }
        }
        map
    }

    /// Reads the record back.
    ///
    /// # Errors
    /// [`MetadataError`] naming the first missing or malformed key.
    pub fn from_map(map: &BTreeMap<String, String>) -> Result<Self, MetadataError> {
        let r = RUN_METADATA_NAME;
        Ok(Self {
            format_version: get(map, r, "format_version")?.to_string(),
            tool_version: get(map, r, "tool_version")?.to_string(),
            scene: get(map, r, "scene")?.to_string(),
            mass: get_f64(map, r, "mass")?,
            radius: get_f64(map, r, "radius")?,
            gravity: get_f64(map, r, "gravity")?,
            inertia_x: get_f64(map, r, "inertia_x")?,
            inertia_z: get_f64(map, r, "inertia_z")?,
            friction: get_optional_f64(map, r, "friction")?,
            time_unit: get_f64(map, r, "time_unit")?,
            integrator: get_parsed(map, r, "integrator")?,
            rtol: get_f64(map, r, "rtol")?,
            atol: get_f64(map, r, "atol")?,
            step: get_f64(map, r, "step")?,
            rate: get_f64(map, r, "rate")?,
            steady_kind: match get(map, r, "steady_kind")? {
                NO_STEADY => None,
                _ => Some(get_parsed(map, r, "steady_kind")?),
            },
            phi_dot: get_optional_f64(map, r, "phi_dot")?,
            psi_dot: get_optional_f64(map, r, "psi_dot")?,
            r_g: get_optional_f64(map, r, "r_g")?,
            r_c: get_optional_f64(map, r, "r_c")?,
            dissipation: dissipation_from_map(map)?,
        })
    }
}

/// The keys of the dissipation law in the `coin-log` record, present together or not at all.
pub const DISSIPATION_KEYS: [&str; 4] = [
    "dissipation",
    "dissipation_coefficient",
    "dissipation_m",
    "dissipation_k",
];

/// The dissipation law of a `coin-log` record: `None` when none of its keys is there.
fn dissipation_from_map(
    map: &BTreeMap<String, String>,
) -> Result<Option<Dissipation>, MetadataError> {
    let r = RUN_METADATA_NAME;
    if DISSIPATION_KEYS.iter().all(|k| !map.contains_key(*k)) {
        return Ok(None);
    }
    let model: DissipationModel = get_parsed(map, r, DISSIPATION_KEYS[0])?;
    let coefficient = get_f64(map, r, DISSIPATION_KEYS[1])?;
    let m = get_f64(map, r, DISSIPATION_KEYS[2])?;
    let k = get_f64(map, r, DISSIPATION_KEYS[3])?;
    Dissipation::new(model, coefficient, m, k)
        .map(Some)
        .map_err(|e| MetadataError::Invalid {
            record: r,
            key: DISSIPATION_KEYS[0],
            value: model.to_string(),
            reason: e.to_string(),
        })
}

impl ResultMetadata {
    /// The record's key/value map.
    #[must_use]
    pub fn to_map(&self) -> BTreeMap<String, String> {
        let entries = [
            ("steps", self.steps.to_string()),
            ("rhs_evaluations", self.rhs_evaluations.to_string()),
            ("rejected_steps", self.rejected_steps.to_string()),
            ("termination", self.termination.to_string()),
            ("termination_time", number_string(self.termination_time)),
        ];
        let mut map: BTreeMap<String, String> = entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        if let Some(alpha) = self.termination_alpha {
            map.insert(TERMINATION_ALPHA_KEY.to_string(), number_string(alpha));
        }
        map
    }

    /// Reads the record back.
    ///
    /// # Errors
    /// [`MetadataError`] naming the first missing or malformed key.
    pub fn from_map(map: &BTreeMap<String, String>) -> Result<Self, MetadataError> {
        let r = RESULT_METADATA_NAME;
        Ok(Self {
            steps: get_u64(map, r, "steps")?,
            rhs_evaluations: get_u64(map, r, "rhs_evaluations")?,
            rejected_steps: get_u64(map, r, "rejected_steps")?,
            termination: get_parsed(map, r, "termination")?,
            termination_time: get_f64(map, r, "termination_time")?,
            termination_alpha: match map.get(TERMINATION_ALPHA_KEY) {
                None => None,
                Some(_) => Some(get_f64(map, r, TERMINATION_ALPHA_KEY)?),
            },
        })
    }
}
