//! Datasets, not single files (format.md: Sweeps): a sweep file names a base scene and what varies; `run`
//! records (as `record` would), verifies and catalogues every run of it, or of one shard, into a folder on
//! threads, and resumes when run again; `collect` merges the shards' catalogues. A run's values depend
//! only on the sweep file and the run's index ([`Sweep::values`]). The CLI reads the shard's environment,
//! installs the signal handler that sets the stop flag, and draws the progress.

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

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, PoisonError, RwLock};

/// Calls `work` on each position 0 … `len` − 1 on up to `jobs` threads until `stop` is set (`None`: no
/// result for it); `handle` gets the results on the calling thread as they come, in batches of those that
/// came while it handled the previous one (so that one journal sync serves them all: the sweep is never
/// slower than the disk syncs one row). Positions, not a list of items: a sweep of 10⁹ runs must not
/// hold a list of them.
fn on_threads<R: Send>(
    len: u64,
    jobs: usize,
    stop: &AtomicBool,
    work: impl Fn(u64) -> Option<R> + Sync,
    mut handle: impl FnMut(Vec<R>),
) {
    let next = AtomicU64::new(0);
    let (sender, receiver) = mpsc::channel();
    let threads = usize::try_from(len.max(1)).map_or(jobs.max(1), |len| jobs.clamp(1, len));
    // The next position's result, skipping those without one; `None` once `stop` is set or every
    // position is taken.
    let next_result = || {
        while !stop.load(Ordering::SeqCst) {
            let position = next.fetch_add(1, Ordering::SeqCst);
            if position >= len {
                return None;
            }
            if let Some(result) = work(position) {
                return Some(result);
            }
        }
        None
    };
    // How many of the threads work, set once all are spawned: the system may refuse a thread (its limit
    // on processes or threads), and then half of those it gave stay idle, since a run needs one more
    // thread while it runs (verify's reading thread; the writer compresses on its own without one).
    let gate = RwLock::new(0_usize);
    let worker = |number: usize, sender: mpsc::Sender<R>| {
        if number >= *gate.read().unwrap_or_else(PoisonError::into_inner) {
            return;
        }
        while let Some(result) = next_result() {
            if sender.send(result).is_err() {
                break;
            }
        }
    };
    std::thread::scope(|scope| {
        let mut working = gate.write().unwrap_or_else(PoisonError::into_inner);
        let spawned = (0..threads)
            .take_while(|&number| {
                let (sender, worker) = (sender.clone(), &worker);
                // Not scope.spawn, which panics when refused.
                let builder = std::thread::Builder::new();
                builder
                    .spawn_scoped(scope, move || worker(number, sender))
                    .is_ok()
            })
            .count();
        *working = if spawned < threads {
            spawned.div_ceil(2)
        } else {
            spawned
        };
        drop(working);
        drop(sender);
        if spawned == 0 {
            // Not one thread: the work is done here, each result handled as it comes.
            while let Some(result) = next_result() {
                handle(vec![result]);
            }
        }
        for first in &receiver {
            let mut batch = vec![first];
            batch.extend(receiver.try_iter());
            handle(batch);
        }
    });
}
