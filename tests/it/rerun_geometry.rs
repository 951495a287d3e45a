//! The `rerun` channel as Rerun sees it (docs/format.md: Rerun geometry; issue 26): a fresh Protobuf
//! recording with `--rerun`, converted by Rerun's own importer (`rerun mcap convert -d urdf ...`) and read
//! back with the Rerun SDK (`scripts/readers/rerun_geometry.py`), has geometry archetypes for the coin (the
//! URDF's `Cylinders3D`), the track (`Points3D`) and the table (`VoxelGridMap`), whose positions at three
//! times agree with the recorded centre and contact point to f32 rounding. Negative controls: the same
//! comparison one sample later fails every position check, and a recording without the channel fails for
//! want of the geometry.

use crate::support::other_writers::python;
use crate::support::process::run_tool;
use crate::support::record::coin_log_text;
use crate::support::repo;
use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// Runs `rerun_geometry.py` on `mcap` (converting it to `rrd`): exit code, its JSON (if any), stderr.
fn geometry(mcap: &Path, rrd: &Path, shift: bool) -> (i32, Option<Value>, String) {
    let mut c = Command::new(python());
    c.arg(repo().join("scripts/readers/rerun_geometry.py"))
        .arg(mcap)
        .arg(rrd);
    if shift {
        c.arg("--shift");
    }
    let o = run_tool(&mut c, "run scripts/test");
    let err = o.stderr.clone();
    println!(
        "--- rerun_geometry.py{}\n{err}",
        if shift { " --shift" } else { "" }
    );
    (
        o.status.code().unwrap_or(-1),
        serde_json::from_str(&o.stdout).ok(),
        err,
    )
}

fn record(path: &str, extra: &[&str]) {
    let mut args = vec![
        "record",
        "wobble",
        "--duration",
        "10",
        "--encoding",
        "protobuf",
    ];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["-o", path, "--overwrite"]);
    let (code, _, err) = coin_log_text(&args);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn rerun_draws_the_coin_table_and_track_where_the_recording_puts_them() {
    let dir = tempfile::tempdir().unwrap();
    let mcap = dir.path().join("wobble.mcap");
    let rrd = dir.path().join("wobble.rrd");
    record(mcap.to_str().unwrap(), &["--rerun"]);
    let (code, doc, err) = geometry(&mcap, &rrd, false);
    assert_eq!(code, 0, "{err}");
    let doc = doc.expect("rerun_geometry.py prints JSON");
    let checks = doc["checks"].as_array().unwrap();
    let names = [
        "coin centre",
        "coin contact",
        "track end",
        "table under the contact (margin >= 10 a)",
    ];
    for name in names {
        let at: Vec<&Value> = checks.iter().filter(|c| c["name"] == name).collect();
        assert_eq!(at.len(), 3, "{name} at three times");
        for c in at {
            assert_eq!(c["ok"], true, "{c}");
        }
    }
    assert_eq!(doc["ok"], true);

    // Negative control 1: one sample (0.01) later, every position check fails.
    let (code, doc, err) = geometry(&mcap, &rrd, true);
    assert_eq!(code, 1, "{err}");
    let doc = doc.expect("rerun_geometry.py prints JSON");
    let positions: Vec<&Value> = doc["checks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["name"] != names[3])
        .collect();
    assert_eq!(positions.len(), 9);
    assert!(positions.iter().all(|c| c["ok"] == false), "{doc}");

    // Negative control 2: the default recording has no Rerun geometry.
    let plain = dir.path().join("plain.mcap");
    record(plain.to_str().unwrap(), &[]);
    let (code, doc, err) = geometry(&plain, &rrd, false);
    assert_eq!(code, 1, "{err}");
    assert!(doc.is_none());
    assert!(err.contains("record with --rerun"), "{err}");
}

#[test]
fn the_rerun_channel_is_refused_in_json_and_without_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.mcap");
    let path = out.to_str().unwrap();
    let (code, _, err) = coin_log_text(&["record", "wobble", "--rerun", "-o", path]);
    println!("{err}");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--encoding protobuf"), "{err}");
    let (code, _, err) = coin_log_text(&[
        "record",
        "wobble",
        "--encoding",
        "protobuf",
        "--channels",
        "tf,rerun",
        "-o",
        path,
    ]);
    println!("{err}");
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("add \"scene\""), "{err}");
    assert!(!out.exists(), "nothing written");
}
