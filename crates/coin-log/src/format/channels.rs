//! The channels of the format (format.md: Channels and fields): name, topic, schema name and schema bytes.
//! The schema bytes are the files in `schemas/`, embedded at build time, so a log's schema is the file.

use super::Encoding;
use std::fmt;
use std::str::FromStr;

/// Schema encoding of every channel in the default encoding, JSON ([`Encoding::Json`]).
pub const SCHEMA_ENCODING: &str = "jsonschema";
/// Message encoding of every channel in the default encoding, JSON ([`Encoding::Json`]).
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

    /// The channel a topic belongs to: its main topic, or one of the extra Foxglove topics ([`Topic`]).
    #[must_use]
    pub fn from_topic(topic: &str) -> Option<Self> {
        Topic::from_name(topic).map(Topic::channel)
    }
}

/// Track levels of the `scene` channel: topics `/scene/track/0` … `/scene/track/15` (docs/format.md: Frames
/// and Foxglove output).
pub const TRACK_LEVELS: usize = 16;

/// The track topics, level by level.
const TRACK_TOPICS: [&str; TRACK_LEVELS] = [
    "/scene/track/0",
    "/scene/track/1",
    "/scene/track/2",
    "/scene/track/3",
    "/scene/track/4",
    "/scene/track/5",
    "/scene/track/6",
    "/scene/track/7",
    "/scene/track/8",
    "/scene/track/9",
    "/scene/track/10",
    "/scene/track/11",
    "/scene/track/12",
    "/scene/track/13",
    "/scene/track/14",
    "/scene/track/15",
];

/// An MCAP topic of the format. Every channel writes its main topic ([`Channel::topic`]); the two Foxglove
/// channels write more, so that a viewer that restores only the latest message of each topic after a seek
/// still has every frame and the whole track: `tf` also writes `/tf_static`, and `scene` writes
/// `/scene/follow`, `/scene/table` and the track levels `/scene/track/<level>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Topic {
    /// The channel's main topic.
    Main(Channel),
    /// `/tf_static` (`tf`): world → table, once.
    TfStatic,
    /// `/scene/follow` (`scene`): world → coin_level, the level frame at the coin's centre.
    SceneFollow,
    /// `/scene/table` (`scene`): the table under the coin.
    SceneTable,
    /// `/scene/track/<level>` (`scene`): one level of the contact track, level < [`TRACK_LEVELS`].
    SceneTrack(u8),
}

impl Topic {
    /// Number of topics: every channel's main topic, then the Foxglove extras.
    pub const COUNT: usize = Channel::ALL.len() + 3 + TRACK_LEVELS;

    /// Every topic, main topics first in the channel table's order.
    pub fn all() -> impl Iterator<Item = Topic> {
        let extras = [Self::TfStatic, Self::SceneFollow, Self::SceneTable];
        // TRACK_LEVELS (16) fits in a u8.
        let levels = (0..TRACK_LEVELS).map(|l| Self::SceneTrack(u8::try_from(l).unwrap_or(0)));
        Channel::ALL
            .into_iter()
            .map(Self::Main)
            .chain(extras)
            .chain(levels)
    }

    /// A dense index in 0..[`Self::COUNT`].
    #[must_use]
    pub fn index(self) -> usize {
        let n = Channel::ALL.len();
        match self {
            Self::Main(c) => c as usize,
            Self::TfStatic => n,
            Self::SceneFollow => n + 1,
            Self::SceneTable => n + 2,
            Self::SceneTrack(l) => n + 3 + usize::from(l).min(TRACK_LEVELS - 1),
        }
    }

    /// The channel (recorded or not as a whole) the topic belongs to.
    #[must_use]
    pub fn channel(self) -> Channel {
        match self {
            Self::Main(c) => c,
            Self::TfStatic => Channel::Tf,
            Self::SceneFollow | Self::SceneTable | Self::SceneTrack(_) => Channel::Scene,
        }
    }

    /// The MCAP topic name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Main(c) => c.topic(),
            Self::TfStatic => "/tf_static",
            Self::SceneFollow => "/scene/follow",
            Self::SceneTable => "/scene/table",
            Self::SceneTrack(l) => TRACK_TOPICS[usize::from(l).min(TRACK_LEVELS - 1)],
        }
    }

    /// Schema name.
    #[must_use]
    pub fn schema_name(self) -> &'static str {
        match self {
            Self::Main(c) => c.schema_name(),
            Self::TfStatic | Self::SceneFollow => Channel::Tf.schema_name(),
            Self::SceneTable | Self::SceneTrack(_) => Channel::Scene.schema_name(),
        }
    }

    /// The topic with this name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::all().find(|t| t.name() == name)
    }
}

impl From<Channel> for Topic {
    fn from(channel: Channel) -> Self {
        Self::Main(channel)
    }
}

impl fmt::Display for Topic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The schema bytes a file in `encoding` stores for a schema name this tool writes: the JSON Schema of
/// `schemas/<name>.json`, or the serialized `FileDescriptorSet` ([`super::protobuf::descriptor_set`]).
#[must_use]
pub fn schema_data(schema_name: &str, encoding: Encoding) -> Option<&'static [u8]> {
    match encoding {
        Encoding::Json => schema_bytes(schema_name),
        Encoding::Protobuf => super::protobuf::descriptor_set(schema_name),
    }
}

/// The bytes of `schemas/<name>.json` for a schema name this tool writes.
#[must_use]
pub fn schema_bytes(schema_name: &str) -> Option<&'static [u8]> {
    Some(match schema_name {
        "coin_log.AngularVelocity" => {
            include_bytes!("../../../../schemas/coin_log.AngularVelocity.json")
        }
        "coin_log.Angles" => include_bytes!("../../../../schemas/coin_log.Angles.json"),
        "coin_log.Quaternion" => include_bytes!("../../../../schemas/coin_log.Quaternion.json"),
        "coin_log.Position" => include_bytes!("../../../../schemas/coin_log.Position.json"),
        "coin_log.Reaction" => include_bytes!("../../../../schemas/coin_log.Reaction.json"),
        "coin_log.Energy" => include_bytes!("../../../../schemas/coin_log.Energy.json"),
        "coin_log.Invariants" => include_bytes!("../../../../schemas/coin_log.Invariants.json"),
        "coin_log.Work" => include_bytes!("../../../../schemas/coin_log.Work.json"),
        "foxglove.FrameTransform" => {
            include_bytes!("../../../../schemas/foxglove.FrameTransform.json")
        }
        "foxglove.SceneUpdate" => include_bytes!("../../../../schemas/foxglove.SceneUpdate.json"),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topics_have_distinct_names_and_dense_indexes() {
        let all: Vec<Topic> = Topic::all().collect();
        assert_eq!(all.len(), Topic::COUNT);
        for (i, t) in all.iter().enumerate() {
            assert_eq!(t.index(), i, "{t}");
            assert_eq!(Topic::from_name(t.name()), Some(*t));
            for &e in Encoding::ALL {
                assert!(schema_data(t.schema_name(), e).is_some(), "{t} {e}");
            }
        }
        let names: std::collections::BTreeSet<&str> = all.iter().map(|t| t.name()).collect();
        assert_eq!(names.len(), all.len());
        assert_eq!(Channel::from_topic("/scene/track/15"), Some(Channel::Scene));
        assert_eq!(Channel::from_topic("/tf_static"), Some(Channel::Tf));
        assert_eq!(Channel::from_topic("/scene/track/16"), None);
    }
}
