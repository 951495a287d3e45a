//! `coin-log verify` (placeholder until its issue lands; owned by the helper building it).

use super::Outcome;

/// Arguments of `coin-log verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {}

pub fn run(_args: VerifyArgs) -> anyhow::Result<Outcome> {
    anyhow::bail!("`coin-log verify` is not built yet")
}
