//! The compression bound of issue 9: the time one thread takes to zstd-compress the bytes of a recording,
//! chunk by chunk as `record::writer` does, and the JSON payloads alone in pieces of the same size.
//!
//! `cargo run --release --example compression_bound -- FILE.mcap [LEVEL...]` (default: the writer's level).
//! Prints, per level, the median of 5 passes: seconds, MB/s, messages/s and the compressed size.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use coin_log::record::writer::{DEFAULT_CHUNK_SIZE, ZSTD_LEVEL};
use mcap::records::Record;
use std::io::Read;
use std::time::Instant;

const PASSES: usize = 5;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .expect("usage: compression_bound FILE.mcap [LEVEL...]");
    let mut levels: Vec<i32> = args.map(|a| a.parse().expect("a zstd level")).collect();
    if levels.is_empty() {
        levels.push(ZSTD_LEVEL);
    }
    let bytes = std::fs::read(&path).unwrap();

    // The uncompressed records of every chunk, as the writer handed them to its worker.
    let mut chunks = Vec::new();
    for record in mcap::read::LinearReader::new(&bytes).unwrap() {
        if let Record::Chunk { header, data } = record.unwrap() {
            let size = usize::try_from(header.uncompressed_size).unwrap();
            let records = match header.compression.as_str() {
                "zstd" => zstd::bulk::decompress(&data, size).unwrap(),
                "lz4" => {
                    let mut out = Vec::with_capacity(size);
                    lz4::Decoder::new(&*data)
                        .unwrap()
                        .read_to_end(&mut out)
                        .unwrap();
                    out
                }
                _ => data.into_owned(),
            };
            chunks.push(records);
        }
    }
    // The JSON payloads alone, back to back, cut into pieces of the chunk size.
    let mut payloads = Vec::new();
    let mut messages = 0_u64;
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        payloads.extend_from_slice(&message.unwrap().data);
        messages += 1;
    }
    let pieces: Vec<&[u8]> = payloads.chunks(DEFAULT_CHUNK_SIZE).collect();
    let chunk_refs: Vec<&[u8]> = chunks.iter().map(Vec::as_slice).collect();
    let records_len: usize = chunks.iter().map(Vec::len).sum();
    println!(
        "{path}: {messages} messages; {} chunks, {records_len} bytes of records; {} bytes of JSON",
        chunks.len(),
        payloads.len()
    );
    for level in levels {
        for (what, input, len) in [
            ("chunk records", &chunk_refs, records_len),
            ("JSON payloads", &pieces, payloads.len()),
        ] {
            let (seconds, compressed) = time_compression(input, level);
            #[allow(clippy::cast_precision_loss)]
            let (mb, msgs) = (len as f64 / seconds / 1e6, messages as f64 / seconds);
            println!(
                "zstd level {level:>2}, {what}: {seconds:.3} s, {mb:.0} MB/s, {:.2} M messages/s, {compressed} bytes ({:.2}x)",
                msgs / 1e6,
                len as f64 / compressed as f64
            );
        }
    }
}

/// Median seconds of `PASSES` single-threaded passes, and the compressed size.
fn time_compression(input: &[&[u8]], level: i32) -> (f64, usize) {
    let mut compressor = zstd::bulk::Compressor::new(level).unwrap();
    let mut out = Vec::new();
    let mut times = Vec::new();
    let mut compressed = 0;
    for _ in 0..PASSES {
        compressed = 0;
        let start = Instant::now();
        for piece in input {
            out.clear();
            out.reserve(zstd::compress_bound(piece.len()));
            compressed += compressor.compress_to_buffer(piece, &mut out).unwrap();
        }
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    (times[PASSES / 2], compressed)
}
