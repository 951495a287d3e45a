//! Writing MCAP logs (CONTRACT: Channels, Metadata records).

pub mod channels;
pub mod messages;

pub use channels::{schema_bytes, Channel, UnknownChannel, MESSAGE_ENCODING, SCHEMA_ENCODING};
pub mod foxglove;
pub mod metadata;

pub use foxglove::{Foxglove3d, FoxgloveBatch};
pub use metadata::{
    ResultMetadata, RunMetadata, FORMAT_VERSION, RESULT_METADATA_NAME, RUN_METADATA_NAME,
};
