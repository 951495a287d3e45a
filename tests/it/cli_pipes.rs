//! Standard output that goes away or fills up (format.md: Exit codes). Rust ignores SIGPIPE, so a closed
//! pipe is an EPIPE write error: `scenes | head -1`, `verify a b | true`, `record … | true` must exit
//! quietly with the code the command would have had (verify's verdict included), never panic (exit 101).
//! Any other write error (`> /dev/full`: ENOSPC) is an error message and exit 1, or the command's own
//! worse code.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{exe, listing, read_back};
use std::fs::File;
use std::path::Path;
use std::process::{Command, Stdio};

/// Runs coin-log in `dir` with its stdout a pipe whose reading end is closed at once (the reader is gone
/// before the command prints); returns the exit code and stderr.
fn with_closed_stdout(dir: &Path, args: &[&str]) -> (i32, String) {
    let mut child = Command::new(exe())
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    println!("{args:?} | (closed): exit {:?}: {err}", out.status.code());
    (
        out.status.code().expect("exited normally, not by a signal"),
        err,
    )
}

/// Runs coin-log in `dir` with its stdout `/dev/full`; returns the exit code and stderr.
fn with_full_stdout(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = Command::new(exe())
        .args(args)
        .current_dir(dir)
        .stdout(File::create("/dev/full").unwrap())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    println!("{args:?} > /dev/full: exit {:?}: {err}", out.status.code());
    (
        out.status.code().expect("exited normally, not by a signal"),
        err,
    )
}

fn assert_no_panic(err: &str) {
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "a panic: {err}"
    );
}

/// A finished recording of `wobble` (1 time unit) named `name` in `dir`, and a file that is not MCAP.
fn files(dir: &Path) {
    let out = Command::new(exe())
        .args(["record", "wobble", "--duration", "1", "-o", "good.mcap"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::write(dir.join("bad.mcap"), "not an MCAP file").unwrap();
}

#[test]
fn a_closed_pipe_ends_every_command_quietly_with_its_own_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    files(dir.path());
    for (args, expected) in [
        (vec!["scenes"], 0),
        (vec!["scenes", "--show", "wobble"], 0),
        (vec!["verify", "good.mcap"], 0),
        (vec!["verify", "good.mcap", "--json"], 0),
        (vec!["verify", "good.mcap", "bad.mcap"], 2),
    ] {
        let (code, err) = with_closed_stdout(dir.path(), &args);
        assert_no_panic(&err);
        assert_eq!(code, expected, "{args:?}: {err}");
        assert!(!err.contains("Broken pipe"), "{args:?}: quiet: {err}");
    }
}

#[test]
fn record_into_a_closed_pipe_keeps_the_finished_file_and_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err) = with_closed_stdout(
        dir.path(),
        &["record", "wobble", "--duration", "2", "-o", "w.mcap"],
    );
    assert_no_panic(&err);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "quiet: {err}");
    assert_eq!(listing(dir.path()), vec!["w.mcap".to_string()]);
    let file = read_back(&std::fs::read(dir.path().join("w.mcap")).unwrap());
    assert_eq!(file.on_topic("/coin/omega").len(), 201);
}

#[test]
fn a_full_stdout_is_an_error_and_exit_1_or_the_worse_verdict() {
    let dir = tempfile::tempdir().unwrap();
    files(dir.path());
    for (args, expected) in [
        (vec!["scenes"], 1),
        (vec!["verify", "good.mcap"], 1),
        (vec!["verify", "good.mcap", "bad.mcap"], 2),
    ] {
        let (code, err) = with_full_stdout(dir.path(), &args);
        assert_no_panic(&err);
        assert_eq!(code, expected, "{args:?}: {err}");
        assert!(
            err.contains("error: cannot write to standard output: No space left on device"),
            "{args:?}: {err}"
        );
    }
    let (code, err) = with_full_stdout(
        dir.path(),
        &["record", "wobble", "--duration", "1", "-o", "r.mcap"],
    );
    assert_no_panic(&err);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("No space left on device")
            && err.contains("the recording `r.mcap` is complete; only its summary was lost"),
        "{err}"
    );
    let file = read_back(&std::fs::read(dir.path().join("r.mcap")).unwrap());
    assert_eq!(file.on_topic("/coin/omega").len(), 101);
}
