//! Writing MCAP recordings: the recorder that integrates a scene straight into a file, and the Foxglove 3D
//! output. What goes into the file is defined by [`crate::format`].

pub mod estimate;
pub mod foxglove;
pub mod recorder;
pub mod summary;

pub use estimate::{estimate, Estimate};
pub use foxglove::{Foxglove3d, FoxgloveBatch};
pub use recorder::{
    expected_shortfalls, record, record_with_tap, ChannelDeclaration, NoTap, RecordError,
    RecordOptions, Tap, COMPRESSION_THREADS,
};
pub use summary::{Failure, RecordSummary};
