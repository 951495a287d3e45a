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
pub mod random;
mod run;
pub mod shard;
mod space;
mod validate;

pub use catalogue::{
    columns, FailureKind, RunStatus, LEADING_COLUMNS, TRAILING_COLUMNS, WALL_TIME_COLUMN,
};
pub use collect::{collect, Collected};
pub use definition::{
    Axis, Draw, Random, RunSceneError, Settings, Sweep, CHANNELS_KEY, MAX_AXIS_VALUES, MAX_RUNS,
};
pub use error::SweepError;
pub use file::{AxisFile, DrawFile, NormalFile, OutputFile, RandomFile, SweepFile};
pub use folder::{
    part_file_name, run_file_name, CATALOGUE_FILE, FORMAT_VERSION, PLAN_FILE, STATE_DIR,
    SWEEP_JSON_FILE,
};
pub use hash::{sha256_file, sha256_hex};
pub use preview::{preview, Preview, MESSAGES_PER_SECOND, SAMPLED_RUNS};
pub use run::{run, Progress, RunOptions, SweepOutcome};
pub use shard::{Shard, ShardError};
pub use space::{linspace, logspace};
