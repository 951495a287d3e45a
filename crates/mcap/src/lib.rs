//! MCAP files (<https://mcap.dev/spec>) read and written as records, in bounded memory. This module
//! knows MCAP, not what the messages mean: `record` and `verify` (and any later command that reads files)
//! put the coin-log contract on top of it. It depends on nothing else in the crate.
//!
//! **Writing**: [`McapWriter`] writes a chunked, indexed file with statistics, summary offsets and CRCs,
//! compressing whole chunks on worker threads ([`WriterOptions`], [`Compression`]). The same bytes go
//! out whatever the worker count or timing. [`ChunkCompressor`] is the code its workers compress a chunk
//! with, public so that a benchmark can time compression alone; [`DEFAULT_CHUNK_SIZE`] and [`ZSTD_LEVEL`]
//! are the writer's defaults.
//!
//! **Reading**: [`read`] (a path) and [`read_from`] (any reader of known length) walk a file once, in
//! file order, passing its channels (each with its schema), metadata and messages to a [`Visitor`].
//! Memory is bounded by [`READ_MEMORY_BOUND`] whatever the file says or holds, never by its length: no
//! record, chunk or decompressed chunk larger than [`MAX_RECORD_BYTES`] is accepted, every claimed length
//! is checked against the file size before anything is allocated for it, and a chunk is decompressed with
//! a limit, never trusting the size it declares. A worker thread reads and decompresses ahead and checks
//! the data, summary and chunk CRCs. Along the way the reader checks the file's structure (message indexes,
//! chunk indexes, statistics, metadata indexes, summary offsets, footer) and returns what it found as a
//! [`Structure`]; a file that cannot be read to its end is a [`ReadError`] whose [`ReadErrorKind`] says
//! why. [`read_with_progress`] also reports the bytes read so far.
//!
//! **Summary**: [`read_summary`] reads what a file says about itself (statistics, channels, chunk
//! indexes, metadata) from its summary section alone, in a few seeks, whatever the file's length.

mod budget;
mod digest;
mod early_metadata;
mod findings;
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
pub use reader::{
    read, read_from, read_with_progress, ReadError, ReadErrorKind, Structure, Visitor,
};
pub use summary::{read_summary, ChannelSummary, Summary};
pub use writer::{
    ChunkCompressor, Compression, McapWriter, WriteError, WriterOptions, DEFAULT_CHUNK_SIZE,
    ZSTD_LEVEL,
};
