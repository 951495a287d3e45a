//! The file format, typed (docs/format.md): everything a coin-log MCAP file contains that `scene`, `record`
//! and `verify` must agree on: channels and topics, message types in both [`Encoding`]s, metadata records,
//! [`Termination`], [`log_time`], and the [`tolerances`] a file is judged by with what they will accept
//! ([`promise`]). It knows the physics' vocabulary but nothing of scenes, the recorder or the checks.

pub mod channels;
mod encoding;
pub(crate) mod fields;
pub mod json;
pub mod messages;
pub mod metadata;
pub mod promise;
pub mod protobuf;
mod termination;
mod time;
pub mod tolerances;

pub use channels::{schema_data, Channel, Topic, ROS_STRING, TRACK_LEVELS};
pub use encoding::Encoding;
pub use messages::{schema_bytes, FRAME_TRANSFORM, SCENE_UPDATE};
pub use metadata::{
    header_library, MetadataError, ResultMetadata, RunMetadata, FORMAT_VERSION,
    RESULT_METADATA_NAME, RUN_METADATA_NAME,
};
pub use termination::Termination;
pub use time::{log_time, TimeError};
