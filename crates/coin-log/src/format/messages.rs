//! The schemas of the format (format.md: Channels and fields): the `coin_log.*` message types, declared
//! here, and Foxglove's schema names. Each type deserialises strictly (unknown or missing fields
//! rejected) and writes itself straight into a reused buffer (ryu's shortest round-trip floats, in schema
//! order), refusing the non-finite numbers serde_json would write as `null`.

use super::encoding::Encoding;
use serde::Deserialize;

/// A number that JSON cannot carry.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("field `{field}` of a `{schema}` message is {value}; messages carry finite numbers only")]
#[allow(missing_docs, reason = "each field is named in the message")]
pub struct NonFiniteField {
    pub schema: &'static str,
    pub field: &'static str,
    pub value: f64,
}

/// The floor of N in the friction ratio, a fraction of Mg: the ratio is F / max(N, floor · Mg), finite even at
/// the sample where N reaches 0 (a `lift-off` event), where the demand for friction grows without bound.
pub const FRICTION_RATIO_FLOOR: f64 = 1e-12;

/// The friction ratio F / max(N, [`FRICTION_RATIO_FLOOR`] · M g) of `coin_log.Reaction`: the friction
/// coefficient needed to roll without slipping.
///
/// ```
/// use coin_log::format::messages::friction_ratio;
/// assert_eq!(friction_ratio(0.5, 2.0, 1.0, 1.0), 0.25);
/// assert_eq!(friction_ratio(0.5, 0.0, 1.0, 1.0), 0.5e12);
/// ```
#[must_use]
pub fn friction_ratio(friction: f64, normal: f64, mass: f64, gravity: f64) -> f64 {
    friction / normal.max(FRICTION_RATIO_FLOOR * mass * gravity)
}

/// The energy drift E − E₀ relative to the drift scale max(|E₀|, M g a) (`model::drift`), in units of
/// [`f64::EPSILON`]: the `drift_eps` field of `coin_log.Energy`. A plot's autoscaled axis shows it where
/// E − E₀ itself (≈ 1e-12) is below the axis' resolution.
///
/// ```
/// use coin_log::format::messages::drift_eps;
/// assert_eq!(drift_eps(2.0 + 4.0 * f64::EPSILON, 2.0, 1.0), 2.0);
/// assert_eq!(drift_eps(0.0, 0.0, 1.0), 0.0);
/// ```
#[must_use]
pub fn drift_eps(total: f64, e0: f64, energy_scale: f64) -> f64 {
    (total - e0) / (f64::EPSILON * e0.abs().max(energy_scale))
}

/// Appends Protobuf field `number` = `value` (wire type 64-bit) to `buf`.
#[inline]
pub fn put_double(buf: &mut Vec<u8>, number: u32, value: f64) {
    prost::encoding::double::encode(number, &value, buf);
}

/// Appends the shortest round-trip decimal form of a finite `value` to `buf`.
#[inline]
pub fn push_number(buf: &mut Vec<u8>, value: f64, formatter: &mut ryu::Buffer) {
    buf.extend_from_slice(formatter.format_finite(value).as_bytes());
}

/// Reads a field added in a later version of a schema: a number, never `null` (a missing field gives `None`
/// through `#[serde(default)]`).
fn added_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    f64::deserialize(d).map(Some)
}

/// A `coin_log.*` message type as the format declares it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MessageType {
    /// Schema name.
    pub schema: &'static str,
    /// Field names in schema order (the JSON keys, `t` first; Protobuf field number = position + 1).
    pub fields: &'static [&'static str],
    /// Field names of the schema's first version (before any field added since).
    pub first_fields: &'static [&'static str],
    /// The JSON Schema, the bytes of `schemas/<schema>.json` embedded at build time.
    pub json_schema: &'static [u8],
}

/// Every `coin_log.*` message type.
pub const MESSAGE_TYPES: [MessageType; 8] = [
    AngularVelocity::TYPE,
    Angles::TYPE,
    QuaternionMessage::TYPE,
    Position::TYPE,
    ReactionMessage::TYPE,
    EnergyMessage::TYPE,
    InvariantsMessage::TYPE,
    WorkMessage::TYPE,
];

/// The `coin_log.*` type of schema name `schema`.
#[must_use]
pub fn message_type(schema: &str) -> Option<&'static MessageType> {
    MESSAGE_TYPES.iter().find(|t| t.schema == schema)
}

/// Declares the name of a Foxglove schema this tool writes, with the bytes of its file `schemas/<name>.json`.
macro_rules! foxglove_schema {
    ($(#[$doc:meta])* $name:ident, $json:ident = $schema:literal) => {
        $(#[$doc])*
        pub const $name: &str = $schema;
        const $json: &[u8] = include_bytes!(concat!("../../../../schemas/", $schema, ".json"));
    };
}

foxglove_schema!(
    /// Foxglove's frame transform (`/tf`, `/tf_static`, `/scene/follow`).
    FRAME_TRANSFORM, FRAME_TRANSFORM_JSON = "foxglove.FrameTransform"
);
foxglove_schema!(
    /// Foxglove's scene update (`/scene`, `/scene/table`, `/scene/track/<level>`).
    SCENE_UPDATE, SCENE_UPDATE_JSON = "foxglove.SceneUpdate"
);

/// Foxglove's point cloud (`/rerun/track`, Protobuf only: for Rerun's MCAP importer).
pub const POINT_CLOUD: &str = "foxglove.PointCloud";
/// Foxglove's voxel grid (`/rerun/table`, Protobuf only: for Rerun's MCAP importer).
pub const VOXEL_GRID: &str = "foxglove.VoxelGrid";

/// The bytes of `schemas/<name>.json` for a schema name this tool writes.
#[must_use]
pub fn schema_bytes(schema_name: &str) -> Option<&'static [u8]> {
    match schema_name {
        FRAME_TRANSFORM => Some(FRAME_TRANSFORM_JSON),
        SCENE_UPDATE => Some(SCENE_UPDATE_JSON),
        name => message_type(name).map(|t| t.json_schema),
    }
}

/// What the recorder and the readers need of every `coin_log.*` message type.
pub trait Message: Copy + serde::de::DeserializeOwned {
    /// Appends this message to `buf` in `encoding`; fails ([`NonFiniteField`]) if a field is NaN or
    /// infinite, leaving `buf` as it was.
    fn write(&self, encoding: Encoding, buf: &mut Vec<u8>) -> Result<(), NonFiniteField>;
    /// The message of the field values `v` in schema order (0 past its end); without the added fields
    /// when `first` (a schema of the type's first version).
    fn from_values(v: &[f64], first: bool) -> Self;
    /// Whether every field of the current schema is present (false for a message of a file written
    /// before an `added` field).
    fn is_complete(&self) -> bool;
    /// Simulation time.
    fn t(&self) -> f64;
}

/// Defines a message type (a field without a doc is the one of format.md's table, `t` the simulation
/// time). Fields listed under `added` came with a later version of the schema (docs/format.md
/// says which): they are `Option<f64>`, `None` in messages of files written before them, and the recorder
/// always writes them.
macro_rules! message {
    ($(#[$doc:meta])* $name:ident, $schema:literal, { $($(#[$fdoc:meta])* $field:ident),+ $(,)? }
     $(added { $($(#[$adoc:meta])* $added:ident),+ $(,)? })?) => {
        $(#[$doc])*
        #[allow(missing_docs)]
        #[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            $($(#[$fdoc])* pub $field: f64,)+
            $($(
                $(#[$adoc])*
                #[serde(default, deserialize_with = "added_number")]
                pub $added: Option<f64>,
            )+)?
        }

        impl $name {
            /// What the format says of the type.
            pub const TYPE: MessageType = MessageType {
                schema: $schema,
                fields: &[$(stringify!($field)),+ $($(, stringify!($added))+)?],
                first_fields: &[$(stringify!($field)),+],
                json_schema: include_bytes!(concat!("../../../../schemas/", $schema, ".json")),
            };

            /// The field values in schema order, `None` for an added field the message lacks.
            #[inline]
            fn values(&self) -> impl Iterator<Item = Option<f64>> {
                [$(Some(self.$field)),+ $($(, self.$added)+)?].into_iter()
            }

            /// `Err` naming the first field that is NaN or infinite.
            fn check_finite(&self) -> Result<(), NonFiniteField> {
                for (&field, value) in Self::TYPE.fields.iter().zip(self.values()) {
                    if let Some(value) = value.filter(|v| !v.is_finite()) {
                        return Err(NonFiniteField { schema: $schema, field, value });
                    }
                }
                Ok(())
            }

            /// Appends this message in Protobuf to `buf`: every field as a double numbered by its place in the
            /// schema (t = 1), zeros included; an added field only when it is `Some`.
            pub(crate) fn write_protobuf(&self, buf: &mut Vec<u8>) -> Result<(), NonFiniteField> {
                self.check_finite()?;
                for (number, value) in (1..).zip(self.values()) {
                    if let Some(v) = value {
                        put_double(buf, number, v);
                    }
                }
                Ok(())
            }

            /// Appends this message as one compact JSON object to `buf`: the fields in schema order, an
            /// added field only when it is `Some`; fails as [`Message::write`] does.
            pub fn write_json(&self, buf: &mut Vec<u8>) -> Result<(), NonFiniteField> {
                /// Each field's `"name":`, in schema order.
                const KEYS: &[&str] = &[$(concat!("\"", stringify!($field), "\":")),+
                    $($(, concat!("\"", stringify!($added), "\":"))+)?];
                self.check_finite()?;
                let mut formatter = ryu::Buffer::new();
                // `{` before the first field, `,` before each other.
                let mut separator = b'{';
                for (key, value) in KEYS.iter().zip(self.values()) {
                    if let Some(v) = value {
                        buf.push(separator);
                        separator = b',';
                        buf.extend_from_slice(key.as_bytes());
                        push_number(buf, v, &mut formatter);
                    }
                }
                buf.push(b'}');
                Ok(())
            }
        }

        impl Message for $name {
            #[inline]
            fn write(&self, encoding: Encoding, buf: &mut Vec<u8>) -> Result<(), NonFiniteField> {
                match encoding {
                    Encoding::Json => self.write_json(buf),
                    Encoding::Protobuf => self.write_protobuf(buf),
                }
            }

            #[allow(unused_variables)]
            fn from_values(v: &[f64], first: bool) -> Self {
                let mut it = v.iter().copied();
                Self {
                    $($field: it.next().unwrap_or(0.0),)+
                    $($($added: (!first).then(|| it.next().unwrap_or(0.0)),)+)?
                }
            }

            fn is_complete(&self) -> bool {
                true $($(&& self.$added.is_some())+)?
            }

            fn t(&self) -> f64 {
                self.t
            }
        }
    };
}

message!(
    /// `/coin/omega`: ω in the lean frame [rad/time].
    AngularVelocity, "coin_log.AngularVelocity", {
    t,
    x,
    y,
    z,
});

message!(
    /// `/coin/angles`: θ, φ, ψ \[rad\], φ and ψ unwrapped.
    Angles, "coin_log.Angles", {
    t,
    /// θ, lean.
    theta,
    /// φ, heading.
    phi,
    /// ψ, spin.
    psi,
} added {
    /// φ̇ = ω_Y / cos θ (physics eq 18), the heading rate [rad/time].
    phi_dot,
});

message!(
    /// `/coin/quaternion`: q of physics §1.
    QuaternionMessage, "coin_log.Quaternion", {
    t,
    x,
    y,
    z,
    w,
});

message!(
    /// `/coin/position` (centre) and `/coin/contact` (contact point), world frame, y up \[length\].
    Position, "coin_log.Position", {
    t,
    x,
    /// y (height).
    y,
    z,
});

message!(
    /// `/coin/reaction`: R (world frame), F and N \[force\].
    ReactionMessage, "coin_log.Reaction", {
    t,
    x,
    y,
    z,
    /// F = √(R_x² + R_z²).
    friction,
    /// N = R_y.
    normal,
} added {
    /// F / max(N, 1e-12 Mg): the friction coefficient needed to roll without slipping.
    friction_ratio,
});

message!(
    /// `/coin/energy` [mass·length²/time²].
    EnergyMessage, "coin_log.Energy", {
    t,
    total,
    kinetic,
    potential,
} added {
    /// E − E₀, E₀ the total energy at the first sample of the file.
    change,
    /// (E − E₀) / (ε max(|E₀|, Mga)), ε = [`f64::EPSILON`]: the relative drift in units of round-off
    /// ([`drift_eps`]).
    drift_eps,
});

message!(
    /// `/coin/invariants`: C1, C2 of physics §6.
    InvariantsMessage, "coin_log.Invariants", {
    t,
    c1,
    c2,
});

message!(
    /// `/coin/work`: the dissipated work and the energy balance (physics §11) [mass·length²/time²].
    WorkMessage, "coin_log.Work", {
    t,
    /// W, the energy dissipated since t = 0.
    dissipated,
    /// E + W, constant for an exact solution.
    balance,
});
