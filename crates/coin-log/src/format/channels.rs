//! The channels of the format (format.md: Channels and fields): name, topic, schema name and fields, and the
//! schema bytes a file stores in either encoding.

use super::messages::{
    schema_bytes, Angles, AngularVelocity, EnergyMessage, InvariantsMessage, MessageType, Position,
    QuaternionMessage, ReactionMessage, WorkMessage, FRAME_TRANSFORM, POINT_CLOUD, SCENE_UPDATE,
    VOXEL_GRID,
};
use super::Encoding;
use std::fmt;

coin_log_names::named_enum! {
    /// A recordable channel; the name is the one of scene files and `--channels`. `work` and `rerun` are
    /// last here (both opt-in), but in a file `work` is written, and registered, with the other
    /// `coin_log.*` channels before `/tf` and `/scene` (format.md's channel table, which says what each
    /// carries).
    #[allow(missing_docs)]
    #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
    pub enum Channel: "channel" {
        Omega = "omega",
        Angles = "angles",
        Quaternion = "quaternion",
        Position = "position",
        Contact = "contact",
        Reaction = "reaction",
        Energy = "energy",
        Invariants = "invariants",
        Tf = "tf",
        Scene = "scene",
        Work = "work",
        Rerun = "rerun",
    }
}

impl Channel {
    /// The channels a scene records when it lists none and has no dissipation (format.md: all ten, every
    /// channel but the last two, `work`, which dissipation adds, and `rerun`, which `record.rerun` adds).
    pub const DEFAULT: &'static [Channel] = match Self::ALL.split_last() {
        Some((_, [default @ .., _])) => default,
        _ => &[],
    };

    /// The encodings a file may record the channel in: Rerun's importer decodes Protobuf, not JSON.
    #[must_use]
    pub fn encodings(self) -> &'static [Encoding] {
        match self {
            Self::Rerun => &[Encoding::Protobuf],
            _ => Encoding::ALL,
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
            Self::Rerun => "/rerun/coin_body",
        }
    }

    /// The `coin_log.*` message type of the channel; `None` for Foxglove's `/tf`, `/scene`, `/rerun/coin_body`.
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
            Self::Tf | Self::Scene | Self::Rerun => return None,
        })
    }

    /// Schema name.
    #[must_use]
    pub fn schema_name(self) -> &'static str {
        match self.message_type() {
            Some(t) => t.schema,
            None if self == Self::Scene => SCENE_UPDATE,
            None => FRAME_TRANSFORM,
        }
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

macro_rules! track_topics {
    ($($level:literal)*) => {
        [$(concat!("/scene/track/", $level)),*]
    };
}

/// The track topics, level by level.
const TRACK_TOPICS: [&str; TRACK_LEVELS] = track_topics!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15);

/// An MCAP topic of the format: every channel's main topic ([`Channel::topic`]), and the extra topics of
/// `tf`, `scene` and `rerun` (format.md: Frames and Foxglove output, Rerun geometry).
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
    /// `/rerun/robot_description` (`rerun`): the coin's shape as a URDF, once (ROS 2 `std_msgs/msg/String`).
    RerunRobot,
    /// `/rerun/table` (`rerun`): the table as a voxel grid, when it moves.
    RerunTable,
    /// `/rerun/track` (`rerun`): the contact points since the previous drawing update, as a point cloud.
    RerunTrack,
}

/// The schema of `/rerun/robot_description`: ROS 2's `std_msgs/msg/String` in CDR, the one form Rerun's
/// URDF decoder reads (whatever the file's encoding).
pub const ROS_STRING: &str = "std_msgs/msg/String";
/// The MCAP schema encoding, schema text and message encoding of [`ROS_STRING`].
pub const ROS_STRING_WIRE: (&str, &[u8], &str) = ("ros2msg", b"string data", "cdr");

impl Topic {
    /// Number of topics: every channel's main topic, then the Foxglove extras.
    pub const COUNT: usize = Channel::ALL.len() + 6 + TRACK_LEVELS;

    /// Every topic, main topics first in the channel table's order.
    pub fn all() -> impl Iterator<Item = Topic> {
        let extras = [Self::TfStatic, Self::SceneFollow, Self::SceneTable];
        let levels = (0..=u8::MAX).take(TRACK_LEVELS).map(Self::SceneTrack);
        let rerun = [Self::RerunRobot, Self::RerunTable, Self::RerunTrack];
        Channel::ALL
            .iter()
            .map(|&c| Self::Main(c))
            .chain(extras)
            .chain(levels)
            .chain(rerun)
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
            Self::RerunRobot => n + 3 + TRACK_LEVELS,
            Self::RerunTable => n + 4 + TRACK_LEVELS,
            Self::RerunTrack => n + 5 + TRACK_LEVELS,
        }
    }

    /// The channel (recorded or not as a whole) the topic belongs to.
    #[must_use]
    pub fn channel(self) -> Channel {
        match self {
            Self::Main(c) => c,
            Self::TfStatic => Channel::Tf,
            Self::SceneFollow | Self::SceneTable | Self::SceneTrack(_) => Channel::Scene,
            Self::RerunRobot | Self::RerunTable | Self::RerunTrack => Channel::Rerun,
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
            Self::RerunRobot => "/rerun/robot_description",
            Self::RerunTable => "/rerun/table",
            Self::RerunTrack => "/rerun/track",
        }
    }

    /// Schema name.
    #[must_use]
    pub fn schema_name(self) -> &'static str {
        match self {
            Self::Main(c) => c.schema_name(),
            Self::TfStatic | Self::SceneFollow => Channel::Tf.schema_name(),
            Self::SceneTable | Self::SceneTrack(_) => Channel::Scene.schema_name(),
            Self::RerunRobot => ROS_STRING,
            Self::RerunTable => VOXEL_GRID,
            Self::RerunTrack => POINT_CLOUD,
        }
    }

    /// The MCAP schema encoding, schema bytes and message encoding of the topic in a file of `encoding`
    /// (`None` if the topic cannot be recorded in it: [`Channel::encodings`]).
    #[must_use]
    pub fn wire(self, encoding: Encoding) -> Option<(&'static str, &'static [u8], &'static str)> {
        if self == Self::RerunRobot {
            return Some(ROS_STRING_WIRE);
        }
        if !self.channel().encodings().contains(&encoding) {
            return None;
        }
        let data = schema_data(self.schema_name(), encoding)?;
        Some((
            encoding.schema_encoding(),
            data,
            encoding.message_encoding(),
        ))
    }

    /// The topic with this name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::all().find(|t| t.name() == name)
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
