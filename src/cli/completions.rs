//! `coin-log completions SHELL` and `coin-log man`: shell completions and man pages generated from the
//! clap definitions, so they always list every command and flag this binary has.

use super::{Cli, Outcome};
use anyhow::Context;
use clap::CommandFactory;
use std::path::PathBuf;

/// Arguments of `coin-log completions`.
///
/// Prints the completion script for SHELL on stdout. For example, bash: `coin-log completions bash >
/// ~/.local/share/bash-completion/completions/coin-log`; zsh: `coin-log completions zsh >
/// ~/.zfunc/_coin-log` (with `fpath+=~/.zfunc` before `compinit`); fish: `coin-log completions fish >
/// ~/.config/fish/completions/coin-log.fish`.
#[derive(Debug, clap::Args)]
pub struct CompletionsArgs {
    /// The shell.
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

/// Arguments of `coin-log man`.
///
/// Prints the man page of coin-log (roff) on stdout, e.g. `coin-log man | man -l -`; with `--out DIR`
/// writes `coin-log.1` and one page per subcommand (`coin-log-record.1`, `coin-log-bench-precision.1`,
/// ...) into DIR.
#[derive(Debug, clap::Args)]
pub struct ManArgs {
    /// Folder for the man pages (created if missing).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Runs `coin-log completions`.
pub fn completions(args: &CompletionsArgs) -> anyhow::Result<Outcome> {
    let mut cmd = Cli::command();
    // Into a buffer first: clap_complete panics when its writer fails (a closed pipe), and every print
    // goes through `output` so that a closed or full stdout ends cleanly.
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut cmd, "coin-log", &mut script);
    out!("{}", String::from_utf8_lossy(&script));
    Ok(Outcome::Success)
}

/// Runs `coin-log man`.
pub fn man(args: &ManArgs) -> anyhow::Result<Outcome> {
    let cmd = Cli::command();
    match &args.out {
        None => {
            let mut page = Vec::new();
            clap_mangen::Man::new(cmd)
                .render(&mut page)
                .context("writing the man page")?;
            out!("{}", String::from_utf8_lossy(&page));
        }
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the folder `{}`", dir.display()))?;
            clap_mangen::generate_to(cmd, dir)
                .with_context(|| format!("writing man pages into `{}`", dir.display()))?;
            outln!("{}", dir.display());
        }
    }
    Ok(Outcome::Success)
}
