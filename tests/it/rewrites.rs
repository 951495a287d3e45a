//! Recordings rewritten with their messages grouped by channel, each channel's record written just before
//! its first message (what a tool that copies channel after channel writes with the `mcap` crate's
//! `Writer::write`): legal MCAP, times increasing per channel, so verify must judge it like the original,
//! and `export --wide`, which needs the messages grouped by time, must say which channels are out of step.

#![allow(clippy::unwrap_used)]

use crate::support::record::{coin_log, coin_log_text, read_back, record_scene};
use coin_log::format::RUN_METADATA_NAME;
use serde_json::Value;
use std::path::Path;

/// Copies `src` into `dst`: its metadata records, then its messages sorted by channel (stable), each
/// channel registered by the writer at its first message.
fn grouped_by_channel(src: &Path, dst: &Path) {
    grouped_by_channel_with(src, dst, mcap::WriteOptions::new());
}

/// [`grouped_by_channel`] written with `options`.
fn grouped_by_channel_with(src: &Path, dst: &Path, options: mcap::WriteOptions) {
    let bytes = std::fs::read(src).unwrap();
    let file = read_back(&bytes);
    let mut messages: Vec<_> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .collect();
    messages.sort_by_key(|m| m.channel.id);
    let out = std::io::BufWriter::new(std::fs::File::create(dst).unwrap());
    let mut w = options.create(out).unwrap();
    assert!(file.metadata.contains_key(RUN_METADATA_NAME));
    for (name, (_, metadata)) in &file.metadata {
        w.write_metadata(&mcap::records::Metadata {
            name: name.clone(),
            metadata: metadata.clone(),
        })
        .unwrap();
    }
    for m in &messages {
        w.write(m).unwrap();
    }
    w.finish().unwrap();
}

fn verify_json(path: &Path) -> (i32, Value) {
    let (code, out, err) = coin_log_text(&["verify", "--json", path.to_str().unwrap()]);
    let v: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}{err}"));
    (code, v["files"][0].clone())
}

/// Each sample of the grouped copy is whole again: it was cut into one sample per channel (a channel
/// declared late made the samples before it look complete), and verify judged 1 of the 41 samples of
/// `circle-plus` and passed it (exit 0), and called `wobble` unverifiable (constraint skipped).
#[test]
fn a_rewrite_grouped_by_channel_verifies_like_the_original() {
    let dir = tempfile::tempdir().unwrap();
    for (scene, args) in [
        ("wobble", &["--duration", "0.4"][..]),
        (
            "circle-plus",
            &["--duration", "0.4", "--encoding", "protobuf"][..],
        ),
    ] {
        let original = record_scene(dir.path(), scene, args);
        let grouped = dir.path().join(format!("{scene}-grouped.mcap"));
        grouped_by_channel(&original, &grouped);
        let (code, ours) = verify_json(&original);
        assert_eq!(code, 0, "{ours}");
        let (code, theirs) = verify_json(&grouped);
        println!("{scene}: {}", theirs["checks"][0]["reason"]);
        assert_eq!(code, 0, "{scene}: {theirs}");
        let (a, b) = (
            ours["checks"].as_array().unwrap(),
            theirs["checks"].as_array().unwrap(),
        );
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            for key in ["id", "status", "value", "tolerance"] {
                assert_eq!(
                    x[key], y[key],
                    "{scene}: {key}\n  original {x}\n  grouped  {y}"
                );
            }
            if x["id"] != "integrity" {
                assert_eq!(x["reason"], y["reason"], "{scene}");
            } else {
                assert!(
                    y["reason"].as_str().unwrap().contains(" 41 samples:"),
                    "{y}"
                );
            }
        }
    }
}

/// `export --wide` of the grouped copy is refused, as documented; the error names the channel of the
/// message the out-of-order one follows (it said `/coin/angles has a message at log time 0 ns after one
/// at 100000000 ns`, as if /coin/angles itself were out of order, when that message was /coin/omega's).
#[test]
fn the_wide_error_on_a_rewrite_grouped_by_channel_names_both_channels() {
    let dir = tempfile::tempdir().unwrap();
    let original = record_scene(
        dir.path(),
        "wobble",
        &["--duration", "0.1", "--channels", "omega,angles"],
    );
    grouped_by_channel(&original, &dir.path().join("grouped.mcap"));
    let out = coin_log(dir.path(), &["export", "grouped.mcap", "--wide"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let says =
        "/coin/angles has a message at log time 0 ns after one at 100000000 ns on /coin/omega: \
                the messages are not in time order";
    assert!(stderr.contains(says), "{says}: {stderr}");
    assert!(!dir.path().join("grouped-csv").exists());
}

/// A grouped copy with more samples than verify holds while it waits for a sample's channels (4096): it
/// judged the first 4096 `/coin/omega` samples without their angles, the rest in pieces, and passed
/// (energy judged over 4096 samples, with another drift than the original's). It is read again in log-time
/// order through the chunk indexes and judged like the original, with a note saying so.
#[test]
fn a_long_rewrite_grouped_by_channel_is_judged_in_log_time_order() {
    let dir = tempfile::tempdir().unwrap();
    let original = record_scene(dir.path(), "wobble", &["--duration", "45"]);
    let grouped = dir.path().join("grouped.mcap");
    grouped_by_channel(&original, &grouped);
    let ((code, ours), (theirs_code, theirs)) = (verify_json(&original), verify_json(&grouped));
    assert_eq!((code, theirs_code), (0, 0), "{theirs}");
    for (x, y) in ours["checks"]
        .as_array()
        .unwrap()
        .iter()
        .zip(theirs["checks"].as_array().unwrap())
    {
        for key in ["id", "status", "value", "tolerance"] {
            assert_eq!(x[key], y[key], "{key}\n  original {x}\n  grouped  {y}");
        }
    }
    let integrity = theirs["checks"][0]["reason"].as_str().unwrap();
    assert!(integrity.contains(" 4501 samples"), "{integrity}");
    assert!(
        integrity.contains("every sample was judged in log-time order through the chunk indexes"),
        "{integrity}"
    );
}

/// Without chunk indexes the grouped copy cannot be read in log-time order: verify says how many samples
/// it judged in pieces and how to have every sample judged whole, instead of a silent pass.
#[test]
fn a_long_unchunked_rewrite_grouped_by_channel_says_it_was_judged_in_pieces() {
    let dir = tempfile::tempdir().unwrap();
    let original = record_scene(
        dir.path(),
        "wobble",
        &["--duration", "45", "--channels", "omega,angles,energy"],
    );
    let grouped = dir.path().join("grouped.mcap");
    grouped_by_channel_with(
        &original,
        &grouped,
        mcap::WriteOptions::new().use_chunks(false),
    );
    let (_, theirs) = verify_json(&grouped);
    let integrity = theirs["checks"][0]["reason"].as_str().unwrap();
    for says in [
        "samples were judged before all their channels had arrived",
        "it has no summary that lists its chunks; rewrite it with its messages in log-time order",
    ] {
        assert!(integrity.contains(says), "{says}: {integrity}");
    }
}
