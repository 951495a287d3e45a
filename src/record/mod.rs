//! Writing MCAP logs (CONTRACT: Channels, Metadata records): the contract's data types and the recorder
//! that integrates a scene straight into a file through [`crate::mcap_io::McapWriter`].

pub mod channels;
pub mod foxglove;
pub mod messages;
pub mod metadata;
pub mod recorder;
pub mod summary;

pub use channels::{schema_bytes, Channel, UnknownChannel, MESSAGE_ENCODING, SCHEMA_ENCODING};
pub use foxglove::{Foxglove3d, FoxgloveBatch};
pub use metadata::{
    ResultMetadata, RunMetadata, FORMAT_VERSION, RESULT_METADATA_NAME, RUN_METADATA_NAME,
};
pub use recorder::{
    record, run_metadata, write_options, Compression, RecordError, RecordOptions,
    COMPRESSION_THREADS,
};
pub use summary::{Failure, RecordSummary, Termination};
