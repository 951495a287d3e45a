//! `coin_log_mcap::read_from`: a visitor that stops and an error in the middle end the read and its
//! worker thread; a late metadata record comes before the first message; attachments are checked.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used)]

use coin_log_mcap::{
    read_from, Compression, McapWriter, MessageHeader, ReadError, ReadErrorKind, Structure,
    Visitor, WriterOptions,
};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::ops::ControlFlow;
use std::sync::mpsc;
use std::time::Duration;

/// Generous deadline of the hang tests: reading these few MiB takes milliseconds.
const DEADLINE: Duration = Duration::from_secs(20);

/// An uncompressed file of `messages` 1 KiB messages in 64 KiB chunks (many more batches than the
/// prefetch queue holds), with a metadata record `late` written after the first `late_after` messages.
fn file(messages: u32, late_after: u32) -> Vec<u8> {
    let mut options = WriterOptions::new(Compression::None, "test");
    options.chunk_size = 1 << 16;
    let mut w = McapWriter::new(Cursor::new(Vec::new()), &options).unwrap();
    let schema = w.add_schema("s", "jsonschema", b"{}").unwrap();
    let channel = w
        .add_channel(schema, "/t", "json", &BTreeMap::new())
        .unwrap();
    let data = vec![b' '; 1024];
    for i in 0..messages {
        if i == late_after {
            let entries = BTreeMap::from([("k".to_string(), "v".to_string())]);
            w.write_metadata("late", &entries).unwrap();
        }
        w.write_message(channel, i, u64::from(i), u64::from(i), &data)
            .unwrap();
    }
    w.finish().unwrap().0.into_inner()
}

/// Records what it is given; stops at message `stop_at`.
#[derive(Default)]
struct Recorder {
    stop_at: u64,
    messages: u64,
    events: Vec<String>,
}

impl Visitor for Recorder {
    fn metadata(&mut self, name: &str, _: &BTreeMap<String, String>) {
        self.events
            .push(format!("metadata {name} after {} messages", self.messages));
    }
    fn message(&mut self, _: &MessageHeader, _: &[u8]) -> ControlFlow<()> {
        self.messages += 1;
        if self.messages == self.stop_at {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Reads `bytes` on another thread, failing the test if it has not returned by [`DEADLINE`].
fn read_with_deadline(bytes: Vec<u8>, stop_at: u64) -> (Recorder, Structure, Option<ReadError>) {
    let (done, result) = mpsc::channel();
    std::thread::spawn(move || {
        let mut v = Recorder {
            stop_at,
            ..Recorder::default()
        };
        let len = bytes.len() as u64;
        let (s, e) = read_from(Cursor::new(bytes), len, &mut v);
        let _ = done.send((v, s, e));
    });
    result
        .recv_timeout(DEADLINE)
        .unwrap_or_else(|_| panic!("the reader did not return within {DEADLINE:?}: it hangs"))
}

#[test]
fn a_visitor_that_stops_early_ends_the_read_and_its_worker() {
    // 8 MiB of records: the worker fills the queue (4 batches of ~1 MiB) long before the end.
    let bytes = file(8192, u32::MAX);
    assert!(bytes.len() > 8 << 20, "{} bytes", bytes.len());
    for stop_at in [1, 100, 5000] {
        let (v, _, e) = read_with_deadline(bytes.clone(), stop_at);
        assert_eq!(v.messages, stop_at);
        assert_eq!(e.unwrap().kind, ReadErrorKind::Stopped);
    }
}

#[test]
fn a_metadata_record_after_the_first_chunks_comes_before_the_first_message() {
    let bytes = file(8192, 3000);
    let (v, s, e) = read_with_deadline(bytes, u64::MAX);
    assert_eq!(e, None);
    assert!(s.problems.is_empty(), "{}", s.problems.summary());
    assert_eq!(v.events, ["metadata late after 0 messages"]);
    assert_eq!(v.messages, 8192);
}

/// A file by the `mcap` crate's writer with one attachment whose data is `hello`, and the offset of
/// that data (no data-section CRC, so that the tests can edit the attachment alone).
fn file_with_attachment() -> (Vec<u8>, usize) {
    let options = mcap::WriteOptions::new().calculate_data_section_crc(false);
    let mut w = options.create(Cursor::new(Vec::new())).unwrap();
    w.attach(&mcap::Attachment {
        log_time: 1,
        create_time: 2,
        name: "note".into(),
        media_type: "text/plain".into(),
        data: Cow::Borrowed(b"hello"),
    })
    .unwrap();
    w.finish().unwrap();
    let bytes = w.into_inner().into_inner();
    let at = bytes.windows(5).position(|w| w == b"hello").unwrap();
    (bytes, at)
}

#[test]
fn an_attachment_is_checked_for_its_framing_and_crc() {
    let (bytes, at) = file_with_attachment();
    let (_, s, e) = read_with_deadline(bytes.clone(), u64::MAX);
    assert_eq!(e, None);
    assert!(s.problems.is_empty(), "{}", s.problems.summary());
    // One byte of its data changed: the CRC it stores no longer holds.
    let mut flipped = bytes.clone();
    flipped[at] ^= 1;
    let (_, s, _) = read_with_deadline(flipped, u64::MAX);
    let problems = s.problems.summary();
    assert!(
        problems.contains("attachment `note` at byte ")
            && problems.contains("does not match the stored"),
        "{problems}"
    );
    // Its data length claiming more than the record holds: malformed, not an allocation.
    let mut lying = bytes;
    lying[at - 8..at].copy_from_slice(&u64::MAX.to_le_bytes());
    let (_, _, e) = read_with_deadline(lying, u64::MAX);
    let e = e.unwrap();
    assert_eq!(e.kind, ReadErrorKind::Corrupt);
    assert!(
        e.to_string()
            .contains("malformed attachment record at byte "),
        "{e}"
    );
}

#[test]
fn an_error_in_the_middle_ends_the_read_and_its_worker() {
    // A byte flipped in the middle of the file, inside a chunk's records (chunks are 98% of these
    // bytes; this file is deterministic): a chunk CRC error the consumer returns while the worker is
    // still reading ahead.
    let mut bytes = file(8192, u32::MAX);
    let middle = bytes.len() / 2;
    bytes[middle] ^= 1;
    let (_, _, e) = read_with_deadline(bytes, u64::MAX);
    let e = e.unwrap();
    assert_eq!(e.kind, ReadErrorKind::Corrupt, "{e}");
}

/// The streaming pass counts what the summary section states: the same channels (first definitions,
/// by id, with their message counts), messages, time range, chunks and sizes; only the metadata, which
/// the visitor is given, stays out of it.
#[test]
fn the_streaming_pass_counts_what_the_summary_section_states() {
    let mut options = WriterOptions::new(Compression::Zstd, "test");
    options.chunk_size = 1 << 12;
    let mut w = McapWriter::new(Cursor::new(Vec::new()), &options).unwrap();
    let a = w.add_schema("a", "jsonschema", b"{}").unwrap();
    let b = w.add_schema("b", "jsonschema", b"{}").unwrap();
    let none = BTreeMap::new();
    let ca = w.add_channel(a, "/a", "json", &none).unwrap();
    let cb = w.add_channel(b, "/b", "json", &none).unwrap();
    for i in 0..500_u32 {
        // Out of order on purpose: the range is the minimum and the maximum, not the first and last.
        let t = 10_000 + u64::from(i * 7919 % 1000);
        w.write_message(ca, i, t, t, b"{}").unwrap();
        if i % 3 == 0 {
            w.write_message(cb, i, t + 5, t + 5, b"{}").unwrap();
        }
    }
    let bytes = w.finish().unwrap().0.into_inner();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.mcap");
    std::fs::write(&path, &bytes).unwrap();
    let stated = coin_log_mcap::read_summary(&path).unwrap().unwrap();
    let (_, streamed, e) = read_with_deadline(bytes, u64::MAX);
    assert_eq!(e, None);
    assert_eq!(streamed.summary.messages, 500 + 167);
    assert_eq!(streamed.summary.time_range, Some((10_000, 10_999 + 5)));
    let counts: Vec<_> = streamed
        .summary
        .channels
        .iter()
        .map(|c| (c.topic.as_str(), c.messages))
        .collect();
    assert_eq!(counts, [("/a", 500), ("/b", 167)]);
    assert!(
        streamed.summary.chunks > 1,
        "{} chunks",
        streamed.summary.chunks
    );
    assert_eq!(streamed.summary.metadata, []);
    assert_eq!(streamed.summary, stated);
}

/// When the channels outgrow what the reader keeps, the read ends there, and the streamed summary lists
/// exactly the channels the visitor was given (the refused one is not among them).
#[test]
fn the_streamed_channels_are_those_the_visitor_was_given_when_the_budget_ends_the_read() {
    #[derive(Default)]
    struct Channels(Vec<u16>);
    impl Visitor for Channels {
        fn channel(&mut self, id: u16, _: &str, _: &str, _: Option<&coin_log_mcap::Schema<'_>>) {
            self.0.push(id);
        }
        fn message(&mut self, _: &MessageHeader, _: &[u8]) -> ControlFlow<()> {
            ControlFlow::Continue(())
        }
    }
    let options = WriterOptions::new(Compression::None, "test");
    let mut w = McapWriter::new(Cursor::new(Vec::new()), &options).unwrap();
    let schema = w.add_schema("s", "jsonschema", b"{}").unwrap();
    let long = "x".repeat(1000);
    // 20 000 channels of about 1 kB: more than the 16 MiB the reader keeps of schemas and channels.
    for i in 0..20_000_u32 {
        let c = w
            .add_channel(schema, &format!("/{i}{long}"), "json", &BTreeMap::new())
            .unwrap();
        w.write_message(c, 0, u64::from(i), u64::from(i), b"{}")
            .unwrap();
    }
    let bytes = w.finish().unwrap().0.into_inner();
    let len = bytes.len() as u64;
    let mut v = Channels::default();
    let (s, e) = read_from(Cursor::new(bytes), len, &mut v);
    assert_eq!(e.unwrap().kind, ReadErrorKind::TooLarge);
    assert!(
        !v.0.is_empty() && v.0.len() < 20_000,
        "{} channels",
        v.0.len()
    );
    let streamed: Vec<u16> = s.summary.channels.iter().map(|c| c.id).collect();
    assert_eq!(streamed, v.0);
}

/// A file cut while it is read (here by the visitor, when the metadata record found before the stream is
/// passed on) breaks off where its old length no longer holds; the error says the file changed size
/// rather than blaming a record length ("... which ends with the MCAP magic, so a record length is
/// wrong") or calling a whole file truncated.
#[test]
fn a_file_cut_while_it_is_read_is_named_as_changed() {
    struct Cutter {
        path: std::path::PathBuf,
        to: u64,
    }
    impl Visitor for Cutter {
        fn metadata(&mut self, _: &str, _: &BTreeMap<String, String>) {
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(&self.path)
                .unwrap();
            f.set_len(self.to).unwrap();
        }
        fn message(&mut self, _: &MessageHeader, _: &[u8]) -> ControlFlow<()> {
            ControlFlow::Continue(())
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.mcap");
    let bytes = file(8000, 0);
    let (len, to) = (bytes.len() as u64, bytes.len() as u64 / 3);
    std::fs::write(&path, &bytes).unwrap();
    let mut cutter = Cutter {
        path: path.clone(),
        to,
    };
    let (_, e) = coin_log_mcap::read(&path, &mut cutter);
    let e = e.expect("the cut file breaks off");
    println!("{e:?}");
    assert!(
        e.detail.starts_with(&format!(
            "the file changed size while it was read ({len} bytes when opened, {to} now)"
        )),
        "{}",
        e.detail
    );
    // A file that stays as it was keeps its own error (negative control: a cut copy).
    std::fs::write(&path, &bytes[..to as usize]).unwrap();
    let (_, e) = coin_log_mcap::read(&path, &mut Recorder::default());
    assert!(e.unwrap().detail.starts_with("truncated"));
}
