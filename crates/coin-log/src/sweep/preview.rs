//! `coin-log sweep --dry-run` (format.md: Dry run): the run count, the first runs' values, and the size
//! and time the sweep will take, estimated from the runs' scenes without recording anything.

use super::catalogue::cell;
use super::definition::Sweep;
use super::shard::Shard;
use crate::record;

/// Runs whose scenes are resolved for the estimate; a larger sweep is estimated from this many, evenly
/// spaced.
pub const SAMPLED_RUNS: u64 = 1000;

/// Messages recorded, hashed and verified per second by one job, for the time estimate: measured on the
/// 2-core development machine with `coin-log bench sweep` (short `wobble` runs, every channel, JSON,
/// zstd). Long or stiff runs integrate more slowly per message, so this is a rough guide only.
pub const MESSAGES_PER_SECOND: f64 = 250_000.0;

/// What a dry run shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Preview {
    /// The shard's runs.
    pub runs: u64,
    /// The first runs: index and the swept keys' values, as catalogue cells.
    pub first: Vec<(u64, Vec<String>)>,
    /// Runs whose scenes were resolved.
    pub sampled: u64,
    /// Of those, how many give no valid scene, and the first of them with its reason.
    pub invalid: u64,
    /// The first invalid run and why.
    pub first_invalid: Option<(u64, String)>,
    /// Estimated messages of the shard's runs (sampled runs scaled up).
    pub messages: u64,
    /// Estimated bytes of the shard's files.
    pub bytes: u64,
    /// Estimated wall time with `jobs` at once \[s\].
    pub seconds: f64,
}

/// The dry run of `sweep`'s `shard` with `rows` first rows, estimated for `jobs` at once.
#[must_use]
#[allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)] // estimates
pub fn preview(sweep: &Sweep, shard: Shard, rows: usize, jobs: usize) -> Preview {
    let runs = shard.len(sweep.runs());
    let cells = |index| {
        sweep
            .values(index)
            .map(|v| v.iter().map(cell).collect())
            .unwrap_or_default()
    };
    let first = shard
        .runs(sweep.runs())
        .take(rows)
        .map(|i| (i, cells(i)))
        .collect();
    let sampled = runs.min(SAMPLED_RUNS);
    let (mut messages, mut bytes, mut invalid, mut first_invalid) = (0u64, 0u64, 0u64, None);
    for j in 0..sampled {
        let m = u64::try_from(u128::from(j) * u128::from(runs) / u128::from(sampled)).unwrap_or(0);
        let index = shard.index() + m * shard.count();
        let scene = sweep
            .values(index)
            .map_err(Into::into)
            .and_then(|v| sweep.scene(&v));
        match scene {
            Ok(scene) => {
                let e =
                    record::estimate(&scene, sweep.settings.compression, sweep.settings.encoding);
                messages += e.messages;
                bytes += e.bytes;
            }
            Err(e) => {
                invalid += 1;
                first_invalid.get_or_insert((index, e.to_string()));
            }
        }
    }
    let scale = if sampled == 0 {
        0.0
    } else {
        runs as f64 / sampled as f64
    };
    let messages = (messages as f64 * scale) as u64;
    let seconds = messages as f64 / (MESSAGES_PER_SECOND * jobs.max(1) as f64);
    Preview {
        runs,
        first,
        sampled,
        invalid,
        first_invalid,
        messages,
        bytes: (bytes as f64 * scale) as u64,
        seconds,
    }
}
