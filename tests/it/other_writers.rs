//! Files from other MCAP writers: a recording rewritten losslessly by the Python `mcap` writer and by
//! `@mcap/core`'s McapWriter, in every layout a user gets by re-chunking, recompressing or moving the
//! metadata (`support::other_writers`), must verify exactly like the original: exit 0 and the same check
//! values. Every layout, and cut or damaged copies of each, is also run under a deadline: no input may
//! make verify hang (the `coin-log` metadata after the first chunk once did).
#![allow(clippy::unwrap_used)]

use crate::support::other_writers::{rewrites, DEFECTIVE, LAYOUTS};
use crate::support::record::{coin_log_within, top_level_records, HANG_DEADLINE};
use serde_json::Value;
use std::path::Path;

/// `coin-log verify --json FILE` under the hang deadline: exit code, the file's object, stderr.
fn verify_json(path: &Path) -> (i32, Value, String) {
    let (code, out, err) =
        coin_log_within(HANG_DEADLINE, &["verify", "--json", path.to_str().unwrap()]);
    let v: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}{err}"));
    (code, v["files"][0].clone(), err)
}

/// Asserts that `theirs` has the same checks as `ours`: ids, statuses, values and tolerances bit for bit,
/// and the same reasons except integrity's (which counts the file's chunks).
fn assert_same_checks(name: &str, ours: &Value, theirs: &Value) {
    let (a, b) = (
        ours["checks"].as_array().unwrap(),
        theirs["checks"].as_array().unwrap(),
    );
    assert_eq!(a.len(), b.len(), "{name}");
    for (x, y) in a.iter().zip(b) {
        for key in ["id", "status", "value", "tolerance"] {
            assert_eq!(
                x[key], y[key],
                "{name}: {} {key}\n  original {x}\n  rewrite  {y}",
                x["id"]
            );
        }
        if x["id"] != "integrity" {
            assert_eq!(x["reason"], y["reason"], "{name}: {} reason", x["id"]);
        }
    }
}

/// The offset of the first message (a chunk's or a top-level one) and of the `coin-log` metadata record.
fn first_message_and_run_metadata(bytes: &[u8]) -> (usize, usize) {
    let records = top_level_records(bytes);
    let first = records
        .iter()
        .find(|r| r.0 == 0x06 || r.0 == 0x05)
        .unwrap()
        .1;
    let run = records
        .iter()
        .find(|(op, at, _)| {
            let name_len = u32::from_le_bytes(bytes[at + 9..at + 13].try_into().unwrap()) as usize;
            *op == 0x0C && &bytes[at + 13..at + 13 + name_len] == b"coin-log"
        })
        .unwrap()
        .1;
    (first, run)
}

#[test]
fn every_rewrite_by_the_python_and_typescript_writers_verifies_like_the_original() {
    let r = rewrites();
    let (code, original, err) = verify_json(&r.original);
    assert_eq!(code, 0, "{original}{err}");
    for check in original["checks"].as_array().unwrap() {
        // A steady circle does not nutate: that one check is skipped, by design, with its reason.
        let expected = if check["id"] == "nutation" {
            "skip"
        } else {
            "pass"
        };
        assert_eq!(
            check["status"], expected,
            "every other check runs on the original: {check}"
        );
    }
    for layout in LAYOUTS {
        let path = r.file(layout.name);
        let (code, theirs, err) = verify_json(path);
        println!(
            "{}: exit {code}, verdict {}",
            layout.name, theirs["verdict"]
        );
        assert_eq!(code, 0, "{}: {theirs}\n{err}", layout.name);
        assert_eq!(theirs["verdict"], "ok", "{}", layout.name);
        assert_eq!(theirs["problem"], Value::Null, "{}", layout.name);
        assert_eq!(err, "", "{}", layout.name);
        assert_same_checks(layout.name, &original, &theirs);
    }
}

/// The layouts marked late really put the `coin-log` record after the first chunk (or message), and the
/// others before it, so that the test above covers the case that hung.
#[test]
fn the_late_layouts_put_the_run_metadata_after_the_first_messages() {
    let r = rewrites();
    for (layout, path) in &r.files {
        let (first, run) = first_message_and_run_metadata(&std::fs::read(path).unwrap());
        println!(
            "{}: first message record at byte {first}, coin-log metadata at byte {run}",
            layout.name
        );
        assert_eq!(run > first, layout.late, "{}", layout.name);
    }
    let (first, run) = first_message_and_run_metadata(&std::fs::read(&r.original).unwrap());
    assert!(run < first, "coin-log record writes its metadata first");
}

/// Valid MCAP that is not in coin-log's layout: the physics is judged the same, and integrity names what
/// is missing or wrong (exit 1).
#[test]
fn a_rewrite_without_summary_or_with_a_wrong_metadata_index_is_judged_and_fails_integrity() {
    let r = rewrites();
    let (_, original, _) = verify_json(&r.original);
    // Without a summary, each chunk lacks its message indexes, and the summary is missing.
    let chunks = top_level_records(&std::fs::read(r.file("py-no-summary-last")).unwrap())
        .iter()
        .filter(|(op, _, _)| *op == 0x06)
        .count();
    assert!(
        chunks > 10,
        "{chunks} chunks: small chunks, as the layout is meant to have"
    );
    #[allow(clippy::cast_precision_loss)]
    let missing = (chunks + 1) as f64;
    for (name, problem, count) in [
        (
            "py-no-summary-last",
            "chunk at byte 42: no message index for channel(s) [1, 2, 3, 4, 5, 6, 7, 8, 9,",
            missing,
        ),
        (
            "ts-unchunked-last",
            "metadata indexes do not match the metadata records (2 records, 2 index entries)",
            1.0,
        ),
    ] {
        assert!(DEFECTIVE.iter().any(|l| l.name == name));
        let (code, theirs, _) = verify_json(r.file(name));
        let integrity = &theirs["checks"][0];
        println!("{name}: exit {code}; {integrity}");
        assert_eq!(code, 1, "{name}");
        assert_eq!(theirs["verdict"], "failed");
        assert_eq!(integrity["status"], "fail");
        assert_eq!(integrity["value"], count, "{name}: number of problems");
        assert!(
            integrity["reason"].as_str().unwrap().contains(problem),
            "{name}: {integrity}"
        );
        let physics = |v: &Value| {
            let mut v = v.clone();
            v["checks"].as_array_mut().unwrap().remove(0);
            v
        };
        assert_same_checks(name, &physics(&original), &physics(&theirs));
    }
}

/// Every layout, and copies cut at a third, two thirds and 3 bytes before the end, and with a byte
/// flipped in the middle, each verified as a child process that must exit within [`HANG_DEADLINE`]: the
/// exact code for whole and cut files, never a panic.
#[test]
fn no_layout_and_no_cut_or_damaged_copy_makes_verify_hang() {
    let r = rewrites();
    let dir = tempfile::tempdir().unwrap();
    let mut runs = 0;
    for (layout, path) in &r.files {
        let whole = std::fs::read(path).unwrap();
        let defective = DEFECTIVE.iter().any(|l| l.name == layout.name);
        let (code, _, err) = verify_json(path);
        assert_eq!(
            code,
            if defective { 1 } else { 0 },
            "{}: {err}",
            layout.name
        );
        let n = whole.len();
        for cut in [n / 3, 2 * n / 3, n - 3] {
            let copy = dir.path().join(format!("{}-cut-{cut}.mcap", layout.name));
            std::fs::write(&copy, &whole[..cut]).unwrap();
            let (code, _, err) = verify_json(&copy);
            let expected = format!(
                "error: {}: truncated: the file ends at byte {cut}",
                copy.display()
            );
            assert_eq!(code, 2, "{err}");
            assert!(err.starts_with(&expected), "{err}\nexpected: {expected}");
            runs += 1;
        }
        let mut flipped = whole.clone();
        flipped[n / 2] ^= 0x20;
        let copy = dir.path().join(format!("{}-flipped.mcap", layout.name));
        std::fs::write(&copy, &flipped).unwrap();
        let (code, file, err) = verify_json(&copy);
        println!(
            "{} with byte {} flipped: exit {code}, {}",
            layout.name,
            n / 2,
            file["problem"]
        );
        assert!(
            code == 1 || code == 2,
            "{}: exit {code}\n{err}",
            layout.name
        );
        assert!(!err.contains("panicked"), "{err}");
        runs += 2;
    }
    println!("{runs} runs of verify, each within {HANG_DEADLINE:?}");
}
