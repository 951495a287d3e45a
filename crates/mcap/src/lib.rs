//! MCAP files (<https://mcap.dev/spec>) written and read as records, in bounded memory. It knows MCAP,
//! not coins (docs/architecture.md).
//!
//! - Writing: [`McapWriter`] writes a chunked, indexed file, compressing chunks on worker threads.
//! - Reading: [`read`], [`read_with_progress`] and [`read_from`] walk a file once, in file order, passing
//!   its channels, metadata and messages to a [`Visitor`] and checking its structure ([`Structure`]), in
//!   at most [`READ_MEMORY_BOUND`] whatever the file says or holds.
//! - Log-time order: [`read_in_log_time_order`] reads the messages of a file's chunks in log-time order
//!   through its chunk indexes, for a file whose writer put channels far apart.
//! - Summary: [`read_summary`] reads what a file says about itself from its summary section alone.

mod budget;
mod digest;
mod early_metadata;
mod findings;
mod ordered;
mod prefetch;
mod reader;
#[doc(hidden)]
pub mod records;
mod summary;
mod writer;

pub use budget::{MAX_RECORD_BYTES, READ_MEMORY_BOUND};
pub use findings::BoundedFindings;
pub use mcap::records::MessageHeader;
pub use mcap::Schema;
pub use ordered::{read_in_log_time_order, ORDERED_CHUNK_BYTES};
pub use reader::{
    read, read_from, read_with_progress, regular_file, ReadError, ReadErrorKind, Structure, Visitor,
};
pub use summary::{read_summary, ChannelSummary, Summary};
pub use writer::{
    ChunkCompressor, Compression, McapWriter, WriteError, WriterOptions, DEFAULT_CHUNK_SIZE,
    ZSTD_LEVEL,
};
