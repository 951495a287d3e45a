//! The file format, typed: everything a coin-log MCAP file contains that `scene`, `record` and `verify` must
//! agree on (docs/format.md). The channels with their topics and schemas ([`channels`]); the schemas and
//! the `coin_log.*` message types with their JSON form ([`messages`], read back by [`json`]) and their Protobuf form ([`protobuf`], the two [`Encoding`]s); the two metadata
//! records with typed values ([`metadata`]); how a run ended ([`Termination`]); and the one conversion from
//! simulation time to log time ([`log_time`]); and the tolerances a file is judged by, derived from its
//! recorded integrator settings ([`tolerances`]), and what they will accept, predicted from the settings
//! ([`promise`]).
//!
//! It knows the physics' vocabulary (integrator [`Method`](crate::integrate::Method), steady
//! [`SteadyFamily`](crate::model::SteadyFamily), [`Branch`](crate::model::Branch), physical events) but
//! nothing about scenes, the recorder or the checks, which all import it.

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

pub use channels::{
    schema_data, Channel, Topic, MESSAGE_ENCODING, ROS_STRING, SCHEMA_ENCODING, TRACK_LEVELS,
};
pub use encoding::Encoding;
pub use messages::{schema_bytes, FRAME_TRANSFORM, SCENE_UPDATE};
pub use metadata::{
    MetadataError, ResultMetadata, RunMetadata, FORMAT_VERSION, RESULT_METADATA_NAME,
    RUN_METADATA_NAME,
};
pub use termination::Termination;
pub use time::{log_time, TimeError};
