//! `coin-log completions SHELL` and `coin-log man`: shell completions and man pages generated from the
//! clap definitions, so they always list every command and flag this binary has.

use super::{Cli, Outcome};
use anyhow::Context;
use clap::CommandFactory;
use coin_log::files::{shown, OutputFolder};
use std::io::Write;
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
    /// Folder for the man pages (created if missing; pages already there are replaced, but never a link,
    /// pipe or device in their place).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Runs `coin-log completions`.
pub fn completions(args: &CompletionsArgs) -> anyhow::Result<Outcome> {
    let mut cmd = Cli::command();
    // Into a buffer first: clap_complete panics when its writer fails (a closed pipe), and every print
    // goes through `output` so that a closed or full stdout ends cleanly.
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut cmd, BIN, &mut script);
    let mut script = String::from_utf8_lossy(&script).into_owned();
    if args.shell == clap_complete::Shell::Bash {
        script = bash_states_fixed(&script);
    }
    out!("{script}");
    Ok(Outcome::Success)
}

/// The binary's name, as completions and man pages know it.
const BIN: &str = "coin-log";

/// clap_complete's bash script of a binary with a hyphen in its name (clap issue #6421): the loop over the
/// words sets the state `coin__log__subcmd__record`, but the `case` arms that complete a subcommand are
/// labelled `coin__subcmd__log__subcmd__record` (the hyphen of the name escaped as a subcommand
/// separator), so no arm matched and no subcommand's flags or values ever completed. The arms get the
/// loop's spelling.
fn bash_states_fixed(script: &str) -> String {
    let state = BIN.replace('-', "__");
    let broken = BIN.replace('-', "__subcmd__");
    script.replace(
        &format!("\n        {broken}"),
        &format!("\n        {state}"),
    )
}

/// Runs `coin-log man`.
pub fn man(args: &ManArgs) -> anyhow::Result<Outcome> {
    let Some(dir) = &args.out else {
        let mut page = Vec::new();
        clap_mangen::Man::new(Cli::command())
            .render(&mut page)
            .context("writing the man page")?;
        out!("{}", String::from_utf8_lossy(&page));
        return Ok(Outcome::Success);
    };
    // The pages replace earlier ones (regular files only), all moved into place once every page is written.
    let mut folder = OutputFolder::create(dir, true)?;
    let mut cmd = Cli::command().disable_help_subcommand(true);
    cmd.build();
    write_pages(cmd, &mut folder)?;
    folder.commit()?;
    outln!("{}", shown(dir));
    Ok(Outcome::Success)
}

/// The page of `cmd` and of each visible subcommand, as `clap_mangen::generate_to` names them, written
/// through `folder` (generate_to itself would follow a link and block on a named pipe).
fn write_pages(cmd: clap::Command, folder: &mut OutputFolder) -> anyhow::Result<()> {
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        write_pages(sub.clone(), folder)?;
    }
    let man = clap_mangen::Man::new(cmd);
    let name = man.get_filename();
    let mut page = Vec::new();
    man.render(&mut page)?;
    folder
        .file(&name)?
        .write_all(&page)
        .with_context(|| format!("writing `{}`", shown(&folder.path().join(&name))))
}
