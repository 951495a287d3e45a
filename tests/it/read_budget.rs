//! The reader's memory budget (`coin_log_mcap::READ_MEMORY_BOUND`), held by every command that reads a
//! file: `verify`, `info`, `export` and `plot` each run as a child process on files crafted to cost
//! memory (issue 25: zero bytes after the magic, zstd chunk bombs with a true and a false declared size,
//! ten million legal unknown records in a good file, records claiming more than the reader accepts, a map
//! of a million entries), with their peak RSS measured by the kernel (`support::rss`) and asserted under
//! the bound; what exceeds the budget is refused with the figure. Chunks at the limit (the positive
//! control) read like small ones, within the same bound.

#![allow(clippy::unwrap_used)]

use crate::support::crafted;
use crate::support::rss::{coin_log_peak, Measured};
use crate::support::writers::{record, recorded, wobble, Spec};
use coin_log_mcap::{MAX_RECORD_BYTES, READ_MEMORY_BOUND};
use mcap::records::op;
use std::path::Path;

/// The limit as the reader's messages give it.
const LIMIT: &str = "16777216 bytes (16 MiB)";

/// Runs `verify`, `info`, `export` and `plot` on `file`, prints each one's peak RSS, and asserts it
/// under the budget; returns them in that order.
fn every_command(kind: &str, file: &Path) -> Vec<Measured> {
    let out = tempfile::tempdir().unwrap();
    let csv = out.path().join("csv");
    let svg = out.path().join("plot.svg");
    let f = file.to_str().unwrap();
    let runs = [
        vec!["verify", f],
        vec!["info", f],
        vec!["export", f, "--out", csv.to_str().unwrap()],
        vec!["plot", f, "--out", svg.to_str().unwrap()],
    ];
    let mut over = Vec::new();
    let measured: Vec<Measured> = runs
        .iter()
        .map(|args| {
            let m = coin_log_peak(args);
            let mib = m.peak_rss as f64 / f64::from(1 << 20);
            println!(
                "{kind}: {:<6} peak RSS {mib:7.1} MiB, exit {}: {}",
                args[0],
                m.code,
                m.stderr.lines().last().unwrap_or("").trim()
            );
            if m.peak_rss >= READ_MEMORY_BOUND {
                over.push(format!("{} {mib:.1} MiB", args[0]));
            }
            m
        })
        .collect();
    assert!(
        over.is_empty(),
        "{kind}: peak RSS at or above the reader's bound of {} MiB: {over:?}",
        READ_MEMORY_BOUND >> 20
    );
    measured
}

#[test]
fn four_hundred_megabytes_of_zeros_after_the_magic_are_read_within_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("zeros.mcap");
    crafted::zeros_after_magic(&path, 400_000_000);
    let [verify, ..] = &every_command("400 MB of zeros", &path)[..] else {
        unreachable!()
    };
    assert_eq!(verify.code, 2, "{}", verify.stderr);
    assert!(verify.stderr.contains("truncated"), "{}", verify.stderr);
}

#[test]
fn a_chunk_bomb_declaring_its_true_size_is_refused_before_it_is_decompressed() {
    let dir = tempfile::tempdir().unwrap();
    let expanded = (256 << 20) + (1 << 20);
    for (name, declared) in [("true size", expanded), ("2^40", 1 << 40)] {
        let path = dir.path().join("bomb.mcap");
        crafted::chunk_bomb(&path, expanded, declared);
        let len = std::fs::metadata(&path).unwrap().len();
        assert!(len < 64 << 10, "{len} bytes");
        let runs = every_command(
            &format!("chunk bomb ({len} B to 257 MiB), declaring {name}"),
            &path,
        );
        let at = crafted::start().len();
        let refusal = format!(
            "the chunk at byte {at} declares {declared} bytes of records, more than the {LIMIT} this \
             reader accepts in one chunk"
        );
        assert_eq!(runs[0].code, 2, "{}", runs[0].stderr);
        for m in &runs[..2] {
            assert!(
                m.stderr.contains(&refusal) || m.stdout.contains(&refusal),
                "{m:?}"
            );
        }
    }
}

#[test]
fn a_chunk_bomb_declaring_a_small_size_is_corrupt_and_decompressed_no_further() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bomb.mcap");
    crafted::chunk_bomb(&path, (256 << 20) + (1 << 20), 1024);
    let runs = every_command("chunk bomb declaring 1 KiB", &path);
    assert_eq!(runs[0].code, 2, "{}", runs[0].stderr);
    let at = crafted::start().len();
    assert!(
        runs[0].stderr.contains(&format!(
            "corrupt chunk at byte {at}: its records decompress to more than the 1024 bytes its \
             header claims"
        )),
        "{}",
        runs[0].stderr
    );
}

#[test]
fn ten_million_unknown_records_in_a_good_file_are_read_within_the_budget() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let path = dir.path().join("flood.mcap");
    crafted::with_private_records(&good, &path, 10_000_000);
    let runs = every_command("10 M empty records of opcode 0x80 in a good file", &path);
    // Legal MCAP: judged like the file without them.
    let plain = coin_log_peak(&["verify", good.to_str().unwrap()]);
    assert_eq!(
        (runs[0].code, plain.code),
        (0, 0),
        "{}{}",
        runs[0].stdout,
        runs[0].stderr
    );
    assert!(runs.iter().all(|m| m.code == 0), "{runs:?}");
}

#[test]
fn records_claiming_more_than_the_limit_are_refused_with_the_figure() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("claims.mcap");
    let claimed = 300_000_000;
    for (name, opcode) in [
        ("metadata", op::METADATA),
        ("chunk", op::CHUNK),
        ("0x80", 0x80),
    ] {
        crafted::claiming(&path, opcode, claimed, 400_000_000);
        let runs = every_command(
            &format!("a {name} record claiming 300 MB (sparse, 400 MB)"),
            &path,
        );
        let at = crafted::start().len();
        let refusal = format!(
            "the record (opcode {opcode:#04x}) at byte {at} is {claimed} bytes long, more than the \
             {LIMIT} this reader accepts in one record"
        );
        assert_eq!(runs[0].code, 2, "{}", runs[0].stderr);
        assert!(runs[0].stderr.contains(&refusal), "{}", runs[0].stderr);
    }
}

#[test]
fn topics_longer_than_a_format_width_are_shown_cut_in_a_table_that_keeps_its_columns() {
    // `info` padded its columns with `{:<w$}`, which panics for w > 65 535: a topic of 70 000 characters did.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long-topics.mcap");
    let mut f = crafted::start();
    for (id, topic) in [(0u16, "t".repeat(70_000)), (1, "/coin/omega".to_string())] {
        let mut body = id.to_le_bytes().to_vec();
        body.extend(0u16.to_le_bytes());
        body.extend(crafted::string(&topic));
        body.extend(crafted::string("json"));
        body.extend(0u32.to_le_bytes());
        f.extend(crafted::record(op::CHANNEL, &body));
    }
    f.extend(crafted::end());
    std::fs::write(&path, f).unwrap();
    let runs = every_command("two channels, one with a 70 000-character topic", &path);
    for (run, command) in runs.iter().zip(["verify", "info", "export", "plot"]) {
        assert!(
            !run.stderr.contains("panicked") && run.code != 101,
            "{command}: {}",
            run.stderr
        );
    }
    let info = &runs[1];
    assert_eq!(info.code, 0, "{}", info.stderr);
    assert!(
        info.stdout.len() < 2000,
        "{} bytes of info",
        info.stdout.len()
    );
    let cut = format!("  {}…  ", "t".repeat(200));
    assert!(info.stdout.contains(&cut), "{}", info.stdout);
    let export = &runs[2];
    assert!(
        export.stderr.len() < 2000,
        "{} bytes of export error",
        export.stderr.len()
    );
    assert!(
        export
            .stderr
            .contains(&format!("({}…: not a coin-log channel", "t".repeat(200))),
        "{}",
        export.stderr
    );
    // The other rows keep the column width of 64 characters, not the long topic's.
    let omega = format!("  {:<64}  ", "/coin/omega");
    assert!(info.stdout.contains(&omega), "{}", info.stdout);
}

#[test]
fn a_metadata_record_of_a_million_entries_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("entries.mcap");
    crafted::metadata_with_entries(&path, 1_000_000);
    let len = std::fs::metadata(&path).unwrap().len();
    assert!(
        len < MAX_RECORD_BYTES,
        "{len} bytes: a record the reader accepts by its size"
    );
    let runs = every_command("a metadata record of 1 M entries (13 MB)", &path);
    assert_eq!(runs[0].code, 2, "{}", runs[0].stderr);
    assert!(
        runs[0]
            .stderr
            .contains("`metadata` has more than 65536 entries, more than this reader accepts"),
        "{}",
        runs[0].stderr
    );
}

#[test]
fn chunks_at_the_limit_read_like_small_ones_within_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    let spec = |chunk_size| Spec {
        duration: 10.0,
        rate: 2000.0,
        chunk_size: Some(chunk_size),
        ..wobble()
    };
    let small = dir.path().join("small.mcap");
    record(&spec(1 << 20), &small);
    let large = dir.path().join("large.mcap");
    // The mcap crate closes a chunk once it exceeds the chunk size: one message less than the limit.
    record(&spec(MAX_RECORD_BYTES - 4096), &large);
    let chunks = mcap::Summary::read(&std::fs::read(&large).unwrap())
        .unwrap()
        .unwrap()
        .chunk_indexes;
    let largest = chunks.iter().map(|c| c.uncompressed_size).max().unwrap();
    assert!(
        largest > MAX_RECORD_BYTES - (64 << 10) && largest <= MAX_RECORD_BYTES,
        "largest chunk {largest} bytes"
    );
    let runs = every_command("chunks of 16 MiB (the limit)", &large);
    let json = |p: &Path| {
        let out = coin_log_peak(&["verify", p.to_str().unwrap(), "--json"]).stdout;
        let mut v: serde_json::Value = serde_json::from_str(&out).unwrap();
        // The reason of integrity counts chunks; the peak RSS is the machine's.
        for key in ["path", "peak_rss_bytes"] {
            v["files"][0][key] = serde_json::Value::Null;
        }
        v["files"][0]["checks"][0]["reason"] = serde_json::Value::Null;
        v
    };
    assert_eq!(json(&large), json(&small));
    assert!(runs.iter().all(|m| m.code == 0), "{runs:?}");
}

/// A schema under the record limit, used by one channel, counts twice (itself, and with the channel that
/// may keep it): 9 MiB of schema is refused at 18 MiB kept, and the message says why it is more than the
/// file holds (it said the schemas "take more than 16 MiB" where the file has 9). Negative control: the
/// same schema with no channel reads on.
#[test]
fn a_schema_used_by_a_channel_counts_twice_and_the_refusal_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let schema_bytes = 9 << 20;
    for with_channel in [true, false] {
        let mut schema = 1u16.to_le_bytes().to_vec();
        schema.extend(crafted::string("big"));
        schema.extend(crafted::string("jsonschema"));
        schema.extend((schema_bytes as u32).to_le_bytes());
        schema.extend(vec![b' '; schema_bytes]);
        let mut f = crafted::start();
        let at = f.len();
        f.extend(crafted::record(op::SCHEMA, &schema));
        let channel_at = f.len();
        if with_channel {
            let mut channel = 1u16.to_le_bytes().to_vec();
            channel.extend(1u16.to_le_bytes());
            channel.extend(crafted::string("/big"));
            channel.extend(crafted::string("json"));
            channel.extend(0u32.to_le_bytes());
            f.extend(crafted::record(op::CHANNEL, &channel));
        }
        f.extend(crafted::end());
        let path = dir.path().join("schema.mcap");
        std::fs::write(&path, f).unwrap();
        let (code, _, err) =
            crate::support::record::coin_log_text(&["verify", path.to_str().unwrap()]);
        println!("schema at byte {at}, channel {with_channel}: exit {code}: {err}");
        assert_eq!(code, 2, "{err}");
        let refusal = format!(
            "the schemas, channels and metadata read up to byte {channel_at} take more than the {LIMIT} \
             this reader keeps of them (a schema counts once more with each channel that uses it)"
        );
        assert_eq!(err.contains(&refusal), with_channel, "{err}");
    }
}
