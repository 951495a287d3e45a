//! The sweep from Python (README.md, Sweeps): `examples/sweep_catalogue.py` opens the catalogue of the
//! README's first sweep (`examples/sweep.toml`) with pandas, picks the runs that toppled and reads one
//! channel of one of them with the `mcap` package; its output is checked against the catalogue as read
//! here. Needs the test venv (`scripts/test`: pandas and mcap from scripts/requirements.txt): a missing
//! package fails the test, never skips it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::other_writers::python;
use crate::support::process::run_tool;
use crate::support::repo;
use crate::sweep::{run_in, Csv};
use std::process::Command;

#[test]
fn the_python_example_picks_the_toppled_runs_and_reads_a_channel_of_one() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = repo().join("examples/sweep.toml");
    let (code, out, err) = run_in(
        dir.path(),
        &["sweep", sweep.to_str().unwrap(), "-o", "lean-sweep"],
    );
    assert_eq!(
        code, 0,
        "the README's first sweep finishes every run: {out}{err}"
    );
    let c = Csv::read(&dir.path().join("lean-sweep/catalogue.csv"));
    let toppled: Vec<_> = c
        .records()
        .into_iter()
        .filter(|r| r["termination"] == "flat-landing")
        .collect();
    assert_eq!(
        toppled.len(),
        10,
        "every coin released without spin topples, none of the spinning ones"
    );
    let first = toppled
        .iter()
        .min_by(|a, b| {
            a["t_end"]
                .parse::<f64>()
                .unwrap()
                .total_cmp(&b["t_end"].parse().unwrap())
        })
        .unwrap();
    let script = repo().join("examples/sweep_catalogue.py");
    let run = run_tool(
        Command::new(python())
            .arg(&script)
            .arg("lean-sweep")
            .current_dir(dir.path()),
        "run scripts/test",
    );
    let (stdout, stderr) = (&run.stdout, &run.stderr);
    println!("{stdout}{stderr}");
    assert!(run.status.success(), "examples/sweep_catalogue.py failed (is pandas in the venv? scripts/test installs scripts/requirements.txt): {stderr}");
    assert!(
        stderr.trim().is_empty(),
        "no warning from pandas or mcap: {stderr}"
    );
    assert!(stdout.starts_with("10 of 20 runs toppled\n"), "{stdout}");
    let samples = first["samples"].as_str();
    let expected = format!(
        "run {} ({}): {samples} samples of /coin/angles, theta from {} to ",
        first["index"], first["file"], first["initial.theta"]
    );
    let last = stdout.lines().last().unwrap_or_default();
    assert!(last.starts_with(&expected), "`{expected}` in `{last}`");
    assert!(
        last.ends_with(&format!(" at t = {}", first["t_end"])),
        "the last sample is at t_end: {last}"
    );
}

#[test]
fn the_python_example_says_so_when_no_run_toppled() {
    // It used to end in a pandas traceback (argmin of an empty sequence) and exit 1.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("spin.toml"),
        "base = \"wobble\"\nset = { \"run.duration\" = 1.0, \"run.rate\" = 200.0 }\n[[axis]]\nkey = \"initial.theta\"\nvalues = [0.5, 0.6]\n",
    )
    .unwrap();
    let (code, out, err) = run_in(dir.path(), &["sweep", "spin.toml", "-o", "spin"]);
    assert_eq!(code, 0, "{out}{err}");
    let script = repo().join("examples/sweep_catalogue.py");
    let run = run_tool(
        Command::new(python())
            .arg(&script)
            .arg("spin")
            .current_dir(dir.path()),
        "run scripts/test",
    );
    let (stdout, stderr) = (&run.stdout, &run.stderr);
    assert!(run.status.success(), "{stdout}{stderr}");
    assert!(stderr.trim().is_empty(), "{stderr}");
    assert!(stdout.starts_with("0 of 2 runs toppled\n"), "{stdout}");
}
