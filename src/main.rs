//! The `coin-log` command-line tool: a thin clap front end over the `coin_log` library.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
