//! The two metadata records (format.md, Metadata): `coin-log`, written before the first message, and
//! `coin-log.result`, written when the run finishes. Numbers are shortest round-trip strings; optional values
//! are empty strings; names (integrator, steady kind, termination) are typed here and written by their
//! `Display`, read by their `FromStr`. Nothing machine- or clock-dependent goes in.

use super::Termination;
use crate::integrate::Method;
use crate::model::{CoinParams, Dissipation, DissipationModel, Inertia, SteadyFamily};
use std::collections::BTreeMap;

/// Name of the metadata record written before the first message.
pub const RUN_METADATA_NAME: &str = "coin-log";
/// Name of the metadata record written at the end.
pub const RESULT_METADATA_NAME: &str = "coin-log.result";
/// `format_version` of this contract.
pub const FORMAT_VERSION: &str = "1";

/// A metadata record that cannot be read back.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum MetadataError {
    /// A required key is absent.
    #[error("metadata `{record}` has no key `{key}`")]
    Missing {
        record: &'static str,
        key: &'static str,
    },
    /// A value does not parse: the `reason` says why, and what would.
    #[error("metadata `{record}`: `{key}` = {value:?}: {reason}")]
    Invalid {
        record: &'static str,
        key: &'static str,
        value: String,
        reason: String,
    },
}

/// Shortest round-trip decimal string of a number (the contract's number format).
#[must_use]
pub fn number_string(value: f64) -> String {
    ryu::Buffer::new().format(value).to_string()
}

/// How a metadata value is written, and read back.
trait Value: Sized {
    fn write(&self) -> String;
    /// The value `text` holds, or why it holds none.
    fn read(text: &str) -> Result<Self, String>;
}

impl Value for String {
    fn write(&self) -> String {
        self.clone()
    }
    fn read(text: &str) -> Result<Self, String> {
        Ok(text.to_string())
    }
}

impl Value for f64 {
    fn write(&self) -> String {
        number_string(*self)
    }
    fn read(text: &str) -> Result<Self, String> {
        text.parse().map_err(|_| "not a number".into())
    }
}

impl Value for u64 {
    fn write(&self) -> String {
        self.to_string()
    }
    fn read(text: &str) -> Result<Self, String> {
        text.parse()
            .map_err(|_| "not a non-negative integer".into())
    }
}

/// An optional number: the empty string when there is none.
impl Value for Option<f64> {
    fn write(&self) -> String {
        self.map(number_string).unwrap_or_default()
    }
    fn read(text: &str) -> Result<Self, String> {
        (!text.is_empty()).then(|| f64::read(text)).transpose()
    }
}

/// The `steady_kind` value of no steady motion.
const NO_STEADY: &str = "none";

impl Value for Option<SteadyFamily> {
    fn write(&self) -> String {
        self.map_or_else(|| NO_STEADY.to_string(), |k| k.write())
    }
    fn read(text: &str) -> Result<Self, String> {
        (text != NO_STEADY)
            .then(|| SteadyFamily::read(text))
            .transpose()
    }
}

/// Typed names, written by their `Display` and read by their `FromStr`, whose error says what is allowed.
macro_rules! named_values {
    ($($t:ty),+) => {$(
        impl Value for $t {
            fn write(&self) -> String {
                self.to_string()
            }
            fn read(text: &str) -> Result<Self, String> {
                text.parse().map_err(|e: coin_log_names::UnknownName| e.to_string())
            }
        }
    )+};
}
named_values!(Method, Termination, DissipationModel, SteadyFamily);

/// The value of `key` in `record`'s `map`.
fn read<T: Value>(
    record: &'static str,
    map: &BTreeMap<String, String>,
    key: &'static str,
) -> Result<T, MetadataError> {
    let text = map.get(key).ok_or(MetadataError::Missing { record, key })?;
    T::read(text).map_err(|reason| MetadataError::Invalid {
        record,
        key,
        value: text.clone(),
        reason,
    })
}

/// Values written only when they are there: an absent key (or set of keys) is `None`.
trait OptionalKeys: Sized {
    fn write(&self, key: &'static str, map: &mut BTreeMap<String, String>);
    fn read(
        record: &'static str,
        map: &BTreeMap<String, String>,
        key: &'static str,
    ) -> Result<Self, MetadataError>;
}

/// A value written only when there: its key, by its [`Value`].
impl<T: Value> OptionalKeys for Option<T> {
    fn write(&self, key: &'static str, map: &mut BTreeMap<String, String>) {
        if let Some(v) = self {
            map.insert(key.to_string(), v.write());
        }
    }
    fn read(
        record: &'static str,
        map: &BTreeMap<String, String>,
        key: &'static str,
    ) -> Result<Self, MetadataError> {
        map.contains_key(key)
            .then(|| read(record, map, key))
            .transpose()
    }
}

/// The keys of the dissipation law in the `coin-log` record, present together or not at all.
pub const DISSIPATION_KEYS: [&str; 4] = [
    "dissipation",
    "dissipation_coefficient",
    "dissipation_m",
    "dissipation_k",
];

/// The dissipation law: the keys [`DISSIPATION_KEYS`] (the first is the field's).
impl OptionalKeys for Option<Dissipation> {
    fn write(&self, _: &'static str, map: &mut BTreeMap<String, String>) {
        if let Some(d) = self {
            let values = [d.model().to_string()]
                .into_iter()
                .chain([d.coefficient(), d.m(), d.k()].map(number_string));
            for (k, v) in DISSIPATION_KEYS.iter().zip(values) {
                map.insert((*k).to_string(), v);
            }
        }
    }
    fn read(
        record: &'static str,
        map: &BTreeMap<String, String>,
        _: &'static str,
    ) -> Result<Self, MetadataError> {
        if DISSIPATION_KEYS.iter().all(|k| !map.contains_key(*k)) {
            return Ok(None);
        }
        let [model_key, coefficient, m, k] = DISSIPATION_KEYS;
        let model: DissipationModel = read(record, map, model_key)?;
        Dissipation::new(
            model,
            read(record, map, coefficient)?,
            read(record, map, m)?,
            read(record, map, k)?,
        )
        .map(Some)
        .map_err(|e| MetadataError::Invalid {
            record,
            key: model_key,
            value: model.to_string(),
            reason: e.to_string(),
        })
    }
}

/// Declares a metadata record: the struct, and `to_map` / `from_map` over its fields, each the key of the
/// field's name written and read by its [`Value`]; the fields after `optional:` are written only when there
/// ([`OptionalKeys`]). A value that does not read back is an error naming the first such key, in field order.
macro_rules! record {
    (
        $(#[$meta:meta])*
        pub struct $name:ident = $record:ident {
            $( $(#[$fmeta:meta])* pub $field:ident: $ty:ty, )+
            optional:
            $( $(#[$ometa:meta])* pub $opt:ident: $oty:ty, )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq)]
        pub struct $name {
            $( $(#[$fmeta])* pub $field: $ty, )+
            $( $(#[$ometa])* pub $opt: $oty, )+
        }

        impl $name {
            /// The record's key/value map.
            #[must_use]
            pub fn to_map(&self) -> BTreeMap<String, String> {
                let mut map = BTreeMap::new();
                $( map.insert(stringify!($field).to_string(), Value::write(&self.$field)); )+
                $( OptionalKeys::write(&self.$opt, stringify!($opt), &mut map); )+
                map
            }

            /// Reads the record back, or fails naming the first missing or malformed key.
            pub fn from_map(map: &BTreeMap<String, String>) -> Result<Self, MetadataError> {
                Ok(Self {
                    $( $field: read($record, map, stringify!($field))?, )+
                    $( $opt: OptionalKeys::read($record, map, stringify!($opt))?, )+
                })
            }
        }
    };
}

record! {
    /// The `coin-log` record: what was simulated and how; its keys are format.md's (Metadata records).
    #[allow(missing_docs)]
    pub struct RunMetadata = RUN_METADATA_NAME {
        pub format_version: String,
        pub tool_version: String,
        pub scene: String,
        pub mass: f64,
        pub radius: f64,
        pub gravity: f64,
        pub inertia_x: f64,
        pub inertia_z: f64,
        pub friction: Option<f64>,
        pub time_unit: f64,
        pub integrator: Method,
        pub rtol: f64,
        pub atol: f64,
        pub step: f64,
        pub rate: f64,
        pub steady_kind: Option<SteadyFamily>,
        pub phi_dot: Option<f64>,
        pub psi_dot: Option<f64>,
        pub r_g: Option<f64>,
        pub r_c: Option<f64>,
        optional:
        pub dissipation: Option<Dissipation>,
    }
}

/// The Header's `library` in a file coin-log `version` records: `coin-log/0.1.0`.
#[must_use]
pub fn header_library(version: &str) -> String {
    format!("coin-log/{version}")
}

impl RunMetadata {
    /// The body the record stores; `Err` lists each parameter that is unusable, joined by "; ".
    pub fn params(&self) -> Result<CoinParams, String> {
        let inertia = Inertia::Explicit {
            inertia_x: self.inertia_x,
            inertia_z: self.inertia_z,
        };
        CoinParams::new(self.mass, self.radius, self.gravity, inertia).map_err(|errors| {
            let list: Vec<String> = errors.iter().map(ToString::to_string).collect();
            list.join("; ")
        })
    }
}

record! {
    /// The `coin-log.result` record: how the run ended; its keys are format.md's (Metadata records).
    #[allow(missing_docs)]
    pub struct ResultMetadata = RESULT_METADATA_NAME {
        pub steps: u64,
        pub rhs_evaluations: u64,
        pub rejected_steps: u64,
        pub termination: Termination,
        pub termination_time: f64,
        optional:
        pub termination_alpha: Option<f64>,
        pub expected_to_fail: Option<String>,
    }
}
