//! Scenes and flags at the limits of double precision, of the 1 ns time base and of the integrators
//! (format.md: Scene files, Limits): refused at once naming key, value and limit, never a NaN, an empty
//! problem list, a repeated log time or an event that is an artefact of integration error; flags that do
//! not apply are warned about and cannot move verify's tolerances; a built-in name never hides a local
//! file silently.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{coin_log, listing, read_back};
use coin_log::format::{RunMetadata, RUN_METADATA_NAME};
use coin_log::scene::{self, presets, Scene};
use std::path::Path;
use std::process::Output;

fn code(output: &Output) -> i32 {
    output.status.code().expect("exited normally")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// `record` with `args` in a fresh folder: exit 1, stderr holding every needle, never an empty problem
/// list, and nothing written.
fn refused(args: &[&str], needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let mut all = vec!["record"];
    all.extend_from_slice(args);
    let out = coin_log(dir.path(), &all);
    let err = stderr(&out);
    println!("{args:?} → exit {}: {err}", code(&out));
    assert_eq!(code(&out), 1, "{err}");
    assert!(!err.contains("0 problems"), "{err}");
    for needle in needles {
        assert!(err.contains(needle), "stderr should say {needle:?}: {err}");
    }
    assert!(listing(dir.path()).is_empty(), "nothing is written");
    err
}

#[test]
fn scales_beyond_double_precision_are_refused_naming_key_and_range() {
    for (set, needle) in [
        ("body.radius=1e-200", "`body.radius` = 1e-200 is outside 1e-150 … 1e150"),
        ("body.radius=1e300", "`body.radius` = 1e300 is outside 1e-150 … 1e150"),
        (
            "body.radius=1e-100",
            "`body.radius` = 1e-100 with `body.mass` = 1 and `body.gravity` = 1 gives the inertia scale M·a² = 1e-200",
        ),
    ] {
        let err = refused(&["wobble", "--set", set], &[needle, "normal double-precision"]);
        assert!(!err.contains("NaN"), "{err}");
    }
    refused(
        &[
            "wobble",
            "--set",
            "body.mass=1e100",
            "--set",
            "body.radius=1e100",
        ],
        &["M·a² = 1e300", "M·g·a = 1e200"],
    );
}

#[test]
fn a_rate_the_nanosecond_time_base_cannot_hold_apart_is_refused() {
    let max = coin_log::scene::limits::max_rate(30.0).floor();
    refused(
        &["wobble", "--rate", "2e9"],
        &[
            "`run.rate` = 2000000000 is above",
            &format!("use rate ≤ {max}"),
            "(set by `--rate`)",
        ],
    );
}

#[test]
fn a_highest_rate_below_one_is_given_as_it_is_not_floored_to_zero() {
    // max_rate(1e20) = 1/(1e-9 + 6·2⁻⁵³·1e20) = 1.5012e-5 per time unit; the message said "use rate ≤ 0".
    let err = refused(
        &["wobble", "--set", "run.duration=1e20"],
        &["is too long", "use rate ≤ 1.501e-5"],
    );
    assert!(!err.contains("rate ≤ 0"), "{err}");
}

/// At the highest rate, and with a duration 0.3 ns past a grid point, every sample has its own log time
/// and the last one is at the duration.
#[test]
fn samples_at_the_limits_of_the_time_base_have_strictly_increasing_log_times() {
    let dir = tempfile::tempdir().unwrap();
    let rate = coin_log::scene::limits::max_rate(1e-6).floor().to_string();
    for (name, args) in [
        (
            "fast.mcap",
            vec!["--duration", "1e-6", "--rate", rate.as_str()],
        ),
        ("odd.mcap", vec!["--duration", "1.0000000003"]),
    ] {
        let mut all = vec!["record", "wobble", "--channels", "omega", "-o", name];
        all.extend_from_slice(&args);
        let out = coin_log(dir.path(), &all);
        assert_eq!(code(&out), 0, "{}", stderr(&out));
        let file = read_back(&std::fs::read(dir.path().join(name)).unwrap());
        let times: Vec<u64> = file
            .on_topic("/coin/omega")
            .iter()
            .map(|m| m.log_time)
            .collect();
        let repeats = times.windows(2).filter(|w| w[0] >= w[1]).count();
        println!(
            "{args:?}: {} samples, last at {} ns, {repeats} not increasing",
            times.len(),
            times.last().unwrap()
        );
        assert_eq!(repeats, 0);
        let end: f64 = args[1].parse().unwrap();
        assert_eq!(
            *times.last().unwrap(),
            coin_log::format::log_time(end).unwrap()
        );
    }
}

#[test]
fn an_initial_state_outside_the_model_is_refused_saying_what_it_needs() {
    refused(
        &["circle-plus", "--set", "body.friction=0.01"],
        &[
            "`body.friction` = 0.01 is below |F|/N = 0.2042 needed at t = 0",
            "give friction ≥ 0.2042",
        ],
    );
    refused(
        &["wobble", "--set", "initial.omega=[3, 0, 0]"],
        &["`initial.omega`", "≤ 0 at t = 0", "lift-off", "N > 0"],
    );
    // ω_Z = 1e150 overflowed in the first step (a numerical failure after one sample); now refused.
    refused(
        &[
            "wobble",
            "--integrator",
            "rk4",
            "--set",
            "initial.omega=[0, 0, 1e150]",
        ],
        &["`run.step` = 0.001 is above", "(hW)⁴ would exceed 1e-3"],
    );
    refused(
        &["straight", "--set", "initial.steady.omega_z=1e100"],
        &["`run.duration` = 20 times W", "more than 1e10"],
    );
}

/// A dissipative couple that is not finite at t = 0, or that an adaptive method's error estimate cannot
/// square, or that a fixed step cannot resolve, is refused up front naming the law's key and the value
/// that would do; each used to write a 1-sample file ending "non-finite at t = 0" (exit 1), or a "flat
/// landing" at t = 9e-14 with rk4.
#[test]
fn a_dissipative_couple_beyond_double_precision_or_the_step_is_refused() {
    let law = |l: &str| format!("body.dissipation={l}");
    refused(
        &[
            "euler-disk",
            "--set",
            &law("{model=\"power-law\",coefficient=1e-7,m=2,k=1e300}"),
        ],
        &[
            "`body.dissipation.k` = 1e300",
            "non-finite dissipated power",
            "use k < 439.1",
        ],
    );
    // κ = 0 makes P = 0 however large (sin α)^(−k) is: the conservative coin. (It used to be refused
    // here as 0·∞ = NaN, the artefact Dissipation::power no longer makes.)
    let scene = scene::file_with_sets(
        &presets::preset("euler-disk").unwrap(),
        &[law("{model=\"power-law\",coefficient=0,m=2,k=1e300}")],
    )
    .unwrap();
    let scene = Scene::from_file(&scene).unwrap();
    let d = scene.dissipation.unwrap();
    assert_eq!(d.power(scene.initial.theta, scene.initial.omega_y), 0.0);
    refused(
        &[
            "euler-disk",
            "--set",
            &law("{model=\"power-law\",coefficient=1e-7,m=1e300,k=1}"),
        ],
        &[
            "`body.dissipation.m` = 1e300",
            "|φ̇|^m overflows",
            "use m < 165.6",
        ],
    );
    for kappa in ["1e300", "1e200"] {
        refused(
            &[
                "euler-disk",
                "--set",
                &law(&format!("{{model=\"viscous\",coefficient={kappa}}}")),
            ],
            &[
                &format!("`body.dissipation.coefficient` = {kappa}"),
                "more than 1e150·atol = 1e138",
                "use coefficient ≤ 4.33e131",
            ],
        );
    }
    refused(
        &[
            "euler-disk",
            "--integrator",
            "rk4",
            "--set",
            &law("{model=\"viscous\",coefficient=100}"),
        ],
        &[
            "`run.step` = 0.0008333333333333334 is above 0.178/W = 1.11e-8",
            "W = max(|ω|, |φ̇|, |ψ̇|, 1/τ, λ) = 16010000",
        ],
    );
}

/// A body whose time unit is so short that even the shortest run (1 ns) is beyond 1e10 radians: the
/// refusal said "use duration ≤ 0.999e-65" (a mantissa below 1, and a duration below the 1e-9 floor that
/// would itself be refused); it now names τ and the units. A spin that fast asks to slow the motion.
#[test]
fn a_motion_no_duration_can_hold_is_refused_with_a_fix_that_works() {
    let err = refused(
        &[
            "wobble",
            "--set",
            "body.radius=1e-75",
            "--set",
            "body.gravity=1e75",
            "--atol",
            "1e-80",
        ],
        &[
            "`run.duration` = 30 times W",
            "so would the shortest duration, 1e-9",
            "τ = √(a/g) = 1e-75 is too short: express the scene in units where τ is nearer 1",
        ],
    );
    assert!(!err.contains("use duration ≤"), "{err}");
    refused(
        &["straight", "--set", "initial.steady.omega_z=1e100"],
        &[
            "so would the shortest duration",
            "slow the motion to W ≤ 1e19",
        ],
    );
}

#[test]
fn tolerances_and_steps_beyond_what_the_integrators_deliver_are_refused() {
    refused(
        &["wobble", "--rtol", "1"],
        &["`run.rtol` = 1 is above 1e-3", "(set by `--rtol`)"],
    );
    refused(
        &["wobble", "--rtol", "1e-30", "--atol", "1e-30"],
        &[
            "`run.rtol` = 1e-30 is below 2.22e-15",
            "use rtol ≥ 2.220446049250313e-15",
        ],
    );
    refused(
        &["wobble", "--atol", "1"],
        &["`run.atol` = 1 is above 0.001"],
    );
    refused(
        &[
            "wobble",
            "--integrator",
            "rk4",
            "--step",
            "0.5",
            "--rate",
            "1",
        ],
        &[
            "`run.step` = 0.5 is above 0.178/W = 0.1105",
            "W = max(|ω|, |φ̇|, |ψ̇|, 1/τ) = 1.609",
            "use step ≤ 0.1105",
        ],
    );
}

fn json_summary(dir: &Path, args: &[&str]) -> (serde_json::Value, String) {
    let mut all = vec!["record"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--json", "--overwrite"]);
    let out = coin_log(dir, &all);
    let err = stderr(&out);
    assert_eq!(code(&out), 0, "{err}");
    (serde_json::from_slice(&out.stdout).unwrap(), err)
}

/// `lift-off` at rtol 1e-3 ends at a lift-off 9e-5 late with an energy drift 13 times verify's
/// tolerance: the summary says the event is not to be trusted. (Before the driver probed inside steps,
/// the dip of N below 0 fell inside one step and the run landed flat half a time unit later.) At rtol 1e-4
/// the lift-off is trusted (the control).
#[test]
fn an_event_after_too_much_energy_drift_is_flagged_as_not_to_be_trusted() {
    let dir = tempfile::tempdir().unwrap();
    let loose = [
        "lift-off", "--rtol", "1e-3", "--atol", "1e-6", "-o", "l.mcap",
    ];
    let (s, err) = json_summary(dir.path(), &loose);
    println!("{s}\n{err}");
    assert_eq!(s["termination"], "lift-off");
    assert_eq!(s["event_trusted"], false);
    assert!(s["energy_drift"].as_f64().unwrap() > s["energy_tolerance"].as_f64().unwrap());
    assert!(
        err.contains("warning: the lift-off at t = 2.674") && err.contains("is not to be trusted"),
        "{err}"
    );
    let table_args: Vec<&str> = ["record"]
        .into_iter()
        .chain(loose)
        .chain(["--overwrite"])
        .collect();
    let out = coin_log(dir.path(), &table_args);
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("(not to be trusted: energy drift above the tolerance)"),
        "{table}"
    );
    let (s, err) = json_summary(
        dir.path(),
        &[
            "lift-off", "--rtol", "1e-4", "--atol", "1e-6", "-o", "l.mcap",
        ],
    );
    println!("{s}\n{err}");
    assert_eq!(s["termination"], "lift-off");
    assert_eq!(s["event_trusted"], true);
    assert!(!err.contains("not to be trusted"), "{err}");
    let (s, _) = json_summary(dir.path(), &["wobble", "--duration", "1", "-o", "w.mcap"]);
    assert_eq!(s["event_trusted"], serde_json::Value::Null, "no event");
}

/// The `coin-log` metadata of `path` and verify's energy tolerance for it.
fn metadata_and_tolerance(dir: &Path, name: &str) -> (RunMetadata, f64) {
    let file = read_back(&std::fs::read(dir.join(name)).unwrap());
    let metadata = RunMetadata::from_map(&file.metadata[RUN_METADATA_NAME].1).unwrap();
    let out = coin_log(dir, &["verify", name, "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let energy = report["files"][0]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == "energy")
        .unwrap()["tolerance"]
        .as_f64()
        .unwrap();
    (metadata, energy)
}

/// `--step` with dop853 and `--rtol`/`--atol` with rk4 are warned about, stored as 0, left out of the
/// stored scene, and leave verify's tolerance where the settings that applied put it.
#[test]
fn settings_the_integrator_does_not_use_are_warned_about_and_change_nothing() {
    let dir = tempfile::tempdir().unwrap();
    for (flags, name, key) in [
        (vec!["--step", "0.1"], "a.mcap", "run.step"),
        (vec![], "a0.mcap", ""),
        (
            vec!["--integrator", "rk4", "--rtol", "1e-3", "--atol", "1e-3"],
            "f.mcap",
            "run.rtol",
        ),
        (vec!["--integrator", "rk4"], "f0.mcap", ""),
    ] {
        let mut args = vec!["wobble", "--duration", "2", "-o", name];
        args.extend_from_slice(&flags);
        let (_, err) = json_summary(dir.path(), &args);
        println!("{flags:?}: {err}");
        if key.is_empty() {
            assert!(!err.contains("warning"), "{err}");
        } else {
            assert!(
                err.contains(&format!("warning: `{key}` = "))
                    && err.contains("does not apply to")
                    && err.contains("ignored (stored as 0)"),
                "{err}"
            );
        }
    }
    let (adaptive, tol_a) = metadata_and_tolerance(dir.path(), "a.mcap");
    let (_, tol_a0) = metadata_and_tolerance(dir.path(), "a0.mcap");
    let (fixed, tol_f) = metadata_and_tolerance(dir.path(), "f.mcap");
    let (_, tol_f0) = metadata_and_tolerance(dir.path(), "f0.mcap");
    println!("dop853: step {} tol {tol_a} (without --step {tol_a0}); rk4: rtol {} atol {} tol {tol_f} (without {tol_f0})", adaptive.step, fixed.rtol, fixed.atol);
    assert_eq!(adaptive.step, 0.0);
    assert_eq!((fixed.rtol, fixed.atol), (0.0, 0.0));
    assert_eq!(fixed.step, 1e-3);
    assert!(!adaptive.scene.contains("step ="), "{}", adaptive.scene);
    assert!(
        !fixed.scene.contains("rtol =") && !fixed.scene.contains("atol ="),
        "{}",
        fixed.scene
    );
    assert_eq!(tol_a, tol_a0, "--step cannot move dop853's tolerance");
    assert_eq!(tol_f, tol_f0, "--rtol cannot loosen rk4's tolerance");
}

#[test]
fn the_step_actually_used_is_shown() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "wobble",
            "--integrator",
            "rk4",
            "--rate",
            "300",
            "--duration",
            "1",
        ],
    );
    let (err, table) = (
        stderr(&out),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    );
    println!("{err}{table}");
    assert_eq!(code(&out), 0, "{err}");
    assert!(
        err.contains("note: step 0.001 rounded down to 8.3333e-4 so that a whole number of steps (4) fits between samples (1/rate = 3.3333e-3)"),
        "{err}"
    );
    assert!(
        table.contains("integrator       rk4 (step 8.3333e-4): 1200 steps"),
        "{table}"
    );
    let (s, _) = json_summary(
        dir.path(),
        &[
            "wobble",
            "--integrator",
            "rk4",
            "--rate",
            "300",
            "--duration",
            "1",
        ],
    );
    let step = s["step"].as_f64().unwrap();
    assert!((step - 1.0 / 1200.0).abs() < 1e-18, "{step}");
    assert_eq!(s["rtol"], serde_json::Value::Null);
}

#[test]
fn channel_names_are_trimmed() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "wobble",
            "--duration",
            "1",
            "--channels",
            "omega, angles",
            "-o",
            "c.mcap",
        ],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let file = read_back(&std::fs::read(dir.path().join("c.mcap")).unwrap());
    assert_eq!(file.topics(), vec!["/coin/angles", "/coin/omega"]);
}

/// A bare name is the built-in, and a local file of that name is named in a note; a path is the file.
#[test]
fn a_local_file_named_like_a_built_in_is_never_shadowed_silently() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(crate::support::repo().join("datasets/scenes/wobble.toml"))
        .unwrap()
        .replace("duration = 30.0", "duration = 1.0");
    std::fs::write(dir.path().join("wobble"), &text).unwrap();
    let (s, err) = json_summary(dir.path(), &["wobble", "-o", "builtin.mcap"]);
    println!("{err}");
    assert_eq!(s["samples"], 3001, "the built-in (30 time units)");
    assert!(
        err.contains("note: `wobble` is the built-in scene; the file `wobble` in this folder is not used (give `./wobble` to use it)"),
        "{err}"
    );
    let (s, err) = json_summary(dir.path(), &["./wobble", "-o", "file.mcap"]);
    assert_eq!(s["samples"], 101, "the file (1 time unit)");
    assert!(!err.contains("note"), "{err}");
    std::fs::rename(dir.path().join("wobble"), dir.path().join("wobble.toml")).unwrap();
    let (_, err) = json_summary(dir.path(), &["wobble", "-o", "builtin.mcap"]);
    assert!(
        err.contains("the file `wobble.toml` in this folder is not used"),
        "{err}"
    );
    let (s, _) = json_summary(dir.path(), &["wobble.toml", "-o", "file.mcap"]);
    assert_eq!(s["samples"], 101);
}

/// Every sample of a run at the highest rate gets its own nanosecond, at several durations; a rate
/// 20 % above 1e9 repeats log times (the negative control).
#[test]
#[allow(
    clippy::cast_precision_loss,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]
fn samples_at_the_highest_rate_have_strictly_increasing_log_times() {
    // The first 10⁵ samples and the last 10⁶ (where the rounding of t is largest) of each run.
    for duration in [1e-3, 1.0, 1e3, 1e5] {
        let rate = coin_log::scene::limits::max_rate(duration);
        let interval = 1.0 / rate;
        let n = (duration * rate) as u64;
        let windows = [0..n.min(100_000), n.saturating_sub(1_000_000)..n];
        for window in windows {
            let mut last = coin_log::format::log_time(window.start as f64 * interval).unwrap_or(0);
            for k in window.start + 1..=window.end {
                let t = k as f64 * interval;
                let ns = coin_log::format::log_time(t).unwrap_or(0);
                assert!(
                    ns > last,
                    "duration {duration}, rate {rate}: sample {k} at t = {t} repeats {ns} ns"
                );
                last = ns;
            }
        }
        println!("duration {duration:e}: rate {rate:.9e}, {n} samples, checked ones distinct");
    }
    let (rate, duration) = (1.2e9, 1e-6);
    let interval = 1.0 / rate;
    let times: Vec<u64> = (0..=(duration * rate) as u64)
        .map(|k| coin_log::format::log_time(k as f64 * interval).unwrap_or(0))
        .collect();
    let repeats = times.windows(2).filter(|w| w[0] == w[1]).count();
    println!("control: rate {rate:e} over {duration}: {repeats} repeated log times");
    assert!(repeats > 0, "the control should repeat log times");
}

#[test]
fn a_steady_lean_at_the_flat_margin_is_not_told_to_roll_straight() {
    // θ = 0 is straight rolling: the advice names that kind.
    refused(
        &["circle-plus", "--set", "initial.steady.theta=0"],
        &[
            "`initial.steady.theta` = 0 is outside 0 < |θ| < π/2 − 0.0001",
            "use kind = \"straight\" for θ = 0",
        ],
    );
    // A lean at the flat margin is too flat, not upright: "straight" would be wrong advice.
    for theta in ["1.5707", "-1.5707"] {
        let set = format!("initial.steady.theta={theta}");
        let err = refused(
            &["circle-plus", "--set", &set],
            &[
                &format!("`initial.steady.theta` = {theta} is outside 0 < |θ| < π/2 − 0.0001"),
                "a rolling coin must lean less than flat",
            ],
        );
        assert!(!err.contains("straight"), "{err}");
    }
}

#[test]
fn a_small_ignored_or_rounded_setting_is_shown_as_given_not_as_a_row_of_zeros() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let mut all = vec!["record", "wobble", "--duration", "0.01", "--dry-run"];
        all.extend_from_slice(args);
        let out = coin_log(dir.path(), &all);
        assert_eq!(code(&out), 0, "{}", stderr(&out));
        stderr(&out)
    };
    // As refusals print values (`run.duration` = 1e-10), so do the warning and the note.
    let err = run(&["--integrator", "rk4", "--rtol", "1e-8"]);
    assert!(
        err.contains("warning: `run.rtol` = 1e-8 (set by `--rtol`) does not apply to rk4"),
        "{err}"
    );
    let err = run(&["--step", "1e-9"]);
    assert!(
        err.contains("warning: `run.step` = 1e-9 (set by `--step`) does not apply to dop853"),
        "{err}"
    );
    let err = run(&["--integrator", "rk4", "--rate", "300", "--step", "1e-7"]);
    assert!(err.contains("note: step 1e-7 rounded down to "), "{err}");
    assert!(!err.contains("0.0000"), "{err}");
}

/// A couple too fast for an adaptive method's error estimate is as much the atol's doing as κ's:
/// `euler-disk --atol 5e-324` was told only to lower κ to 4.25e-181. The refusal now names the atol that
/// does, and that atol is accepted.
#[test]
fn a_couple_refused_for_a_tiny_atol_names_the_atol_that_does() {
    let err = refused(
        &["euler-disk", "--atol", "5e-324"],
        &["use coefficient ≤ 4.25e-181, or atol ≥ "],
    );
    let atol = err
        .split("or atol ≥ ")
        .nth(1)
        .unwrap()
        .split(|c: char| c.is_whitespace() || c == '(')
        .next()
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &["record", "euler-disk", "--atol", atol, "--dry-run"],
    );
    assert_eq!(code(&out), 0, "--atol {atol}: {}", stderr(&out));
}
