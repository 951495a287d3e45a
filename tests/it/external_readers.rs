//! Independent readers in CI: every committed dataset and two fresh recordings (a steady circle, and the
//! dissipative `euler-disk` with its `coin_log.Work` channel, physics §11) are read with
//! `@mcap/core`'s indexed reader (the library Foxglove uses; `scripts/readers/check.mjs`) and with the
//! Python `mcap` package (`scripts/readers/check.py`): all messages decoded, counts equal to the statistics,
//! `foxglove.*` messages valid against `@foxglove/schemas`, `coin_log.*` against `schemas/`.
//! A negative control proves the readers refuse a file that breaks the schema.
//!
//! The tools are installed by `scripts/test`; a missing one fails the test (never skips it).

use crate::support::other_writers::{node_readers, python};
use crate::support::process::run_tool;
use crate::support::record::coin_log_text;
use crate::support::writers::{record_circle, Damage};
use crate::support::{dataset_files, repo};
use std::path::PathBuf;
use std::process::Command;

/// Runs both readers on `files`; returns (success, output) of each.
fn run_readers(files: &[PathBuf]) -> [(bool, String); 2] {
    let node = run_tool(
        Command::new("node")
            .arg(node_readers().join("check.mjs"))
            .args(files),
        "install Node.js 20 and run scripts/test",
    );
    let py = run_tool(
        Command::new(python())
            .arg(repo().join("scripts/readers/check.py"))
            .args(files),
        "run scripts/test",
    );
    [node, py].map(|o| (o.status.success(), o.stdout + &o.stderr))
}

#[test]
fn both_independent_readers_accept_every_dataset_and_a_fresh_recording() {
    let dir = tempfile::tempdir().unwrap();
    let fresh = dir.path().join("fresh-circle.mcap");
    record_circle(&fresh, 3.0, Damage::None);
    let dissipative = dir.path().join("fresh-euler-disk.mcap");
    let (code, out, err) = coin_log_text(&[
        "record",
        "euler-disk",
        "--duration",
        "2",
        "-o",
        dissipative.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{out}{err}");
    let mut files = dataset_files();
    files.push(fresh);
    files.push(dissipative);
    let [(node_ok, node_out), (py_ok, py_out)] = run_readers(&files);
    println!("--- @mcap/core (check.mjs)\n{node_out}--- python mcap (check.py)\n{py_out}");
    assert!(node_ok, "@mcap/core reader refused a file:\n{node_out}");
    assert!(py_ok, "python mcap reader refused a file:\n{py_out}");
    for out in [&node_out, &py_out] {
        assert!(
            out.contains(&format!("{} passed, 0 failed", files.len())),
            "every file checked: {out}"
        );
    }
}

#[test]
fn both_readers_refuse_a_scene_entity_without_a_required_field() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad-scene.mcap");
    record_circle(&bad, 1.0, Damage::SceneEntityWithoutMetadata);
    let [(node_ok, node_out), (py_ok, py_out)] = run_readers(&[bad]);
    println!("--- check.mjs\n{node_out}--- check.py\n{py_out}");
    assert!(!node_ok && node_out.contains("metadata"), "{node_out}");
    assert!(!py_ok && py_out.contains("metadata"), "{py_out}");
}

#[test]
fn both_readers_refuse_a_coin_log_message_with_an_undeclared_field() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad-energy.mcap");
    record_circle(&bad, 1.0, Damage::EnergyWithExtraField);
    let [(node_ok, node_out), (py_ok, py_out)] = run_readers(&[bad]);
    println!("--- check.mjs\n{node_out}--- check.py\n{py_out}");
    assert!(!node_ok && node_out.contains("power"), "{node_out}");
    assert!(!py_ok && py_out.contains("power"), "{py_out}");
}

/// `coin-log export` read back by Python (`csv`, `float`) against the MCAP read by the Python `mcap`
/// package and `json`: every value equal bit for bit; a table with one value changed by one unit in the
/// last place is refused.
#[test]
fn python_reads_the_exported_tables_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let path = crate::support::record::record_scene(dir.path(), "wobble", &["--duration", "3"]);
    let out =
        crate::support::record::coin_log(dir.path(), &["export", "wobble.mcap", "--out", "t"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let check = |what: &str| {
        let o = run_tool(
            Command::new(python())
                .arg(repo().join("scripts/readers/check_export.py"))
                .arg(&path)
                .arg(dir.path().join("t")),
            "run scripts/test",
        );
        let text = format!("{}{}", o.stdout, o.stderr);
        println!("--- check_export.py ({what})\n{text}");
        (o.status.success(), text)
    };
    let (ok, text) = check("as exported");
    assert!(ok && text.contains("values equal bit for bit"), "{text}");
    let table = dir.path().join("t/energy.csv");
    let csv = std::fs::read_to_string(&table).unwrap();
    let mut lines: Vec<String> = csv.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[10].split(',').map(str::to_string).collect();
    let x: f64 = cells[1].parse().unwrap();
    cells[1] = ryu::Buffer::new()
        .format_finite(f64::from_bits(x.to_bits() + 1))
        .to_string();
    lines[10] = cells.join(",");
    std::fs::write(&table, lines.join("\n") + "\n").unwrap();
    let (ok, text) = check("one value changed by one ulp");
    assert!(!ok && text.contains("energy.csv row 10 `total`"), "{text}");
}
