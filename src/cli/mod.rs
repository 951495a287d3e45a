//! Command-line parsing and the exit-code policy (format.md: Exit codes). Only this module prints, through
//! [`output`].

#[macro_use]
mod output;
mod analyse;
mod bench;
mod completions;
mod export;
mod info;
#[cfg(feature = "live")]
mod live;
mod plot;
mod progress;
mod record;
mod rss;
mod scene_arg;
mod scenes;
mod sweep;
mod text;
mod verify;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Simulate a coin rolling without slipping and record it as MCAP datasets for Foxglove.
///
/// Exit codes: 0 success; 1 error (bad scene or flag, I/O, numerical failure) or, for `verify`, a failed
/// check; 2 usage error or, for `verify`, an unreadable file; 130 interrupted (SIGINT, SIGTERM, SIGHUP).
/// When stdout is closed by its reader the command exits quietly with its own code; another error writing
/// stdout (a full disk) is reported and exits 1 unless the code was already worse.
#[derive(Debug, Parser)]
#[command(name = "coin-log", version, about, long_about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Integrate a scene and write its trajectory as an MCAP file.
    Record(record::RecordArgs),
    /// Re-read stored logs and judge them from the file alone.
    Verify(verify::VerifyArgs),
    /// List the built-in scenes, or print one as TOML.
    Scenes(scenes::ScenesArgs),
    /// Benchmarks: error against cost of every integrator, and the hard-case stability suite.
    Bench(bench::BenchArgs),
    /// Show what files hold: channels, time range, body, run settings, termination; or the stored scene.
    Info(info::InfoArgs),
    /// Write a file's channels as CSV tables (one per channel, or one joined on t).
    Export(export::ExportArgs),
    /// Draw a one-page SVG overview of a file.
    Plot(plot::PlotArgs),
    /// Simulate a scene in real time (or faster) and serve it live to Foxglove.
    ///
    /// Serves the run over the Foxglove WebSocket protocol at --speed times real time (one time unit of the
    /// scene per second at 1): in Foxglove, Open connection → Foxglove WebSocket → the URL printed on stderr
    /// (ws://127.0.0.1:8765 by default). The channels, schemas and messages are byte for byte those of
    /// `record`; -o FILE records them at the same time. The first sample is shown at once and the clock
    /// starts when a viewer subscribes (--no-wait: at once). When the run ends the server keeps serving its
    /// final state until Ctrl-C (--exit: quits at once); Ctrl-C during the run stops it (the file is
    /// finished, marked interrupted, exit 130). The server listens on 127.0.0.1, this machine only;
    /// --host 0.0.0.0 listens on every interface, where anyone who can reach the machine can connect (no
    /// authentication, no encryption).
    #[cfg(feature = "live")]
    Live(live::LiveArgs),
    /// Not in this build: says how to get it.
    #[cfg(not(feature = "live"))]
    #[command(hide = true, disable_help_flag = true)]
    Live(NoLive),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(completions::CompletionsArgs),
    /// Print the man page, or write one per command into a folder.
    Man(completions::ManArgs),
    /// What a scene's motion will do, without simulating it; `analyse map`: the stability map.
    Analyse(analyse::AnalyseArgs),
    /// Record a dataset: every run of a sweep file (grid axes, random draws), with a catalogue; resumable,
    /// shardable over a cluster (`sweep collect` merges the shards).
    Sweep(sweep::SweepArgs),
}

/// `live` in a build without the `live` feature: any arguments, to answer with how to get it.
#[cfg(not(feature = "live"))]
#[derive(Debug, clap::Args)]
struct NoLive {
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    args: Vec<String>,
}

/// What a command ended with; the one place exit codes are decided (format.md: Exit codes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// 0: finished.
    Success,
    /// 1: a check failed, or an error or numerical failure.
    Failure,
    /// 2: unreadable input or usage error.
    Unusable,
    /// 130: interrupted by SIGINT, SIGTERM or SIGHUP.
    Interrupted,
}

impl Outcome {
    /// The process exit code.
    pub fn code(self) -> u8 {
        match self {
            Outcome::Success => 0,
            Outcome::Failure => 1,
            Outcome::Unusable => 2,
            Outcome::Interrupted => 130,
        }
    }
}

impl From<Outcome> for ExitCode {
    fn from(o: Outcome) -> Self {
        ExitCode::from(o.code())
    }
}

/// Parses the command line, runs the command and maps the result to an exit code.
pub fn main() -> ExitCode {
    block_file_size_signal();
    let matches = negative_numbers(<Cli as clap::CommandFactory>::command()).try_get_matches();
    let cli = match matches.and_then(|m| <Cli as clap::FromArgMatches>::from_arg_matches(&m)) {
        Ok(cli) => cli,
        // --help, --version and usage errors, printed so that a failed write is seen (`--help > /dev/full`).
        Err(e) => return output::settle(output::clap_message(&e)).into(),
    };
    let outcome = run(cli).unwrap_or_else(|e| {
        output::errln!("error: {}", with_causes(&e));
        Outcome::Failure
    });
    output::settle(outcome).into()
}

/// Blocks SIGXFSZ in this thread, before any other starts (they inherit the mask): a write beyond the
/// file-size limit (`ulimit -f`) then fails with EFBIG ("File too large"), which every command reports
/// and cleans up after as for a full disk, instead of the signal killing the process and leaving its
/// temporary file behind.
fn block_file_size_signal() {
    #[cfg(unix)]
    {
        use nix::sys::signal::{SigSet, Signal};
        let mut set = SigSet::empty();
        set.add(Signal::SIGXFSZ);
        // Without it (it cannot fail for a valid signal) the default stays: killed at the limit.
        let _ = set.thread_block();
    }
}

/// Every option of every command takes a negative number as its value: without it clap read
/// `--duration -1` as an unknown flag `-1` and advised `-- -1`, which does not work either; with it the
/// value reaches the option's own check, which says what range it takes.
fn negative_numbers(command: clap::Command) -> clap::Command {
    command
        .mut_args(|a| {
            // Only options that take a value: clap's debug assertions refuse the setting on a flag.
            let takes = !a.is_positional() && a.get_action().takes_values();
            a.allow_negative_numbers(takes)
        })
        .mut_subcommands(negative_numbers)
}

/// The error and its causes, each cause left out where the message already says it: the library's errors
/// name their cause in their own message, and `{:#}` printed it twice ("is a named pipe…: is a named
/// pipe…").
fn with_causes(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1).map(ToString::to_string) {
        if !text.contains(&cause) {
            text = format!("{text}: {cause}");
        }
    }
    text
}

fn run(cli: Cli) -> anyhow::Result<Outcome> {
    match cli.command {
        Command::Record(args) => record::run(args),
        Command::Verify(args) => verify::run(args),
        Command::Scenes(args) => scenes::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Info(args) => info::run(&args),
        Command::Export(args) => export::run(&args),
        Command::Plot(args) => plot::run(&args),
        #[cfg(feature = "live")]
        Command::Live(args) => live::run(args),
        #[cfg(not(feature = "live"))]
        Command::Live(_) => {
            output::errln!(
                "error: this coin-log was built without the live view (cargo feature `live`): build it with \
                 `cargo build --release --features live`, or install it with `cargo install --path . \
                 --features live`"
            );
            Ok(Outcome::Unusable)
        }
        Command::Completions(args) => completions::completions(&args),
        Command::Man(args) => completions::man(&args),
        Command::Analyse(args) => analyse::run(args),
        Command::Sweep(args) => sweep::run(args),
    }
}

/// The clap value parser of an enum declared with `coin_log_names::named_enum!`: its names are the possible
/// values (listed in `--help` and in the error), parsed by the enum's own `FromStr`.
pub(crate) fn named<
    T: coin_log_names::Named + std::str::FromStr<Err = coin_log_names::UnknownName>,
>() -> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(T::NAMES).try_map(|s| s.parse::<T>())
}

/// The clap value parser of a name checked later, by the scene or the command with its own message and exit
/// code (`--integrator`, `analyse map --branch`): it takes any text, as clap's plain string parser does,
/// and offers `names` to shell completion, which without possible values completes file names instead.
/// Give the argument `hide_possible_values = true`: its help already lists the names.
#[derive(Clone)]
pub(crate) struct Suggested(pub &'static [&'static str]);

impl clap::builder::TypedValueParser for Suggested {
    type Value = String;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<String, clap::Error> {
        clap::builder::StringValueParser::new().parse_ref(cmd, arg, value)
    }

    fn possible_values(
        &self,
    ) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        Some(Box::new(
            self.0.iter().map(|n| clap::builder::PossibleValue::new(*n)),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        super::negative_numbers(Cli::command()).debug_assert();
    }
}
