//! `bench throughput` (issue 9) on a tiny workload: the library's rows are sane (counts agree, times
//! positive, the bound ratio finite), and `record --json` / `verify --json` carry `peak_rss_bytes`. No
//! timing assertions: the numbers depend on the machine.
#![allow(
    clippy::unwrap_used,
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss
)]

use crate::support::record::{coin_log, exe};
use crate::support::repo;
use coin_log::bench::throughput::{
    self, compression_bound, record_run, recording_path, ThroughputOptions,
};

fn value(rows: &[throughput::ThroughputRow], workload_starts: &str, quantity: &str) -> f64 {
    rows.iter()
        .find(|r| r.workload.starts_with(workload_starts) && r.quantity == quantity)
        .unwrap_or_else(|| panic!("no row {workload_starts} / {quantity}: {rows:#?}"))
        .value
}

#[test]
fn the_throughput_bench_returns_sane_rows_on_a_tiny_workload() {
    let dir = tempfile::tempdir().unwrap();
    let options = ThroughputOptions {
        exe: exe(),
        dir: dir.path().to_path_buf(),
        durations: vec![0.5, 1.0],
        repeats: 1,
    };
    let report = throughput::run(&options).unwrap();
    print!("{}", throughput::table(&report));
    assert!(report.cores >= 1);
    for r in &report.rows {
        assert!(
            r.value.is_finite() && r.value > 0.0,
            "{} / {}: {} (expected finite and > 0)",
            r.workload,
            r.quantity,
            r.value
        );
    }
    for duration in [0.5, 1.0] {
        let path = recording_path(dir.path(), duration);
        let recorded = record_run(&exe(), &path, duration).unwrap();
        let bound = compression_bound(&path).unwrap();
        // 7 channels at 1 kHz, samples at 0, 1 ms, ..., duration.
        let expected = 7 * (1000.0 * duration) as u64 + 7;
        println!(
            "duration {duration}: record {} messages, read back {}, expected {expected}",
            recorded.messages, bound.messages
        );
        assert_eq!(recorded.messages, expected);
        assert_eq!(bound.messages, recorded.messages);
        assert!(bound.json_bytes > bound.compressed_bytes && bound.compressed_bytes > 0);
        assert!(bound.seconds > 0.0);
    }
    let ratio = value(&report.rows, "zstd bound 1", "record time / bound");
    assert!(ratio.is_finite() && ratio > 0.0, "ratio {ratio}");
    let csv = throughput::csv(&report);
    assert!(csv.starts_with(throughput::CSV_HEADER));
    assert_eq!(csv.lines().count(), report.rows.len() + 1);
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
