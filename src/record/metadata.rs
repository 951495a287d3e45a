//! The two metadata records of the contract (CONTRACT: Metadata records): `coin-log`, written before the
//! first message, and `coin-log.result`, written when the run finishes. Numbers are shortest round-trip
//! strings; optional values are empty strings. Nothing machine- or clock-dependent goes in.

use std::collections::BTreeMap;

/// Name of the metadata record written before the first message.
pub const RUN_METADATA_NAME: &str = "coin-log";
/// Name of the metadata record written at the end.
pub const RESULT_METADATA_NAME: &str = "coin-log.result";
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
    #[error("metadata `{record}`: `{key}` = {value:?} is not {expected}")]
    Invalid {
        /// Record name.
        record: &'static str,
        /// Key.
        key: &'static str,
        /// Value found.
        value: String,
        /// What was expected.
        expected: &'static str,
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
    /// Integrator name.
    pub integrator: String,
    /// rtol.
    pub rtol: f64,
    /// atol.
    pub atol: f64,
    /// Fixed step (the value used by fixed-step methods; recorded for all).
    pub step: f64,
    /// Samples per time unit.
    pub rate: f64,
    /// `straight` | `centre-fixed` | `circle` | `spin-upright` | `none`.
    pub steady_kind: String,
    /// Steady φ̇.
    pub phi_dot: Option<f64>,
    /// Steady ψ̇.
    pub psi_dot: Option<f64>,
    /// Steady R_G.
    pub r_g: Option<f64>,
    /// Steady R_C.
    pub r_c: Option<f64>,
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
    /// completed | flat-landing | lift-off | slip | interrupted | step-size-underflow | non-finite
    /// (and newton-failure for the implicit method).
    pub termination: String,
    /// Time the run ended.
    pub termination_time: f64,
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
        expected: "a number",
    })
}

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
        expected: "a non-negative integer",
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
            ("integrator", self.integrator.clone()),
            ("rtol", number_string(self.rtol)),
            ("atol", number_string(self.atol)),
            ("step", number_string(self.step)),
            ("rate", number_string(self.rate)),
            ("steady_kind", self.steady_kind.clone()),
            ("phi_dot", optional_string(self.phi_dot)),
            ("psi_dot", optional_string(self.psi_dot)),
            ("r_g", optional_string(self.r_g)),
            ("r_c", optional_string(self.r_c)),
        ];
        entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect()
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
            integrator: get(map, r, "integrator")?.to_string(),
            rtol: get_f64(map, r, "rtol")?,
            atol: get_f64(map, r, "atol")?,
            step: get_f64(map, r, "step")?,
            rate: get_f64(map, r, "rate")?,
            steady_kind: get(map, r, "steady_kind")?.to_string(),
            phi_dot: get_optional_f64(map, r, "phi_dot")?,
            psi_dot: get_optional_f64(map, r, "psi_dot")?,
            r_g: get_optional_f64(map, r, "r_g")?,
            r_c: get_optional_f64(map, r, "r_c")?,
        })
    }
}

impl ResultMetadata {
    /// The record's key/value map.
    #[must_use]
    pub fn to_map(&self) -> BTreeMap<String, String> {
        let entries = [
            ("steps", self.steps.to_string()),
            ("rhs_evaluations", self.rhs_evaluations.to_string()),
            ("rejected_steps", self.rejected_steps.to_string()),
            ("termination", self.termination.clone()),
            ("termination_time", number_string(self.termination_time)),
        ];
        entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect()
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
            termination: get(map, r, "termination")?.to_string(),
            termination_time: get_f64(map, r, "termination_time")?,
        })
    }
}
