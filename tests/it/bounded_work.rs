//! No setting makes a run that never ends: a fixed step that cannot advance time, or more fixed steps than
//! `run.max_steps`, is a scene error before anything is simulated (key, value, fix); an adaptive run stops
//! when its step budget is spent (termination `step-budget-spent`, exit 1, the file finished up to there);
//! durations below the 1 ns log-time resolution are refused with the figure. The cases
//! (`rk4 --step 1e-300`, `gauss4 --step 1e-17 --duration 0.001`, `rk4 --step 1e-12 --duration 0.001`) ran
//! forever or for minutes; now they are refused at once.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::coin_log;
use coin_log::integrate::{
    run_method_bounded, Bounds, Method, MethodConfig, NoEvents, OdeSystem, RunEnd, RunSettings,
    StepError,
};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Exit code, stderr, and the folder's listing after `record wobble` with `flags` in a fresh folder.
fn record(flags: &[&str]) -> (i32, String, Vec<String>, Duration) {
    let dir = tempfile::tempdir().unwrap();
    let mut args = vec!["record", "wobble", "-o", "w.mcap"];
    args.extend_from_slice(flags);
    let started = Instant::now();
    let out = coin_log(dir.path(), &args);
    let took = started.elapsed();
    let listing = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        listing,
        took,
    )
}

/// The three runs that never ended (or took minutes) are scene errors naming `run.step`, its
/// value and a step that would do, within a second and without writing anything; the control, the same
/// integrators at a step inside the limit, records.
#[test]
fn fixed_steps_that_cannot_end_or_exceed_the_budget_are_refused_before_simulating() {
    for (flags, says) in [
        (
            &["--integrator", "rk4", "--step", "1e-300"][..],
            "`run.step` = 1e-300 cannot advance time: t + step rounds back to t at t = duration = 30",
        ),
        (
            &[
                "--integrator", "gauss4", "--step", "1e-17", "--duration", "0.001",
            ][..],
            "`run.step` = 1e-17 takes 1e14 steps over duration 0.001, more than run.max_steps = 100000000",
        ),
        (
            &[
                "--integrator", "rk4", "--step", "1e-12", "--duration", "0.001",
            ][..],
            "`run.step` = 1e-12 takes 1e9 steps over duration 0.001, more than run.max_steps = 100000000",
        ),
    ] {
        let (code, err, listing, took) = record(flags);
        println!("{flags:?} ({took:?}): exit {code}: {err}");
        assert_eq!(code, 1, "{err}");
        assert!(err.contains(says), "{err}");
        assert!(err.contains("use step ≥ "), "the fix: {err}");
        assert!(listing.is_empty(), "nothing written: {listing:?}");
        assert!(took < Duration::from_secs(5), "refused at once: {took:?}");
    }
    // At the budget (0.001 / 1e-10 = 1e7 steps) accepted, one step beyond refused.
    let (code, err, _, _) = record(&[
        "--integrator",
        "gauss4",
        "--step",
        "1e-10",
        "--duration",
        "0.001",
        "--dry-run",
    ]);
    assert_eq!(code, 0, "at the budget: {err}");
    let (code, err, _, _) = record(&[
        "--integrator",
        "rk4",
        "--step",
        "1e-10",
        "--duration",
        "0.001",
        "--max-steps",
        "9999999",
        "--dry-run",
    ]);
    assert_eq!(code, 1, "one step beyond: {err}");
    assert!(err.contains("more than run.max_steps = 9999999"), "{err}");
    let (code, err, listing, _) = record(&["--integrator", "rk4", "--duration", "1"]);
    assert_eq!(code, 0, "control: {err}");
    assert_eq!(listing, ["w.mcap"]);
}

/// An adaptive run that needs more steps than `--max-steps` stops when they are spent, with exit 1, the
/// named termination, a message naming the flag, and a finished file that passes `integrity`; the
/// control (the default budget) completes.
#[test]
fn an_adaptive_run_stops_when_its_step_budget_is_spent() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "wobble",
            "-o",
            "w.mcap",
            "--max-steps",
            "100",
            "--json",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    println!("{err}");
    assert_eq!(out.status.code(), Some(1), "{err}");
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["termination"], "step-budget-spent");
    assert_eq!(summary["steps"], 100);
    let t = summary["termination_time"].as_f64().unwrap();
    assert!(t > 0.0 && t < 30.0, "stopped inside the run: {t}");
    assert!(
        err.contains("the step budget of 100 steps was spent at t = ")
            && err.contains("--max-steps"),
        "{err}"
    );
    // The advice names the steps the whole run needs at the pace so far: the control below takes 232.
    let needed: f64 = err
        .split("the whole run needs about ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no estimate: {err}"));
    assert!((116.0..=464.0).contains(&needed), "{needed}: {err}");
    assert!(
        err.contains("steps: raise --max-steps (run.max_steps) with a margin above that"),
        "{err}"
    );
    let verify = coin_log(dir.path(), &["verify", "w.mcap", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&verify.stdout).unwrap();
    let integrity = report["files"][0]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == "integrity")
        .unwrap()
        .clone();
    assert_eq!(integrity["status"], "pass", "{integrity}");
    let control = coin_log(dir.path(), &["record", "wobble", "-o", "c.mcap", "--json"]);
    let summary: serde_json::Value = serde_json::from_slice(&control.stdout).unwrap();
    assert_eq!(summary["termination"], "completed");
}

/// Durations below 1 ns are refused with the figure (5e-324 used to end as "stiff or singular"); 1 ns
/// itself records a file whose two samples have their own log times and which passes `integrity`.
#[test]
fn durations_below_the_log_time_resolution_are_refused_with_the_figure() {
    let below = f64::from_bits(1e-9_f64.to_bits() - 1).to_string();
    for duration in ["5e-324", below.as_str(), "1e-12"] {
        let (code, err, listing, _) = record(&["--duration", duration]);
        println!("--duration {duration}: exit {code}: {err}");
        assert_eq!(code, 1, "{err}");
        assert!(
            err.contains("is below 1e-9, the log-time resolution")
                && err.contains("duration ≥ 1e-9"),
            "{err}"
        );
        assert!(!err.contains("stiff or singular"), "{err}");
        assert!(listing.is_empty());
    }
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "-o", "w.mcap", "--duration", "1e-9"],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let verify = coin_log(dir.path(), &["verify", "w.mcap", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&verify.stdout).unwrap();
    let checks = report["files"][0]["checks"].as_array().unwrap();
    let integrity = checks.iter().find(|c| c["id"] == "integrity").unwrap();
    println!("{integrity}");
    assert_eq!(integrity["status"], "pass");
}

/// y' = 1: a clock, for the driver's bounds.
struct Clock;

impl OdeSystem<1> for Clock {
    fn rhs(&self, _t: f64, _y: &[f64; 1], dydt: &mut [f64; 1]) {
        dydt[0] = 1.0;
    }
}

/// The driver checks its bounds after every step, not at samples: with one sample interval spanning the
/// whole run, a raised stop flag ends it before its first step (at the first sample) and a budget of 7
/// steps ends it after exactly 7; without bounds (the control) it completes.
#[test]
fn the_driver_sees_a_stop_and_a_spent_budget_between_samples() {
    let settings = RunSettings {
        t0: 0.0,
        t_end: 1.0,
        sample_interval: 1.0,
    };
    let config = MethodConfig {
        method: Method::Rk4,
        rtol: 0.0,
        atol: 0.0,
        step: 1e-3,
    };
    let run = |bounds: &Bounds<'_>| {
        let mut samples = 0;
        let outcome = run_method_bounded(
            &config,
            &Clock,
            &[0.0],
            &settings,
            bounds,
            &NoEvents,
            |_, _| {
                samples += 1;
                coin_log::integrate::Flow::Continue
            },
        );
        (outcome, samples)
    };
    let stop = AtomicBool::new(true);
    let (stopped, samples) = run(&Bounds {
        stop: Some(&stop),
        ..Bounds::default()
    });
    println!("stop raised: {stopped:?}, {samples} samples");
    assert_eq!(stopped.termination, RunEnd::Stopped { t: 0.0 });
    assert_eq!((stopped.stats.steps, samples), (0, 1));
    let (spent, _) = run(&Bounds {
        max_steps: Some(7),
        ..Bounds::default()
    });
    println!("budget 7: {spent:?}");
    assert_eq!(spent.stats.steps, 7);
    assert!(
        matches!(spent.termination, RunEnd::Failed(StepError::BudgetSpent { steps: 7, t }) if (t - 0.007).abs() < 1e-15),
        "{spent:?}"
    );
    let (free, samples) = run(&Bounds::default());
    assert_eq!(
        (free.termination, free.stats.steps, samples),
        (RunEnd::Completed, 1000, 2)
    );
}

/// A dissipative couple strong enough makes the equations stiff: an explicit method's step stays near its
/// stability limit whatever the tolerance, and the budget is spent at t ≈ 1e-14 of 2000 time units. The
/// advice says that raising --max-steps cannot give the steps needed and names the coefficient; it said
/// "raise --max-steps, run.max_steps, or loosen --rtol/--atol", which cannot work.
#[test]
fn a_stiff_couple_that_spends_the_budget_is_named_as_the_cause() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "euler-disk",
            "--set",
            "body.dissipation={model=\"viscous\",coefficient=3e13}",
            "--max-steps",
            "10000",
            "-o",
            "s.mcap",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the step budget of 10000 steps was spent at t = "),
        "{err}"
    );
    assert!(
        err.contains("more than raising --max-steps can give"),
        "{err}"
    );
    assert!(
        err.contains("the dissipative couple makes the equations stiff")
            && err.contains("use a smaller body.dissipation.coefficient"),
        "{err}"
    );
    assert!(!err.contains("loosen --rtol/--atol"), "{err}");
}
