//! The channels of the format (format.md: Channels and fields): name, topic, schema name and schema bytes.
//! The schema bytes are the files in `schemas/`, embedded at build time, so a log's schema is the file.

use std::fmt;
use std::str::FromStr;

/// Schema encoding of every channel.
pub const SCHEMA_ENCODING: &str = "jsonschema";
/// Message encoding of every channel.
pub const MESSAGE_ENCODING: &str = "json";

/// A recordable channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Channel {
    /// ω in the lean frame.
    Omega,
    /// θ, φ, ψ.
    Angles,
    /// Orientation quaternion.
    Quaternion,
    /// Centre position.
    Position,
    /// Contact point.
    Contact,
    /// Reaction of the table.
    Reaction,
    /// Energy.
    Energy,
    /// Chaplygin integrals C1, C2.
    Invariants,
    /// Foxglove frame transforms.
    Tf,
    /// Foxglove scene (coin and track).
    Scene,
    /// Dissipated work W and the balance E + W (only with dissipation, physics §11).
    Work,
}

impl Channel {
    /// Every channel. `work` is last here, but in a file it is written, and registered, with the other
    /// `coin_log.*` channels before `/tf` and `/scene` (format.md's channel table).
    pub const ALL: [Channel; 11] = [
        Self::Omega,
        Self::Angles,
        Self::Quaternion,
        Self::Position,
        Self::Contact,
        Self::Reaction,
        Self::Energy,
        Self::Invariants,
        Self::Tf,
        Self::Scene,
        Self::Work,
    ];

    /// The channels a scene records when it lists none and has no dissipation (format.md: all ten); with
    /// dissipation, `work` is added.
    pub const DEFAULT: [Channel; 10] = [
        Self::Omega,
        Self::Angles,
        Self::Quaternion,
        Self::Position,
        Self::Contact,
        Self::Reaction,
        Self::Energy,
        Self::Invariants,
        Self::Tf,
        Self::Scene,
    ];

    /// The channel's name in scene files and `--channels`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Omega => "omega",
            Self::Angles => "angles",
            Self::Quaternion => "quaternion",
            Self::Position => "position",
            Self::Contact => "contact",
            Self::Reaction => "reaction",
            Self::Energy => "energy",
            Self::Invariants => "invariants",
            Self::Tf => "tf",
            Self::Scene => "scene",
            Self::Work => "work",
        }
    }

    /// MCAP topic.
    #[must_use]
    pub fn topic(self) -> &'static str {
        match self {
            Self::Omega => "/coin/omega",
            Self::Angles => "/coin/angles",
            Self::Quaternion => "/coin/quaternion",
            Self::Position => "/coin/position",
            Self::Contact => "/coin/contact",
            Self::Reaction => "/coin/reaction",
            Self::Energy => "/coin/energy",
            Self::Invariants => "/coin/invariants",
            Self::Tf => "/tf",
            Self::Scene => "/scene",
            Self::Work => "/coin/work",
        }
    }

    /// Schema name.
    #[must_use]
    pub fn schema_name(self) -> &'static str {
        match self {
            Self::Omega => "coin_log.AngularVelocity",
            Self::Angles => "coin_log.Angles",
            Self::Quaternion => "coin_log.Quaternion",
            Self::Position | Self::Contact => "coin_log.Position",
            Self::Reaction => "coin_log.Reaction",
            Self::Energy => "coin_log.Energy",
            Self::Invariants => "coin_log.Invariants",
            Self::Tf => "foxglove.FrameTransform",
            Self::Scene => "foxglove.SceneUpdate",
            Self::Work => "coin_log.Work",
        }
    }

    /// The fields of the channel's messages in schema order (the JSON keys, `t` first) for the
    /// `coin_log.*` channels; `None` for Foxglove's `/tf` and `/scene`, whose messages are nested.
    #[must_use]
    pub fn fields(self) -> Option<&'static [&'static str]> {
        use super::messages::{
            Angles, AngularVelocity, EnergyMessage, InvariantsMessage, Position, QuaternionMessage,
            ReactionMessage, WorkMessage,
        };
        Some(match self {
            Self::Omega => AngularVelocity::FIELDS,
            Self::Angles => Angles::FIELDS,
            Self::Quaternion => QuaternionMessage::FIELDS,
            Self::Position | Self::Contact => Position::FIELDS,
            Self::Reaction => ReactionMessage::FIELDS,
            Self::Energy => EnergyMessage::FIELDS,
            Self::Invariants => InvariantsMessage::FIELDS,
            Self::Work => WorkMessage::FIELDS,
            Self::Tf | Self::Scene => return None,
        })
    }

    /// Every channel's name, comma-separated, for messages.
    #[must_use]
    pub fn names() -> String {
        Self::ALL.map(Self::name).join(", ")
    }

    /// The channel with this topic.
    #[must_use]
    pub fn from_topic(topic: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.topic() == topic)
    }
}

/// The bytes of `schemas/<name>.json` for a schema name this tool writes.
#[must_use]
pub fn schema_bytes(schema_name: &str) -> Option<&'static [u8]> {
    Some(match schema_name {
        "coin_log.AngularVelocity" => include_bytes!("../../schemas/coin_log.AngularVelocity.json"),
        "coin_log.Angles" => include_bytes!("../../schemas/coin_log.Angles.json"),
        "coin_log.Quaternion" => include_bytes!("../../schemas/coin_log.Quaternion.json"),
        "coin_log.Position" => include_bytes!("../../schemas/coin_log.Position.json"),
        "coin_log.Reaction" => include_bytes!("../../schemas/coin_log.Reaction.json"),
        "coin_log.Energy" => include_bytes!("../../schemas/coin_log.Energy.json"),
        "coin_log.Invariants" => include_bytes!("../../schemas/coin_log.Invariants.json"),
        "coin_log.Work" => include_bytes!("../../schemas/coin_log.Work.json"),
        "foxglove.FrameTransform" => include_bytes!("../../schemas/foxglove.FrameTransform.json"),
        "foxglove.SceneUpdate" => include_bytes!("../../schemas/foxglove.SceneUpdate.json"),
        _ => return None,
    })
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown channel name, with the list of valid ones.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown channel `{name}`; valid channels: {valid}", name = .0, valid = Channel::names())]
pub struct UnknownChannel(pub String);

impl FromStr for Channel {
    type Err = UnknownChannel;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| UnknownChannel(s.to_string()))
    }
}
