//! The compression bound: the time one thread takes to zstd-compress the bytes of a recording,
//! chunk by chunk as `coin_log_mcap::McapWriter` does, and the JSON payloads alone in pieces of the same size.
//!
//! `cargo run --release --example compression_bound -- FILE.mcap [LEVEL...]`. Prints the median of 5 passes
//! (seconds, MB/s, messages/s, compressed size) for the writer's own `ChunkCompressor` (zstd at its level,
//! lz4, none: what a recording costs to compress), then for each zstd LEVEL given.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::print_stdout, reason = "a measurement printed for the reader")]

use coin_log_mcap::{ChunkCompressor, Compression, DEFAULT_CHUNK_SIZE, ZSTD_LEVEL};
use mcap::records::Record;
use std::io::Read;
use std::time::Instant;

const PASSES: usize = 5;

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .expect("usage: compression_bound FILE.mcap [LEVEL...]");
    let levels: Vec<i32> = args.map(|a| a.parse().expect("a zstd level")).collect();
    let bytes = std::fs::read(&path).unwrap();

    let chunks = chunk_records(&bytes);
    let (payloads, messages) = payloads(&bytes);
    let pieces: Vec<&[u8]> = payloads.chunks(DEFAULT_CHUNK_SIZE).collect();
    let chunk_refs: Vec<&[u8]> = chunks.iter().map(Vec::as_slice).collect();
    let records_len: usize = chunks.iter().map(Vec::len).sum();
    println!(
        "{path}: {messages} messages; {} chunks, {records_len} bytes of records; {} bytes of JSON",
        chunks.len(),
        payloads.len()
    );
    let report = |what: &str, seconds: f64, len: usize, compressed: usize| {
        #[allow(clippy::cast_precision_loss)]
        let (mb, msgs, ratio) = (
            len as f64 / seconds / 1e6,
            messages as f64 / seconds / 1e6,
            len as f64 / compressed.max(1) as f64,
        );
        println!("{what}: {seconds:.3} s, {mb:.0} MB/s, {msgs:.2} M messages/s, {compressed} bytes ({ratio:.2}x)");
    };
    for compression in [Compression::Zstd, Compression::Lz4, Compression::None] {
        let (seconds, compressed) = writer_pass(compression, &chunk_refs);
        let name = match compression {
            Compression::Zstd => format!("zstd level {ZSTD_LEVEL}"),
            other => format!("{other:?}").to_lowercase(),
        };
        report(
            &format!("writer's {name} + CRC, chunk records"),
            seconds,
            records_len,
            compressed,
        );
    }
    for level in levels {
        let mut compressor = zstd::bulk::Compressor::new(level).unwrap();
        for (what, input, len) in [
            ("chunk records", &chunk_refs, records_len),
            ("JSON payloads", &pieces, payloads.len()),
        ] {
            let (seconds, compressed) = median_pass(input, |piece, out| {
                out.reserve(zstd::compress_bound(piece.len()));
                compressor.compress_to_buffer(piece, out).unwrap()
            });
            report(
                &format!("zstd level {level:>2}, {what}"),
                seconds,
                len,
                compressed,
            );
        }
    }
}

/// The uncompressed records of every chunk, as the writer handed them to its worker.
fn chunk_records(bytes: &[u8]) -> Vec<Vec<u8>> {
    let mut chunks = Vec::new();
    for record in mcap::read::LinearReader::new(bytes).unwrap() {
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
    chunks
}

/// The JSON payloads alone, back to back, and how many messages they are.
fn payloads(bytes: &[u8]) -> (Vec<u8>, u64) {
    let mut payloads = Vec::new();
    let mut messages = 0_u64;
    for message in mcap::MessageStream::new(bytes).unwrap() {
        payloads.extend_from_slice(&message.unwrap().data);
        messages += 1;
    }
    (payloads, messages)
}

/// The writer's own compressor (and CRC) over the chunk records: median seconds and compressed size.
fn writer_pass(compression: Compression, chunks: &[&[u8]]) -> (f64, usize) {
    let mut compressor = ChunkCompressor::new(compression);
    median_pass(chunks, |piece, out| {
        compressor.compress(piece, out).unwrap();
        crc32fast::hash(piece);
        if out.is_empty() {
            piece.len() // stored as is
        } else {
            out.len()
        }
    })
}

/// Median seconds of `PASSES` single-threaded passes of `compress` over `input`, and the compressed size.
fn median_pass(
    input: &[&[u8]],
    mut compress: impl FnMut(&[u8], &mut Vec<u8>) -> usize,
) -> (f64, usize) {
    let mut out = Vec::new();
    let mut times = Vec::new();
    let mut compressed = 0;
    for _ in 0..PASSES {
        compressed = 0;
        let start = Instant::now();
        for piece in input {
            out.clear();
            compressed += compress(piece, &mut out);
        }
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    (times[PASSES / 2], compressed)
}
