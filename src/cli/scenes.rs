//! `coin-log scenes` (placeholder until its issue lands; owned by the helper building it).

use super::Outcome;

/// Arguments of `coin-log scenes`.
#[derive(Debug, clap::Args)]
pub struct ScenesArgs {}

pub fn run(_args: ScenesArgs) -> anyhow::Result<Outcome> {
    anyhow::bail!("`coin-log scenes` is not built yet")
}
