//! `coin-log record` and `coin-log scenes` as a user runs them: exit codes, messages that name key and
//! value, an output folder left untouched on error, determinism across processes, Ctrl-C.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::process::Process;
use crate::support::record::{coin_log, exe, listing, read_back};
use crate::support::repo;
use coin_log::format::{ResultMetadata, RESULT_METADATA_NAME};
use std::process::Command;
use std::time::{Duration, Instant};

const VALID: &str = r#"description = "test"
[body]
mass = 1.0
radius = 1.0
gravity = 1.0
shape = "thin-disk"
[initial]
theta = 0.3
omega = [0.0, 0.2, 1.0]
[run]
duration = 1.0
integrator = "rk4"
"#;

fn code(output: &std::process::Output) -> i32 {
    output.status.code().expect("exited normally")
}

fn stderr(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Runs `record` on a scene file holding `text` plus `args`; checks exit code 1, that stderr names every
/// `needle`, and that the folder holds nothing but the scene file afterwards.
fn refused(text: &str, args: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.toml"), text).unwrap();
    let before = listing(dir.path());
    let mut all = vec!["record", "bad.toml"];
    all.extend_from_slice(args);
    let out = coin_log(dir.path(), &all);
    let err = stderr(&out);
    println!("{args:?} → exit {}: {err}", code(&out));
    assert_eq!(code(&out), 1, "exit code; stderr: {err}");
    for needle in needles {
        assert!(err.contains(needle), "stderr should name {needle:?}: {err}");
    }
    assert!(
        err.starts_with("error: scene `bad.toml`"),
        "says where: {err}"
    );
    assert_eq!(listing(dir.path()), before, "the folder is unchanged");
}

#[test]
fn a_scene_with_an_unknown_key_is_refused_naming_the_key() {
    refused(&VALID.replace("mass = 1.0", "masss = 1.0"), &[], &["masss"]);
    refused(VALID, &["--set", "run.speed=2"], &["speed", "run"]);
}

#[test]
fn a_value_of_the_wrong_type_is_refused_naming_key_and_value() {
    refused(
        &VALID.replace("mass = 1.0", "mass = \"heavy\""),
        &[],
        &["mass", "heavy"],
    );
    refused(VALID, &["--set", "run.rate=fast"], &["run.rate", "fast"]);
}

/// A `--set` VALUE that is not TOML is taken as a bare string (`--set body.shape=hoop`); where a number
/// belongs, serde's "invalid type: string" alone hid why the number became a string (`1e400` overflows
/// TOML's floats, `.5` is no TOML number, and an empty value is none): the error says so and names the edit.
#[test]
fn a_set_number_that_is_not_toml_is_refused_saying_why() {
    refused(
        VALID,
        &["--set", "run.duration=1e400"],
        &["`run.duration`", "`--set run.duration=1e400`", "overflowed"],
    );
    refused(
        VALID,
        &["--set", "initial.theta=.5"],
        &[
            "`initial.theta`",
            "`--set initial.theta=.5`",
            "not a TOML value",
        ],
    );
    refused(
        VALID,
        &["--set", "initial.theta="],
        &["`--set initial.theta=` gives an empty value"],
    );
}

/// A channel named many times, or an empty item given twice, is one problem, not one per repeat:
/// `--channels omega,omega,…` 5000 times printed 4999 identical lines, and `--channels ,` two.
#[test]
fn a_repeated_channel_is_one_problem() {
    let many = vec!["omega"; 5000].join(",");
    for (list, says) in [
        (many.as_str(), "`record.channels` = \"omega\" is listed 5000 times: list each channel once (set by `--channels`)"),
        ("omega,angles,omega", "`record.channels` = \"omega\" is listed twice"),
        (",", "`record.channels` = \"\" is not a channel"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("bad.toml"), VALID).unwrap();
        let out = coin_log(dir.path(), &["record", "bad.toml", "--channels", list]);
        let err = stderr(&out);
        assert_eq!(code(&out), 1, "{err}");
        assert!(err.contains(says), "{err}");
        assert_eq!(err.matches("record.channels").count(), 1, "one problem: {err}");
        assert_eq!(listing(dir.path()), ["bad.toml"]);
    }
}

#[test]
fn a_nan_is_refused_naming_key_and_value() {
    refused(
        &VALID.replace("radius = 1.0", "radius = nan"),
        &[],
        &["`body.radius` = NaN"],
    );
    refused(VALID, &["--rtol", "NaN"], &["`run.rtol` = NaN", "--rtol"]);
}

#[test]
fn a_tilt_of_half_pi_is_refused_either_way() {
    for theta in ["1.5707963267948966", "-1.5707963267948966"] {
        let text = VALID.replace("theta = 0.3", &format!("theta = {theta}"));
        refused(&text, &[], &[&format!("`initial.theta` = {theta}"), "π/2"]);
    }
}

#[test]
fn a_mass_that_is_not_positive_is_refused() {
    refused(
        &VALID.replace("mass = 1.0", "mass = 0.0"),
        &[],
        &["`body.mass` = 0", "(0, ∞)"],
    );
    refused(
        &VALID.replace("mass = 1.0", "mass = -1.0"),
        &[],
        &["`body.mass` = -1", "(0, ∞)"],
    );
    refused(VALID, &["--set", "body.mass=-2"], &["`body.mass` = -2"]);
}

#[test]
fn a_rate_of_zero_is_refused_naming_the_flag() {
    refused(VALID, &["--rate", "0"], &["`run.rate` = 0", "--rate"]);
    refused(
        &VALID.replace("duration = 1.0", "duration = 1.0\nrate = 0"),
        &[],
        &["`run.rate` = 0"],
    );
}

#[test]
fn a_duration_that_is_not_positive_is_refused() {
    refused(
        VALID,
        &["--duration=0"],
        &["`run.duration` = 0", "--duration"],
    );
    refused(VALID, &["--duration=-5"], &["`run.duration` = -5"]);
}

#[test]
fn an_unknown_channel_is_refused_naming_it() {
    refused(
        VALID,
        &["--channels", "omega,spin"],
        &["`record.channels` = \"spin\"", "--channels"],
    );
    refused(
        &format!("{VALID}[record]\nchannels = [\"omega\", \"wobble\"]\n"),
        &[],
        &["`record.channels` = \"wobble\""],
    );
}

#[test]
fn an_unknown_integrator_is_refused_naming_it() {
    refused(
        VALID,
        &["--integrator", "euler"],
        &["`run.integrator` = \"euler\"", "rk4"],
    );
}

#[test]
fn a_shape_together_with_inertias_is_refused() {
    let text = VALID.replace(
        "shape = \"thin-disk\"",
        "shape = \"hoop\"\ninertia_x = 0.5\ninertia_z = 1.0",
    );
    refused(&text, &[], &["`body.shape` = \"hoop\"", "inertia"]);
}

#[test]
fn every_problem_is_listed_at_once() {
    let text = VALID
        .replace("mass = 1.0", "mass = -1.0")
        .replace("gravity = 1.0", "gravity = 0.0");
    refused(
        &text,
        &["--rate", "0"],
        &[
            "3 problems",
            "`body.mass` = -1",
            "`body.gravity` = 0",
            "`run.rate` = 0",
        ],
    );
}

#[test]
fn an_existing_output_is_never_replaced_without_overwrite() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), VALID).unwrap();
    std::fs::write(dir.path().join("scene.mcap"), "precious").unwrap();
    let before = listing(dir.path());
    let out = coin_log(dir.path(), &["record", "scene.toml"]);
    let err = stderr(&out);
    println!("exit {}: {err}", code(&out));
    assert_eq!(code(&out), 1);
    assert!(
        err.contains("scene.mcap") && err.contains("--overwrite"),
        "{err}"
    );
    assert_eq!(listing(dir.path()), before);
    assert_eq!(
        std::fs::read(dir.path().join("scene.mcap")).unwrap(),
        b"precious"
    );

    let out = coin_log(dir.path(), &["record", "scene.toml", "--overwrite"]);
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    assert_eq!(listing(dir.path()), before);
    assert!(std::fs::read(dir.path().join("scene.mcap"))
        .unwrap()
        .starts_with(b"\x89MCAP0\r\n"));
}

#[test]
fn an_unwritable_folder_is_an_error_that_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), VALID).unwrap();
    let before = listing(dir.path());
    let out = coin_log(
        dir.path(),
        &["record", "scene.toml", "-o", "missing/folder/x.mcap"],
    );
    let err = stderr(&out);
    println!("exit {}: {err}", code(&out));
    assert_eq!(code(&out), 1);
    assert!(err.contains("missing/folder"), "{err}");
    assert_eq!(listing(dir.path()), before);
}

#[test]
fn a_folder_as_output_is_refused_before_recording_even_with_overwrite() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("out")).unwrap();
    let before = listing(dir.path());
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "-o", "out", "--overwrite"],
    );
    let err = stderr(&out);
    println!("exit {}: {err}", code(&out));
    assert_eq!(code(&out), 1);
    assert!(
        err.contains("`out` is a folder") && err.contains("wobble.mcap"),
        "{err}"
    );
    assert_eq!(listing(dir.path()), before);
    assert!(listing(&dir.path().join("out")).is_empty());
}

#[test]
fn an_unknown_scene_name_lists_the_built_ins() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(dir.path(), &["record", "wobbel"]);
    let err = stderr(&out);
    println!("exit {}: {err}", code(&out));
    assert_eq!(code(&out), 1);
    assert!(err.contains("wobbel") && err.contains("wobble"), "{err}");
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn a_flag_that_does_not_parse_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(dir.path(), &["record", "wobble", "--rate", "fast"]);
    println!("exit {}: {}", code(&out), stderr(&out));
    assert_eq!(code(&out), 2);
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn a_recording_lands_under_the_scene_name_with_a_json_summary() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "circle-plus",
            "--duration",
            "2",
            "--integrator",
            "rk4",
            "--json",
        ],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    println!("{summary}");
    assert_eq!(listing(dir.path()), vec!["circle-plus.mcap".to_string()]);
    assert_eq!(summary["termination"], "completed");
    assert_eq!(summary["samples"], 201);
    let bytes = std::fs::read(dir.path().join("circle-plus.mcap")).unwrap();
    assert_eq!(summary["bytes"], bytes.len() as u64);
    assert!(summary["steady_residual"].as_f64().unwrap() < 1e-9);
    for key in [
        "messages",
        "wall_time_s",
        "steps",
        "rhs_evaluations",
        "rejected_steps",
        "energy_drift",
        "termination_time",
    ] {
        assert!(summary.get(key).is_some(), "{key} in {summary}");
    }
}

#[test]
fn a_physical_event_ends_the_run_normally() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "topple",
            "--integrator",
            "rk4",
            "--json",
            "-o",
            "t.mcap",
        ],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    println!("{summary}");
    assert_eq!(summary["termination"], "flat-landing");
    let file = read_back(&std::fs::read(dir.path().join("t.mcap")).unwrap());
    let result = ResultMetadata::from_map(&file.metadata[RESULT_METADATA_NAME].1).unwrap();
    assert_eq!(
        result.termination,
        coin_log::format::Termination::FlatLanding
    );
}

#[test]
fn two_processes_write_byte_identical_files() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["a.mcap", "b.mcap"] {
        let out = coin_log(
            dir.path(),
            &[
                "record",
                "wobble",
                "--duration",
                "5",
                "--integrator",
                "rk4",
                "-o",
                name,
            ],
        );
        assert_eq!(code(&out), 0, "{}", stderr(&out));
    }
    let a = std::fs::read(dir.path().join("a.mcap")).unwrap();
    let b = std::fs::read(dir.path().join("b.mcap")).unwrap();
    println!("a.mcap {} bytes, b.mcap {} bytes", a.len(), b.len());
    assert!(a == b, "the two files differ");
}

#[test]
fn the_scenes_command_lists_and_shows_every_built_in() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(dir.path(), &["scenes"]);
    assert_eq!(code(&out), 0);
    let list = String::from_utf8(out.stdout).unwrap();
    print!("{list}");
    assert_eq!(list.lines().count(), coin_log::scene::presets::NAMES.len());
    for name in coin_log::scene::presets::NAMES {
        let out = coin_log(dir.path(), &["scenes", "--show", name]);
        assert_eq!(code(&out), 0);
        let shown = String::from_utf8(out.stdout).unwrap();
        let file = repo().join(format!("datasets/scenes/{name}.toml"));
        assert_eq!(
            shown,
            std::fs::read_to_string(file).unwrap(),
            "{name}: `scenes --show` and the dataset file differ; regenerate the file"
        );
    }
    let out = coin_log(dir.path(), &["scenes", "--show", "nope"]);
    assert_eq!(code(&out), 1);
}

/// Sends SIGINT to a long recording and checks that it finishes the file, marked interrupted, exit 130.
#[test]
fn ctrl_c_finishes_the_file_marked_interrupted() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = Process::start(
        Command::new(exe())
            .args([
                "record",
                "long-horizon",
                "--rate",
                "1000",
                "--duration",
                "100000",
                "--integrator",
                "rk4",
                "-o",
                "long.mcap",
            ])
            .current_dir(dir.path()),
    );
    // Wait for the temporary file: the signal handler is installed right after it is created.
    let started = Instant::now();
    while listing(dir.path()).is_empty() {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "no temporary file appeared"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    // Within 60 s of SIGINT.
    let out = child.wait_within(Duration::from_secs(60));
    let exit = out.status;
    println!(
        "exit {:?}, stdout:\n{}stderr: {}",
        exit.code(),
        out.stdout,
        out.stderr
    );
    assert_eq!(exit.code(), Some(130));
    assert_eq!(listing(dir.path()), vec!["long.mcap".to_string()]);
    let file = read_back(&std::fs::read(dir.path().join("long.mcap")).unwrap());
    let result = ResultMetadata::from_map(&file.metadata[RESULT_METADATA_NAME].1).unwrap();
    println!(
        "termination {} at t = {}, {} messages",
        result.termination,
        result.termination_time,
        file.messages.len()
    );
    assert_eq!(
        result.termination,
        coin_log::format::Termination::Interrupted
    );
    assert!(result.termination_time > 0.0 && result.termination_time < 100_000.0);
    let last = file.on_topic("/coin/omega").last().unwrap().log_time;
    assert_eq!(
        last,
        coin_log::format::log_time(result.termination_time).unwrap()
    );
}

// A numerical failure (the file finished up to it, exit 1) can no longer be reached from the command line:
// the scene that produced one (ω_Z = 1e150 with rk4) is refused before writing (cli_scene_limits.rs), and
// the recorder's side of it is tested on such a state in record_roundtrip.rs.

/// `--dry-run` names an output the recording would refuse, so that a dry run that passes is not followed
/// by a refusal at once: it said nothing of `-o /dev/null`, a missing folder or an existing file.
#[test]
fn a_dry_run_warns_of_an_output_the_recording_would_refuse() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("exists.mcap"), "x").unwrap();
    for (target, needle) in [
        ("/dev/null", "`/dev/null` is a character device"),
        ("nope/x.mcap", "the folder `nope` does not exist"),
        (
            "exists.mcap",
            "`exists.mcap` already exists; pass --overwrite",
        ),
    ] {
        let out = coin_log(d, &["record", "wobble", "--dry-run", "-o", target]);
        let err = stderr(&out);
        assert_eq!(code(&out), 0, "{err}");
        assert!(
            err.contains(&format!(
                "warning: the recording itself would be refused: {needle}"
            )),
            "{target}: {err}"
        );
        assert!(String::from_utf8_lossy(&out.stdout).contains("[body]"));
    }
    assert_eq!(listing(d), ["exists.mcap"], "nothing written");
    // Negative control: a target the recording may write gives no warning.
    for args in [
        &["record", "wobble", "--dry-run", "-o", "new.mcap"][..],
        &[
            "record",
            "wobble",
            "--dry-run",
            "-o",
            "exists.mcap",
            "--overwrite",
        ][..],
    ] {
        let out = coin_log(d, args);
        assert_eq!(code(&out), 0);
        assert!(
            !stderr(&out).contains("warning"),
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

/// `--max-steps` in another form than digits is a usage error that says how to write it (clap's "invalid
/// digit found in string" for `1e8` said neither).
#[test]
fn a_max_steps_not_in_digits_says_how_to_write_it() {
    let dir = tempfile::tempdir().unwrap();
    for value in ["1e8", "-1", "1.5", "many"] {
        let out = coin_log(dir.path(), &["record", "wobble", "--max-steps", value]);
        let err = stderr(&out);
        assert_eq!(code(&out), 2, "{value}: {err}");
        assert!(
            err.contains("not a whole number of steps in digits: write e.g. 100000000"),
            "{value}: {err}"
        );
    }
    // Negative control: digits are read (and 0 is the scene's error, naming the flag).
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--max-steps", "0", "--dry-run"],
    );
    assert_eq!(code(&out), 1);
    assert!(stderr(&out).contains("(set by `--max-steps`)"));
    let out = coin_log(
        dir.path(),
        &["record", "wobble", "--max-steps", "100000000", "--dry-run"],
    );
    assert_eq!(code(&out), 0, "{}", stderr(&out));
}
