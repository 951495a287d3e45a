//! `coin-log record` (placeholder until its issue lands; owned by the helper building it).

use super::Outcome;

/// Arguments of `coin-log record`.
#[derive(Debug, clap::Args)]
pub struct RecordArgs {}

pub fn run(_args: RecordArgs) -> anyhow::Result<Outcome> {
    anyhow::bail!("`coin-log record` is not built yet")
}
