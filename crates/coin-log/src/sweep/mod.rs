//! Datasets, not single files (format.md: Sweeps): a sweep file names a base scene and what varies (grid
//! axes, random draws); `run` records every run of it (or of one shard) into a folder, `jobs` at once on
//! threads of this process, each file byte for byte what `record` writes for the same resolved scene,
//! verifies each, and writes a catalogue with one row per run; run again, it resumes. `collect` merges the
//! catalogues of shards run on other machines.
//!
//! A run's values depend only on the sweep file and the run's index ([`Sweep::values`]): never on jobs,
//! shards or machines. The library never prints and never starts a process: the CLI reads the
//! environment for the shard, installs the signal handler that sets the stop flag, and draws the progress.

mod catalogue;
mod collect;
mod definition;
mod error;
mod file;
mod folder;
mod hash;
mod preview;
mod random;
mod run;
mod shard;
mod space;
mod validate;

pub use collect::{collect, Collected};
pub use definition::Sweep;
pub use error::SweepError;
pub use hash::sha256_hex;
pub use preview::{preview, Preview, MESSAGES_PER_SECOND, SAMPLED_RUNS};
pub use random::word;
pub use run::{run, Progress, RunOptions, SweepOutcome};
pub use shard::{Shard, ShardError};
pub use space::{linspace, logspace};
