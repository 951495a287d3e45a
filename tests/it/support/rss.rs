//! The peak resident memory of a `coin-log` child process.
//!
//! `getrusage(RUSAGE_CHILDREN)` reports the largest peak of the children a process has waited for, so
//! in this test binary, whose parallel tests start children of their own, it would mix theirs in. Each
//! measured command therefore runs as the only child of a fresh copy of this binary (the ignored
//! [`probe`] test, started with `--exact --ignored`), which waits for it and reports its own
//! `RUSAGE_CHILDREN` peak: the command's, exactly (the kernel's accounting, not a sample).

#![allow(clippy::unwrap_used)]

use super::record::exe;
use super::repo;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The probe reads what to run from here (JSON: `{"args": [...], "dir": "..."}`).
const PROBE_SPEC: &str = "COIN_LOG_RSS_PROBE";
/// A measured command still running after this is killed and fails the test: these commands read their
/// file in seconds.
const DEADLINE: Duration = Duration::from_secs(120);

/// What a measured command did.
#[derive(Debug)]
pub struct Measured {
    /// Exit code (−1 if a signal ended it).
    pub code: i32,
    /// Its standard output.
    pub stdout: String,
    /// Its standard error.
    pub stderr: String,
    /// Its peak resident set size \[bytes\].
    pub peak_rss: u64,
}

/// Runs `coin-log args` (in the repository root) and measures its peak RSS.
pub fn coin_log_peak(args: &[&str]) -> Measured {
    let dir = tempfile::tempdir().unwrap();
    let spec = serde_json::json!({ "args": args, "dir": dir.path() });
    let probe = Command::new(std::env::current_exe().unwrap())
        .args([
            "support::rss::probe",
            "--exact",
            "--ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(PROBE_SPEC, spec.to_string())
        .output()
        .unwrap();
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap_or_default();
    let result = read("result");
    let mut words = result.split_whitespace();
    let (Some(code), Some(kib)) = (words.next(), words.next()) else {
        panic!(
            "the probe of `coin-log {}` reported nothing: {}{}",
            args.join(" "),
            String::from_utf8_lossy(&probe.stdout),
            String::from_utf8_lossy(&probe.stderr)
        );
    };
    Measured {
        code: code.parse().unwrap(),
        stdout: read("stdout"),
        stderr: read("stderr"),
        peak_rss: kib.parse::<u64>().unwrap() * 1024,
    }
}

/// Not a test: the process [`coin_log_peak`] starts. Runs the command it is given, with its output in
/// files, and writes its exit code and peak RSS \[KiB\] (Linux reports `ru_maxrss` in KiB).
#[test]
#[ignore = "the measuring process of coin_log_peak; does nothing on its own"]
fn probe() {
    let Ok(spec) = std::env::var(PROBE_SPEC) else {
        return;
    };
    let spec: serde_json::Value = serde_json::from_str(&spec).unwrap();
    let dir = PathBuf::from(spec["dir"].as_str().unwrap());
    let args: Vec<&str> = spec["args"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    let file = |name: &str| Stdio::from(std::fs::File::create(dir.join(name)).unwrap());
    let mut child = Command::new(exe())
        .args(&args)
        .current_dir(repo())
        .stdin(Stdio::null())
        .stdout(file("stdout"))
        .stderr(file("stderr"))
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            let _ = child.wait();
            panic!("`coin-log {}` still ran after {DEADLINE:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let usage =
        nix::sys::resource::getrusage(nix::sys::resource::UsageWho::RUSAGE_CHILDREN).unwrap();
    let result = format!("{} {}", status.code().unwrap_or(-1), usage.max_rss());
    std::fs::write(dir.join("result"), result).unwrap();
}
