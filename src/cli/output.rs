//! Standard output and standard error of every command (format.md: Exit codes). Every print of `src/cli`
//! goes through the macros of this module (clippy's `print_stdout` and `print_stderr` check it), because
//! `println!` panics when a write fails, and writes do fail: Rust ignores SIGPIPE, so `coin-log scenes |
//! head -1` gets EPIPE once `head` has gone, and `> /dev/full` gets ENOSPC.
//!
//! - stdout closed by the reader (EPIPE): the rest of the output is dropped quietly and the command ends
//!   with the exit code it would have had: the reader chose to stop reading, nothing went wrong.
//! - any other write error on stdout (ENOSPC, EIO): the rest of the output is dropped, and [`settle`]
//!   reports the error on stderr and turns a success into exit 1 (a code that already says something went
//!   wrong, like verify's 1 and 2 or record's 130, is kept).
//! - stderr: written when possible; a failure to write there has nowhere to be reported and is ignored.

use super::Outcome;
use std::fmt;
use std::io::{self, ErrorKind, Write};
use std::sync::Mutex;

/// What became of stdout.
enum State {
    /// Every write so far succeeded.
    Open,
    /// The reader closed the pipe (EPIPE).
    Closed,
    /// Another write error: the first one, reported by [`settle`].
    Failed(io::Error),
}

static STDOUT: Mutex<State> = Mutex::new(State::Open);

fn state() -> std::sync::MutexGuard<'static, State> {
    // A panic while holding the lock cannot leave the state half-updated (each update is one assignment).
    STDOUT
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn note_error(state: &mut State, e: io::Error) {
    if matches!(state, State::Open) {
        *state = if e.kind() == ErrorKind::BrokenPipe {
            State::Closed
        } else {
            State::Failed(e)
        };
    }
}

/// Writes to stdout unless an earlier write failed (use [`out!`] and [`outln!`]).
pub fn write_stdout(args: fmt::Arguments<'_>) {
    let mut state = state();
    if matches!(*state, State::Open) {
        if let Err(e) = io::stdout().lock().write_fmt(args) {
            note_error(&mut state, e);
        }
    }
}

/// Writes to stderr, ignoring failures (use [`errln!`]).
pub fn write_stderr(args: fmt::Arguments<'_>) {
    let _ = io::stderr().lock().write_fmt(args);
}

/// True once a write to stdout failed with an error other than EPIPE (the output is incomplete).
pub fn stdout_failed() -> bool {
    matches!(*state(), State::Failed(_))
}

/// Flushes stdout and gives the exit code: `outcome`, or 1 instead of a success when stdout could not
/// be written for a reason other than a closed pipe (the error is then printed on stderr).
pub fn settle(outcome: Outcome) -> Outcome {
    let mut state = state();
    if matches!(*state, State::Open) {
        if let Err(e) = io::stdout().lock().flush() {
            note_error(&mut state, e);
        }
    }
    match &*state {
        State::Open | State::Closed => outcome,
        State::Failed(e) => {
            write_stderr(format_args!(
                "error: cannot write to standard output: {e}; the output is incomplete\n"
            ));
            match outcome {
                Outcome::Success => Outcome::Failure,
                other => other,
            }
        }
    }
}

/// Prints clap's help, version or usage error (`Cli::try_parse`'s error) with its colours, as
/// `Error::exit` would, but a failed write to stdout counts like every other (`--help > /dev/full`);
/// returns clap's exit code: 0 for help and version, 2 for a usage error.
pub fn clap_message(e: &clap::Error) -> Outcome {
    if e.use_stderr() {
        let _ = e.print();
        return Outcome::Unusable;
    }
    if let Err(error) = e.print().and_then(|()| io::stdout().lock().flush()) {
        note_error(&mut state(), error);
    }
    Outcome::Success
}

/// Prints `value` as one line of JSON. Through `serde_json::Value`, whose objects (without serde_json's
/// `preserve_order`) hold their keys in alphabetical order: the order every JSON output of coin-log has.
///
/// # Errors
/// `value` cannot be represented as JSON (a map with keys that are not strings).
pub fn json(value: &impl serde::Serialize) -> serde_json::Result<()> {
    write_stdout(format_args!("{}\n", serde_json::to_value(value)?));
    Ok(())
}

/// `print!` that survives a closed or full stdout.
macro_rules! out {
    ($($arg:tt)*) => { $crate::cli::output::write_stdout(format_args!($($arg)*)) };
}

/// `println!` that survives a closed or full stdout.
macro_rules! outln {
    () => { $crate::cli::output::write_stdout(format_args!("\n")) };
    ($($arg:tt)*) => {
        $crate::cli::output::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` that survives a closed stderr.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::cli::output::write_stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use errln;
