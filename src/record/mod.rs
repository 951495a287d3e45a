//! Writing MCAP recordings: the recorder that integrates a scene straight into a file (load → resolve →
//! simulate/write → persist; the CLI does the loading and persisting), the Foxglove 3D output, and the
//! chunked writer. What goes into the file is defined by [`crate::format`].

pub mod foxglove;
pub mod recorder;
pub mod summary;
pub mod writer;

pub use foxglove::{Foxglove3d, FoxgloveBatch};
pub use recorder::{
    record, run_metadata, write_options, Compression, RecordError, RecordOptions,
    COMPRESSION_THREADS,
};
pub use summary::{Failure, RecordSummary};
pub use writer::{ChunkCompression, ChunkCompressor, McapWriter, WriteError, WriterOptions};
