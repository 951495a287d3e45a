//! MCAP files crafted to cost a reader memory (the kinds of issue 25): zero bytes after the magic, chunks
//! that expand far beyond their size, floods of legal records, lengths that claim more than a reader
//! should hold. The large ones are sparse (`File::set_len`): they take no disk and no time to write.

#![allow(clippy::unwrap_used)]

use mcap::records::op;
use std::collections::BTreeMap;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The MCAP magic.
pub const MAGIC: &[u8] = mcap::MAGIC;

/// A record: opcode, body length, body.
pub fn record(opcode: u8, body: &[u8]) -> Vec<u8> {
    let mut r = vec![opcode];
    r.extend_from_slice(&(body.len() as u64).to_le_bytes());
    r.extend_from_slice(body);
    r
}

/// An MCAP string: u32 length, bytes.
pub fn string(s: &str) -> Vec<u8> {
    let mut b = (s.len() as u32).to_le_bytes().to_vec();
    b.extend_from_slice(s.as_bytes());
    b
}

/// The magic and a header record.
pub fn start() -> Vec<u8> {
    let mut f = MAGIC.to_vec();
    let mut header = string("");
    header.extend(string("crafted"));
    f.extend(record(op::HEADER, &header));
    f
}

/// DataEnd (no CRC), a footer without a summary, and the end magic.
pub fn end() -> Vec<u8> {
    let mut f = record(op::DATA_END, &[0; 4]);
    f.extend(record(op::FOOTER, &[0; 20]));
    f.extend(MAGIC);
    f
}

/// The MCAP magic followed by `zeros` zero bytes, sparse.
pub fn zeros_after_magic(path: &Path, zeros: u64) {
    let mut f = std::fs::File::create(path).unwrap();
    f.write_all(MAGIC).unwrap();
    f.set_len(MAGIC.len() as u64 + zeros).unwrap();
}

/// A file with one zstd chunk whose records are `expanded` zero bytes (empty records of opcode 0, legal
/// MCAP), declaring `declared` bytes of records: a few KiB that expand to `expanded`.
pub fn chunk_bomb(path: &Path, expanded: u64, declared: u64) {
    let block = vec![0u8; 1 << 20];
    let mut encoder = zstd::stream::Encoder::new(Vec::new(), 19).unwrap();
    let mut left = expanded;
    while left > 0 {
        let n = left.min(block.len() as u64);
        encoder.write_all(&block[..n as usize]).unwrap();
        left -= n;
    }
    let compressed = encoder.finish().unwrap();
    let mut chunk = Vec::new();
    chunk.extend(0u64.to_le_bytes());
    chunk.extend(0u64.to_le_bytes());
    chunk.extend(declared.to_le_bytes());
    chunk.extend(0u32.to_le_bytes());
    chunk.extend(string("zstd"));
    chunk.extend((compressed.len() as u64).to_le_bytes());
    chunk.extend(&compressed);
    let mut f = start();
    f.extend(record(op::CHUNK, &chunk));
    f.extend(end());
    std::fs::write(path, f).unwrap();
}

/// A record of `opcode` claiming a body of `claimed` bytes, after the header, in a sparse file of `len`
/// bytes (the body and what follows are zero bytes).
pub fn claiming(path: &Path, opcode: u8, claimed: u64, len: u64) {
    let mut f = start();
    f.push(opcode);
    f.extend(claimed.to_le_bytes());
    let mut file = std::fs::File::create(path).unwrap();
    file.write_all(&f).unwrap();
    file.set_len(len).unwrap();
}

/// A file whose only record is a `coin-log` metadata record of `entries` distinct keys with empty values.
pub fn metadata_with_entries(path: &Path, entries: usize) {
    let mut map = Vec::new();
    for i in 0..entries {
        map.extend(string(&format!("{i:x}")));
        map.extend(string(""));
    }
    let mut body = string("coin-log");
    body.extend((map.len() as u32).to_le_bytes());
    body.extend(map);
    let mut f = start();
    f.extend(record(op::METADATA, &body));
    f.extend(end());
    std::fs::write(path, f).unwrap();
}

/// Copies the recording `src` to `dst` with the `mcap` crate's writer (same metadata, channels and
/// messages), with `count` empty records of the private opcode 0x80 (legal MCAP that readers skip) after
/// the `coin-log` metadata record.
pub fn with_private_records(src: &Path, dst: &Path, count: u64) {
    let bytes = std::fs::read(src).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut metadata: Vec<mcap::records::Metadata> = summary
        .metadata_indexes
        .iter()
        .map(|i| mcap::read::metadata(&bytes, i).unwrap())
        .collect();
    metadata.sort_by_key(|m| m.name != "coin-log");
    let file = BufWriter::new(std::fs::File::create(dst).unwrap());
    let mut w = mcap::WriteOptions::new()
        .library("coin-log/test")
        .create(file)
        .unwrap();
    w.write_metadata(&metadata[0]).unwrap();
    for _ in 0..count {
        w.write_private_record(0x80, &[], Default::default())
            .unwrap();
    }
    let mut ids = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let id = *ids.entry(m.channel.id).or_insert_with(|| {
            let schema = m.channel.schema.as_ref().unwrap();
            let s = w
                .add_schema(&schema.name, &schema.encoding, &schema.data)
                .unwrap();
            w.add_channel(
                s,
                &m.channel.topic,
                &m.channel.message_encoding,
                &BTreeMap::new(),
            )
            .unwrap()
        });
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: m.sequence,
            log_time: m.log_time,
            publish_time: m.publish_time,
        };
        w.write_to_known_channel(&header, &m.data).unwrap();
    }
    for m in &metadata[1..] {
        w.write_metadata(m).unwrap();
    }
    w.finish().unwrap();
}
