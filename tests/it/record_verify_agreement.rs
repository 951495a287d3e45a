//! `record` promises only what `verify` will accept. For the accepted corners of every integrator (the
//! loosest and tightest rtol/atol, the largest and smallest fixed steps within the limits, the lowest and
//! highest rates) `record`'s word, its warnings before the run, and the `expected_to_fail` of its
//! summary and metadata, is checked against `verify`'s verdict with its default tolerances: a run
//! promised to verify verifies, every check that fails was named in advance, and a file verify cannot
//! judge was warned about. Before, `--rtol 1e-3 --atol 1e-3`, dopri5 at 1e-3, `rk4 --step 0.11 --rate 1`
//! and 1e8 steps of rk4 recorded without a word and failed verify, and so did dop853 at rtol 1e-7 (its
//! dense output's velocity errs by 1.67e-6 against the ceiling 1e-6); 1000 time units at rtol 1e-6 failed
//! `nutation`, which was not named. The table is printed.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{coin_log, read_back};
use coin_log::format::{ResultMetadata, RESULT_METADATA_NAME};
use coin_log::scene::limits::max_rate;
use coin_log::verify::CheckId;
use std::collections::BTreeSet;
use std::path::Path;

/// The largest step `record` accepts for `integrator` on `wobble` (at rate 1/step), read from the refusal
/// of a step of 1: "use step ≤ H".
fn largest_step(dir: &Path, integrator: &str) -> String {
    let out = coin_log(
        dir,
        &[
            "record",
            "wobble",
            "--dry-run",
            "--integrator",
            integrator,
            "--step",
            "1",
            "--rate",
            "1",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    let (_, tail) = err
        .split_once("use step ≤ ")
        .expect("the refusal names the largest step");
    tail.split_whitespace().next().unwrap().to_string()
}

/// What record said and verify found for one corner.
struct Row {
    case: String,
    cannot_judge_warned: bool,
    expected: BTreeSet<String>,
    verify_code: i32,
    failed: BTreeSet<String>,
}

impl Row {
    fn promised(&self) -> bool {
        !self.cannot_judge_warned && self.expected.is_empty()
    }

    fn word(&self) -> String {
        match (self.cannot_judge_warned, self.expected.is_empty()) {
            (false, true) => "verifies".into(),
            (true, true) => "cannot be judged".into(),
            (judge, false) => format!(
                "fails {}{}",
                self.expected.iter().cloned().collect::<Vec<_>>().join(","),
                if judge { " (and cannot be judged)" } else { "" }
            ),
        }
    }

    fn verdict(&self) -> String {
        match (self.verify_code, self.failed.is_empty()) {
            (0, _) => "pass".into(),
            (_, true) => "cannot verify".into(),
            (_, false) => format!(
                "fail {}",
                self.failed.iter().cloned().collect::<Vec<_>>().join(",")
            ),
        }
    }

    /// The promise held: every check that failed was named, and a file verify could not judge was warned
    /// about.
    fn assert_kept(&self) {
        assert_ne!(
            self.agreement(),
            "BROKEN PROMISE",
            "{}: {} / {}",
            self.case,
            self.word(),
            self.verdict()
        );
        assert!(
            self.failed.is_subset(&self.expected),
            "{}: verify failed {:?}, record expected {:?}",
            self.case,
            self.failed,
            self.expected
        );
        if self.verify_code != 0 && self.failed.is_empty() {
            assert!(
                self.cannot_judge_warned,
                "{}: cannot verify, not warned",
                self.case
            );
        }
    }

    fn agreement(&self) -> &'static str {
        match (self.promised(), self.verify_code == 0) {
            (true, true) | (false, false) => "agree",
            (false, true) => "warned, passed",
            (true, false) => "BROKEN PROMISE",
        }
    }
}

/// Records `wobble` with `flags` in `dir`, then verifies it.
fn corner(dir: &Path, case: String, flags: &[String]) -> Row {
    let mut args: Vec<String> = ["record", "wobble", "-o", "c.mcap", "--overwrite", "--json"]
        .map(String::from)
        .to_vec();
    args.extend_from_slice(flags);
    let out = coin_log(dir, &args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(0), "{case}: {err}");
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let expected: BTreeSet<String> = summary["expected_to_fail"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    // Each is one of verify's check ids (format::promise spells them; verify declares them).
    for id in &expected {
        assert!(
            id.parse::<CheckId>().is_ok(),
            "{case}: {id:?} is no check id"
        );
    }
    // The file is marked as the summary says.
    let file = read_back(&std::fs::read(dir.join("c.mcap")).unwrap());
    let result = ResultMetadata::from_map(&file.metadata[RESULT_METADATA_NAME].1).unwrap();
    let marked: BTreeSet<String> = result
        .expected_to_fail
        .as_deref()
        .map(|s| s.split(',').map(String::from).collect())
        .unwrap_or_default();
    assert_eq!(marked, expected, "{case}: metadata and summary agree");
    // What the summary expects, the warning before the run said (the same prediction from t = 0).
    assert_eq!(
        err.contains("verify is expected to refuse this recording"),
        !expected.is_empty(),
        "{case}: {err}"
    );
    let verify = coin_log(dir, &["verify", "c.mcap", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&verify.stdout).unwrap();
    let checks = report["files"][0]["checks"].as_array().unwrap();
    // `steady` is named only where verify runs it, on an unperturbed steady start: it was named on
    // wobble at rtol 1e-7, which is no steady motion. (Other checks may be skipped by what the file holds,
    // e.g. `constraint` at a rate that resolves no window, a case the promise names with its advice.)
    let steady = checks.iter().find(|c| c["id"] == "steady").unwrap();
    if steady["status"] == "skip" {
        assert!(
            !expected.contains("steady"),
            "{case}: steady is named, and skipped"
        );
    }
    let failed = checks
        .iter()
        .filter(|c| c["status"] == "fail")
        .map(|c| c["id"].as_str().unwrap().to_string())
        .collect();
    Row {
        case,
        cannot_judge_warned: err.contains("verify will not be able to judge this recording"),
        expected,
        verify_code: verify.status.code().unwrap(),
        failed,
    }
}

#[test]
fn record_warns_of_every_file_verify_refuses_at_the_corners_of_every_integrator() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |words: &[&str]| words.iter().map(|w| (*w).to_string()).collect::<Vec<_>>();
    let fast = max_rate(1e-3).floor().to_string();
    let few = "omega,angles,position,energy,invariants";
    let mut rows = Vec::new();
    for integrator in ["dop853", "dopri5"] {
        let i = |rest: &[&str]| [s(&["--integrator", integrator]), s(rest)].concat();
        for (case, flags) in [
            (
                "loosest rtol and atol",
                i(&["--rtol", "1e-3", "--atol", "1e-3"]),
            ),
            ("loosest rtol", i(&["--rtol", "1e-3"])),
            (
                "tightest rtol and atol",
                i(&["--rtol", "2.221e-15", "--atol", "1e-16"]),
            ),
            ("rtol 1e-6", i(&["--rtol", "1e-6", "--atol", "1e-9"])),
            ("rtol 1e-7", i(&["--rtol", "1e-7"])),
            (
                "1000 time units at rtol 1e-6",
                i(&[
                    "--rtol",
                    "1e-6",
                    "--atol",
                    "1e-9",
                    "--duration",
                    "1000",
                    "--rate",
                    "10",
                ]),
            ),
            ("defaults", i(&[])),
            ("lowest rate 0.1", i(&["--rate", "0.1"])),
            (
                "highest rate",
                i(&["--duration", "1e-3", "--rate", &fast, "--channels", few]),
            ),
        ] {
            rows.push(corner(d, format!("{integrator}: {case}"), &flags));
        }
    }
    for integrator in ["rk4", "gauss4"] {
        let largest = largest_step(d, integrator);
        let per_step = (1.0 / largest.parse::<f64>().unwrap()).to_string();
        let i = |rest: &[&str]| [s(&["--integrator", integrator]), s(rest)].concat();
        let mut cases = vec![
            (
                format!("largest step {largest}"),
                i(&["--step", &largest, "--rate", &per_step]),
            ),
            (
                "step 0.11 at rate 1".to_string(),
                i(&["--step", "0.11", "--rate", "1"]),
            ),
            ("defaults".to_string(), i(&[])),
            // 1e7 steps under a budget lowered to them; rk4 also at the default budget (1e8 steps) below.
            (
                "smallest step under budget 1e7".to_string(),
                i(&[
                    "--step",
                    "1e-7",
                    "--duration",
                    "1",
                    "--max-steps",
                    "10000000",
                ]),
            ),
            ("lowest rate 0.1".to_string(), i(&["--rate", "0.1"])),
            (
                "highest rate".to_string(),
                i(&["--duration", "1e-3", "--rate", &fast, "--channels", few]),
            ),
        ];
        if integrator == "rk4" {
            cases.push((
                "smallest step (1e8 steps)".to_string(),
                i(&["--step", "1e-10", "--duration", "0.01"]),
            ));
        }
        for (case, flags) in cases {
            rows.push(corner(d, format!("{integrator}: {case}"), &flags));
        }
    }
    println!(
        "{:<40} {:<52} {:<44} {}",
        "integrator: corner", "record's word", "verify's verdict", "agreement"
    );
    for r in &rows {
        println!(
            "{:<40} {:<52} {:<44} {}",
            r.case,
            r.word(),
            r.verdict(),
            r.agreement()
        );
    }
    for r in &rows {
        r.assert_kept();
    }
    // The negative control: the cases are among the warned, and the defaults among the promised.
    for case in [
        "dop853: loosest rtol and atol",
        "dopri5: loosest rtol",
        "dop853: rtol 1e-7",
        "rk4: step 0.11 at rate 1",
        "rk4: smallest step (1e8 steps)",
    ] {
        let r = rows.iter().find(|r| r.case == case).unwrap();
        assert!(
            !r.expected.is_empty() && r.verify_code != 0,
            "{case}: {} / {}",
            r.word(),
            r.verdict()
        );
    }
    for case in ["dop853: defaults", "rk4: defaults", "gauss4: defaults"] {
        let r = rows.iter().find(|r| r.case == case).unwrap();
        assert!(
            r.promised() && r.verify_code == 0,
            "{case}: {} / {}",
            r.word(),
            r.verdict()
        );
    }
}

/// A centre that starts far from the origin: its stored coordinates carry rounding of 2⁻⁵³ |x₀|, which
/// the constraint check's 8th-order difference over samples 0.01 apart amplifies past the tolerance.
/// Before, `--set initial.x=1e10` recorded without a word (expected_to_fail empty) and verify failed
/// `constraint` at 1.05e-4 against 1e-6 (dop853), 7e-4 against 2.4e-7 (rk4); near the origin nothing
/// changes.
#[test]
fn record_warns_when_the_centre_starts_too_far_from_the_origin_for_the_constraint() {
    let dir = tempfile::tempdir().unwrap();
    for r in &initial_corners(dir.path(), "x", &["1e3", "1e10"]) {
        println!("{:<24} {:<40} {}", r.case, r.word(), r.verdict());
        r.assert_kept();
        let far = r.case.ends_with("1e10");
        assert_eq!(r.expected.contains("constraint"), far, "{}", r.case);
        assert_eq!(r.verify_code == 0, !far, "{}: {}", r.case, r.verdict());
    }
}

/// `wobble` recorded by dop853 and rk4 with `initial.KEY` set to each of `values`, as corners named
/// `integrator: KEY0 = value`.
fn initial_corners(dir: &Path, key: &str, values: &[&str]) -> Vec<Row> {
    let mut rows = Vec::new();
    for integrator in ["dop853", "rk4"] {
        for value in values {
            let set = format!("initial.{key}={value}");
            let flags = ["--integrator", integrator, "--set", &set].map(String::from);
            rows.push(corner(
                dir,
                format!("{integrator}: {key}0 = {value}"),
                &flags,
            ));
        }
    }
    rows
}

/// A heading that starts (or grows) large: φ is rounded to 2⁻⁵³ |φ| at every step, which turns the
/// velocity the constraint check compares and shifts the heading advance the nutation check times.
/// Before, `--set initial.phi=1e12` recorded without a word and verify failed `constraint` (7e-4) and
/// `nutation` (0.08); rk4 failed `nutation` from φ₀ = 1e7. A heading within a turn changes nothing.
#[test]
fn record_warns_when_the_heading_is_too_large_for_its_rounding() {
    let dir = tempfile::tempdir().unwrap();
    let rows = initial_corners(dir.path(), "phi", &["3", "1e7", "1e12"]);
    for r in &rows {
        println!("{:<24} {:<44} {}", r.case, r.word(), r.verdict());
        r.assert_kept();
    }
    let row = |case: &str| rows.iter().find(|r| r.case == case).unwrap();
    for case in ["dop853: phi0 = 3", "rk4: phi0 = 3"] {
        assert!(row(case).promised() && row(case).verify_code == 0, "{case}");
    }
    for case in ["dop853: phi0 = 1e12", "rk4: phi0 = 1e12", "rk4: phi0 = 1e7"] {
        assert!(row(case).expected.contains("nutation"), "{case}");
        assert_ne!(row(case).verify_code, 0, "{case}");
    }
}

/// With dissipation verify skips `invariants`, `steady` and the nutation timing; a loose tolerance on
/// Euler's disk named all of `energy`, `invariants`, `constraint`, `steady` in `expected_to_fail`, two
/// of them checks that cannot fail. Now only checks that run are named, and what fails was named.
#[test]
fn a_dissipative_run_is_promised_to_fail_only_checks_verify_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = coin_log(
        dir.path(),
        &[
            "record",
            "euler-disk",
            "--rtol",
            "1e-3",
            "--atol",
            "1e-6",
            "--duration",
            "50",
            "-o",
            "e.mcap",
            "--json",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let expected: BTreeSet<&str> = summary["expected_to_fail"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert!(
        expected.contains("constraint") && expected.contains("energy"),
        "{expected:?}"
    );
    let verify = coin_log(dir.path(), &["verify", "e.mcap", "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&verify.stdout).unwrap();
    for c in report["files"][0]["checks"].as_array().unwrap() {
        let id = c["id"].as_str().unwrap();
        match c["status"].as_str().unwrap() {
            "skip" => assert!(!expected.contains(id), "{id} is named, and skipped"),
            "fail" => assert!(expected.contains(id), "{id} fails, and was not named"),
            _ => {}
        }
    }
    for skipped in ["invariants", "steady", "nutation"] {
        assert!(!expected.contains(skipped), "{skipped}: {expected:?}");
    }
}

/// Samples 1e-8 apart are so close that the rounding of an adaptive method's dense output, differenced by
/// the constraint check, shows: dop853 at rtol 1e-12 (tolerance 1e-9) left a residual of 8.6e-9, and
/// `record` had promised the file would verify (its rounding term was counted for fixed-step methods
/// only). It is now named in advance.
#[test]
fn record_warns_when_samples_are_too_close_for_an_adaptive_methods_rounding() {
    let dir = tempfile::tempdir().unwrap();
    for integrator in ["dop853", "dopri5"] {
        let flags: Vec<String> = [
            "--integrator",
            integrator,
            "--rtol",
            "1e-12",
            "--duration",
            "1e-2",
            "--rate",
            "1e8",
            "--channels",
            "omega,angles,position,energy,invariants",
        ]
        .iter()
        .map(|w| (*w).to_string())
        .collect();
        let r = corner(
            dir.path(),
            format!("{integrator}: rate 1e8 at rtol 1e-12"),
            &flags,
        );
        println!("{:<40} {:<52} {}", r.case, r.word(), r.verdict());
        assert!(r.failed.contains("constraint"), "{}", r.verdict());
        r.assert_kept();
    }
}

/// The summary `record ... --json` printed, and the checks it names in `expected_to_fail`.
fn record_summary(out: &std::process::Output) -> (serde_json::Value, Vec<String>) {
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let expected = summary["expected_to_fail"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    (summary, expected)
}

/// `verify FILE --json` in `dir`: the file's checks.
fn verify_checks(dir: &std::path::Path, file: &str) -> Vec<serde_json::Value> {
    let verify = coin_log(dir, &["verify", file, "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&verify.stdout).unwrap();
    report["files"][0]["checks"].as_array().unwrap().clone()
}

/// The check `id` of `checks`.
fn check<'a>(checks: &'a [serde_json::Value], id: &str) -> &'a serde_json::Value {
    checks.iter().find(|c| c["id"] == id).unwrap()
}

/// A steady motion does not nutate, and verify skips `nutation` on an unperturbed steady start:
/// `circle-plus --rtol 1e-3 --atol 1e-3` was promised to fail it all the same.
#[test]
fn a_steady_run_is_not_promised_to_fail_the_nutation_it_skips() {
    let dir = tempfile::tempdir().unwrap();
    let record = [
        "record",
        "circle-plus",
        "--rtol",
        "1e-3",
        "--atol",
        "1e-3",
        "-o",
        "c.mcap",
        "--json",
    ];
    let (summary, expected) = record_summary(&coin_log(dir.path(), &record));
    assert_eq!(
        expected,
        ["energy", "invariants", "constraint", "steady"],
        "{summary}"
    );
    let checks = verify_checks(dir.path(), "c.mcap");
    let nutation = check(&checks, "nutation");
    assert_eq!(nutation["status"], "skip", "{nutation}");
}

/// A coin that lands flat has no nutation period, and verify skips `nutation` ("there is no period"):
/// `topple --rtol 1e-6 --atol 1e-8` and `lift-off` (which the quadrature lands flat) were promised to
/// fail it all the same. The warning, the summary and the metadata now name only `constraint`, which
/// fails.
#[test]
fn a_run_that_lands_flat_is_not_promised_to_fail_the_nutation_it_skips() {
    let dir = tempfile::tempdir().unwrap();
    for scene in ["topple", "lift-off"] {
        let file = format!("{scene}.mcap");
        let record = [
            "record", scene, "--rtol", "1e-6", "--atol", "1e-8", "-o", &file, "--json",
        ];
        let out = coin_log(dir.path(), &record);
        let (summary, expected) = record_summary(&out);
        let expected: Vec<&str> = expected.iter().map(String::as_str).collect();
        assert!(!expected.contains(&"nutation"), "{scene}: {summary}");
        let warning = String::from_utf8_lossy(&out.stderr);
        assert!(!warning.contains("`nutation`"), "{scene}: {warning}");
        for c in &verify_checks(dir.path(), &file) {
            let id = c["id"].as_str().unwrap();
            match c["status"].as_str().unwrap() {
                "skip" => assert!(
                    !expected.contains(&id),
                    "{scene}: {id} is named, and skipped"
                ),
                "fail" => assert!(
                    expected.contains(&id),
                    "{scene}: {id} fails, and was not named"
                ),
                _ => {}
            }
        }
    }
}

/// Verify skips `nutation` when the integrator's error in ω times its turning points worse than 1e-6 of T
/// (a nutation of 0.3 in ω_X at rtol 1e-5): `wobble --rtol 1e-5 --atol 1e-7` was promised to fail it all
/// the same. The summary and the metadata, which know max|ω_X| after the run, now leave it out.
#[test]
fn a_nutation_too_small_to_time_is_not_promised_to_fail() {
    let dir = tempfile::tempdir().unwrap();
    let record = [
        "record", "wobble", "--rtol", "1e-5", "--atol", "1e-7", "-o", "w.mcap", "--json",
    ];
    let out = coin_log(dir.path(), &record);
    let (summary, expected) = record_summary(&out);
    assert!(!expected.iter().any(|c| c == "nutation"), "{summary}");
    let checks = verify_checks(dir.path(), "w.mcap");
    let nutation = checks.iter().find(|c| c["id"] == "nutation").unwrap();
    assert_eq!(nutation["status"], "skip", "{nutation}");
    assert!(
        nutation["reason"]
            .as_str()
            .unwrap()
            .contains("too small for the recorded accuracy"),
        "{nutation}"
    );
    for c in &checks {
        let id = c["id"].as_str().unwrap();
        let named = expected.iter().any(|e| e == id);
        match c["status"].as_str().unwrap() {
            "skip" => assert!(!named, "{id} is named, and skipped"),
            "fail" => assert!(named, "{id} fails, and was not named"),
            _ => {}
        }
    }
}

/// Verify skips `nutation` with fewer than 8 samples a period ("undersampled"): `wobble` (T = 2.75) for
/// 10⁴ time units at 2 samples a unit was promised to fail it all the same (its drift over the long run
/// is above the nutation tolerance).
#[test]
fn an_undersampled_run_is_not_promised_to_fail_the_nutation_it_skips() {
    let dir = tempfile::tempdir().unwrap();
    let record = [
        "record",
        "wobble",
        "--duration",
        "10000",
        "--rate",
        "2",
        "--channels",
        "omega,angles,position",
        "-o",
        "u.mcap",
        "--json",
    ];
    let out = coin_log(dir.path(), &record);
    let (summary, expected) = record_summary(&out);
    assert!(!expected.iter().any(|c| c == "nutation"), "{summary}");
    let checks = verify_checks(dir.path(), "u.mcap");
    let nutation = check(&checks, "nutation");
    assert_eq!(nutation["status"], "skip", "{nutation}");
    assert!(
        nutation["reason"]
            .as_str()
            .unwrap()
            .starts_with("undersampled"),
        "{nutation}"
    );
}
