//! `coin-log verify` on good recordings and on negative controls: each tampered file must fail the right
//! check, by id, with the measured number in the report.
#![allow(clippy::unwrap_used)]

use crate::support::record::{coin_log_text, read_messages, record_scene, scene_names};
use crate::support::writers::{
    nudge, record, recorded, rewrite, rewrite_run_metadata, rewrite_with_schemas, steady_circle,
    wobble, Edit, Spec,
};
use coin_log::scene::{self, presets, FlagOverrides, Scene};
use coin_log::verify::{
    coverage, verify_file, CheckId, CheckResult, FileReport, Options, Status, Verdict,
};

fn show(r: &FileReport) -> String {
    r.checks
        .iter()
        .map(|c| {
            format!(
                "{:<12} {:<5} value {:?} tol {:?}  {}",
                c.id.name(),
                c.status.to_string(),
                c.value,
                c.tolerance,
                c.reason
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn status(r: &FileReport, id: CheckId) -> Status {
    r.check(id).unwrap().status
}

#[test]
fn a_recorded_wobble_passes_every_check_that_runs() {
    let (_dir, path) = recorded(&wobble(), "wobble.mcap");
    let r = verify_file(&path, &Options::default());
    println!("{}", show(&r));
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    for id in [
        CheckId::Integrity,
        CheckId::Energy,
        CheckId::Constraint,
        CheckId::Consistency,
        CheckId::Validity,
    ] {
        assert_eq!(status(&r, id), Status::Pass, "{id}\n{}", show(&r));
    }
    assert_eq!(status(&r, CheckId::Steady), Status::Skip);
}

#[test]
fn a_recorded_steady_circle_passes_the_steady_check() {
    let (_dir, path) = recorded(&steady_circle(), "circle.mcap");
    let r = verify_file(&path, &Options::default());
    println!("{}", show(&r));
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    assert_eq!(status(&r, CheckId::Steady), Status::Pass);
}

/// Verifies a copy of built-in scene `scene`, recorded by `coin-log record` with default settings, in which
/// `edit` changed messages; prints the report.
fn tampered(scene: &str, edit: impl FnMut(Edit<'_>)) -> FileReport {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), scene, &[]);
    let clean = verify_file(&good, &Options::default());
    assert_eq!(
        clean.exit_code,
        0,
        "the untouched recording must pass\n{}",
        show(&clean)
    );
    let bad = dir.path().join("bad.mcap");
    rewrite(&good, &bad, edit);
    let r = verify_file(&bad, &Options::default());
    println!("{}", show(&r));
    r
}

#[test]
fn a_stored_scene_that_disagrees_with_its_record_or_first_sample_or_does_not_validate_fails() {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "wobble", &[]);
    let edited = |name: &str, from: &str, to: &str| {
        let path = dir.path().join(name);
        let (from, to) = (from.to_string(), to.to_string());
        rewrite_run_metadata(&good, &path, &move |m| {
            let scene = m["scene"].replace(&from, &to);
            assert_ne!(scene, m["scene"], "`{from}` is in the stored scene");
            m.insert("scene".into(), scene);
        });
        let r = verify_file(&path, &Options::default());
        println!("{}", show(&r));
        r
    };
    let reason = |r: &FileReport, id| r.check(id).unwrap().reason.clone();
    // Negative control: the same copy with an edit that changes nothing the run depends on.
    let r = edited(
        "described.mcap",
        "description = \"",
        "description = \"Copied: ",
    );
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    assert!(
        reason(&r, CheckId::Consistency).contains("initial state 0"),
        "{}",
        show(&r)
    );
    // The body: the record says M = 1, the scene 2 (and the inertias of its shape with it).
    let r = edited("mass.mcap", "mass = 1.0", "mass = 2.0");
    assert_eq!(status(&r, CheckId::Integrity), Status::Fail);
    assert!(
        reason(&r, CheckId::Integrity)
            .contains("the `coin-log` metadata says mass = 1.0, but the scene it stores gives 2.0"),
        "{}",
        show(&r)
    );
    // The initial state, which no other field of the record holds: θ0 off by 1e-8.
    let r = edited("theta.mcap", "theta = 0.5", "theta = 0.50000001");
    assert_fails(&r, CheckId::Consistency, 0.9e-8, 1.1e-8);
    assert_eq!(status(&r, CheckId::Integrity), Status::Pass, "{}", show(&r));
    // A scene that record would refuse: its steady check skipped, the file passed.
    let r = edited(
        "invalid.mcap",
        "description = \"",
        "description = \"\\u0007",
    );
    assert!(
        reason(&r, CheckId::Integrity).contains("the metadata's scene is not valid: `description`"),
        "{}",
        show(&r)
    );
    // A description of 100 000 characters fails too, and info and plot show 200 of them.
    let long = format!("description = \"{}", "d".repeat(100_000));
    let r = edited("long.mcap", "description = \"", &long);
    assert_eq!(status(&r, CheckId::Integrity), Status::Fail);
    let path = dir.path().join("long.mcap");
    let (code, info, err) = coin_log_text(&["info", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        info.len() < 3000 && info.contains(&format!("{}…", "d".repeat(199))),
        "{info}"
    );
    let svg = dir.path().join("long.svg");
    let (code, _, err) =
        coin_log_text(&["plot", path.to_str().unwrap(), "-o", svg.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(!std::fs::read_to_string(&svg)
        .unwrap()
        .contains(&"d".repeat(201)));
}

fn assert_fails(r: &FileReport, id: CheckId, low: f64, high: f64) {
    let c = r.check(id).unwrap();
    let value = c.value.unwrap();
    println!(
        "{id}: measured {value:e}, tolerance {:e}, expected in [{low:e}, {high:e}]",
        c.tolerance.unwrap()
    );
    assert_eq!(c.status, Status::Fail, "{}", show(r));
    assert!(
        (low..=high).contains(&value),
        "{id}: measured {value:e} outside [{low:e}, {high:e}]"
    );
    assert_eq!(r.exit_code, 1);
}

#[test]
fn verify_flags_a_log_with_one_energy_message_nudged_by_1e_6() {
    let r = tampered("wobble", |e| {
        if e.topic == "/coin/energy" && e.index == 500 {
            let total: f64 = serde_json::from_slice::<serde_json::Value>(e.data).unwrap()["total"]
                .as_f64()
                .unwrap();
            nudge(e.data, "total", 1e-6 * total);
        }
    });
    // 1e-6 of E relative to max(|E0|, Mga) = |E0|: 1e-6.
    assert_fails(&r, CheckId::Energy, 0.9e-6, 1.1e-6);
}

#[test]
fn verify_flags_a_log_with_one_position_moved_by_1e_4() {
    let r = tampered("wobble", |e| {
        if e.topic == "/coin/position" && e.index == 500 {
            nudge(e.data, "x", 1e-4);
        }
    });
    // The nearest weight 4/5 divides by h = 0.01: 8e-3 relative to a·max|ω| ≈ 1.6.
    assert_fails(&r, CheckId::Constraint, 2e-3, 1e-2);
}

/// Records built-in `scene` with `args` into `dir` and verifies it: the report and its constraint check,
/// and the file.
fn constraint_of(
    dir: &std::path::Path,
    scene: &str,
    args: &[&str],
) -> (FileReport, CheckResult, std::path::PathBuf) {
    let path = record_scene(dir, scene, args);
    let r = verify_file(&path, &Options::default());
    let c = r.check(CheckId::Constraint).unwrap().clone();
    (r, c, path)
}

/// A coin released at θ = 1.5 sinks flat and spins up (φ̇ doubles every 0.05 time units): the windows
/// where its rates grow that fast are not resolved at rate 100, and must be left out rather than failed
/// (they measured 2.5e-7 against a tolerance of 2e-7, all of it the difference's truncation).
#[test]
fn a_coin_spinning_up_as_it_sinks_flat_is_resolved_where_the_sampling_allows_and_a_moved_position_still_fails(
) {
    let dir = tempfile::tempdir().unwrap();
    let args = ["--set", "initial.theta=1.5", "--duration", "1"];
    let (r, c, path) = constraint_of(dir.path(), "wobble", &args);
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    assert_eq!(c.status, Status::Pass, "{}", show(&r));
    assert!(
        c.reason
            .contains("windows left out: the sampling does not resolve"),
        "{}",
        c.reason
    );
    // Negative control: a position moved by 1e-4 where the windows are resolved (t = 0.9) fails.
    let bad = dir.path().join("bad.mcap");
    rewrite(&path, &bad, |e| {
        if e.topic == "/coin/position" && e.index == 90 {
            nudge(e.data, "x", 1e-4);
        }
    });
    let r = verify_file(&bad, &Options::default());
    assert_eq!(
        r.check(CheckId::Constraint).unwrap().status,
        Status::Fail,
        "{}",
        show(&r)
    );
}

/// Euler's disk with a couple 10⁶ times the air film's lands in 0.05 s, φ̇ falling from 72 to 10 within one
/// sample at the scene's 400 Hz: windows judged resolved by the rates alone erred by 4.2e-7 (tolerance
/// 1.8e-7), all of it the sampling's. Now such a file is judged unresolved (never failed), and at 4 kHz it
/// passes.
#[test]
fn a_disk_braked_a_million_times_harder_than_air_is_unresolved_at_400_hz_and_passes_at_4_khz() {
    let dir = tempfile::tempdir().unwrap();
    let braked = [
        "--set",
        "body.dissipation={model=\"moffatt\",coefficient=1e-3}",
        "--set",
        "initial.phi=0.5",
    ];
    let (r, c, _) = constraint_of(dir.path(), "euler-disk", &braked);
    assert_eq!(c.status, Status::Skip, "{}", show(&r));
    assert!(
        c.reason
            .contains("the sampling does not resolve the motion"),
        "{}",
        c.reason
    );
    let fast = [&braked[..], &["--rate", "4000"]].concat();
    let (r, c, _) = constraint_of(dir.path(), "euler-disk", &fast);
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    assert!(
        c.status == Status::Pass && c.value.unwrap() < 1e-8,
        "{}",
        show(&r)
    );
}

/// A light coin (M = 10⁻⁶) under a viscous couple loses most of its spin within the first sample (ω from
/// 1.5 to 0.92 in 0.01): the windows just after erred by 1.2e-6 against 4e-7 when Ω counted the rates'
/// growth once; a singular slowing (φ̇ ∝ 1/(t + d)) is now counted as one.
#[test]
fn a_light_coin_braked_within_its_first_sample_verifies() {
    let dir = tempfile::tempdir().unwrap();
    // θ0 as the sweep that found it drew it.
    let args = [
        "--set",
        "body.mass=1e-6",
        "--set",
        "body.dissipation={model=\"viscous\",coefficient=0.1}",
        "--set",
        "initial.theta=0.10693772645821076",
    ];
    let (r, c, _) = constraint_of(
        dir.path(),
        "wobble",
        &[&args[..], &["--duration", "3"]].concat(),
    );
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    assert_eq!(c.status, Status::Pass, "{}", show(&r));
}

/// A coin at rest almost upright (θ₀ = 1e-200, physics §12 follows θ₀ down to 1e-300) does move: |ω|
/// ~ 1e-198 grows to ~1e-192 by t = 20. |ω| formed through its squares underflowed to 0, and `constraint`
/// skipped it as "ω = 0 throughout" (CANNOT VERIFY); the residual's norm underflowed to 0 in the same way.
/// Judged, it passes; a moved position still fails (the negative control of the judging).
#[test]
fn a_coin_at_rest_a_hair_from_upright_moves_and_is_judged() {
    let dir = tempfile::tempdir().unwrap();
    for theta in ["1e-200", "1e-310"] {
        let args = [
            "--set",
            &format!("initial.theta={theta}"),
            "--set",
            "initial.omega=[0.0, 0.0, 0.0]",
            "--duration",
            "20",
        ];
        let (r, c, path) = constraint_of(dir.path(), "wobble", &args);
        assert_eq!(r.exit_code, 0, "θ0 = {theta}: {}", show(&r));
        assert_eq!(c.status, Status::Pass, "θ0 = {theta}: {}", show(&r));
        assert!(c.value.unwrap() > 0.0, "{}", show(&r));
        if theta == "1e-200" {
            let moved = dir.path().join("moved.mcap");
            rewrite(&path, &moved, |e| {
                if e.topic == "/coin/position" && e.index == 1500 {
                    let v: serde_json::Value = serde_json::from_slice(e.data).unwrap();
                    let z = v["z"].as_f64().unwrap(); // the coin tips over in the y-z plane
                    nudge(e.data, "z", z * 1e-3);
                }
            });
            let r = verify_file(&moved, &Options::default());
            assert_eq!(
                status(&r, CheckId::Constraint),
                Status::Fail,
                "{}",
                show(&r)
            );
        }
    }
}

#[test]
fn verify_flags_a_log_with_one_omega_sample_changed_by_1e_5() {
    let r = tampered("wobble", |e| {
        if e.topic == "/coin/omega" && e.index == 500 {
            nudge(e.data, "z", 1e-5);
        }
    });
    // δE ≈ (Ma² + I_Z) ω_Z δω_Z = 1.5e-5 ω_Z, relative to E0 ≈ 2.6 (ω_Z ≈ 1.5).
    assert_fails(&r, CheckId::Energy, 1e-6, 1e-5);
    assert_eq!(r.check(CheckId::Constraint).unwrap().status, Status::Fail);
}

#[test]
fn verify_flags_a_steady_log_with_theta_shifted_by_1e_5_throughout() {
    let r = tampered("circle-plus", |e| {
        if e.topic == "/coin/angles" {
            nudge(e.data, "theta", 1e-5);
        }
    });
    assert_fails(&r, CheckId::Steady, 0.9e-5, 1e-4);
}

#[test]
fn negative_control_numbers_appear_in_the_json_output() {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "wobble", &[]);
    let bad = dir.path().join("bad.mcap");
    rewrite(&good, &bad, |e| {
        if e.topic == "/coin/position" && e.index == 500 {
            nudge(e.data, "x", 1e-4);
        }
    });
    let (code, stdout, stderr) = coin_log_text(&["verify", "--json", bad.to_str().unwrap()]);
    assert_eq!(code, 1, "{stdout}{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let checks = v["files"][0]["checks"].as_array().unwrap();
    let c = checks.iter().find(|c| c["id"] == "constraint").unwrap();
    println!("{c}");
    assert_eq!(c["status"], "fail");
    assert!(c["value"].as_f64().unwrap() > 1e-3);
    assert_eq!(v["files"][0]["exit_code"], 1);
}

/// `--channels energy`: E cannot be recomputed (no ω, θ) and no motion check can run. No check fails, so
/// the verdict is "cannot verify" (exit 1, the code the contract gave such a file), each skipped check
/// keeps its reason, and the file's `problem` names the required checks that could not run.
#[test]
fn a_log_on_which_no_physics_check_can_run_cannot_be_verified() {
    let spec = Spec {
        channels: vec![coin_log::format::Channel::Energy],
        ..wobble()
    };
    let (_dir, path) = recorded(&spec, "energy-only.mcap");
    let r = verify_file(&path, &Options::default());
    println!("{}", show(&r));
    assert_eq!(r.exit_code, 1);
    assert_eq!(r.verdict, Verdict::CannotVerify);
    let energy = r.check(CheckId::Energy).unwrap();
    assert_eq!(energy.status, Status::Skip);
    assert_eq!(
        energy.reason,
        "no sample has both /coin/omega and /coin/angles, so E cannot be recomputed: record the channels omega and angles"
    );
    let constraint = r.check(CheckId::Constraint).unwrap();
    assert_eq!(constraint.status, Status::Skip);
    assert_eq!(status(&r, CheckId::Integrity), Status::Pass);
    assert_eq!(
        r.problem.as_deref(),
        Some("cannot verify: the required checks energy, constraint or steady (the motion) could not run (each check's reason says why and what to record)")
    );
    let (code, out, err) = coin_log_text(&["verify", path.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(
        out.starts_with(&format!("{}: CANNOT VERIFY (exit 1)\n", path.display())),
        "{out}"
    );
    assert_eq!(
        err,
        format!("error: {}: {}\n", path.display(), r.problem.unwrap())
    );
}

#[test]
fn the_json_output_has_exactly_the_contract_fields() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "wobble", &[]);
    let (code, stdout, _) = coin_log_text(&["verify", "--json", path.to_str().unwrap()]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let keys = |v: &serde_json::Value| {
        let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
        k.sort();
        k
    };
    assert_eq!(keys(&v), ["files"]);
    // The contract's fields plus `peak_rss_bytes`, `verdict` and `problem`, allowed extensions.
    assert_eq!(
        keys(&v["files"][0]),
        [
            "checks",
            "exit_code",
            "path",
            "peak_rss_bytes",
            "problem",
            "verdict"
        ]
    );
    assert_eq!(v["files"][0]["verdict"], "ok");
    assert_eq!(v["files"][0]["problem"], serde_json::Value::Null);
    let ids: Vec<&str> = v["files"][0]["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            assert_eq!(keys(c), ["id", "reason", "status", "tolerance", "value"]);
            c["id"].as_str().unwrap()
        })
        .collect();
    assert_eq!(
        ids,
        [
            "integrity",
            "energy",
            "invariants",
            "steady",
            "constraint",
            "consistency",
            "validity",
            "nutation"
        ]
    );
}

#[test]
fn every_built_in_scene_recorded_with_default_settings_verifies() {
    let dir = tempfile::tempdir().unwrap();
    let names = scene_names();
    assert!(names.len() >= 10, "scenes: {names:?}");
    for name in &names {
        let path = record_scene(dir.path(), name, &[]);
        let r = verify_file(&path, &Options::default());
        println!("{name}:\n{}", show(&r));
        assert_eq!(r.exit_code, 0, "{name}\n{}", show(&r));
    }
}

/// `high-spin` (ω_Z = 50) recorded at 100 samples per unit instead of its 1000: h·|ω| = 0.5, the
/// constraint's finite difference does not resolve the motion, and verify must fail the file (no motion
/// check ran) rather than pass it.
#[test]
fn an_undersampled_recording_fails_because_no_motion_check_can_run() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "high-spin", &["--rate", "100"]);
    let r = verify_file(&path, &Options::default());
    println!("high-spin at rate 100:\n{}", show(&r));
    assert_eq!(r.exit_code, 1, "{}", show(&r));
    let c = r.check(CheckId::Constraint).unwrap();
    assert!(
        c.reason
            .contains("the sampling does not resolve the motion"),
        "{}",
        c.reason
    );
}

#[test]
fn recordings_by_every_integrator_pass_at_default_tolerances() {
    for &method in coin_log::integrate::Method::ALL {
        for (name, spec) in [("wobble", wobble()), ("circle", steady_circle())] {
            let spec = Spec { method, ..spec };
            let (_dir, path) = recorded(&spec, "run.mcap");
            let r = verify_file(&path, &Options::default());
            println!("{method} {name}:\n{}", show(&r));
            assert_eq!(r.exit_code, 0, "{method} {name}\n{}", show(&r));
        }
    }
}

/// Writes a long recording for measuring `verify` by hand (not a timed test):
/// `VERIFY_LONG=/tmp/long.mcap cargo test --release --test it -- --ignored verify::write_a_long_recording`,
/// then `/usr/bin/time -v target/release/coin-log verify /tmp/long.mcap`.
#[test]
#[ignore = "writes a large file for manual throughput measurement"]
fn write_a_long_recording() {
    let path = std::env::var("VERIFY_LONG").unwrap_or_else(|_| "/tmp/long.mcap".into());
    let duration: f64 = std::env::var("VERIFY_LONG_DURATION")
        .ok()
        .and_then(|d| d.parse().ok())
        .unwrap_or(1000.0);
    let compression = match std::env::var("VERIFY_LONG_COMPRESSION").as_deref() {
        Ok("none") => None,
        Ok("lz4") => Some(mcap::Compression::Lz4),
        _ => Some(mcap::Compression::Zstd),
    };
    let spec = Spec {
        duration,
        rate: 1000.0,
        compression,
        ..wobble()
    };
    record(&spec, std::path::Path::new(&path));
    let r = verify_file(std::path::Path::new(&path), &Options::default());
    println!("{}", show(&r));
}

/// Copies `wobble` recorded by `coin-log record` with schema `name` embedded as `edit` changed it (the JSON
/// of this tool's schema file), every message unchanged; verifies the copy and prints the report.
fn with_other_schema(name: &str, edit: impl Fn(&mut serde_json::Value)) -> FileReport {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "wobble", &[]);
    let other = dir.path().join("other-version.mcap");
    let schema_of = |n: &str| {
        let ours = coin_log::format::schema_bytes(n).unwrap().to_vec();
        if n != name {
            return ours;
        }
        let mut v: serde_json::Value = serde_json::from_slice(&ours).unwrap();
        edit(&mut v);
        let theirs = serde_json::to_vec_pretty(&v).unwrap();
        assert_ne!(theirs, ours, "the edit must change the schema");
        theirs
    };
    rewrite_with_schemas(&good, &other, &schema_of, |_| {});
    let r = verify_file(&other, &Options::default());
    println!("{}", show(&r));
    r
}

/// Asserts the exit code, the integrity status and that the integrity reason contains `text`.
fn assert_integrity(r: &FileReport, exit_code: u8, status: Status, text: &str) {
    let integrity = r.check(CheckId::Integrity).unwrap();
    assert_eq!(r.exit_code, exit_code, "{}", show(r));
    assert_eq!(integrity.status, status, "{}", show(r));
    assert!(integrity.reason.contains(text), "{}", integrity.reason);
}

#[test]
fn a_schema_of_another_version_differing_only_in_descriptions_is_noted_and_the_file_verifies() {
    let r = with_other_schema("coin_log.Energy", |v| {
        v["description"] = "Energy, as an older coin-log described it.".into();
        v["properties"]["total"]["description"] = "E = T + V.".into();
    });
    assert_integrity(
        &r,
        0,
        Status::Pass,
        "schema `coin_log.Energy` is another version than this tool's; the messages conform to it",
    );
}

#[test]
fn a_schema_of_another_version_requiring_a_field_the_messages_lack_fails_integrity() {
    let r = with_other_schema("coin_log.Energy", |v| {
        v["properties"]["power"] = serde_json::json!({"type": "number"});
        v["required"].as_array_mut().unwrap().push("power".into());
    });
    assert_integrity(&r, 1, Status::Fail, "schema `coin_log.Energy` is another version than this tool's and requires `power`, which the messages lack");
}

#[test]
fn a_schema_of_another_version_forbidding_a_field_the_messages_have_fails_integrity() {
    let r = with_other_schema("coin_log.Angles", |v| {
        v["properties"].as_object_mut().unwrap().remove("psi");
        v["required"].as_array_mut().unwrap().retain(|f| f != "psi");
    });
    assert_integrity(&r, 1, Status::Fail, "schema `coin_log.Angles` is another version than this tool's and forbids `psi`, which the messages have");
}

#[test]
fn a_schema_of_another_version_with_an_extra_optional_field_still_validates_the_messages() {
    let r = with_other_schema("coin_log.Energy", |v| {
        v["properties"]["power"] = serde_json::json!({"type": "number"});
        v["required"].as_array_mut().unwrap().retain(|f| f != "t");
    });
    assert_integrity(
        &r,
        0,
        Status::Pass,
        "schema `coin_log.Energy` is another version than this tool's; the messages conform to it",
    );
}

#[test]
fn a_schema_of_another_version_typing_a_field_as_a_string_fails_integrity() {
    let r = with_other_schema("coin_log.AngularVelocity", |v| {
        v["properties"]["z"]["type"] = "string".into();
    });
    assert_integrity(&r, 1, Status::Fail, "schema `coin_log.AngularVelocity` is another version than this tool's and types `z` as \"string\", the messages have a number");
}

/// The stored messages of `topic` in `path`, as JSON, in order.
fn stored(path: &std::path::Path, topic: &str) -> Vec<serde_json::Value> {
    read_messages(path)
        .into_iter()
        .filter(|(t, _, _)| t == topic)
        .map(|(_, _, v)| v)
        .collect()
}

/// Asserts that `id` is the one check that fails, with a value within `rel` of `expected`, and that
/// every other check has the status it had on the untouched file.
fn assert_only_failure(r: &FileReport, clean: &FileReport, id: CheckId, expected: f64, rel: f64) {
    let c = r.check(id).unwrap();
    let value = c.value.unwrap();
    println!(
        "{id}: measured {value:e}, expected {expected:e} (to {rel:e} relative), tolerance {:e}",
        c.tolerance.unwrap()
    );
    assert_eq!(c.status, Status::Fail, "{}", show(r));
    assert!(
        (value - expected).abs() <= rel * expected,
        "{id}: measured {value:e}, expected {expected:e} ± {rel:e} relative"
    );
    for &other in CheckId::ALL.iter().filter(|o| **o != id) {
        assert_eq!(
            status(r, other),
            status(clean, other),
            "{other}\n{}",
            show(r)
        );
    }
    assert_eq!((r.exit_code, r.verdict), (1, Verdict::Failed));
}

/// A real `wobble` recording and a copy with `edit` applied; both verified.
fn edited(
    edit: impl FnMut(Edit<'_>),
) -> (
    tempfile::TempDir,
    std::path::PathBuf,
    FileReport,
    FileReport,
) {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "wobble", &[]);
    let clean = verify_file(&good, &Options::default());
    assert_eq!(clean.verdict, Verdict::Ok, "{}", show(&clean));
    let bad = dir.path().join("bad.mcap");
    rewrite(&good, &bad, edit);
    let r = verify_file(&bad, &Options::default());
    println!("{}", show(&r));
    (dir, good, clean, r)
}

/// Negative control of `invariants`: one stored C1 nudged by 1e-9 disagrees with C1 recomputed from θ, ω
/// by 1e-9 / (|C1_0| + |C2_0|), which the 1e-12 recomputation tolerance must catch.
#[test]
fn verify_flags_a_log_with_one_stored_c1_nudged_by_1e_9() {
    let delta = 1e-9;
    let (_dir, good, clean, r) = edited(|e| {
        if e.topic == "/coin/invariants" && e.index == 500 {
            nudge(e.data, "c1", delta);
        }
    });
    let first = &stored(&good, "/coin/invariants")[0];
    let scale = first["c1"].as_f64().unwrap().abs() + first["c2"].as_f64().unwrap().abs();
    // The nudged value is rounded to a double near |C1| ≲ 1: δ is kept to ~1e-16 absolute, 1e-6 relative.
    assert_only_failure(&r, &clean, CheckId::Invariants, delta / scale, 1e-6);
    assert!(r
        .check(CheckId::Invariants)
        .unwrap()
        .reason
        .starts_with("agreement is the worst measure"));
}

/// Negative control of `consistency`: a stored quaternion component nudged by 1e-9 no longer equals the
/// rotation of the stored angles (component difference 1e-9, tolerance 1e-12).
#[test]
fn verify_flags_a_log_with_one_quaternion_inconsistent_with_the_angles() {
    let delta = 1e-9;
    let (_dir, _good, clean, r) = edited(|e| {
        if e.topic == "/coin/quaternion" && e.index == 500 {
            nudge(e.data, "w", delta);
        }
    });
    assert_only_failure(&r, &clean, CheckId::Consistency, delta, 1e-6);
    assert!(r
        .check(CheckId::Consistency)
        .unwrap()
        .reason
        .starts_with("worst: quaternion;"));
}

/// Negative control of `consistency`: a stored contact point moved by 1e-9 is no longer the centre plus
/// c; the measure is relative to max(a, |x|, |z|) of the centre at that sample.
#[test]
fn verify_flags_a_log_with_one_contact_point_inconsistent_with_the_angles() {
    let delta = 1e-9;
    let (_dir, good, clean, r) = edited(|e| {
        if e.topic == "/coin/contact" && e.index == 500 {
            nudge(e.data, "x", delta);
        }
    });
    let centre = &stored(&good, "/coin/position")[500];
    let scale = [
        1.0,
        centre["x"].as_f64().unwrap().abs(),
        centre["z"].as_f64().unwrap().abs(),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    assert_only_failure(&r, &clean, CheckId::Consistency, delta / scale, 1e-6);
    assert!(r
        .check(CheckId::Consistency)
        .unwrap()
        .reason
        .starts_with("worst: contact;"));
}

/// Negative control of `validity`, N < 0: the lift-off release (θ0 = 0.2, no spin) integrated 0.3 time
/// units past the point where N reaches 0 (t ≈ 2.674), with no event to end it: the file says the run
/// completed, so the negative N is not at a recorded event. The value is -min N/(Mg) of the stored
/// reactions (the same numbers, the same division).
#[test]
fn verify_flags_a_log_whose_normal_force_goes_negative_without_a_lift_off_event() {
    let spec = Spec {
        initial: coin_log::model::State {
            theta: 0.2,
            ..Default::default()
        },
        duration: 2.974,
        events: false,
        ..wobble()
    };
    let (_dir, path) = recorded(&spec, "past-lift-off.mcap");
    let clean_spec = Spec {
        events: true,
        ..spec.clone()
    };
    let (_clean_dir, clean_path) = recorded(&clean_spec, "lift-off.mcap");
    let clean = verify_file(&clean_path, &Options::default());
    println!("stopped at the event:\n{}", show(&clean));
    assert_eq!(clean.verdict, Verdict::Ok);
    let r = verify_file(&path, &Options::default());
    println!("integrated past it:\n{}", show(&r));
    let min_normal = stored(&path, "/coin/reaction")
        .iter()
        .map(|m| m["normal"].as_f64().unwrap())
        .fold(f64::INFINITY, f64::min);
    assert!(min_normal < -1e-3, "min N = {min_normal}");
    // serde_json's default float parsing (used here) may be an ulp off; verify reads the text correctly
    // rounded.
    assert_only_failure(&r, &clean, CheckId::Validity, -min_normal, 1e-15);
}

/// Negative control of `validity`, |F| > μN: a nutating coin whose metadata gives μ halfway between its
/// friction ratio at t = 0 (so the scene is one `record` accepts) and the largest it reaches, recorded
/// without a slip event: the value is max(|F| - μN)/(Mg) of the stored reactions.
#[test]
fn verify_flags_a_log_whose_friction_exceeds_mu_n_without_a_slip_event() {
    // The built-in wobble's state: F/N swings from 0.35 at t = 0 to 0.41 as it nutates.
    let nutating = Spec {
        initial: coin_log::model::State {
            theta: 0.5,
            omega_x: 0.3,
            omega_y: 0.2,
            omega_z: 1.5,
            ..Default::default()
        },
        ..wobble()
    };
    let (_dir, probe) = recorded(&nutating, "probe.mcap");
    let ratios: Vec<f64> = stored(&probe, "/coin/reaction")
        .iter()
        .map(|m| m["friction"].as_f64().unwrap() / m["normal"].as_f64().unwrap())
        .collect();
    let largest = ratios.iter().copied().fold(0.0, f64::max);
    assert!(largest > 1.1 * ratios[0], "{} against {largest}", ratios[0]);
    let mu = 0.5 * (ratios[0] + largest);
    let spec = Spec {
        friction: Some(mu),
        events: false,
        ..nutating
    };
    let (_dir2, path) = recorded(&spec, "slipping.mcap");
    let clean = verify_file(&probe, &Options::default());
    let r = verify_file(&path, &Options::default());
    let excess = stored(&path, "/coin/reaction")
        .iter()
        .map(|m| m["friction"].as_f64().unwrap() - mu * m["normal"].as_f64().unwrap())
        .fold(f64::NEG_INFINITY, f64::max);
    println!(
        "μ = {mu} (F/N from {} to {largest}), max |F| - μN = {excess}",
        ratios[0]
    );
    assert!(excess > 1e-3);
    // An ulp of each parsed number (see above), amplified by the cancellation in |F| - μN.
    assert_only_failure(&r, &clean, CheckId::Validity, excess, 1e-13);
}

/// `record` warns before simulating when verify will not be able to judge the recording, with the fix;
/// verify then says CANNOT VERIFY and its constraint check suggests the same rate.
#[test]
fn record_warns_when_verify_cannot_judge_the_recording_and_verify_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("undersampled.mcap");
    let (code, _, err) = coin_log_text(&[
        "record",
        "high-spin",
        "--rate",
        "100",
        "--duration",
        "1",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let warning = "warning: verify will not be able to judge this recording: neither `constraint` nor `steady` will run, so the motion will not be verified: `steady` does not apply (the scene does not start on an unperturbed steady motion), and `constraint` will find no window the sampling resolves: at 100 samples per time unit, h·Ω = 0.5 (Ω = max(|ω|, |φ̇|) = 50 at t = 0), and the finite difference's error 4(hΩ)^8/630 = 2.5e-5 exceeds a tenth of the residual tolerance 2.0e-7; raise --rate to at least 266\n";
    assert_eq!(err, warning);
    let (code, out, err) = coin_log_text(&["verify", path.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("CANNOT VERIFY (exit 1)"), "{out}");
    assert!(
        out.contains("record at a higher --rate (at least 266)"),
        "{out}"
    );
    assert!(
        err.contains(
            "cannot verify: the required check constraint or steady (the motion) could not run"
        ),
        "{err}"
    );
    // The default rate of the scene raises no warning.
    let (code, _, err) = coin_log_text(&[
        "record",
        "high-spin",
        "--duration",
        "1",
        "-o",
        path.to_str().unwrap(),
        "--overwrite",
    ]);
    assert_eq!((code, err.as_str()), (0, ""));
}

/// A run that an event ends early has fewer samples and a tighter residual tolerance than its duration
/// promised: `record` asks again once it knows. Before, Euler's disk under a viscous couple of κ = 1e-4
/// fell flat after 0.084 of its 2000 time units with no warning at all, and verify said CANNOT VERIFY.
#[test]
fn record_warns_after_a_run_an_event_ended_too_early_for_verify_to_judge() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("viscous.mcap");
    let (code, _, err) = coin_log_text(&[
        "record",
        "euler-disk",
        "--set",
        "body.dissipation.model=\"viscous\"",
        "--set",
        "body.dissipation.coefficient=1e-4",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        err,
        "warning: verify will not be able to judge this recording, which ended at t = 0.08404771017188632 \
         before its duration: neither `constraint` nor `steady` will run, so the motion will not be \
         verified: `steady` does not apply (the scene does not start on an unperturbed steady motion), \
         and `constraint` will find no window the sampling resolves: at 400 samples per time unit, \
         h·Ω = 0.221 (Ω = max(|ω|, |φ̇|) + |d ln Ω/dt| = 72.6 + 16 = 88.6 at t = 0), and the finite \
         difference's error \
         4(hΩ)^8/630 = 3.7e-8 exceeds a tenth of the residual tolerance 2.4e-7; raise --rate to at \
         least 471\n"
    );
    let (code, out, _) = coin_log_text(&["verify", path.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("CANNOT VERIFY (exit 1)"), "{out}");
    // At the rate it names, verify judges the run (and record says nothing).
    let (code, _, err) = coin_log_text(&[
        "record",
        "euler-disk",
        "--set",
        "body.dissipation.model=\"viscous\"",
        "--set",
        "body.dissipation.coefficient=1e-4",
        "--rate",
        "471",
        "-o",
        path.to_str().unwrap(),
        "--overwrite",
    ]);
    assert_eq!((code, err.as_str()), (0, ""));
    let (code, out, _) = coin_log_text(&["verify", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
}

#[test]
fn the_json_names_are_the_names() {
    for v in Verdict::ALL {
        assert_eq!(serde_json::to_value(v).unwrap(), v.name());
    }
    for c in CheckId::ALL {
        assert_eq!(serde_json::to_value(c).unwrap(), c.name());
    }
    for s in Status::ALL {
        assert_eq!(serde_json::to_value(s).unwrap(), s.name());
    }
}

fn preset_scene(name: &str, sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(ToString::to_string).collect();
    let file = scene::file_with_sets(&presets::preset(name).unwrap(), &sets).unwrap();
    scene::resolve(&file, &FlagOverrides::default()).unwrap()
}

#[test]
fn every_built_in_scene_as_given_can_be_verified() {
    for name in presets::NAMES {
        let s = preset_scene(name, &[]);
        assert_eq!(coverage(&s), Vec::<String>::new(), "{name}");
    }
}

#[test]
fn missing_channels_are_named_with_the_fix() {
    let s = preset_scene("wobble", &["record.channels=[\"energy\"]"]);
    assert_eq!(
        coverage(&s),
        [
            "`energy` will not run: it recomputes E from ω and θ, and omega and angles are not \
             recorded; add channels omega, angles",
            "neither `constraint` nor `steady` will run, so the motion will not be verified: \
             `steady` does not apply (the scene does not start on an unperturbed steady motion), and \
             `constraint` needs the centre's positions with ω and θ, and omega and angles and \
             position are not recorded; add channels omega, angles, position"
        ]
    );
    // A steady scene is judged by `steady` without positions.
    let s = preset_scene("circle-plus", &["record.channels=[\"omega\", \"angles\"]"]);
    assert_eq!(coverage(&s), Vec::<String>::new());
}

/// Ω of the forecast is the rate plus its relative change at t = 0; a strong couple's braking made Ω =
/// 1.23e8 on `euler-disk` (|ω| = 14.4, |φ̇| = 72.6), which the warning called max(|ω|, |φ̇|). It names both
/// terms now, printed as three digits (not 72.60000000000001).
#[test]
fn a_forecast_rate_made_of_the_braking_says_so() {
    let s = preset_scene(
        "euler-disk",
        &[
            "body.dissipation={model=\"power-law\",coefficient=1e-12,m=10,k=0}",
            "run.rate=4000",
        ],
    );
    let c = coverage(&s);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(
        c[0].contains("(Ω = max(|ω|, |φ̇|) + |d ln Ω/dt| = 72.6 + 123000000 = 123000000 at t = 0)"),
        "{}",
        c[0]
    );
}

#[test]
fn a_rate_that_does_not_resolve_the_motion_is_named_with_the_rate_that_does() {
    let s = preset_scene("high-spin", &["run.rate=100"]);
    let c = coverage(&s);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(
        c[0].contains("at 100 samples per time unit, h·Ω = 0.5 (Ω = max(|ω|, |φ̇|) = 50 at t = 0)"),
        "{}",
        c[0]
    );
    let fix = c[0].rsplit("raise --rate to at least ").next().unwrap();
    let fix: f64 = fix.parse().unwrap();
    // The suggested rate is enough, and a rate 1% lower would not be.
    let s = preset_scene("high-spin", &[&format!("run.rate={fix}")]);
    assert_eq!(coverage(&s), Vec::<String>::new());
    let s = preset_scene("high-spin", &[&format!("run.rate={}", fix * 0.99)]);
    assert_eq!(coverage(&s).len(), 1);
}

/// The rate advised is one `record` accepts. Euler's disk under a viscous κ = 1e6 changes ω at 1.6e11 a
/// time unit: `record` advised `--rate` 6.39e11, which it then refused (samples 1 ns apart allow at most
/// ~1e9), and now says no rate resolves the start and what can help. Under κ = 10 over 1e5 time units
/// the rate it needs, 1.6e7, is allowed but not for so long (1e11 samples at most): the advice shortens
/// the duration too, and followed it is accepted and resolves the motion.
#[test]
fn the_rate_advised_to_resolve_the_motion_is_one_record_accepts() {
    let viscous =
        |kappa: &str| format!("body.dissipation={{model=\"viscous\",coefficient={kappa}}}");
    let s = preset_scene("euler-disk", &[&viscous("1e6"), "run.duration=1"]);
    let c = coverage(&s);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(!c[0].contains("raise --rate"), "{}", c[0]);
    assert!(
        c[0].ends_with(
            "no --rate resolves the motion as it starts: that takes at least 639000000000 samples per \
             time unit, and samples 1 ns apart (the log-time resolution) allow at most 999999333; slow \
             the motion, or express the scene in a shorter time unit (a motion that slows down later \
             may still be judged where a rate allowed resolves it)"
        ),
        "{}",
        c[0]
    );
    let s = preset_scene("euler-disk", &[&viscous("10"), "run.duration=1e5"]);
    let c = coverage(&s);
    assert_eq!(c.len(), 1, "{c:?}");
    let fix = c[0].rsplit("raise --rate to at least ").next().unwrap();
    let (rate, duration) = fix
        .split_once(" and shorten --duration to at most ")
        .unwrap();
    let duration = duration.split_once(' ').unwrap().0;
    let s = preset_scene(
        "euler-disk",
        &[
            &viscous("10"),
            &format!("run.duration={duration}"),
            &format!("run.rate={rate}"),
        ],
    );
    assert_eq!(coverage(&s), Vec::<String>::new());
}

/// A steady circle kicked by a small δω_X nutates with a small amplitude, and the integrator keeps ω to
/// ε of the state's scale, not of that amplitude: the turning points are timed no better than its error
/// over ω_X's slope. Before, `circle-plus` kicked by 1e-5 (dop853 at its defaults, its ω within 1.6e-11
/// of an independent solution) FAILED `nutation` at 2.6e-8 against 1e-8, and by 1e-7 at 5e-5, although
/// `record` promised it would verify. The period is still judged where the timing allows (1e-4), and a
/// too small nutation is skipped with the reason; a clock running 1e-6 fast still fails (analyse.rs).
#[test]
fn a_small_nutation_about_a_steady_circle_is_judged_within_what_the_recording_can_time() {
    let dir = tempfile::tempdir().unwrap();
    for (kick, judged) in [("1e-5", false), ("1e-7", false), ("1e-4", true)] {
        let set = format!("initial.perturbation={{omega=[{kick},0,0]}}");
        let path = record_scene(dir.path(), "circle-plus", &["--set", &set]);
        let r = verify_file(&path, &Options::default());
        println!("kick {kick}\n{}", show(&r));
        assert_eq!(r.exit_code, 0, "kick {kick}\n{}", show(&r));
        let c = r.check(CheckId::Nutation).unwrap();
        if judged {
            assert_eq!(c.status, Status::Pass, "kick {kick}: {c:?}");
            assert!(c.reason.contains("+ timing "), "{}", c.reason);
        } else {
            assert_eq!(c.status, Status::Skip, "kick {kick}: {c:?}");
            assert!(
                c.reason.contains("too small for the recorded accuracy"),
                "{}",
                c.reason
            );
        }
    }
}

/// A coin upright at rest (θ = 0, ω = 0) is an equilibrium: ω stays 0, the constraint check finds
/// nothing moving, and verify cannot verify. Before, `record` gave no warning for it (the coverage
/// prediction looked only at channels and sampling); the steady form of the same state is judged by
/// `steady` and gets none, and a coin given any tilt or spin gets none either.
#[test]
fn a_coin_upright_at_rest_is_warned_of_and_verify_cannot_verify_it() {
    let at_rest = ["initial.theta=0.0", "initial.omega=[0.0, 0.0, 0.0]"];
    let s = preset_scene("wobble", &at_rest);
    let c = coverage(&s);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(
        c[0].contains("the coin starts upright at rest (θ = 0, ω = 0)"),
        "{}",
        c[0]
    );
    let s = preset_scene("straight", &["initial.steady.omega_z=0.0"]);
    assert_eq!(coverage(&s), Vec::<String>::new());
    let s = preset_scene(
        "wobble",
        &["initial.theta=0.0", "initial.omega=[0.0, 0.0, 1.0]"],
    );
    assert_eq!(coverage(&s), Vec::<String>::new());
    // What verify says of the recording.
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(
        dir.path(),
        "wobble",
        &["--set", at_rest[0], "--set", at_rest[1], "--duration", "1"],
    );
    let r = verify_file(&path, &Options::default());
    assert_eq!(r.verdict, Verdict::CannotVerify, "{}", show(&r));
}

/// A couple strong enough to change the rates within a sample from the first instant: `euler-disk` with
/// `power-law` m = 1, k = 5, κ = 1e-3 lands flat after 0.077 s, and the constraint check, which adds each
/// window's relative rate of change to its rate, resolves none of its windows at 400 Hz: verify cannot
/// verify. Before, the prediction took only Ω₀ = max(|ω₀|, |φ̇₀|) and `record` gave no warning; it now adds
/// |d ln Ω/dt| at t = 0 from the scene's equations, as the check does.
#[test]
fn a_couple_that_brakes_within_a_sample_from_the_start_is_warned_of() {
    let law = "body.dissipation={model=\"power-law\",coefficient=1e-3,m=1,k=5}";
    let s = preset_scene("euler-disk", &[law]);
    let c = coverage(&s);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(
        c[0].contains("will find no window the sampling resolves"),
        "{}",
        c[0]
    );
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "euler-disk", &["--set", law]);
    let r = verify_file(&path, &Options::default());
    assert_eq!(r.verdict, Verdict::CannotVerify, "{}", show(&r));
    // The scene as given is unchanged.
    assert_eq!(
        coverage(&preset_scene("euler-disk", &[])),
        Vec::<String>::new()
    );
}

/// verify's own advice for a file whose sampling resolves no window is a rate `record` accepts, or says
/// none is: `wobble` spinning at ω_Z = 5e8, sampled 1e6 a time unit, was told "at least 2.66e9".
#[test]
fn verify_advises_no_rate_beyond_the_one_nanosecond_base() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(
        dir.path(),
        "wobble",
        &[
            "--set",
            "initial.omega=[0,0,5e8]",
            "--duration",
            "2e-5",
            "--rate",
            "1e6",
        ],
    );
    let r = verify_file(&path, &Options::default());
    let c = r
        .checks
        .iter()
        .find(|c| c.id == CheckId::Constraint)
        .unwrap();
    assert_eq!(c.status, Status::Skip, "{}", c.reason);
    assert!(!c.reason.contains("--rate (at least"), "{}", c.reason);
    assert!(
        c.reason.contains("no --rate resolves it: that takes at least 2.66e9 samples per time unit, and samples 1 ns apart (the log-time resolution) allow at most 999999999"),
        "{}",
        c.reason
    );
}
