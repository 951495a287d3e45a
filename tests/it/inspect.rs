//! `info`, `export` and `plot` on real recordings (the binary's own, and the same data written by the
//! `mcap` crate without a summary section): what `info` reports against what the file holds when read
//! independently, the stored scene recording the same bytes again for every built-in scene, the exported
//! tables equal to the MCAP's messages bit for bit, and the plot a well-formed SVG with its panels.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{coin_log, coin_log_text, read_back, record_scene, ReadBack};
use crate::support::repo;
use coin_log::format::{Channel, RUN_METADATA_NAME};
use coin_log::inspect::export::{TF_COLUMNS, WIDE_TABLE};
use coin_log::inspect::plot::PANELS;
use coin_log::inspect::seconds_text;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// Copies `src` into `dst` with the `mcap` crate's writer and no summary section (no statistics, no
/// indexes), as a recording from another writer or an unfinished one might be.
fn without_summary(src: &Path, dst: &Path) {
    copy_with(
        src,
        dst,
        mcap::WriteOptions::new()
            .emit_summary_records(false)
            .emit_summary_offsets(false)
            .emit_statistics(false)
            .emit_chunk_indexes(false)
            .emit_metadata_indexes(false),
    );
}

/// Copies the `coin-log` record and the messages of `src` into `dst` with the `mcap` crate's writer, lz4
/// chunks and the summary `options` make.
fn copy_with(src: &Path, dst: &Path, options: mcap::WriteOptions) {
    copy_twice(src, dst, options, "");
}

/// [`copy_with`], with the messages of `topic` written twice, on two channels of that topic (legal
/// MCAP: two publishers of one topic).
fn copy_twice(src: &Path, dst: &Path, options: mcap::WriteOptions, topic: &str) {
    let bytes = std::fs::read(src).unwrap();
    let file = read_back(&bytes);
    let out = std::io::BufWriter::new(std::fs::File::create(dst).unwrap());
    let mut w = options
        .compression(Some(mcap::Compression::Lz4))
        .library("another-writer")
        .create(out)
        .unwrap();
    let run = &file.metadata[RUN_METADATA_NAME].1;
    w.write_metadata(&mcap::records::Metadata {
        name: RUN_METADATA_NAME.into(),
        metadata: run.clone(),
    })
    .unwrap();
    crate::support::writers::copy_messages_twice(&bytes, &mut w, topic, |_| {});
    w.finish().unwrap();
}

/// The per-topic message counts and the time range of a recording, read by the `mcap` crate.
fn counts(file: &ReadBack) -> (BTreeMap<String, u64>, u64, u64) {
    let mut counts = BTreeMap::new();
    for m in &file.messages {
        *counts.entry(m.topic.clone()).or_insert(0) += 1;
    }
    let start = file.messages.iter().map(|m| m.log_time).min().unwrap();
    let end = file.messages.iter().map(|m| m.log_time).max().unwrap();
    (counts, start, end)
}

/// `info --json` against the file read independently, from the summary and from a file without one.
#[test]
fn info_reports_what_the_file_holds_with_or_without_a_summary() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "topple", &["--compression", "lz4"]);
    let bare = dir.path().join("bare.mcap");
    without_summary(&path, &bare);
    let file = read_back(&std::fs::read(&path).unwrap());
    let (expected, start, end) = counts(&file);
    let out = coin_log(dir.path(), &["info", "--json", "topple.mcap", "bare.mcap"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(&out);
    let files = v["files"].as_array().unwrap();
    assert_eq!(files.len(), 2);
    for (f, from, library) in [
        (&files[0], "summary", "coin-log/"),
        (&files[1], "scan", "another-writer"),
    ] {
        println!("{}", serde_json::to_string_pretty(f).unwrap());
        assert_eq!(f["read_from"], from);
        assert!(f["library"].as_str().unwrap().starts_with(library));
        let got: BTreeMap<String, u64> = f["channels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                (
                    c["topic"].as_str().unwrap().to_string(),
                    c["messages"].as_u64().unwrap(),
                )
            })
            .collect();
        assert_eq!(got, expected, "per-channel counts");
        assert_eq!(f["messages"], expected.values().sum::<u64>());
        assert_eq!(f["start_time"].as_f64().unwrap(), start as f64 / 1e9);
        assert_eq!(f["end_time"].as_f64().unwrap(), end as f64 / 1e9);
        assert_eq!(f["coin_log"], true);
        assert_eq!(f["body"]["mass"], 1.0);
        assert_eq!(f["body"]["inertia_x"], 0.25);
        assert_eq!(f["run"]["integrator"], "dop853");
        assert_eq!(f["run"]["duration"], 30.0);
        assert_eq!(
            f["file_size"],
            std::fs::metadata(dir.path().join(f["path"].as_str().unwrap()))
                .unwrap()
                .len()
        );
        assert!(f["description"].as_str().unwrap().contains("flat landing"));
        // omega has one message per sample: (n - 1) samples over the span.
        let omega = &f["channels"][0];
        let rate = (expected["/coin/omega"] - 1) as f64 / ((end - start) as f64 / 1e9);
        assert_eq!(omega["rate"].as_f64().unwrap(), rate);
    }
    assert_eq!(files[0]["compression"], "lz4");
    assert_eq!(files[0]["result"]["termination"], "flat-landing");
    assert!(files[0]["result"]["termination_time"].as_f64().unwrap() > 1.8);
    // The copy has no result record: info says so rather than inventing one.
    assert!(files[1]["result"].is_null());
    let (code, text, _) = coin_log_text(&["info", path.to_str().unwrap()]);
    print!("{text}");
    assert_eq!(code, 0);
    for expected in [
        "flat-landing at t = 1.9",
        "/coin/omega",
        "coin_log.AngularVelocity",
        "lz4",
        "summary section",
    ] {
        assert!(text.contains(expected), "`{expected}` in:\n{text}");
    }
}

/// MCAP makes each group of the summary optional: a summary with statistics but without the metadata
/// indexes, the chunk indexes or the schema and channel records does not say what the file holds, so
/// `info` reads the file instead and describes it as it describes the copy with the whole summary (it
/// said `coin_log` false, 0 chunks or no channels).
#[test]
fn info_reads_the_file_when_its_summary_leaves_a_group_out() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "topple", &["--duration", "1"]);
    let options = || mcap::WriteOptions::new().chunk_size(Some(64 << 10));
    copy_with(&path, &dir.path().join("whole.mcap"), options());
    let copies = [
        ("no-metadata-index", options().emit_metadata_indexes(false)),
        ("no-chunk-index", options().emit_chunk_indexes(false)),
        ("no-channels", options().emit_summary_records(false)),
    ];
    for (name, o) in copies {
        copy_with(&path, &dir.path().join(format!("{name}.mcap")), o);
    }
    let out = coin_log(
        dir.path(),
        &[
            "info",
            "--json",
            "whole.mcap",
            "no-metadata-index.mcap",
            "no-chunk-index.mcap",
            "no-channels.mcap",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(&out);
    let files = v["files"].as_array().unwrap();
    let whole = &files[0];
    assert_eq!(whole["read_from"], "summary");
    assert_eq!(whole["coin_log"], true);
    assert!(whole["chunks"].as_u64().unwrap() > 1, "{whole}");
    assert_eq!(whole["channels"].as_array().unwrap().len(), 13, "{whole}");
    let comparable = |f: &serde_json::Value| {
        let mut f = f.clone();
        for key in ["path", "file_size", "read_from"] {
            f.as_object_mut().unwrap().remove(key);
        }
        f
    };
    for f in &files[1..] {
        println!(
            "{}: read from {}, coin_log {}, {} chunks, {} channels",
            f["path"],
            f["read_from"],
            f["coin_log"],
            f["chunks"],
            f["channels"].as_array().unwrap().len()
        );
        assert_eq!(f["read_from"], "scan", "{}", f["path"]);
        assert_eq!(comparable(f), comparable(whole), "{}", f["path"]);
    }
}

/// A file cut in half is described up to the break, with the problem named and exit 1; a file that is not
/// MCAP is an error naming the problem.
#[test]
fn info_describes_a_truncated_file_up_to_the_break_and_refuses_a_non_mcap_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "wobble", &[]);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(dir.path().join("half.mcap"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.path().join("notes.mcap"), b"just some text\n").unwrap();
    let out = coin_log(dir.path(), &["info", "--json", "half.mcap"]);
    assert_eq!(out.status.code(), Some(1));
    let f = &json(&out)["files"][0];
    println!("{f}");
    assert_eq!(f["read_from"], "scan");
    assert!(f["problem"].as_str().unwrap().contains("truncated"), "{f}");
    let n = f["messages"].as_u64().unwrap();
    assert!(n > 0 && n < 27912, "{n} messages before the break");
    let (code, _, err) = coin_log_text(&["info", dir.path().join("notes.mcap").to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("not an MCAP file"), "{err}");
}

/// A file that breaks off part way is described up to the break on stdout and exits 1; the error is on
/// stderr too, as `plot` and `info --scene` put it there: with stdout in a file or a pipe, exit 1 came with
/// nothing on stderr.
#[test]
fn info_names_the_problem_of_a_truncated_file_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "circle-plus", &["--duration", "1"]);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(dir.path().join("half.mcap"), &bytes[..bytes.len() / 2]).unwrap();
    for json in [false, true] {
        let mut args = vec!["info", "half.mcap"];
        if json {
            args.push("--json");
        }
        let out = coin_log(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.starts_with("error: half.mcap: ") && err.contains("truncated"),
            "--json {json}: {err}"
        );
        assert!(String::from_utf8_lossy(&out.stdout).contains("truncated"));
    }
    // A whole file: nothing on stderr.
    let out = coin_log(dir.path(), &["info", "circle-plus.mcap"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `info F --scene > s.toml && record s.toml -o G` writes G equal to F byte for byte, for every built-in
/// scene; the description and every default survive, and the scene file's name does not enter the file.
#[test]
fn the_stored_scene_records_the_same_bytes_again_for_every_built_in() {
    let dir = tempfile::tempdir().unwrap();
    let names = coin_log::scene::presets::NAMES;
    for name in names {
        let original = record_scene(dir.path(), name, &[]);
        let out = coin_log(dir.path(), &["info", original.to_str().unwrap(), "--scene"]);
        assert_eq!(out.status.code(), Some(0), "{name}");
        let text = String::from_utf8(out.stdout).unwrap();
        // Another stem than the scene's name: the file must not depend on it.
        let toml = dir.path().join(format!("copied-{name}.toml"));
        std::fs::write(&toml, &text).unwrap();
        let again = dir.path().join(format!("again-{name}.mcap"));
        let (code, _, err) = coin_log_text(&[
            "record",
            toml.to_str().unwrap(),
            "-o",
            again.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{name}: {err}");
        let (a, b) = (
            std::fs::read(&original).unwrap(),
            std::fs::read(&again).unwrap(),
        );
        println!(
            "{name:<18} {} bytes, re-recorded from its stored scene: {}",
            a.len(),
            if a == b { "identical" } else { "DIFFERENT" }
        );
        assert!(a == b, "{name}: the re-recording differs\n{text}");
        let preset = coin_log::scene::presets::preset(name).unwrap();
        let description = preset.description.unwrap();
        assert!(text.contains(&description), "{name}: description kept");
        for key in [
            "rate =",
            "integrator =",
            "flat_margin =",
            "thickness =",
            "channels =",
        ] {
            assert!(text.contains(key), "{name}: `{key}` written out:\n{text}");
        }
        crate::support::assert_uses_its_settings(name, &text);
        assert!(!text.contains("copied-"), "{name}");
    }
}

/// Non-default compression: the comment names the flag that reproduces the bytes.
#[test]
fn the_stored_scene_names_a_non_default_compression() {
    let dir = tempfile::tempdir().unwrap();
    let original = record_scene(
        dir.path(),
        "circle-plus",
        &["--compression", "none", "--duration", "2"],
    );
    let (code, text, _) = coin_log_text(&["info", original.to_str().unwrap(), "--scene"]);
    assert_eq!(code, 0);
    assert!(text.contains("--compression none"), "{text}");
    std::fs::write(dir.path().join("s.toml"), &text).unwrap();
    let again = dir.path().join("g.mcap");
    let (code, _, err) = coin_log_text(&[
        "record",
        dir.path().join("s.toml").to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
        "--compression",
        "none",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(std::fs::read(&original).unwrap() == std::fs::read(&again).unwrap());
    let (code, _, err) = coin_log_text(&[
        "info",
        "--scene",
        original.to_str().unwrap(),
        original.to_str().unwrap(),
    ]);
    // A usage error (exit 2, as `--scene --json` is clap's), not a failure to read a file (exit 1).
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("one file"), "{err}");
}

/// A file another program rewrote (its header's library is not `coin-log/<version>`) holds the scene that
/// coin-log recorded, but not bytes that `coin-log record` writes: `--scene` said "this writes the same
/// bytes again" for a copy by Python's or Rust's `mcap` writer, even one that kept a single sample. It now
/// names the library and gives no command line.
#[test]
fn the_stored_scene_of_a_rewritten_file_claims_no_reproduction() {
    // The command line's start (src/cli/info.rs: REPRODUCE).
    const REPRODUCE: &str = "#     coin-log record ";
    let dir = tempfile::tempdir().unwrap();
    let original = record_scene(
        dir.path(),
        "circle-plus",
        &["--compression", "lz4", "--duration", "0.5"],
    );
    let copy = dir.path().join("copy.mcap");
    copy_with(&original, &copy, mcap::WriteOptions::new());
    let (code, text, err) = coin_log_text(&["info", copy.to_str().unwrap(), "--scene"]);
    assert_eq!(code, 0, "{err}");
    assert!(!text.contains(REPRODUCE), "{text}");
    assert!(
        text.contains("`another-writer`") && text.contains("no command line"),
        "{text}"
    );
    assert!(
        text.contains("[body]"),
        "the scene is still printed: {text}"
    );
    // The original still has its command line.
    let (code, text, err) = coin_log_text(&["info", original.to_str().unwrap(), "--scene"]);
    assert_eq!(code, 0, "{err}");
    assert!(text.contains(REPRODUCE), "{text}");
}

/// A recording with the `rerun` channel (Protobuf, with `/rerun/robot_description` in CDR in every file,
/// as `record` writes it) is reproduced by `record --encoding protobuf`: `--scene` said its encoding was
/// `mixed (cdr, protobuf)`, "not those of one `coin-log record`", and gave no command line.
#[test]
fn the_stored_scene_of_a_rerun_recording_gives_its_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let original = record_scene(
        dir.path(),
        "circle-plus",
        &["--rerun", "--encoding", "protobuf", "--duration", "0.5"],
    );
    let (code, text, err) = coin_log_text(&["info", original.to_str().unwrap(), "--scene"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        text.contains(
            "#     coin-log record SCENE.toml -o OUT.mcap --encoding protobuf --compression zstd"
        ),
        "{text}"
    );
    std::fs::write(dir.path().join("s.toml"), &text).unwrap();
    let again = dir.path().join("again.mcap");
    let (code, _, err) = coin_log_text(&[
        "record",
        dir.path().join("s.toml").to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
        "--encoding",
        "protobuf",
        "--compression",
        "zstd",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(std::fs::read(&original).unwrap() == std::fs::read(&again).unwrap());
}

/// The rows of a CSV table: the header and the fields of each line (no quoting in number tables).
fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    (
        header,
        lines
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect(),
    )
}

/// Every value of `table` against the messages of `topic` read by the `mcap` crate and serde_json:
/// equal bits, one row per message in order, the header `fields`. Returns the values compared.
fn compare_flat(file: &ReadBack, topic: &str, table: &Path, fields: &[&str]) -> usize {
    let (header, rows) = csv(table);
    let messages = file.on_topic(topic);
    assert_eq!(rows.len(), messages.len(), "{topic}: one row per message");
    assert_eq!(header, fields, "{topic}: header = the schema's fields");
    let mut compared = 0;
    for (row, m) in rows.iter().zip(messages) {
        let v: serde_json::Map<String, serde_json::Value> =
            serde_json::from_slice(&m.data).unwrap();
        for (name, cell) in header.iter().zip(row) {
            let expected = v[name].as_f64().unwrap();
            let got: f64 = cell.parse().unwrap();
            assert_eq!(
                got.to_bits(),
                expected.to_bits(),
                "{topic}.{name}: {cell} vs {expected:?}"
            );
            compared += 1;
        }
    }
    compared
}

/// Every table of a per-channel export equals the MCAP's messages bit for bit; `/tf` is flattened with
/// its exact timestamps; `/scene` is skipped with the reason; a second export refuses to overwrite.
#[test]
fn export_writes_every_value_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "wobble", &["--duration", "5"]);
    let out = coin_log(
        dir.path(),
        &["export", "wobble.mcap", "--out", "tables", "--json"],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = json(&out);
    println!("{summary}");
    let file = read_back(&std::fs::read(&path).unwrap());
    let tables = dir.path().join("tables");
    let mut compared = 0;
    for c in Channel::DEFAULT {
        let Some(t) = c.message_type() else { continue };
        let table = tables.join(format!("{}.csv", c.name()));
        compared += compare_flat(&file, c.topic(), &table, t.fields);
    }
    println!("{compared} values equal bit for bit");
    assert!(compared > 8 * 501 * 3);
    // /tf: the frame ids, the exact timestamp, translation and rotation.
    let (header, rows) = csv(&tables.join("tf.csv"));
    assert_eq!(header, TF_COLUMNS);
    let tf = file.on_topic("/tf");
    assert_eq!(rows.len(), tf.len());
    for (row, m) in rows.iter().zip(tf) {
        let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        let ns = v["timestamp"]["sec"].as_u64().unwrap() * 1_000_000_000
            + v["timestamp"]["nsec"].as_u64().unwrap();
        assert_eq!(ns, m.log_time);
        assert_eq!(
            row[0].parse::<f64>().unwrap(),
            ns as f64 / 1e9,
            "t is the exact timestamp"
        );
        assert_eq!(row[1], v["parent_frame_id"].as_str().unwrap());
        assert_eq!(row[2], v["child_frame_id"].as_str().unwrap());
        for (cell, (part, axis)) in row[3..].iter().zip([
            ("translation", "x"),
            ("translation", "y"),
            ("translation", "z"),
            ("rotation", "x"),
            ("rotation", "y"),
            ("rotation", "z"),
            ("rotation", "w"),
        ]) {
            assert_eq!(
                cell.parse::<f64>().unwrap().to_bits(),
                v[part][axis].as_f64().unwrap().to_bits()
            );
        }
    }
    // Skipped: the display geometry only (/scene and its table and track topics), each with the reason.
    let skipped = summary["skipped"].as_array().unwrap();
    assert!(skipped.iter().any(|k| k["topic"] == "/scene"), "{summary}");
    for k in skipped {
        let topic = k["topic"].as_str().unwrap();
        assert!(topic == "/scene" || topic.starts_with("/scene/t"), "{k}");
        assert!(
            k["reason"].as_str().unwrap().contains("/coin/contact"),
            "{k}"
        );
    }
    assert!(tables.join("tf_static.csv").exists() && tables.join("scene_follow.csv").exists());
    // Again without --overwrite: refused, the tables untouched, no temporary file left.
    let before = std::fs::read(tables.join("omega.csv")).unwrap();
    let out = coin_log(dir.path(), &["export", "wobble.mcap", "--out", "tables"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--overwrite"));
    assert_eq!(std::fs::read(tables.join("omega.csv")).unwrap(), before);
    let names: Vec<String> = std::fs::read_dir(&tables)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names
            .iter()
            .all(|n| n.ends_with(".csv") && !n.starts_with('.')),
        "{names:?}"
    );
    assert_eq!(
        names.len(),
        11,
        "eight channels, tf, tf_static, scene_follow"
    );
}

/// The comparison above fails when one value differs by one unit in the last place (negative control).
#[test]
fn the_bit_comparison_catches_one_ulp() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(
        dir.path(),
        "circle-plus",
        &["--duration", "1", "--channels", "omega"],
    );
    let out = coin_log(dir.path(), &["export", "circle-plus.mcap", "--out", "t"]);
    assert_eq!(out.status.code(), Some(0));
    let table = dir.path().join("t/omega.csv");
    let text = std::fs::read_to_string(&table).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[5].split(',').map(str::to_string).collect();
    let x: f64 = cells[2].parse().unwrap();
    cells[2] = ryu::Buffer::new()
        .format_finite(f64::from_bits(x.to_bits() + 1))
        .to_string();
    lines[5] = cells.join(",");
    std::fs::write(&table, lines.join("\n") + "\n").unwrap();
    let file = read_back(&std::fs::read(&path).unwrap());
    let fields = Channel::Omega.message_type().unwrap().fields;
    let caught = std::panic::catch_unwind(|| compare_flat(&file, "/coin/omega", &table, fields));
    assert!(caught.is_err(), "a one-ulp change must fail the comparison");
}

/// A file written before the fields added since the first version (`verify` accepts it) exports with
/// the first version's fields, bit for bit, and plots.
#[test]
fn a_first_version_file_exports_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let path = repo().join("tests/fixtures/wobble-first-version.mcap");
    let shown = path.to_str().unwrap();
    let out = coin_log(dir.path(), &["export", shown, "--out", "tables"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let file = read_back(&std::fs::read(&path).unwrap());
    let mut compared = 0;
    for c in Channel::DEFAULT {
        if let Some(t) = c.message_type() {
            let table = dir.path().join(format!("tables/{}.csv", c.name()));
            compared += compare_flat(&file, c.topic(), &table, t.first_fields);
        }
    }
    assert_eq!(compared, 61 * 34);
    let out = coin_log(dir.path(), &["plot", shown, "--out", "p.svg"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let svg = std::fs::read_to_string(dir.path().join("p.svg")).unwrap();
    check_plot(&svg, "completed at t = 1");
}

/// The wide table: one row per sample, `<channel>.<field>` columns, values bit for bit; the same from a
/// file without a summary.
#[test]
fn the_wide_table_joins_the_channels_on_t() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "topple", &[]);
    let bare = dir.path().join("bare.mcap");
    without_summary(&path, &bare);
    let file = read_back(&std::fs::read(&path).unwrap());
    for (source, folder) in [("topple.mcap", "wide"), ("bare.mcap", "wide-bare")] {
        let out = coin_log(dir.path(), &["export", source, "--wide", "--out", folder]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        print!("{}", String::from_utf8_lossy(&out.stdout));
        let (header, rows) = csv(&dir.path().join(folder).join(WIDE_TABLE));
        let samples = file.on_topic("/coin/omega");
        assert_eq!(rows.len(), samples.len());
        assert_eq!(header[0], "t");
        let mut compared = 0;
        for (col, name) in header.iter().enumerate().skip(1) {
            let (channel, field) = name.split_once('.').unwrap();
            let channel: Channel = channel.parse().unwrap();
            for (row, m) in rows.iter().zip(file.on_topic(channel.topic())) {
                let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
                assert_eq!(
                    row[col].parse::<f64>().unwrap().to_bits(),
                    v[field].as_f64().unwrap().to_bits(),
                    "{name}"
                );
                assert_eq!(
                    row[0].parse::<f64>().unwrap().to_bits(),
                    v["t"].as_f64().unwrap().to_bits()
                );
                compared += 1;
            }
        }
        // t, then every other field of the eight coin_log channels recorded by default (no `work`
        // without dissipation), from the format's field lists.
        let fields: usize = Channel::DEFAULT
            .iter()
            .filter_map(|c| c.message_type())
            .map(|t| t.fields.len() - 1)
            .sum();
        assert_eq!(header.len(), 1 + fields);
        println!("{source}: {compared} values equal bit for bit");
    }
    assert_eq!(
        std::fs::read(dir.path().join("wide/samples.csv")).unwrap(),
        std::fs::read(dir.path().join("wide-bare/samples.csv")).unwrap()
    );
}

/// Two channels of one topic (legal MCAP) would make one table twice: export refuses the file naming
/// the topic and the table, before anything lands (it moved the first `omega.csv` into place, failed on
/// the second, and left a temporary file in the folder).
#[test]
fn two_channels_of_one_topic_are_refused_and_nothing_lands() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "topple", &["--duration", "1"]);
    for topic in ["/coin/omega", "/tf_static"] {
        let copy = dir.path().join("twice.mcap");
        copy_twice(&path, &copy, mcap::WriteOptions::new(), topic);
        for existing in [false, true] {
            let out_dir = dir.path().join("tables");
            if existing {
                std::fs::create_dir(&out_dir).unwrap();
            }
            let (code, _, err) = coin_log_text(&[
                "export",
                copy.to_str().unwrap(),
                "--out",
                out_dir.to_str().unwrap(),
            ]);
            println!("{topic}: exit {code}: {err}");
            assert_eq!(code, 1, "{err}");
            let table = format!(
                "`{}.csv`",
                topic.trim_start_matches('/').replace("coin/", "")
            );
            assert!(
                err.contains(&format!("two channels of the topic {topic}")) && err.contains(&table),
                "{err}"
            );
            if existing {
                assert!(
                    std::fs::read_dir(&out_dir).unwrap().next().is_none(),
                    "left empty"
                );
                std::fs::remove_dir(&out_dir).unwrap();
            } else {
                assert!(!out_dir.exists(), "not created");
            }
        }
    }
}

/// Parquet is not built in: a clear error naming why and how to convert; nothing is written.
#[test]
fn parquet_is_refused_with_the_way_to_convert() {
    let dir = tempfile::tempdir().unwrap();
    record_scene(dir.path(), "circle-plus", &["--duration", "1"]);
    let out = coin_log(
        dir.path(),
        &["export", "circle-plus.mcap", "--format", "parquet"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    for expected in ["not built in", "crates", "polars", "round_trip"] {
        assert!(err.contains(expected), "`{expected}` in {err}");
    }
    assert!(!dir.path().join("circle-plus-csv").exists());
}

/// An export that stops part way (a truncated file) leaves no table, no temporary file, and not the
/// folder it created.
#[test]
fn a_failed_export_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "wobble", &[]);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(dir.path().join("half.mcap"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    let out = coin_log(dir.path(), &["export", "half.mcap", "--out", "t"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("truncated") && err.contains("nothing exported"),
        "{err}"
    );
    assert!(!dir.path().join("t").exists(), "the folder it made is gone");
    // Into a folder that was there, the folder stays, empty.
    std::fs::create_dir(dir.path().join("u")).unwrap();
    let out = coin_log(dir.path(), &["export", "half.mcap", "--out", "u"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read_dir(dir.path().join("u")).unwrap().count(), 0);
}

fn svg_texts(svg: &str) -> Vec<String> {
    let doc =
        roxmltree::Document::parse(svg).unwrap_or_else(|e| panic!("not well-formed XML: {e}"));
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc.descendants()
        .filter(|n| n.is_element() && n.tag_name().name() == "text")
        .map(|n| {
            n.descendants()
                .filter(roxmltree::Node::is_text)
                .filter_map(|d| d.text())
                .collect::<String>()
                .trim()
                .to_string()
        })
        .collect()
}

/// Checks an overview SVG: well-formed, every panel titled, the termination named.
fn check_plot(svg: &str, termination: &str) {
    let texts = svg_texts(svg);
    for panel in PANELS {
        assert!(
            texts.iter().any(|t| t == panel),
            "panel `{panel}` missing; texts: {texts:?}"
        );
    }
    assert!(
        texts.iter().any(|t| t.contains(termination)),
        "`{termination}` marked"
    );
}

/// `plot` of wobble and topple: well-formed SVG with every panel and the termination; the committed
/// pictures in docs/ are such pictures too; a file that is not coin-log's is refused.
#[test]
fn plot_draws_every_panel_and_marks_the_termination() {
    let dir = tempfile::tempdir().unwrap();
    for (name, termination) in [
        ("wobble", "completed at t = 30"),
        ("topple", "flat-landing at t = 1.9"),
    ] {
        record_scene(dir.path(), name, &[]);
        let out = coin_log(dir.path(), &["plot", &format!("{name}.mcap")]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let svg = std::fs::read_to_string(dir.path().join(format!("{name}.svg"))).unwrap();
        check_plot(&svg, termination);
        let committed =
            std::fs::read_to_string(repo().join(format!("docs/plot-{name}.svg"))).unwrap();
        check_plot(&committed, termination);
        // Again: refused without --overwrite.
        let out = coin_log(dir.path(), &["plot", &format!("{name}.mcap")]);
        assert_eq!(out.status.code(), Some(1));
    }
    // Negative control: an SVG without the panels fails the check.
    let bare = "<svg xmlns=\"http://www.w3.org/2000/svg\"><text>lean θ(t)</text></svg>";
    assert!(std::panic::catch_unwind(|| check_plot(bare, "completed")).is_err());
    std::fs::write(dir.path().join("other.mcap"), b"\x89MCAP0\r\n").unwrap();
    let out = coin_log(dir.path(), &["plot", "other.mcap"]);
    assert_eq!(out.status.code(), Some(1));
}

/// A description may hold U+FFFE and U+FFFF (`record` refuses only control characters), which XML 1.0
/// does not allow in a document: plot wrote them into the title as they were, and the SVG was not
/// well-formed (Python's parser: "not well-formed (invalid token)"). They are drawn escaped, as a message
/// shows a control character.
#[test]
fn plot_escapes_the_characters_xml_does_not_allow() {
    let dir = tempfile::tempdir().unwrap();
    let (code, toml, err) = coin_log_text(&["scenes", "--show", "circle-plus"]);
    assert_eq!(code, 0, "{err}");
    let toml: String = toml
        .lines()
        .map(|l| {
            if l.starts_with("description") {
                "description = \"odd \\uFFFE \\uFFFF <&> ]]> end\"".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let scene = dir.path().join("odd.toml");
    std::fs::write(&scene, toml).unwrap();
    record_scene(dir.path(), scene.to_str().unwrap(), &["--duration", "0.1"]);
    let out = coin_log(dir.path(), &["plot", "odd.toml.mcap", "-o", "odd.svg"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(dir.path().join("odd.svg")).unwrap();
    let texts = svg_texts(&svg);
    assert!(
        texts
            .iter()
            .any(|t| t.starts_with("odd \\u{fffe} \\u{ffff} <&> ]]> end")),
        "{texts:?}"
    );
}

/// A scene in units where a = g = 1e70 (within the limits `record` accepts) was plotted with tick labels
/// and settings of 70 and more digits (`-6000000000000000435188618289175410756950246457879131733109260932874240.0`,
/// `a = 10000000000000000000000000000000000000000000000000000000000000000000000`), far wider than the
/// label area: large values are written in exponent form, as `info` writes them (`a = 1e70`).
#[test]
fn plot_writes_large_values_in_exponent_form() {
    let dir = tempfile::tempdir().unwrap();
    record_scene(
        dir.path(),
        "circle-plus",
        &[
            "--duration",
            "0.5",
            "--set",
            "body.radius=1e70",
            "--set",
            "body.gravity=1e70",
        ],
    );
    let out = coin_log(dir.path(), &["plot", "circle-plus.mcap"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let texts = svg_texts(&std::fs::read_to_string(dir.path().join("circle-plus.svg")).unwrap());
    let longest_number = |t: &str| {
        t.split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max()
            .unwrap_or(0)
    };
    for t in &texts {
        assert!(longest_number(t) < 20, "a number of 20 digits or more: {t}");
    }
    assert!(
        texts
            .iter()
            .any(|t| t.contains("a = 1e70, g = 1e70, I_X = 2.5e139, I_Z = 5e139")),
        "{texts:?}"
    );
    // The track panel's ticks (of the order of 1e70) are labelled in exponent form, and the one at 0,
    // which plotters computes as about 1e55 off, as 0.
    let large = texts
        .iter()
        .filter(|t| t.contains('e') && t.parse::<f64>().is_ok_and(|v| v.abs() >= 1e60))
        .count();
    assert!(large >= 8, "{large} large ticks: {texts:?}");
    assert!(
        !texts.iter().any(
            |t| t.parse::<f64>().is_ok_and(|v| v != 0.0 && v.abs() < 1e60)
                && t.contains('e')
                && !t.contains("e-")
        ),
        "{texts:?}"
    );
}

/// A run of a microsecond: every time panel's ticks tell the times apart (plotters' own labels, 5 decimals
/// without an exponent, printed `0.0` on every tick: 56 of them on the page).
#[test]
fn a_microsecond_run_is_plotted_with_time_ticks_that_differ() {
    let dir = tempfile::tempdir().unwrap();
    record_scene(
        dir.path(),
        "wobble",
        &["--duration", "1e-6", "--rate", "1e7"],
    );
    let out = coin_log(dir.path(), &["plot", "wobble.mcap"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let texts = svg_texts(&std::fs::read_to_string(dir.path().join("wobble.svg")).unwrap());
    let count = |label: &str| texts.iter().filter(|t| *t == label).count();
    // θ, energy drift, invariant drift, N and |F|/N: five time axes.
    for tick in ["0", "2.0e-7", "5.0e-7", "1.0e-6"] {
        assert_eq!(count(tick), 5, "tick `{tick}`: {texts:?}");
    }
    assert!(count("0.0") <= 1, "{texts:?}");
}

/// Values whose drift or ratio spans more than the doubles can (a stored energy of 1e300 against E0 ≈ 2.6;
/// C1 = 1e300 at one sample; N = 1e-320, so |F|/N overflows; θ or the centre at ±1e308) are drawn, not
/// waited on: plotters' log axis counted its decades as `usize` from a span of `inf` and looped for hours,
/// its linear axis likewise on an infinite range, and the track panel's range of NaN panicked (found by
/// mutation fuzzing of the readers).
#[test]
fn plot_finishes_on_values_that_overflow_its_axes() {
    use crate::support::record::{coin_log_within, HANG_DEADLINE};
    use crate::support::writers::{nudge, rewrite};
    let dir = tempfile::tempdir().unwrap();
    let recorded = record_scene(dir.path(), "wobble", &["--duration", "0.2"]);
    let set = |data: &mut Vec<u8>, field: &str, to: f64| {
        let v: serde_json::Value = serde_json::from_slice(data).unwrap();
        nudge(data, field, to - v[field].as_f64().unwrap());
    };
    // (topic, field, [(message index, value)]).
    type Damage<'a> = (&'a str, &'a str, &'a [(usize, f64)]);
    let cases: [Damage<'_>; 6] = [
        ("/coin/energy", "total", &[(4, 1e300)]),
        ("/coin/angles", "theta", &[(3, 1e308), (5, -1e308)]),
        ("/coin/invariants", "c1", &[(4, 1e300)]),
        ("/coin/invariants", "c1", &[(0, 1e300)]),
        ("/coin/reaction", "normal", &[(4, 1e-320)]),
        ("/coin/position", "x", &[(3, 1e308), (5, -1e308)]),
    ];
    for (topic, field, values) in cases {
        let damaged = dir.path().join("damaged.mcap");
        rewrite(&recorded, &damaged, |e| {
            for &(index, to) in values {
                if e.topic == topic && e.index == index {
                    set(e.data, field, to);
                }
            }
        });
        let svg = dir.path().join("damaged.svg");
        let (code, _, err) = coin_log_within(
            HANG_DEADLINE,
            &[
                "plot",
                damaged.to_str().unwrap(),
                "-o",
                svg.to_str().unwrap(),
                "--overwrite",
            ],
        );
        assert_eq!(code, 0, "{topic} {field} {values:?}: {err}");
        check_plot(&std::fs::read_to_string(&svg).unwrap(), "completed");
    }
}

/// The default outputs of a file whose name is not UTF-8 are named with its stem's own bytes (`\xff.svg`,
/// `\xff-csv`), not a lossy copy (`\u{fffd}.svg`, which two such names would share).
#[test]
fn default_outputs_keep_the_bytes_of_a_name_that_is_not_utf8() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let recorded = record_scene(dir.path(), "wobble", &["--duration", "0.1"]);
    let file = OsStr::from_bytes(b"\xff.mcap");
    std::fs::rename(&recorded, dir.path().join(file)).unwrap();
    for command in ["plot", "export"] {
        let out = coin_log(dir.path(), &[OsStr::new(command), file]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{command}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let mut names: Vec<Vec<u8>> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().as_bytes().to_vec())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            b"\xff-csv".to_vec(),
            b"\xff.mcap".to_vec(),
            b"\xff.svg".to_vec()
        ]
    );
}

/// `export --wide` of a file with only frame transforms: the error names, for each topic, the table that
/// exporting per channel writes (it said `tf.csv` for /tf_static and /scene/follow too).
#[test]
fn the_wide_error_names_each_frame_topics_own_table() {
    let dir = tempfile::tempdir().unwrap();
    record_scene(
        dir.path(),
        "wobble",
        &["--duration", "0.1", "--channels", "tf,scene"],
    );
    let out = coin_log(dir.path(), &["export", "wobble.mcap", "--wide"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    for (topic, table) in [
        ("/tf", "tf.csv"),
        ("/tf_static", "tf_static.csv"),
        ("/scene/follow", "scene_follow.csv"),
    ] {
        let says = format!(
            "{topic}: frame transforms are not one per sample; export per channel for {table}"
        );
        assert!(stderr.contains(&says), "{says}: {stderr}");
    }
}

/// `info` of a recording at 0.001 samples per time unit: the rate column shows the rate (`1.00e-3`), not
/// `0.00` as if the channel had none (ordinary rates keep two decimals: the README's example pins them).
#[test]
fn info_shows_a_rate_below_two_decimals() {
    let dir = tempfile::tempdir().unwrap();
    record_scene(
        dir.path(),
        "wobble",
        &[
            "--duration",
            "3000",
            "--rate",
            "0.001",
            "--channels",
            "omega",
        ],
    );
    let out = coin_log(dir.path(), &["info", "wobble.mcap"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    let row = text
        .lines()
        .find(|l| l.trim_start().starts_with("/coin/omega"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(row.trim_end().ends_with(" 4    1.00e-3"), "{row}");
}

/// The paths the test used, for the README's example: every committed dataset is described by `info`.
#[test]
fn info_describes_every_committed_dataset_from_its_summary() {
    let files: Vec<PathBuf> = crate::support::dataset_files();
    let mut args = vec!["info".to_string(), "--json".to_string()];
    args.extend(files.iter().map(|p| p.display().to_string()));
    let out = coin_log(&repo(), &args);
    assert_eq!(out.status.code(), Some(0));
    let v = json(&out);
    for (f, path) in v["files"].as_array().unwrap().iter().zip(&files) {
        let file = read_back(&std::fs::read(path).unwrap());
        let (expected, _, _) = counts(&file);
        assert_eq!(f["read_from"], "summary");
        assert_eq!(
            f["messages"],
            expected.values().sum::<u64>(),
            "{}",
            path.display()
        );
        assert_eq!(f["result"]["termination"], "completed");
    }
}

/// A summary section whose CRC does not match is not trusted: `info` reads the whole file instead, and
/// names the damage (exit 1); the counts still come from the messages themselves.
#[test]
fn info_does_not_trust_a_summary_whose_crc_fails() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "circle-plus", &["--duration", "2"]);
    let mut bytes = std::fs::read(&path).unwrap();
    let footer = bytes.len() - 37;
    let summary_start =
        u64::from_le_bytes(bytes[footer + 9..footer + 17].try_into().unwrap()) as usize;
    // A byte inside the first summary record's body (the schema's data): only the CRC can tell.
    bytes[summary_start + 40] ^= 0x20;
    std::fs::write(dir.path().join("bad.mcap"), &bytes).unwrap();
    let out = coin_log(dir.path(), &["info", "--json", "bad.mcap"]);
    assert_eq!(out.status.code(), Some(1));
    let f = &json(&out)["files"][0];
    println!("{f}");
    assert_eq!(f["read_from"], "scan");
    assert!(f["problem"].as_str().unwrap().contains("summary"), "{f}");
    let file = read_back(&std::fs::read(&path).unwrap());
    assert_eq!(f["messages"], file.messages.len());
}

#[test]
fn log_times_print_as_exact_decimals() {
    for (ns, text) in [
        (0, "0"),
        (1_500_000_000, "1.5"),
        (10_000_000, "0.01"),
        (1, "0.000000001"),
        (30_000_000_001, "30.000000001"),
    ] {
        assert_eq!(seconds_text(ns), text);
    }
}

/// `info --scene` on a file that cannot be read to its end (cut in its chunk, or with a header record
/// claiming more bytes than the file has) still prints the stored scene, but exits 1 with the problem on
/// stderr, as `info` does, and its comment does not claim that a command line writes the same bytes again.
#[test]
fn the_stored_scene_of_a_damaged_file_is_printed_with_exit_1_and_no_reproduction_claim() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "straight", &["--duration", "0.5"]);
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let mut lying = bytes.clone();
    lying[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
    let header = dir.path().join("header.mcap");
    std::fs::write(&header, &lying).unwrap();
    for (file, problem) in [
        (&cut, "truncated"),
        (&header, "claims 18446744073709551615 bytes"),
    ] {
        let (code, text, err) = coin_log_text(&["info", file.to_str().unwrap(), "--scene"]);
        println!(
            "exit {code}: {err}{}",
            text.lines().take(3).collect::<Vec<_>>().join("\n")
        );
        assert_eq!(code, 1, "{text}{err}");
        assert!(err.starts_with("error: ") && err.contains(problem), "{err}");
        assert!(
            text.contains("could not be read to its end")
                && !text.contains("writes the same bytes"),
            "{text}"
        );
        assert!(text.contains("[body]"), "the scene is printed: {text}");
    }
    // The whole file: exit 0 and the command line.
    let (code, text, err) = coin_log_text(&["info", path.to_str().unwrap(), "--scene"]);
    assert_eq!(code, 0, "{err}");
    assert!(text.contains("writes the same bytes again"), "{text}");
}

/// `info --scene` on a file read whole whose summary is damaged (its metadata index entry points a byte
/// past the record, as @mcap/core's unchunked writer makes it, with no summary CRC to catch it):
/// exit 1 with the problem, as `info`, and the comment says why no command line writes the bytes without
/// claiming that the file could not be read to its end (it said so, though the whole file was read).
#[test]
fn the_stored_scene_of_a_file_with_a_damaged_summary_says_the_whole_file_was_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "straight", &["--duration", "0.5"]);
    let mut bytes = std::fs::read(&path).unwrap();
    // The footer (opcode, length, summary_start, ...) is the 29 bytes before the end magic.
    let footer = bytes.len() - 8 - 29;
    let summary_start = usize::try_from(u64::from_le_bytes(
        bytes[footer + 9..footer + 17].try_into().unwrap(),
    ))
    .unwrap();
    // Walk the summary's records to the metadata index (opcode 0x0D): its first field is the offset.
    let mut at = summary_start;
    while bytes[at] != 0x0D {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap());
        at += 9 + usize::try_from(len).unwrap();
    }
    let offset = u64::from_le_bytes(bytes[at + 9..at + 17].try_into().unwrap());
    bytes[at + 9..at + 17].copy_from_slice(&(offset + 1).to_le_bytes());
    // No summary CRC (0: not computed), so that the summary reads and only the index is wrong.
    bytes[footer + 25..footer + 29].copy_from_slice(&[0; 4]);
    let damaged = dir.path().join("damaged.mcap");
    std::fs::write(&damaged, &bytes).unwrap();
    let (code, text, err) = coin_log_text(&["info", damaged.to_str().unwrap(), "--scene"]);
    println!(
        "exit {code}: {err}{}",
        text.lines().take(3).collect::<Vec<_>>().join("\n")
    );
    assert_eq!(code, 1, "{text}{err}");
    assert!(err.contains("the summary section is damaged"), "{err}");
    assert!(!text.contains("could not be read to its end"), "{text}");
    assert!(!text.contains("writes the same bytes again:"), "{text}");
    assert!(
        text.contains("Its summary section is damaged") && text.contains("the whole file was read"),
        "{text}"
    );
    assert!(text.contains("[body]"), "the scene is printed: {text}");
}

/// A frame transform that does not decode is named by its own topic: every frame-transform topic has its
/// table, and the error said `/tf` for a message on /tf_static or /scene/follow too.
#[test]
fn an_undecodable_frame_transform_is_named_by_its_own_topic() {
    let dir = tempfile::tempdir().unwrap();
    let recorded = record_scene(
        dir.path(),
        "wobble",
        &["--duration", "0.1", "--channels", "tf,scene"],
    );
    for topic in ["/tf", "/tf_static", "/scene/follow"] {
        let damaged = dir.path().join("damaged.mcap");
        crate::support::writers::rewrite(&recorded, &damaged, |e| {
            if e.topic == topic && e.index == 0 {
                *e.data = b"{".to_vec();
            }
        });
        let out = coin_log(dir.path(), &["export", "damaged.mcap", "--out", "x"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{topic}: {stderr}");
        assert!(
            stderr.contains(&format!("{topic}: the message at log time ")),
            "{topic}: {stderr}"
        );
        assert!(
            stderr.contains("is not a foxglove.FrameTransform"),
            "{topic}: {stderr}"
        );
    }
}

#[test]
fn plot_gives_a_tiny_track_a_scale() {
    // Plotters puts one tick on an axis narrower than about 2.2e-16: a track where a = 1e-70 had one
    // label on each axis, no scale at all. It is now drawn in units of a power of ten, its ticks
    // labelled in the true values.
    let dir = tempfile::tempdir().unwrap();
    let tiny = ["body.radius=1e-70", "body.gravity=1e-70"];
    let mut args = vec!["--duration", "2", "--atol", "1e-75"];
    for set in &tiny {
        args.extend(["--set", set]);
    }
    record_scene(dir.path(), "circle-plus", &args);
    let out = coin_log(dir.path(), &["plot", "circle-plus.mcap"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let texts = svg_texts(&std::fs::read_to_string(dir.path().join("circle-plus.svg")).unwrap());
    let ticks: Vec<f64> = texts
        .iter()
        .filter_map(|t| t.trim().parse::<f64>().ok())
        .filter(|v| *v != 0.0 && v.abs() < 1e-60)
        .collect();
    assert!(ticks.len() >= 8, "{ticks:?}: {texts:?}");
    // The track lies within a few radii (R_C = 5.2 a) of the origin.
    assert!(ticks.iter().all(|v| v.abs() < 2e-69), "{ticks:?}");
}
