//! `bench throughput`. The library part: the workload recorded in-process is byte for byte the
//! file the command's child `coin-log record` writes, its compression bound counts every message, and the
//! rows follow from the runs (medians, rates, ratio, missing peak RSS). The command on a tiny workload
//! prints sane rows, and `record --json` / `verify --json` carry `peak_rss_bytes`. No timing assertions:
//! the numbers depend on the machine.
#![allow(
    clippy::unwrap_used,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use crate::support::process::Process;
use crate::support::record::{coin_log, exe};
use crate::support::repo;
use coin_log::record::{self, RecordOptions};
use coin_log_bench::throughput::{
    self, compression_bound, recording_path, workload_scene, Bound, DurationRuns, ExportRun,
    RecordRun, ThroughputError, ThroughputReport, ThroughputRow, VerifyRun, CSV_HEADER,
};
use coin_log_mcap::Compression;
use std::io::Cursor;
use std::process::Command;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

fn row<'a>(rows: &'a [ThroughputRow], workload_starts: &str, quantity: &str) -> &'a ThroughputRow {
    rows.iter()
        .find(|r| r.workload.starts_with(workload_starts) && r.quantity == quantity)
        .unwrap_or_else(|| panic!("no row {workload_starts} / {quantity}: {rows:#?}"))
}

/// The fields of one CSV line (quoted fields may hold commas and doubled quotes).
fn csv_fields(line: &str) -> Vec<String> {
    let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

/// Relative difference, for values computed from exact inputs.
fn close(measured: f64, expected: f64) -> bool {
    (measured - expected).abs() <= 1e-15 * expected.abs()
}

#[test]
fn the_throughput_command_records_the_library_workload_and_prints_sane_rows() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(exe())
        .args([
            "bench",
            "throughput",
            "--durations",
            "0.5,1",
            "--repeats",
            "1",
        ])
        .arg("--out")
        .arg(dir.path())
        .arg("--keep")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    print!("{stdout}");
    assert!(
        out.status.success(),
        "bench throughput: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("throughput.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(CSV_HEADER));
    // Eleven rows per duration: record 5, bound 2, verify 2, export 2 (the integration and one RHS
    // evaluation are criterion benchmarks).
    let rows: Vec<Vec<String>> = lines.map(csv_fields).collect();
    assert_eq!(rows.len(), 2 * 11, "{csv}");
    for fields in &rows {
        let value: f64 = fields[2].parse().unwrap();
        println!("{} / {}: {value}", fields[0], fields[1]);
        assert!(
            value.is_finite() && value > 0.0,
            "{fields:?}: expected finite and > 0"
        );
    }

    for duration in [0.5, 1.0] {
        let path = recording_path(dir.path(), duration);
        let kept = std::fs::read(&path).unwrap();
        let scene = workload_scene(duration).unwrap();
        let mut recorded = Cursor::new(Vec::new());
        let options = RecordOptions {
            compression: Compression::Zstd,
            ..RecordOptions::default()
        };
        let summary = record::record(
            &scene,
            &options,
            &mut recorded,
            &AtomicBool::new(false),
            |_| {},
        )
        .unwrap();
        assert!(
            recorded.get_ref() == &kept,
            "duration {duration}: the in-process workload ({} bytes) differs from the command's \
             recording ({} bytes)",
            recorded.get_ref().len(),
            kept.len()
        );
        let bound = compression_bound(&path).unwrap();
        // 7 channels at 1 kHz, samples at 0, 1 ms, ..., duration.
        let expected = 7 * (1000.0 * duration) as u64 + 7;
        println!(
            "duration {duration}: recorded {} messages, read back {}, expected {expected}",
            summary.messages, bound.messages
        );
        assert_eq!(summary.messages, expected);
        assert_eq!(bound.messages, expected);
        assert!(bound.json_bytes > bound.compressed_bytes && bound.compressed_bytes > 0);
        assert!(bound.seconds > 0.0);
    }
}

#[test]
fn the_rows_are_medians_and_rates_of_the_runs() {
    const MIB: u64 = 1 << 20;
    let messages = 7007;
    let record = |seconds, peak_rss| RecordRun {
        messages,
        bytes: 100_000,
        seconds,
        peak_rss,
    };
    let bound = |seconds| Bound {
        messages,
        json_bytes: 400_000,
        compressed_bytes: 100_000,
        seconds,
    };
    let verify = |seconds| VerifyRun {
        seconds,
        peak_rss: None,
    };
    let export = |seconds| ExportRun {
        seconds,
        peak_rss: Some(3 * MIB),
    };
    let runs = DurationRuns {
        records: vec![
            record(3.0, Some(10 * MIB)),
            record(1.0, None),
            record(2.0, Some(12 * MIB)),
        ],
        bounds: vec![bound(0.5), bound(1.5), bound(1.0)],
        verifies: vec![verify(1.0), verify(1.0), verify(4.0)],
        exports: vec![export(7.0), export(0.5), export(3.5)],
        ..DurationRuns::new(0.5)
    };
    let rows = runs.rows().unwrap();
    let report = ThroughputReport::new(rows.clone());
    print!("{}", throughput::table(&report));
    assert_eq!(rows.len(), 11);
    // Medians: record 2 s, bound 1 s, verify 1 s, export 3.5 s; peak RSS of the two reported, 11 MiB.
    let checks = [
        ("record wobble 0.5", "messages/s", 7007.0 / 2.0),
        ("record wobble 0.5", "JSON MB/s", 400_000.0 / 2.0 / 1e6),
        ("record wobble 0.5", "file size", 100_000.0),
        ("record wobble 0.5", "peak RSS", 11.0 * 1_048_576.0),
        ("zstd bound 0.5", "compression time", 1.0),
        ("zstd bound 0.5", "record time / bound", 2.0),
        ("verify 0.5", "messages/s", 7007.0),
        ("export 0.5", "messages/s", 7007.0 / 3.5),
        ("export 0.5", "peak RSS", 3.0 * 1_048_576.0),
    ];
    for (workload, quantity, expected) in checks {
        let r = row(&rows, workload, quantity);
        println!("{workload} / {quantity}: {} (expected {expected})", r.value);
        assert!(close(r.value, expected), "{r:?}: expected {expected}");
    }
    assert_eq!(
        row(&rows, "zstd bound", "record time / bound").met(),
        Some(true),
        "a ratio of exactly 2 meets the target ≤ 2"
    );
    let unreported = row(&rows, "verify", "peak RSS");
    assert!(
        unreported.value.is_nan(),
        "{unreported:?}: no peak RSS was reported"
    );
    let csv = throughput::csv(&report);
    assert!(csv.starts_with(CSV_HEADER));
    assert_eq!(csv.lines().count(), rows.len() + 1);

    let no_export = DurationRuns {
        exports: Vec::new(),
        ..runs.clone()
    };
    assert!(matches!(
        no_export.rows(),
        Err(ThroughputError::NoRuns { .. })
    ));
    let empty = DurationRuns {
        verifies: Vec::new(),
        ..runs
    };
    assert!(matches!(
        empty.rows(),
        Err(ThroughputError::NoRuns { duration }) if close(duration, 0.5)
    ));
}

fn run(args: &[&str]) -> serde_json::Value {
    let out = coin_log(&repo(), args);
    assert!(
        out.status.success(),
        "coin-log {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn record_and_verify_json_carry_the_peak_rss() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("w.mcap");
    let p = path.to_str().unwrap();
    let record = run(&["record", "wobble", "--duration", "1", "-o", p, "--json"]);
    let verify = run(&["verify", p, p, "--json"]);
    let files = verify["files"].as_array().unwrap();
    assert_eq!(files.len(), 2);
    let mut peaks = vec![&record["peak_rss_bytes"]];
    peaks.extend(files.iter().map(|f| &f["peak_rss_bytes"]));
    for peak in peaks {
        println!("peak_rss_bytes: {peak}");
        if cfg!(target_os = "linux") {
            let bytes = peak.as_u64().unwrap_or(0);
            assert!(bytes > 1 << 20, "peak RSS {bytes} B, expected > 1 MiB");
        } else {
            assert!(peak.is_null() || peak.is_u64(), "{peak}");
        }
    }
}

/// The bench deletes its recordings and its export folders when done. A link or a named pipe of a
/// recording's name is refused before any work and kept (it was deleted after the child `record` refused
/// it), and a folder of the user's named like the old export folder (`throughput-D.csv.d`) is neither
/// written into nor deleted: the exports go to a folder of the bench's own, removed afterwards.
#[test]
fn what_the_bench_did_not_write_is_never_deleted() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(dir.path().join("precious.txt"), "mine").unwrap();
    std::os::unix::fs::symlink(
        dir.path().join("precious.txt"),
        out.join("throughput-0.01.mcap"),
    )
    .unwrap();
    crate::support::mkfifo(&out.join("throughput-0.02.mcap"));
    for d in ["0.01", "0.02"] {
        let run = coin_log(
            &out,
            &[
                "bench",
                "throughput",
                "--durations",
                d,
                "--repeats",
                "1",
                "--out",
                ".",
            ],
        );
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{d}: {stderr}");
        assert!(stderr.contains(&format!("throughput-{d}.mcap")), "{stderr}");
        assert!(
            !stderr.contains("exited with"),
            "refused before any run: {stderr}"
        );
    }
    let link = std::fs::symlink_metadata(out.join("throughput-0.01.mcap")).unwrap();
    assert!(link.file_type().is_symlink(), "the link is kept");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("precious.txt")).unwrap(),
        "mine"
    );
    assert!(
        std::fs::symlink_metadata(out.join("throughput-0.02.mcap")).is_ok(),
        "the pipe is kept"
    );

    let mine = out.join("throughput-0.03.csv.d");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    let run = coin_log(
        &out,
        &[
            "bench",
            "throughput",
            "--durations",
            "0.03",
            "--repeats",
            "1",
            "--out",
            ".",
        ],
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
        "mine"
    );
    assert_eq!(
        std::fs::read_dir(&mine).unwrap().count(),
        1,
        "nothing exported into it"
    );
    let mut left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        [
            "throughput-0.01.mcap",
            "throughput-0.02.mcap",
            "throughput-0.03.csv.d",
            "throughput.csv"
        ],
        "the recording and the export folder are gone, the user's entries kept"
    );
}

/// A duration the workload cannot measure is refused before any run, naming --durations: one beyond the
/// 64-bit nanosecond log times was refused by the child `record` of that duration after the others had
/// been measured, in a message quoting the child's command line; one too short for verify to judge (1e-9:
/// one sample) by the child `verify`, with "cannot verify".
#[test]
fn a_duration_the_workload_cannot_measure_is_refused_before_any_run() {
    let dir = tempfile::tempdir().unwrap();
    for (durations, shown, reason) in [
        (
            "0.01,2e10",
            "20000000000.0",
            "`run.duration` = 20000000000 is too long",
        ),
        (
            "0.01,1e-9",
            "1e-9",
            "the run has 1 on its sampling grid; give a longer duration\n",
        ),
    ] {
        let run = coin_log(
            dir.path(),
            &[
                "bench",
                "throughput",
                "--durations",
                durations,
                "--repeats",
                "1",
                "--out",
                "o",
            ],
        );
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{stderr}");
        assert!(
            stderr.starts_with(&format!(
                "error: --durations: {shown} time units cannot be measured"
            )),
            "{stderr}"
        );
        assert!(stderr.contains(reason), "{stderr}");
        assert!(!stderr.contains("exited with"), "{stderr}");
        assert!(run.stdout.is_empty());
        assert!(
            !dir.path().join("o").exists(),
            "nothing measured, nothing written"
        );
    }
}

/// SIGTERM to the bench alone (a scheduler's stop, `kill PID`) killed it and left its recording, with its
/// child `record` running on. Now the child is stopped as the signal stops it, the recordings are removed,
/// nothing else is written, and the bench exits 130.
#[test]
fn a_signal_stops_the_bench_and_its_child_and_removes_the_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut bench = Process::start(
        Command::new(exe())
            .args([
                "bench",
                "throughput",
                "--durations",
                "200",
                "--repeats",
                "1",
            ])
            .arg("--out")
            .arg(&out),
    );
    let entries = || std::fs::read_dir(&out).map_or(0, Iterator::count);
    let started = Instant::now();
    while entries() == 0 {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no recording appeared"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(300));
    let status = Command::new("kill")
        .args(["-TERM", &bench.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success(), "the bench ended before the signal");
    let ended = bench.wait_within(Duration::from_secs(60));
    assert_eq!(ended.status.code(), Some(130), "{}", ended.stderr);
    assert!(ended.stderr.contains("interrupted"), "{}", ended.stderr);
    // A child left running would still move its file into place.
    std::thread::sleep(Duration::from_millis(500));
    let left: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
    assert!(left.is_empty(), "{left:?}\n{}", ended.stderr);
}
