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

/// What a dry run shows: the shard's `runs`; the `first` runs' indexes and swept values (as catalogue
/// cells); of the `sampled` runs whose scenes were resolved, how many give no valid scene (`invalid`) and
/// the first of them with its reason; the shard's `messages`, `bytes` and wall time with `jobs` at once
/// (`seconds`), estimated from the sampled runs scaled up.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub struct Preview {
    pub runs: u64,
    pub first: Vec<(u64, Vec<String>)>,
    pub sampled: u64,
    pub invalid: u64,
    pub first_invalid: Option<(u64, String)>,
    pub messages: u64,
    pub bytes: u64,
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
