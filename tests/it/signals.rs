//! The first signal is seen inside the integrator's step loop, not at the next sample: a recording whose
//! samples lie 1e7 time units (or 1e300) apart, or 1 ns apart, stops within a few milliseconds of SIGINT
//! with a finished file that verifies and says `interrupted` (exit 130), for every integrator. Before,
//! `--rate 1e-7 --duration 1e8` integrated on for minutes after the first signal.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::process::Process;
use crate::support::record::{coin_log, exe};
use coin_log::scene::limits::max_rate;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How long after the signal the recorder must have exited: the "within 100 ms" for the
/// integrator, with room for finishing the file and a loaded machine.
const LATENCY_BOUND: Duration = Duration::from_secs(2);

/// Records `args` in `dir`, lets it run for a second after its temporary file appears, sends SIGINT and
/// waits for the exit; returns the exit code, the latency from the signal to the exit, and stdout.
fn record_then_interrupt(dir: &Path, args: &[&str]) -> (Option<i32>, Duration, String, String) {
    let mut child = Process::start(
        Command::new(exe())
            .args(["record", "centre-fixed", "-o", "run.mcap"])
            .args(args)
            .current_dir(dir),
    );
    let started = Instant::now();
    while std::fs::read_dir(dir).unwrap().next().is_none() {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "no temporary file appeared"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_secs(1));
    let signalled = Instant::now();
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(
        status.success(),
        "kill -INT: the recording ended before the signal"
    );
    let out = child.wait_within(Duration::from_secs(60));
    (
        out.status.code(),
        signalled.elapsed(),
        out.stdout,
        out.stderr,
    )
}

/// The case and the extremes of the documented limits (the lowest rates, the highest rate; the
/// fixed-step methods with a budget raised so that they would run for minutes): each stops within
/// [`LATENCY_BOUND`] of SIGINT, exit 130, its file verifies and is marked interrupted.
#[test]
fn the_first_signal_stops_a_recording_between_samples_at_once_at_any_rate() {
    let highest = max_rate(10.0).floor().to_string();
    let cases: [(&str, Vec<&str>); 6] = [
        (
            "dop853, rate 1e-7",
            vec!["--rate", "1e-7", "--duration", "1e8"],
        ),
        (
            "dop853, rate 1e-300",
            vec!["--rate", "1e-300", "--duration", "1e9"],
        ),
        (
            "dopri5, rate 1e-7",
            vec![
                "--integrator",
                "dopri5",
                "--rate",
                "1e-7",
                "--duration",
                "1e8",
            ],
        ),
        (
            "rk4, rate 1e-7",
            vec![
                "--integrator",
                "rk4",
                "--rate",
                "1e-7",
                "--duration",
                "1e8",
                "--max-steps",
                "100000000000",
            ],
        ),
        (
            "gauss4, rate 1e-7",
            vec![
                "--integrator",
                "gauss4",
                "--rate",
                "1e-7",
                "--duration",
                "1e8",
                "--max-steps",
                "100000000000",
            ],
        ),
        (
            "dop853, highest rate",
            vec![
                "--rate",
                &highest,
                "--duration",
                "10",
                "--channels",
                "omega,angles,position",
            ],
        ),
    ];
    let mut table = vec![format!(
        "{:<22} {:>6} {:>12} {:>9} {}",
        "case", "exit", "latency ms", "samples", "verify"
    )];
    for (name, args) in cases {
        let dir = tempfile::tempdir().unwrap();
        let (code, latency, stdout, stderr) = record_then_interrupt(dir.path(), &args);
        let samples = stdout
            .lines()
            .find_map(|l| l.strip_prefix("samples"))
            .map_or("?", str::trim)
            .to_string();
        let verify = coin_log(dir.path(), &["verify", "run.mcap"]);
        let verdict = String::from_utf8_lossy(&verify.stdout).into_owned();
        table.push(format!(
            "{name:<22} {:>6} {:>12.1} {samples:>9} exit {}",
            code.map_or("-".into(), |c| c.to_string()),
            latency.as_secs_f64() * 1e3,
            verify.status.code().unwrap_or(-1)
        ));
        println!("{}", table.last().unwrap());
        assert_eq!(code, Some(130), "{name}: {stdout}\n{stderr}");
        assert!(
            latency < LATENCY_BOUND,
            "{name}: exited {latency:?} after the signal"
        );
        assert!(
            stdout.contains("termination      interrupted at t = "),
            "{name}: {stdout}"
        );
        assert_eq!(
            verify.status.code(),
            Some(0),
            "{name}: the interrupted file verifies: {verdict}"
        );
    }
    println!("{}", table.join("\n"));
}
