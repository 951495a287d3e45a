//! `coin-log verify` on broken input: each case builds the broken file and asserts the exact exit code and
//! message. Unreadable, not MCAP, not coin-log, truncated or corrupt: exit 2 and a clear message, never a
//! panic; a readable file with a defect in its content (non-monotonic times, a malformed message): exit 1.

#![allow(clippy::unwrap_used)]

use crate::support::record::{
    coin_log_text, coin_log_within, record_scene, top_level_records as records, HANG_DEADLINE,
};
use crate::support::writers::{recorded, rewrite, rewrite_with_metadata, wobble, Spec};
use coin_log::verify::{verify_bytes, Options};
use std::path::Path;

/// CRC-32 (IEEE), as MCAP uses.
fn crc32(data: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in data {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn verify(path: &Path) -> (i32, String, String) {
    coin_log_text(&["verify", path.to_str().unwrap()])
}

fn small_chunks(compression: Option<mcap::Compression>) -> Spec {
    Spec {
        chunk_size: Some(16 * 1024),
        compression,
        ..wobble()
    }
}

#[test]
fn a_missing_file_is_unreadable() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nope.mcap");
    let (code, _, err) = verify(&path);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: cannot read: No such file or directory (os error 2)",
            path.display()
        )
    );
}

#[test]
fn a_directory_is_not_an_mcap_file() {
    let dir = tempfile::tempdir().unwrap();
    let (code, _, err) = verify(dir.path());
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: is a directory, not an MCAP file",
            dir.path().display()
        )
    );
}

#[test]
fn an_empty_file_is_not_an_mcap_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty.mcap");
    std::fs::write(&path, b"").unwrap();
    let (code, _, err) = verify(&path);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: empty file (0 bytes), not an MCAP file",
            path.display()
        )
    );
}

#[test]
fn a_text_file_is_not_an_mcap_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("notes.mcap");
    std::fs::write(&path, b"these are notes, not a recording\n").unwrap();
    let (code, _, err) = verify(&path);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: not an MCAP file (it does not start with the MCAP magic bytes)",
            path.display()
        )
    );
    std::fs::write(&path, b"abc").unwrap();
    let (code, _, err) = verify(&path);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: not an MCAP file (3 bytes, shorter than an MCAP header)",
            path.display()
        )
    );
}

#[test]
fn an_mcap_from_another_tool_is_not_a_coin_log_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("other.mcap");
    let mut w = mcap::WriteOptions::new()
        .library("other-tool")
        .create(std::io::BufWriter::new(
            std::fs::File::create(&path).unwrap(),
        ))
        .unwrap();
    let ch = w
        .add_channel(0, "/foo", "json", &std::collections::BTreeMap::new())
        .unwrap();
    w.write_to_known_channel(
        &mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        },
        b"{}",
    )
    .unwrap();
    w.finish().unwrap();
    drop(w);
    let (code, _, err) = verify(&path);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: not a coin-log file: it has no `coin-log` metadata record (written by `other-tool`)",
            path.display()
        )
    );
}

#[test]
fn a_truncated_file_is_judged_on_its_readable_messages_and_is_unusable() {
    let (dir, good) = recorded(&small_chunks(Some(mcap::Compression::Zstd)), "good.mcap");
    let bytes = std::fs::read(&good).unwrap();
    let cut = bytes.len() / 2;
    let path = dir.path().join("truncated.mcap");
    std::fs::write(&path, &bytes[..cut]).unwrap();
    let recs = records(&bytes);
    let (_, inside, _) = *recs
        .iter()
        .find(|(_, at, len)| *at < cut && at + 9 + len > cut)
        .unwrap();
    let (code, out, err) = coin_log_text(&["verify", "--json", path.to_str().unwrap()]);
    println!("{err}");
    assert_eq!(code, 2);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let file = &v["files"][0];
    let energy = file["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == "energy")
        .unwrap();
    assert_eq!(energy["status"], "pass", "{energy}");
    let integrity = file["checks"].as_array().unwrap()[0].clone();
    assert_eq!(integrity["status"], "fail");
    let prefix = format!(
        "error: {}: truncated: the file ends at byte {cut} inside the record that starts at byte {inside}, before the MCAP footer; judged the ",
        path.display()
    );
    assert!(err.starts_with(&prefix), "{err}\nexpected prefix {prefix}");
    let n: u64 = err[prefix.len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(n > 1000 && n < 8008, "judged {n} messages");
    assert!(err.trim_end().ends_with("messages read before it"));
}

#[test]
fn a_flipped_byte_in_an_uncompressed_chunk_fails_its_crc() {
    let (dir, good) = recorded(&small_chunks(None), "good.mcap");
    let mut bytes = std::fs::read(&good).unwrap();
    let (_, chunk, _) = *records(&bytes).iter().find(|r| r.0 == 0x06).unwrap();
    // The digit of the first message's "t":0 inside the chunk.
    let at = chunk
        + bytes[chunk..]
            .windows(5)
            .position(|w| w == b"{\"t\":")
            .unwrap()
        + 5;
    bytes[at] ^= 0x01;
    let path = dir.path().join("flipped.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let (code, _, err) = verify(&path);
    println!("{err}");
    assert_eq!(code, 2);
    let prefix = format!(
        "error: {}: corrupt chunk at byte {chunk}: CRC 0x",
        path.display()
    );
    assert!(err.starts_with(&prefix), "{err}");
    assert!(
        err.contains("of its records does not match the stored 0x"),
        "{err}"
    );
}

#[test]
fn a_flipped_byte_in_a_compressed_chunk_is_reported_with_the_chunk_offset() {
    let (dir, good) = recorded(&small_chunks(Some(mcap::Compression::Zstd)), "good.mcap");
    let mut bytes = std::fs::read(&good).unwrap();
    let (_, chunk, len) = *records(&bytes).iter().find(|r| r.0 == 0x06).unwrap();
    bytes[chunk + 9 + len / 2] ^= 0x40;
    let path = dir.path().join("flipped.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let (code, _, err) = verify(&path);
    println!("{err}");
    assert_eq!(code, 2);
    let prefix = format!("error: {}: corrupt chunk at byte {chunk}: ", path.display());
    assert!(err.starts_with(&prefix), "{err}");
}

#[test]
fn a_flipped_byte_in_the_summary_fails_its_crc() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let mut bytes = std::fs::read(&good).unwrap();
    let (_, stats, _) = *records(&bytes).iter().find(|r| r.0 == 0x0B).unwrap();
    bytes[stats + 9] ^= 0x01; // message_count
    let path = dir.path().join("flipped.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let (code, _, err) = verify(&path);
    println!("{err}");
    assert_eq!(code, 2);
    let prefix = format!("error: {}: corrupt summary section: CRC 0x", path.display());
    assert!(err.starts_with(&prefix), "{err}");
    assert!(
        err.trim_end().ends_with("judged the 8008 messages read"),
        "{err}"
    );
}

#[test]
fn a_summary_record_claiming_a_huge_length_is_refused_without_allocating_it() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let mut bytes = std::fs::read(&good).unwrap();
    let len = bytes.len();
    let (op, first, _) = *records(&bytes)
        .iter()
        .skip_while(|r| r.0 != 0x0F)
        .nth(1)
        .unwrap();
    bytes[first + 1..first + 9].copy_from_slice(&(1u64 << 60).to_le_bytes());
    let path = dir.path().join("huge.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let (code, _, err) = verify(&path);
    assert_eq!(code, 2);
    assert_eq!(
        err.trim(),
        format!(
            "error: {}: record (opcode {op:#04x}) at byte {first} claims 1152921504606846976 bytes, more than the file's {len}: the file is corrupt or crafted; judged the 8008 messages read before it",
            path.display()
        )
    );
}

#[test]
fn a_summary_with_huge_counts_and_sizes_but_a_valid_crc_fails_integrity_only() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let mut bytes = std::fs::read(&good).unwrap();
    let recs = records(&bytes);
    let (_, index, _) = *recs.iter().find(|r| r.0 == 0x08).unwrap();
    // chunk_length and message_count claim 2^62.
    bytes[index + 9 + 24..index + 9 + 32].copy_from_slice(&(1u64 << 62).to_le_bytes());
    let (_, stats, _) = *recs.iter().find(|r| r.0 == 0x0B).unwrap();
    bytes[stats + 9..stats + 17].copy_from_slice(&(1u64 << 62).to_le_bytes());
    // Re-sign the summary so that only the claims are wrong.
    let footer = bytes.len() - 8 - 29;
    let summary_start =
        u64::from_le_bytes(bytes[footer + 9..footer + 17].try_into().unwrap()) as usize;
    let crc = crc32(&bytes[summary_start..footer + 9 + 16]);
    bytes[footer + 9 + 16..footer + 9 + 20].copy_from_slice(&crc.to_le_bytes());
    let path = dir.path().join("claims.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let (code, out, err) = verify(&path);
    println!("{out}{err}");
    assert_eq!(code, 1);
    assert!(
        out.contains("statistics: message_count = 4611686018427387904, the file has 8008"),
        "{out}"
    );
    assert!(
        out.contains("chunk indexes do not match the chunks"),
        "{out}"
    );
}

#[test]
fn non_monotonic_log_times_fail_integrity() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let path = dir.path().join("backwards.mcap");
    rewrite(&good, &path, |e| {
        if e.topic == "/coin/omega" && e.index == 11 {
            *e.log_time = 90_000_000;
        }
    });
    let (code, out, err) = coin_log_text(&["verify", "--json", path.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let integrity = &v["files"][0]["checks"][0];
    println!("{integrity}");
    assert_eq!(integrity["id"], "integrity");
    assert_eq!(integrity["status"], "fail");
    let reason = integrity["reason"].as_str().unwrap();
    assert!(
        reason.contains("/coin/omega: log times not increasing: 90000000 ns after 100000000 ns"),
        "{reason}"
    );
    assert!(
        reason.contains(
            "/coin/omega: log_time 90000000 ns is not round(t·1e9) = 110000000 ns for t = 0.11"
        ),
        "{reason}"
    );
}

#[test]
fn a_message_with_an_unknown_field_fails_integrity() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let path = dir.path().join("extra.mcap");
    rewrite(&good, &path, |e| {
        if e.topic == "/coin/energy" && e.index == 3 {
            e.data.pop();
            e.data.extend_from_slice(b",\"extra\":1}");
        }
    });
    let (code, out, _) = verify(&path);
    println!("{out}");
    assert_eq!(code, 1);
    assert!(
        out.contains("/coin/energy: message at 30000000 ns does not parse: unknown field `extra`"),
        "{out}"
    );
}

#[test]
fn several_files_exit_with_the_worst_code() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let empty = dir.path().join("empty.mcap");
    std::fs::write(&empty, b"").unwrap();
    let (code, out, _) =
        coin_log_text(&["verify", good.to_str().unwrap(), empty.to_str().unwrap()]);
    println!("{out}");
    assert_eq!(code, 2);
    let (code, _, _) = coin_log_text(&["verify", good.to_str().unwrap()]);
    assert_eq!(code, 0);
}

/// The cuts of `bytes` the sweep tries: every top-level record boundary, one byte and one record prefix
/// (9 bytes) past it, every byte of the leading magic, the last 9 bytes, and about 100 evenly spaced
/// offsets; all strictly inside the file.
fn cuts(bytes: &[u8]) -> Vec<usize> {
    let n = bytes.len();
    let mut cuts: Vec<usize> = records(bytes)
        .iter()
        .flat_map(|(_, at, _)| [*at, at + 1, at + 9])
        .chain(1..=8)
        .chain(n - 9..n)
        .chain((1..100).map(|k| k * n / 100))
        .filter(|c| (1..n).contains(c))
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    cuts
}

/// A file cut anywhere is a prefix of a plausible MCAP: verify must say "truncated" and where, with exit
/// code 2, never a panic, whether the cut falls in the magic, a record prefix, the metadata, a chunk, the
/// summary, the footer or the end magic. Checked on a real recording (metadata first) and on its rewrite
/// by the Python writer with the metadata last (the cut then usually comes before the metadata; feature
/// `external-readers`).
#[test]
fn a_recording_cut_anywhere_is_reported_as_truncated() {
    let dir = tempfile::tempdir().unwrap();
    #[cfg_attr(not(feature = "external-readers"), allow(unused_mut))]
    let mut paths = vec![record_scene(
        dir.path(),
        "circle-plus",
        &["--duration", "3"],
    )];
    #[cfg(feature = "external-readers")]
    paths.push(
        crate::support::other_writers::rewrites()
            .file("py-zstd-small-last")
            .to_path_buf(),
    );
    let mut total = 0;
    for path in paths {
        let bytes = std::fs::read(&path).unwrap();
        let cuts = cuts(&bytes);
        for &cut in &cuts {
            let r = verify_bytes("cut.mcap", &bytes[..cut], &Options::default());
            let problem = r.problem.as_deref().unwrap_or("");
            let expected = format!("truncated: the file ends at byte {cut}");
            assert!(
                r.exit_code == 2 && problem.starts_with(&expected),
                "{} cut at {cut} of {}: exit {}, {problem:?}",
                path.display(),
                bytes.len(),
                r.exit_code
            );
        }
        println!("{}: {} cuts, all truncated", path.display(), cuts.len());
        total += cuts.len();
    }
    assert!(total > 300, "{total} cuts");
}

/// What each kind of cut says, through the binary: printed once, on stderr; the table on stdout says
/// UNUSABLE; the JSON carries the same sentence as `problem`.
#[test]
fn a_truncated_file_says_where_it_was_cut_once_on_stderr_and_in_the_json() {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "circle-plus", &["--duration", "3"]);
    let bytes = std::fs::read(&good).unwrap();
    // Every message of the file comes before the footer's summary: a cut there has read them all.
    let all = crate::support::record::read_back(&bytes).messages.len();
    let recs = records(&bytes);
    let chunk = recs.iter().find(|r| r.0 == 0x06).unwrap();
    let run = recs.iter().find(|r| r.0 == 0x0C).unwrap();
    let footer = recs.iter().find(|r| r.0 == 0x02).unwrap();
    let n = bytes.len();
    let messages = |s: &str| s.to_string();
    for (cut, detail) in [
        (
            3,
            messages("truncated: the file ends at byte 3, inside the MCAP magic it starts with; no `coin-log` metadata record comes before that point, so there is nothing to judge"),
        ),
        (
            8,
            messages("truncated: the file ends at byte 8, right after the MCAP magic, before the MCAP footer; no `coin-log` metadata record comes before that point, so there is nothing to judge"),
        ),
        (
            run.1 + 20,
            format!("truncated: the file ends at byte {} inside the record that starts at byte {}, before the MCAP footer; no `coin-log` metadata record comes before that point, so there is nothing to judge", run.1 + 20, run.1),
        ),
        (
            chunk.1 + 100,
            format!("truncated: the file ends at byte {} inside the record that starts at byte {}, before the MCAP footer; judged the 0 messages read before it", chunk.1 + 100, chunk.1),
        ),
        (
            footer.1,
            format!("truncated: the file ends at byte {}, after a whole record, before the MCAP footer; judged the {all} messages read before it", footer.1),
        ),
        (
            n - 3,
            format!("truncated: the file ends at byte {}, inside the MCAP end magic; judged the {all} messages read", n - 3),
        ),
    ] {
        let path = dir.path().join(format!("cut-{cut}.mcap"));
        std::fs::write(&path, &bytes[..cut]).unwrap();
        let (code, out, err) = coin_log_text(&["verify", path.to_str().unwrap()]);
        assert_eq!(code, 2, "{out}{err}");
        assert_eq!(err, format!("error: {}: {detail}\n", path.display()));
        assert!(
            out.starts_with(&format!("{}: UNUSABLE (exit 2)\n", path.display())),
            "{out}"
        );
        // No second copy under the verdict line (the table, when the file was judged, follows it; the
        // integrity row then counts the cut among its problems).
        let second = out.lines().nth(1).unwrap_or("  check ");
        assert!(second.starts_with("  check "), "printed once: {out}");
        let (code, out, _) = coin_log_text(&["verify", "--json", path.to_str().unwrap()]);
        assert_eq!(code, 2);
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v["files"][0]["problem"], detail.as_str());
        assert_eq!(v["files"][0]["verdict"], "unusable");
    }
}

/// A pipe cannot be read twice (the metadata is looked up before the stream): refused with the reason.
#[test]
fn a_pipe_is_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.mcap");
    crate::support::mkfifo(&fifo);
    // Nothing ever writes to the FIFO: verify must not open it for reading (which would block).
    let (code, out, err) = coin_log_within(HANG_DEADLINE, &["verify", fifo.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}");
    assert_eq!(
        err,
        format!(
            "error: {}: is not a regular file (a pipe, socket or device): an MCAP file is read by seeking to its summary and metadata, which a stream cannot do; save it to a file first\n",
            fifo.display()
        )
    );
}

/// A second channel on `/coin/energy` (legal MCAP: two publishers of one topic) whose messages disagree
/// with the first: integrity fails naming the topic and both channel ids. Verify judged it ok, reading
/// one message per sample and never looking at the other channel's.
#[test]
fn a_second_channel_on_a_coin_log_topic_fails_integrity() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let path = dir.path().join("two-energies.mcap");
    let bytes = std::fs::read(&good).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let metadata: Vec<mcap::records::Metadata> = summary
        .metadata_indexes
        .iter()
        .map(|i| mcap::read::metadata(&bytes, i).unwrap())
        .collect();
    let mut w = mcap::WriteOptions::new()
        .create(std::io::BufWriter::new(
            std::fs::File::create(&path).unwrap(),
        ))
        .unwrap();
    for m in metadata.iter().filter(|m| m.name == "coin-log") {
        w.write_metadata(m).unwrap();
    }
    let ids =
        crate::support::writers::copy_messages_twice(&bytes, &mut w, "/coin/energy", |data| {
            crate::support::writers::nudge(data, "total", 1.0);
        });
    for m in metadata.iter().filter(|m| m.name != "coin-log") {
        w.write_metadata(m).unwrap();
    }
    w.finish().unwrap();
    let (code, out, err) = coin_log_text(&["verify", "--json", path.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let integrity = &v["files"][0]["checks"][0];
    println!("exit {code}: {integrity}");
    assert_eq!(code, 1, "{out}{err}");
    assert_eq!(integrity["status"], "fail");
    let reason = integrity["reason"].as_str().unwrap();
    let first = ids[&("/coin/energy".to_string(), false)];
    let second = ids[&("/coin/energy".to_string(), true)];
    assert!(
        reason.contains(&format!(
            "topic `/coin/energy` is on two channels ({first} and {second})"
        )),
        "{reason}"
    );
    // The same file with one channel per topic passes: the defect is the second channel.
    let (code, _, err) = verify(&good);
    assert_eq!(code, 0, "{err}");
}

/// A run that an event ended (topple: `flat-landing` at t = 1.9…) ends at its last sample, written at the
/// event: a `coin-log.result` that moves its termination_time by 1e-6, or by half a sample interval, fails
/// integrity. Verify let any time up to 1/rate past the last sample pass, the reach it gives a failure
/// (found by mutating the result record of a lift-off recording by 6e-6: `ok`).
#[test]
fn an_event_run_whose_termination_time_is_not_its_last_sample_fails_integrity() {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "topple", &[]);
    let (code, out, err) = verify(&good);
    assert_eq!(code, 0, "{out}{err}");
    let bytes = std::fs::read(&good).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let result = summary
        .metadata_indexes
        .iter()
        .map(|i| mcap::read::metadata(&bytes, i).unwrap())
        .find(|m| m.name == "coin-log.result")
        .unwrap()
        .metadata;
    assert_eq!(result["termination"], "flat-landing");
    let own: f64 = result["termination_time"].parse().unwrap();
    for delta in [1e-6, 0.005] {
        let path = dir.path().join("moved.mcap");
        let time = (own + delta).to_string();
        let edit_result = |name: &str, entries: &mut std::collections::BTreeMap<String, String>| {
            if name == "coin-log.result" {
                entries.insert("termination_time".into(), time.clone());
            }
        };
        rewrite_with_metadata(&good, &path, &edit_result, |_| {});
        let (code, out, err) = verify(&path);
        println!("termination_time = {time}: exit {code}\n{out}");
        assert_eq!(code, 1, "{out}{err}");
        assert!(
            out.contains(&format!(
                "metadata says termination_time = {time}, but the last sample is at t = {own}: a \
                 run whose termination is `flat-landing` ends at its last sample"
            )),
            "{out}"
        );
    }
}

/// A `coin-log.result` record whose termination_time is not a finite time ≥ 0 (NaN, inf, -5), or not the
/// last sample's time or a failure's before the next (1e308, 1.5 in a run of 10) fails integrity: verify
/// judged such a file ok, and plot labelled its termination "at t = NaN". A run that completed ends at its
/// last sample, so 10.01 fails too (this test used to let it pass as within a failure's reach, the next
/// grid point, though the run did not fail).
#[test]
fn a_result_record_with_a_non_finite_or_negative_termination_time_fails_integrity() {
    let (dir, good) = recorded(&wobble(), "good.mcap");
    let bytes = std::fs::read(&good).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let own = summary
        .metadata_indexes
        .iter()
        .map(|i| mcap::read::metadata(&bytes, i).unwrap())
        .find_map(|m| m.metadata.get("termination_time").cloned())
        .unwrap();
    for time in [
        "NaN",
        "inf",
        "-5",
        "1e308",
        "1.5",
        "10.01",
        "10.000001",
        &own,
    ] {
        let path = dir.path().join("result.mcap");
        let edit_result = |name: &str, entries: &mut std::collections::BTreeMap<String, String>| {
            if name != "coin-log" {
                entries.insert("termination_time".into(), time.into());
            }
        };
        rewrite_with_metadata(&good, &path, &edit_result, |_| {});
        let (code, out, err) = verify(&path);
        println!("termination_time = {time}: exit {code}");
        let complaint = "metadata says termination_time =";
        if time == own {
            // Negative control: the file's own time (its last sample's, 10) passes.
            assert!(!out.contains(complaint), "{out}{err}");
        } else {
            assert_eq!(code, 1, "{out}{err}");
            let value: f64 = time.parse().unwrap();
            let why = if value.is_finite() && value >= 0.0 {
                "but the last sample is at t = 10"
            } else {
                "not a finite time ≥ 0"
            };
            assert!(
                out.contains(complaint) && out.contains(why),
                "{time}: {out}"
            );
        }
    }
}

/// The result record's termination_alpha is α = π/2 − |θ| at the last sample with dissipation and null
/// without: a euler-disk file whose α was moved (0.19… → 6.19…, found by fuzzing), or a wobble file
/// given one, verified ok; each now fails integrity naming the value and what it should be.
#[test]
fn a_termination_alpha_that_is_not_the_last_samples_fails_integrity() {
    let dir = tempfile::tempdir().unwrap();
    for (scene, alpha, says) in [
        ("euler-disk", "6.2", "but the last sample's θ = "),
        (
            "euler-disk",
            "",
            "has no termination_alpha, which a run with dissipation records",
        ),
        (
            "wobble",
            "0.5",
            "termination_alpha = 0.5, but the run has no dissipation",
        ),
    ] {
        let good = record_scene(dir.path(), scene, &["--duration", "0.5"]);
        let (code, out, err) = verify(&good);
        assert_eq!(code, 0, "{out}{err}");
        let path = dir.path().join("edited.mcap");
        let edit_result = |name: &str, entries: &mut std::collections::BTreeMap<String, String>| {
            if name == "coin-log.result" {
                if alpha.is_empty() {
                    entries.remove("termination_alpha");
                } else {
                    entries.insert("termination_alpha".into(), alpha.into());
                }
            }
        };
        rewrite_with_metadata(&good, &path, &edit_result, |_| {});
        let (code, out, err) = verify(&path);
        assert_eq!(code, 1, "{scene} {alpha}: {out}{err}");
        assert!(out.contains(says), "{says}: {out}");
    }
}
