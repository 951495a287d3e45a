//! `coin_log_mcap::McapWriter`: files read back through the `mcap` crate's linear and indexed
//! paths for every compression, with many chunks; statistics, indexes and CRCs are right (and a flipped
//! byte is caught); the bytes do not depend on the worker count; a failing output is an error, never a
//! panic or a hang.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::FailingWriter;
use coin_log_mcap::{Compression, McapWriter, WriteError, WriterOptions};
use mcap::records::Record;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::{McapError, MessageStream, Summary};
use std::collections::BTreeMap;
use std::io::{Cursor, Write};

const COMPRESSIONS: [Compression; 3] = [Compression::Zstd, Compression::Lz4, Compression::None];

/// A message as written: (topic, sequence, log time, publish time, data).
type Written = (String, u32, u64, u64, Vec<u8>);

/// (topic, schema name) of the test channels; two share a schema.
const CHANNELS: [(&str, &str); 3] = [
    ("/a", "test.Vector"),
    ("/b", "test.Vector"),
    ("/c", "test.Scalar"),
];

fn options(compression: Compression, chunk_size: usize, workers: usize) -> WriterOptions {
    WriterOptions {
        chunk_size,
        workers,
        ..WriterOptions::new(compression, "coin-log/test")
    }
}

fn metadata(pairs: &[(&str, &str)]) -> BTreeMap<String, String> {
    pairs
        .iter()
        .map(|(k, v)| ((*k).to_string(), (*v).to_string()))
        .collect()
}

/// Writes `count` messages over the three channels (registered at their first message, as the recorder
/// does), with metadata records at the start, in the middle and at the end. Returns the file and the
/// messages in file order.
fn write_file(
    options: &WriterOptions,
    count: u32,
) -> Result<(Vec<u8>, Vec<Written>), (WriteError, usize)> {
    write_to(Cursor::new(Vec::new()), options, count).map(|(c, w)| (c.into_inner(), w))
}

fn write_to<W: Write>(
    out: W,
    options: &WriterOptions,
    count: u32,
) -> Result<(W, Vec<Written>), (WriteError, usize)> {
    let mut step = 0;
    let mut writer = McapWriter::new(out, options).map_err(|e| (e, step))?;
    writer
        .write_metadata("first", &metadata(&[("k", "v"), ("scene", "a = 1\n")]))
        .map_err(|e| (e, step))?;
    let mut ids = [None; CHANNELS.len()];
    let mut sequences = [0_u32; CHANNELS.len()];
    let mut written = Vec::new();
    // A deterministic spread of payload sizes, from a few bytes to more than a small chunk.
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    for i in 0..count {
        step = i as usize;
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let c = (state >> 33) as usize % CHANNELS.len();
        let (topic, schema) = CHANNELS[c];
        let id = match ids[c] {
            Some(id) => id,
            None => {
                let schema_id = writer
                    .add_schema(schema, "jsonschema", schema.as_bytes())
                    .map_err(|e| (e, step))?;
                let id = writer
                    .add_channel(schema_id, topic, "json", &metadata(&[("i", topic)]))
                    .map_err(|e| (e, step))?;
                ids[c] = Some(id);
                id
            }
        };
        let len = if i % 997 == 0 {
            9000
        } else {
            (state >> 50) as usize % 120
        };
        let data: Vec<u8> = (0..len)
            .map(|k| b"{\"t\":0.125,\"x\":-1.5e-7}"[(k + i as usize) % 23])
            .collect();
        // Mostly increasing, with a step back now and then (bounds are min/max, not first/last).
        let log_time = 1_000 + u64::from(i) * 10 - if i % 50 == 7 { 25 } else { 0 };
        let publish_time = log_time + 3;
        writer
            .write_message(id, sequences[c], log_time, publish_time, &data)
            .map_err(|e| (e, step))?;
        written.push((
            topic.to_string(),
            sequences[c],
            log_time,
            publish_time,
            data,
        ));
        sequences[c] += 1;
        if i == count / 2 {
            writer
                .write_metadata("middle", &metadata(&[("at", "half")]))
                .map_err(|e| (e, step))?;
        }
    }
    writer
        .write_metadata("last", &BTreeMap::new())
        .map_err(|e| (e, step))?;
    writer
        .finish()
        .map(|(out, _)| (out, written))
        .map_err(|e| (e, step))
}

/// Every record of the file, read linearly with every CRC checked (data section, summary section, and
/// each chunk's before its records are yielded). With `emit_chunks`, chunks come whole; without, their
/// records come instead.
fn validated_records(bytes: &[u8], emit_chunks: bool) -> Result<Vec<Record<'static>>, McapError> {
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_prevalidate_chunk_crcs(true)
            .with_check_finishes_after_end_magic(true)
            .with_emit_chunks(emit_chunks),
    );
    let mut rest = bytes;
    let mut records = Vec::new();
    while let Some(event) = reader.next_event() {
        match event? {
            LinearReadEvent::ReadRequest(n) => {
                let n = n.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
            }
            LinearReadEvent::Record { data, opcode } => {
                records.push(mcap::parse_record(opcode, data)?.into_owned());
            }
        }
    }
    Ok(records)
}

fn as_written(m: &mcap::Message) -> Written {
    (
        m.channel.topic.clone(),
        m.sequence,
        m.log_time,
        m.publish_time,
        m.data.to_vec(),
    )
}

fn streamed(bytes: &[u8]) -> Result<Vec<Written>, McapError> {
    MessageStream::new_with_options(bytes, mcap::read::Options::ValidateChunkCrcs.into())?
        .map(|m| m.map(|m| as_written(&m)))
        .collect()
}

#[test]
fn every_compression_reads_back_linearly_with_every_crc_checked() {
    for compression in COMPRESSIONS {
        let (bytes, written) = write_file(&options(compression, 4096, 1), 20_000).unwrap();
        let read = streamed(&bytes).unwrap();
        println!(
            "{compression:?}: {} messages written, {} read back, {} bytes",
            written.len(),
            read.len(),
            bytes.len()
        );
        assert_eq!(read, written, "{compression:?}: messages differ");

        let records = validated_records(&bytes, false).unwrap();
        let messages = records
            .iter()
            .filter(|r| matches!(r, Record::Message { .. }))
            .count();
        assert_eq!(messages, written.len(), "{compression:?}");
        // The layout: header first; schemas and channels (in chunks) before their first message.
        assert!(
            matches!(&records[0], Record::Header(h) if h.library == "coin-log/test" && h.profile.is_empty())
        );
        let names: Vec<_> = records
            .iter()
            .filter_map(|r| match r {
                Record::Metadata(m) => Some(m.name.as_str()),
                _ => None,
            })
            .collect();
        assert_eq!(names, ["first", "middle", "last"], "{compression:?}");
    }
}

#[test]
fn the_summary_indexes_every_chunk_message_and_metadata_record() {
    for compression in COMPRESSIONS {
        let (bytes, written) = write_file(&options(compression, 4096, 1), 20_000).unwrap();
        let summary = Summary::read(&bytes).unwrap().expect("a summary section");

        // Statistics equal the counts written.
        let stats = summary.stats.clone().expect("statistics");
        let mut per_topic: BTreeMap<&str, u64> = BTreeMap::new();
        for (topic, ..) in &written {
            *per_topic.entry(topic.as_str()).or_default() += 1;
        }
        let counted: BTreeMap<&str, u64> = stats
            .channel_message_counts
            .iter()
            .map(|(id, n)| (summary.channels[id].topic.as_str(), *n))
            .collect();
        println!(
            "{compression:?}: {} chunks, stats {:?}",
            summary.chunk_indexes.len(),
            (
                stats.message_count,
                stats.schema_count,
                stats.channel_count,
                stats.metadata_count,
                stats.chunk_count
            )
        );
        assert_eq!(stats.message_count, written.len() as u64);
        assert_eq!(counted, per_topic);
        assert_eq!(stats.schema_count, 2, "two channels share a schema");
        assert_eq!(stats.channel_count, 3);
        assert_eq!(stats.attachment_count, 0);
        assert_eq!(stats.metadata_count, 3);
        assert_eq!(stats.chunk_count as usize, summary.chunk_indexes.len());
        assert!(summary.chunk_indexes.len() > 100, "many chunks");
        let times = written.iter().map(|w| w.2);
        assert_eq!(stats.message_start_time, times.clone().min().unwrap());
        assert_eq!(stats.message_end_time, times.max().unwrap());

        // Schemas and channels are repeated in the summary.
        assert_eq!(summary.schemas.len(), 2);
        for (topic, schema) in CHANNELS {
            let channel = summary
                .channels
                .values()
                .find(|c| c.topic == topic)
                .expect("channel in summary");
            let s = channel.schema.as_ref().expect("schema");
            assert_eq!(
                (s.name.as_str(), s.encoding.as_str()),
                (schema, "jsonschema")
            );
            assert_eq!(&*s.data, schema.as_bytes());
            assert_eq!(channel.message_encoding, "json");
            assert_eq!(channel.metadata, metadata(&[("i", topic)]));
        }

        // Chunk by chunk, through the chunk indexes: the messages in file order, the chunk's time
        // bounds, and message indexes that point at each message.
        let mut through_chunks = Vec::new();
        for index in &summary.chunk_indexes {
            assert_eq!(index.compression, compression.mcap_name());
            let messages: Vec<Written> = summary
                .stream_chunk(&bytes, index)
                .unwrap()
                .map(|m| as_written(&m.unwrap()))
                .collect();
            let times = messages.iter().map(|m| m.2);
            assert_eq!(index.message_start_time, times.clone().min().unwrap());
            assert_eq!(index.message_end_time, times.max().unwrap());
            let indexes = summary.read_message_indexes(&bytes, index).unwrap();
            let indexed: usize = indexes.values().map(Vec::len).sum();
            assert_eq!(indexed, messages.len(), "one index entry per message");
            for (channel, entries) in &indexes {
                let in_chunk: Vec<u64> = messages
                    .iter()
                    .filter(|m| m.0 == channel.topic)
                    .map(|m| m.2)
                    .collect();
                let listed: Vec<u64> = entries.iter().map(|e| e.log_time).collect();
                assert_eq!(listed, in_chunk, "{}", channel.topic);
                for entry in entries.iter().step_by(7) {
                    let m = summary.seek_message(&bytes, index, entry).unwrap();
                    assert_eq!(
                        (m.channel.topic.as_str(), m.log_time),
                        (channel.topic.as_str(), entry.log_time)
                    );
                }
            }
            through_chunks.extend(messages);
        }
        assert_eq!(through_chunks, written);

        // Metadata through its index.
        let names: Vec<_> = summary
            .metadata_indexes
            .iter()
            .map(|i| i.name.as_str())
            .collect();
        assert_eq!(names, ["first", "middle", "last"]);
        let first = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
        assert_eq!(
            first.metadata,
            metadata(&[("k", "v"), ("scene", "a = 1\n")])
        );
    }
}

#[test]
fn the_file_has_the_layout_of_the_spec_with_summary_offsets_for_every_group() {
    let (bytes, _) = write_file(&options(Compression::Zstd, 4096, 1), 5_000).unwrap();
    let records = validated_records(&bytes, true).unwrap();
    let opcode = |r: &Record| r.opcode();
    let data_end = records
        .iter()
        .position(|r| matches!(r, Record::DataEnd(_)))
        .expect("a data end record");
    // Data section: Header, then chunks each followed by message indexes, and metadata between them.
    assert!(matches!(records[0], Record::Header(_)));
    for pair in records[1..data_end].windows(2) {
        if let Record::MessageIndex(_) = pair[1] {
            assert!(
                matches!(pair[0], Record::Chunk { .. } | Record::MessageIndex(_)),
                "a message index follows its chunk"
            );
        }
    }
    // Summary section: groups in order, then the summary offsets, then the footer.
    let summary: Vec<u8> = records[data_end + 1..].iter().map(opcode).collect();
    let mut groups: Vec<u8> = summary.clone();
    groups.dedup();
    println!("summary groups (opcodes): {groups:02x?}");
    assert_eq!(groups, [0x03, 0x04, 0x0B, 0x08, 0x0D, 0x0E, 0x02]);
    let offsets: Vec<_> = records
        .iter()
        .filter_map(|r| match r {
            Record::SummaryOffset(o) => Some(*o),
            _ => None,
        })
        .collect();
    let Some(Record::Footer(footer)) = records.last() else {
        panic!("no footer")
    };
    assert_eq!(offsets.len(), 5);
    assert_eq!(offsets[0].group_start, footer.summary_start);
    for pair in offsets.windows(2) {
        assert_eq!(
            pair[0].group_start + pair[0].group_length,
            pair[1].group_start
        );
    }
    let last = offsets.last().unwrap();
    assert_eq!(
        last.group_start + last.group_length,
        footer.summary_offset_start
    );
    // Each group's records, read from its offset, are of its opcode.
    for o in &offsets {
        let start = usize::try_from(o.group_start).unwrap();
        let end = start + usize::try_from(o.group_length).unwrap();
        let group: Vec<u8> = mcap::read::LinearReader::sans_magic(&bytes[start..end])
            .map(|r| r.unwrap().opcode())
            .collect();
        assert!(!group.is_empty() && group.iter().all(|&op| op == o.group_opcode));
    }
}

/// Flips one byte at `at` and says whether reading still succeeds both ways.
fn flipped(bytes: &[u8], at: usize) -> Vec<u8> {
    let mut copy = bytes.to_vec();
    copy[at] ^= 0x20;
    copy
}

fn find(haystack: &[u8], needle: &[u8]) -> usize {
    haystack
        .windows(needle.len())
        .position(|w| w == needle)
        .expect("pattern in file")
}

#[test]
fn a_flipped_byte_fails_the_chunk_data_or_summary_crc() {
    // Uncompressed chunks so that a flipped byte is still a well-formed record: only a CRC can tell.
    let (bytes, _) = write_file(&options(Compression::None, 4096, 1), 2_000).unwrap();
    assert!(
        validated_records(&bytes, false).is_ok(),
        "the unflipped file reads"
    );

    // In a message in a chunk: the chunk CRC.
    let in_chunk = find(&bytes, b"\"t\":0.125") + 2;
    let chunk_error = streamed(&flipped(&bytes, in_chunk)).unwrap_err();
    println!("message byte flipped: {chunk_error}");
    assert!(matches!(chunk_error, McapError::BadChunkCrc { .. }));

    // In the first metadata record (between chunks): the data section CRC.
    let in_metadata = find(&bytes, b"a = 1");
    let data_error = validated_records(&flipped(&bytes, in_metadata), true).unwrap_err();
    println!("metadata byte flipped: {data_error}");
    assert!(matches!(data_error, McapError::BadDataCrc { .. }));

    // In the summary's copy of a channel: the summary CRC.
    // The last byte before the footer (9 + 20 bytes) and the magic (8): a summary offset's length.
    let in_summary = bytes.len() - 8 - 29 - 1;
    let summary_error = validated_records(&flipped(&bytes, in_summary), true).unwrap_err();
    println!("summary byte flipped: {summary_error}");
    assert!(matches!(summary_error, McapError::BadSummaryCrc { .. }));

    // A compressed chunk with a flipped byte does not read either (bad frame or bad CRC).
    for compression in [Compression::Zstd, Compression::Lz4] {
        let (bytes, _) = write_file(&options(compression, 4096, 1), 2_000).unwrap();
        let summary = Summary::read(&bytes).unwrap().unwrap();
        let chunk = &summary.chunk_indexes[3];
        let middle = chunk.chunk_start_offset + chunk.chunk_length - chunk.compressed_size / 2;
        let error = streamed(&flipped(&bytes, usize::try_from(middle).unwrap())).unwrap_err();
        println!("{compression:?} chunk byte flipped: {error}");
    }
}

#[test]
fn the_bytes_do_not_depend_on_the_worker_count_or_the_run() {
    for compression in COMPRESSIONS {
        let (one, _) = write_file(&options(compression, 4096, 1), 10_000).unwrap();
        let (again, _) = write_file(&options(compression, 4096, 1), 10_000).unwrap();
        let (three, _) = write_file(&options(compression, 4096, 3), 10_000).unwrap();
        // None: what a writer does when the system refuses it a thread.
        let (none, _) = write_file(&options(compression, 4096, 0), 10_000).unwrap();
        println!("{compression:?}: {} bytes", one.len());
        assert!(one == again, "{compression:?}: two runs differ");
        assert!(one == three, "{compression:?}: 1 and 3 workers differ");
        assert!(one == none, "{compression:?}: 1 worker and none differ");
    }
}

#[test]
fn a_message_larger_than_a_chunk_gets_a_chunk_of_its_own() {
    let (bytes, written) = write_file(&options(Compression::Zstd, 64, 2), 3_000).unwrap();
    let summary = Summary::read(&bytes).unwrap().unwrap();
    println!(
        "{} messages in {} chunks of at least 64 bytes",
        written.len(),
        summary.chunk_indexes.len()
    );
    assert_eq!(streamed(&bytes).unwrap(), written);
    assert!(summary
        .chunk_indexes
        .iter()
        .any(|c| c.uncompressed_size > 9000));
}

#[test]
fn a_file_without_messages_is_complete_and_readable() {
    let writer = McapWriter::new(
        Cursor::new(Vec::new()),
        &options(Compression::Zstd, 4096, 1),
    )
    .unwrap();
    let (out, length) = writer.finish().unwrap();
    let bytes = out.into_inner();
    assert_eq!(length, bytes.len() as u64);
    assert!(validated_records(&bytes, false).is_ok());
    assert_eq!(streamed(&bytes).unwrap().len(), 0);
    let stats = Summary::read(&bytes).unwrap().unwrap().stats.unwrap();
    assert_eq!((stats.message_count, stats.chunk_count), (0, 0));
}

#[test]
fn unknown_channels_and_schemas_are_refused_and_equal_registrations_share_an_id() {
    let mut writer =
        McapWriter::new(Cursor::new(Vec::new()), &options(Compression::Lz4, 4096, 1)).unwrap();
    assert!(matches!(
        writer.write_message(1, 0, 0, 0, b"x"),
        Err(WriteError::UnknownChannel { channel_id: 1 })
    ));
    assert!(matches!(
        writer.add_channel(1, "/x", "json", &BTreeMap::new()),
        Err(WriteError::UnknownSchema { schema_id: 1 })
    ));
    let s = writer.add_schema("s", "jsonschema", b"{}").unwrap();
    assert_eq!(writer.add_schema("s", "jsonschema", b"{}").unwrap(), s);
    assert_ne!(writer.add_schema("s", "jsonschema", b"{ }").unwrap(), s);
    let c = writer
        .add_channel(s, "/x", "json", &BTreeMap::new())
        .unwrap();
    assert_eq!(
        writer
            .add_channel(s, "/x", "json", &BTreeMap::new())
            .unwrap(),
        c
    );
    let schemaless = writer
        .add_channel(0, "/raw", "cbor", &BTreeMap::new())
        .unwrap();
    writer.write_message(c, 0, 5, 5, b"{}").unwrap();
    writer.write_message(schemaless, 0, 6, 6, b"\x01").unwrap();
    let (out, _) = writer.finish().unwrap();
    let bytes = out.into_inner();
    let read = streamed(&bytes).unwrap();
    assert_eq!(read.len(), 2);
    let summary = Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(summary.schemas.len(), 2);
    assert!(summary.channels.values().any(|c| c.schema.is_none()));
}

#[test]
fn a_failing_output_is_an_error_from_a_write_or_from_finish_never_a_panic_or_a_hang() {
    for compression in COMPRESSIONS {
        let options = options(compression, 4096, 1);
        let (full, written) = write_file(&options, 20_000).unwrap();
        let size = full.len();
        for limit in [
            0,
            8,
            100,
            70_000,
            70_001,
            size / 3,
            size / 2,
            size - 40,
            size - 1,
        ] {
            let out = FailingWriter::new(limit as u64);
            match write_to(out, &options, 20_000) {
                Ok(_) => panic!(
                    "{compression:?}: an output failing after {limit} of {size} bytes gave a file"
                ),
                Err((e, step)) => {
                    let mut chain = e.to_string();
                    let mut source = std::error::Error::source(&e);
                    while let Some(cause) = source {
                        chain.push_str(&format!(": {cause}"));
                        source = cause.source();
                    }
                    println!("{compression:?}: fails after {limit} of {size} bytes, at message {step} of {}: {chain}", written.len());
                    assert!(
                        chain.contains("no space left on device (test)"),
                        "the cause is kept: {chain}"
                    );
                }
            }
        }
        let out = FailingWriter::new(size as u64);
        let (out, _) = write_to(out, &options, 20_000).unwrap();
        assert!(
            out.into_bytes() == full,
            "{compression:?}: exactly enough room gives the same file"
        );
    }
}

#[test]
fn after_a_failure_every_call_fails_and_dropping_the_writer_returns() {
    let out = FailingWriter::new(200_000);
    let mut writer = McapWriter::new(out, &options(Compression::Zstd, 4096, 2)).unwrap();
    let s = writer.add_schema("s", "jsonschema", b"{}").unwrap();
    let c = writer
        .add_channel(s, "/x", "json", &BTreeMap::new())
        .unwrap();
    let payload = [b'7'; 100];
    let mut first_error = None;
    for i in 0..1_000_000_u32 {
        if let Err(e) = writer.write_message(c, i, u64::from(i), u64::from(i), &payload) {
            first_error = Some((i, e));
            break;
        }
    }
    let (at, error) = first_error.expect("the output fills up");
    println!("first error at message {at}: {error}");
    assert!(matches!(error, WriteError::Io(_)));
    assert!(matches!(
        writer.write_message(c, 0, 0, 0, &payload),
        Err(WriteError::AlreadyFailed)
    ));
    assert!(matches!(
        writer.write_metadata("m", &BTreeMap::new()),
        Err(WriteError::AlreadyFailed)
    ));
    assert!(matches!(writer.finish(), Err(WriteError::AlreadyFailed)));

    // A writer dropped with chunks in flight stops its workers and returns.
    let mut writer = McapWriter::new(Vec::new(), &options(Compression::Zstd, 256, 2)).unwrap();
    let s = writer.add_schema("s", "jsonschema", b"{}").unwrap();
    let c = writer
        .add_channel(s, "/x", "json", &BTreeMap::new())
        .unwrap();
    for i in 0..10_000_u32 {
        writer
            .write_message(c, i, u64::from(i), u64::from(i), &payload)
            .unwrap();
    }
    drop(writer);
}

#[test]
fn a_recording_passes_every_crc_check_for_every_compression() {
    use coin_log::record::{self, RecordOptions};
    use coin_log::scene::{self, presets, FlagOverrides};
    use coin_log_mcap::Compression;
    use std::sync::atomic::AtomicBool;
    let file = presets::preset("wobble").expect("built-in");
    let flags = FlagOverrides {
        duration: Some(20.0),
        ..FlagOverrides::default()
    };
    let scene = scene::resolve(&file, &flags).unwrap();
    for &compression in Compression::ALL {
        let mut out = Cursor::new(Vec::new());
        let summary = record::record(
            &scene,
            &RecordOptions {
                compression,
                ..RecordOptions::default()
            },
            &mut out,
            &AtomicBool::new(false),
            |_| {},
        )
        .unwrap();
        let bytes = out.into_inner();
        let records = validated_records(&bytes, false).unwrap();
        let messages = records
            .iter()
            .filter(|r| matches!(r, Record::Message { .. }))
            .count() as u64;
        let stats = Summary::read(&bytes).unwrap().unwrap().stats.unwrap();
        println!(
            "{compression}: {} bytes, {messages} messages, {} chunks, every CRC checked",
            bytes.len(),
            stats.chunk_count
        );
        assert_eq!(summary.bytes, bytes.len() as u64);
        assert_eq!(messages, summary.messages);
        assert_eq!(stats.message_count, summary.messages);
    }
}
