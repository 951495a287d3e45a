//! The channels of the format (format.md: Channels and fields): name, topic, schema name and fields, and the
//! schema bytes a file stores in either encoding.

use super::messages::{
    schema_bytes, Angles, AngularVelocity, EnergyMessage, InvariantsMessage, MessageType, Position,
    QuaternionMessage, ReactionMessage, WorkMessage, FRAME_TRANSFORM, SCENE_UPDATE,
};
use super::Encoding;
use std::fmt;

/// Schema encoding of every channel in the default encoding, JSON ([`Encoding::Json`]).
pub const SCHEMA_ENCODING: &str = Encoding::Json.schema_encoding();
/// Message encoding of every channel in the default encoding, JSON ([`Encoding::Json`]).
pub const MESSAGE_ENCODING: &str = Encoding::Json.message_encoding();

coin_log_names::named_enum! {
    /// A recordable channel; the name is the one of scene files and `--channels`. `work` is last here, but
    /// in a file it is written, and registered, with the other `coin_log.*` channels before `/tf` and
    /// `/scene` (format.md's channel table).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
    pub enum Channel: "channel" {
        /// ω in the lean frame.
        Omega = "omega",
        /// θ, φ, ψ.
        Angles = "angles",
        /// Orientation quaternion.
        Quaternion = "quaternion",
        /// Centre position.
        Position = "position",
        /// Contact point.
        Contact = "contact",
        /// Reaction of the table.
        Reaction = "reaction",
        /// Energy.
        Energy = "energy",
        /// Chaplygin integrals C1, C2.
        Invariants = "invariants",
        /// Foxglove frame transforms.
        Tf = "tf",
        /// Foxglove scene (coin and track).
        Scene = "scene",
        /// Dissipated work W and the balance E + W (only with dissipation, physics §11).
        Work = "work",
    }
}

impl Channel {
    /// The channels a scene records when it lists none and has no dissipation (format.md: all ten, every
    /// channel but the last, `work`, which dissipation adds).
    pub const DEFAULT: &'static [Channel] = match Self::ALL.split_last() {
        Some((_, default)) => default,
        None => &[],
    };

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

    /// The `coin_log.*` message type of the channel; `None` for Foxglove's `/tf` and `/scene`.
    #[must_use]
    pub fn message_type(self) -> Option<&'static MessageType> {
        Some(match self {
            Self::Omega => &AngularVelocity::TYPE,
            Self::Angles => &Angles::TYPE,
            Self::Quaternion => &QuaternionMessage::TYPE,
            Self::Position | Self::Contact => &Position::TYPE,
            Self::Reaction => &ReactionMessage::TYPE,
            Self::Energy => &EnergyMessage::TYPE,
            Self::Invariants => &InvariantsMessage::TYPE,
            Self::Work => &WorkMessage::TYPE,
            Self::Tf | Self::Scene => return None,
        })
    }

    /// Schema name.
    #[must_use]
    pub fn schema_name(self) -> &'static str {
        match self.message_type() {
            Some(t) => t.schema,
            None if self == Self::Tf => FRAME_TRANSFORM,
            None => SCENE_UPDATE,
        }
    }

    /// The fields of the channel's messages in schema order (the JSON keys, `t` first) for the
    /// `coin_log.*` channels; `None` for Foxglove's `/tf` and `/scene`, whose messages are nested.
    #[must_use]
    pub fn fields(self) -> Option<&'static [&'static str]> {
        self.message_type().map(|t| t.fields)
    }

    /// Every channel's name, comma-separated, for messages.
    #[must_use]
    pub fn names() -> String {
        Self::NAMES.join(", ")
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
            .iter()
            .map(|&c| Self::Main(c))
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
