//! The `mcap` crate (0.26) against this crate on the same records: whether the crate can write and read
//! coin-log's files in place of [`coin_log_mcap::McapWriter`] and [`coin_log_mcap::read`].
//!
//! The workload is `coin-log bench throughput`'s record workload (wobble, 1000 time units at 1 kHz, the
//! seven channels omega…energy, zstd: 7 000 007 messages, 808 MB of JSON). Make the file once and pass it:
//!
//! ```text
//! coin-log record wobble --duration 1000 --rate 1000 \
//!     --channels omega,angles,quaternion,position,contact,reaction,energy -o /tmp/wobble-1000.mcap
//! cargo bench -p coin-log-bench --bench crate_vs_ours -- /tmp/wobble-1000.mcap [ROUNDS]
//! ```
//!
//! Its messages are loaded into memory once (1.2 GB), then every variant runs once per round, in turn
//! (alternating, so that a change in the machine's load hits all of them), and the median of the rounds
//! (default 3) is printed:
//! - **write**: the same schemas, channels, metadata and messages into an in-memory file, by this crate's
//!   writer (zstd level 1, 1 MiB chunks, 1 and 2 workers) and by `mcap::Writer` with the same settings
//!   (`compression_level(1)`, 1 MiB chunks, `compression_threads` 0, 1 and 2); writing only;
//! - **read**: the file from the page cache, every message handed over, by this crate's streaming
//!   reader (all its checks included), by the crate's sans-io `LinearReader` (chunks decompressed, CRCs
//!   checked) with `mcap::parse_record` on every record, and by `mcap::MessageStream` over the file in
//!   memory;
//! - **parse**: the records of every chunk, decompressed beforehand, parsed by this crate's record types
//!   and by `mcap::parse_record` (parsing alone);
//! - **summary**: the summary section and the metadata it indexes, by [`coin_log_mcap::read_summary`]
//!   and by `mcap::Summary::read` plus `mcap::read::metadata` over the file in memory.
//!
//! Each variant's peak RSS above what was resident before it is shown (`VmHWM`, reset before it). First, the bench reports how far
//! `mcap::parse_record` raises the peak address space for a 30-byte metadata index record whose name
//! claims 4 GiB (the reason the reader parses records with its own bounds-checked types).

// A bench binary run by hand: its table is its output, and main reads as the list of races it runs.
#![allow(clippy::print_stdout, clippy::too_many_lines)]

use coin_log_mcap::records::{MessageRecord, Record, WireError};
use coin_log_mcap::{Compression, MessageHeader, Schema, Visitor, WriterOptions};
use mcap::records::op;
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::BTreeMap;
use std::error::Error;
use std::io::{Cursor, Read};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A field of `/proc/self/status` (`VmHWM`: peak resident set, `VmPeak`: peak address space) \[bytes\].
fn status(field: &str) -> usize {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let line = status.lines().find(|l| l.starts_with(field));
    let kb = line.and_then(|l| l.split_whitespace().nth(1)?.parse::<usize>().ok());
    kb.unwrap_or(0) * 1024
}

/// Resets `VmHWM` to the current resident set (Linux ≥ 4.0), so that it measures the next variant alone.
fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

type Result<T> = std::result::Result<T, Box<dyn Error>>;

/// The file's records, in memory, to be written again.
#[derive(Default)]
struct Recording {
    /// Each channel's schema, topic and message encoding.
    channels: Vec<(Schema<'static>, String, String)>,
    metadata: Vec<(String, BTreeMap<String, String>)>,
    headers: Vec<MessageHeader>,
    /// Message data back to back; message i is `data[ends[i - 1]..ends[i]]`.
    data: Vec<u8>,
    ends: Vec<usize>,
}

impl Recording {
    fn messages(&self) -> impl Iterator<Item = (&MessageHeader, &[u8])> {
        let starts = std::iter::once(0).chain(self.ends.iter().copied());
        self.headers
            .iter()
            .zip(starts.zip(self.ends.iter().copied()))
            .map(|(h, (a, b))| (h, &self.data[a..b]))
    }
}

impl Visitor for Recording {
    fn channel(
        &mut self,
        _: u16,
        topic: &str,
        message_encoding: &str,
        schema: Option<&Schema<'_>>,
    ) {
        let schema = schema.map_or_else(
            || Schema {
                id: 0,
                name: String::new(),
                encoding: String::new(),
                data: Vec::new().into(),
            },
            |s| Schema {
                id: s.id,
                name: s.name.clone(),
                encoding: s.encoding.clone(),
                data: s.data.to_vec().into(),
            },
        );
        self.channels
            .push((schema, topic.into(), message_encoding.into()));
    }
    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        self.metadata.push((name.into(), entries.clone()));
    }
    fn message(&mut self, header: &MessageHeader, data: &[u8]) -> ControlFlow<()> {
        self.headers.push(*header);
        self.data.extend_from_slice(data);
        self.ends.push(self.data.len());
        ControlFlow::Continue(())
    }
}

/// Counts what it is handed.
#[derive(Default)]
struct Count {
    messages: u64,
    bytes: u64,
}

impl Visitor for Count {
    fn message(&mut self, _: &MessageHeader, data: &[u8]) -> ControlFlow<()> {
        self.messages += 1;
        self.bytes += data.len() as u64;
        ControlFlow::Continue(())
    }
}

/// Writes `r` with this crate's writer into `out` (emptied first); returns the file's length.
fn write_ours(r: &Recording, workers: usize, out: &mut Vec<u8>) -> Result<u64> {
    out.clear();
    let mut options = WriterOptions::new(Compression::Zstd, "bench");
    options.workers = workers;
    let mut w = coin_log_mcap::McapWriter::new(Cursor::new(std::mem::take(out)), &options)?;
    let (first, rest) = r.metadata.split_at(1.min(r.metadata.len()));
    for (name, entries) in first {
        w.write_metadata(name, entries)?;
    }
    for (s, topic, encoding) in &r.channels {
        let schema = w.add_schema(&s.name, &s.encoding, &s.data)?;
        w.add_channel(schema, topic, encoding, &BTreeMap::new())?;
    }
    for (h, data) in r.messages() {
        w.write_message(h.channel_id, h.sequence, h.log_time, h.publish_time, data)?;
    }
    for (name, entries) in rest {
        w.write_metadata(name, entries)?;
    }
    let (cursor, len) = w.finish()?;
    *out = cursor.into_inner();
    Ok(len)
}

/// Writes `r` with `mcap::Writer` into `out` (emptied first); returns the file's length.
fn write_crate(r: &Recording, threads: u32, out: &mut Vec<u8>) -> Result<u64> {
    out.clear();
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .compression_level(1)
        .compression_threads(threads)
        .chunk_size(Some(1 << 20))
        .library("bench")
        .create(Cursor::new(std::mem::take(out)))?;
    let metadata = |(name, entries): &(String, BTreeMap<String, String>)| mcap::records::Metadata {
        name: name.clone(),
        metadata: entries.clone(),
    };
    let (first, rest) = r.metadata.split_at(1.min(r.metadata.len()));
    for m in first {
        w.write_metadata(&metadata(m))?;
    }
    for (s, topic, encoding) in &r.channels {
        let schema = w.add_schema(&s.name, &s.encoding, &s.data)?;
        w.add_channel(schema, topic, encoding, &BTreeMap::new())?;
    }
    for (h, data) in r.messages() {
        let header = mcap::records::MessageHeader {
            channel_id: h.channel_id,
            sequence: h.sequence,
            log_time: h.log_time,
            publish_time: h.publish_time,
        };
        w.write_to_known_channel(&header, data)?;
    }
    for m in rest {
        w.write_metadata(&metadata(m))?;
    }
    w.finish()?;
    *out = w.into_inner().into_inner();
    Ok(out.len() as u64)
}

/// Reads `path` with this crate's streaming reader.
fn read_ours(path: &Path) -> Result<(u64, u64)> {
    let mut count = Count::default();
    let (_, error) = coin_log_mcap::read(path, &mut count);
    if let Some(e) = error {
        return Err(e.to_string().into());
    }
    Ok((count.messages, count.bytes))
}

/// Reads `path` with the crate's sans-io linear reader and `parse_record`.
fn read_crate_linear(path: &Path) -> Result<(u64, u64)> {
    let mut file = std::fs::File::open(path)?;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_validate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true),
    );
    let (mut messages, mut bytes) = (0, 0);
    while let Some(event) = reader.next_event() {
        match event? {
            LinearReadEvent::ReadRequest(need) => {
                let buf = reader.insert(need.max(1 << 18));
                let n = file.read(buf)?;
                reader.notify_read(n);
            }
            LinearReadEvent::Record { opcode, data } => {
                if let mcap::records::Record::Message { data, .. } =
                    mcap::parse_record(opcode, data)?
                {
                    messages += 1;
                    bytes += data.len() as u64;
                }
            }
        }
    }
    Ok((messages, bytes))
}

/// Reads the file in memory with `mcap::MessageStream`.
fn read_crate_stream(bytes: &[u8]) -> Result<(u64, u64)> {
    let (mut messages, mut total) = (0, 0);
    for m in mcap::MessageStream::new(bytes)? {
        messages += 1;
        total += m?.data.len() as u64;
    }
    Ok((messages, total))
}

/// Every chunk's records, decompressed, back to back, with (opcode, body range) of each.
struct Records {
    bytes: Vec<u8>,
    records: Vec<(u8, std::ops::Range<usize>)>,
}

fn chunk_records(path: &Path) -> Result<Vec<Records>> {
    let mut file = std::fs::File::open(path)?;
    let mut reader = LinearReader::new();
    let mut chunks: Vec<Records> = Vec::new();
    let mut in_chunk = false;
    while let Some(event) = reader.next_event() {
        match event? {
            LinearReadEvent::ReadRequest(need) => {
                let buf = reader.insert(need.max(1 << 18));
                let n = file.read(buf)?;
                reader.notify_read(n);
                in_chunk = false;
            }
            LinearReadEvent::Record { opcode, data } => {
                if !in_chunk || chunks.is_empty() || opcode == op::MESSAGE_INDEX {
                    chunks.push(Records {
                        bytes: Vec::new(),
                        records: Vec::new(),
                    });
                    in_chunk = true;
                }
                let Some(c) = chunks.last_mut() else {
                    continue;
                };
                let start = c.bytes.len();
                c.bytes.extend_from_slice(data);
                c.records.push((opcode, start..c.bytes.len()));
            }
        }
    }
    Ok(chunks)
}

fn parse_crate(chunks: &[Records]) -> Result<u64> {
    use mcap::records::Record as R;
    let mut n = 0;
    for c in chunks {
        for (opcode, body) in &c.records {
            n += match mcap::parse_record(*opcode, &c.bytes[body.clone()])? {
                R::Message { header, .. } => header.log_time & 1,
                R::Schema { header, .. } => u64::from(header.id),
                R::Channel(c) => u64::from(c.id),
                R::MessageIndex(i) => i.records.len() as u64,
                R::ChunkIndex(i) => i.chunk_length,
                R::Statistics(s) => s.message_count,
                R::Metadata(m) => m.metadata.len() as u64,
                R::MetadataIndex(i) => i.offset,
                R::SummaryOffset(o) => o.group_start,
                R::Header(h) => h.library.len() as u64,
                _ => 0,
            };
        }
    }
    Ok(n)
}

/// Parses one record with this crate's record types, as the readers do.
fn parse_one_ours(opcode: u8, body: &[u8]) -> std::result::Result<u64, WireError> {
    use mcap::records as r;
    Ok(match opcode {
        op::MESSAGE => MessageRecord::parse_body(body)?.header.log_time & 1,
        op::SCHEMA => u64::from(Schema::parse_body(body)?.id),
        op::CHANNEL => u64::from(r::Channel::parse_body(body)?.id),
        op::MESSAGE_INDEX => r::MessageIndex::parse_body(body)?.records.len() as u64,
        op::CHUNK_INDEX => r::ChunkIndex::parse_body(body)?.chunk_length,
        op::STATISTICS => r::Statistics::parse_body(body)?.message_count,
        op::METADATA => r::Metadata::parse_body(body)?.metadata.len() as u64,
        op::METADATA_INDEX => r::MetadataIndex::parse_body(body)?.offset,
        op::SUMMARY_OFFSET => r::SummaryOffset::parse_body(body)?.group_start,
        op::HEADER => r::Header::parse_body(body)?.library.len() as u64,
        _ => 0,
    })
}

fn parse_ours(chunks: &[Records]) -> Result<u64> {
    let mut n = 0;
    for c in chunks {
        for (opcode, body) in &c.records {
            n += parse_one_ours(*opcode, &c.bytes[body.clone()])?;
        }
    }
    Ok(n)
}

fn summary_ours(path: &Path) -> Result<u64> {
    let s = coin_log_mcap::read_summary(path)
        .map_err(|e| e.to_string())?
        .ok_or("no summary")?;
    Ok(s.messages + s.metadata.len() as u64)
}

fn summary_crate(bytes: &[u8]) -> Result<u64> {
    let s = mcap::Summary::read(bytes)?.ok_or("no summary")?;
    let mut n = s.stats.map_or(0, |s| s.message_count);
    for index in &s.metadata_indexes {
        mcap::read::metadata(bytes, index)?;
        n += 1;
    }
    Ok(n)
}

/// One measured variant: its name and its times \[s\], peak RSS increases \[bytes\] and results, per round.
struct Variant<'a> {
    name: &'a str,
    run: Box<dyn FnMut() -> Result<u64> + 'a>,
    seconds: Vec<f64>,
    peaks: Vec<usize>,
    result: u64,
}

impl<'a> Variant<'a> {
    fn new(name: &'a str, run: impl FnMut() -> Result<u64> + 'a) -> Self {
        Self {
            name,
            run: Box::new(run),
            seconds: Vec::new(),
            peaks: Vec::new(),
            result: 0,
        }
    }
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Runs every variant once per round, in turn, and prints the medians with the fastest as reference.
fn race(
    title: &str,
    rounds: usize,
    variants: &mut [Variant<'_>],
    per: f64,
    unit: &str,
) -> Result<()> {
    for _ in 0..rounds {
        for v in variants.iter_mut() {
            reset_peak_rss();
            let resident = status("VmRSS:");
            let start = Instant::now();
            v.result = (v.run)()?;
            v.seconds.push(start.elapsed().as_secs_f64());
            v.peaks.push(status("VmHWM:").saturating_sub(resident));
        }
    }
    let best = variants
        .iter()
        .map(|v| median(&v.seconds))
        .fold(f64::INFINITY, f64::min);
    println!("{title}");
    for v in variants.iter() {
        let t = median(&v.seconds);
        let peak = v.peaks.iter().copied().max().unwrap_or(0);
        println!(
            "  {:<58} {:>10.4} s  {:>8.3} {unit}  {:>6.3}× the fastest  RSS +{:>7.1} MiB  ({})",
            v.name,
            t,
            per / t / 1e6,
            t / best,
            peak as f64 / f64::from(1 << 20),
            v.result
        );
    }
    Ok(())
}

/// How far `parse` raises the peak address space on a metadata index record whose name claims 4 GiB
/// (untouched memory: the resident set does not show it, an allocation limit would).
fn claimed_string_peak(parse: impl FnOnce(&[u8]) -> bool) -> (usize, bool) {
    let mut body = Vec::new();
    body.extend_from_slice(&8u64.to_le_bytes());
    body.extend_from_slice(&100u64.to_le_bytes());
    body.extend_from_slice(&u32::MAX.to_le_bytes());
    body.extend_from_slice(b"coin-l");
    let before = status("VmPeak:");
    let ok = parse(&body);
    (status("VmPeak:").saturating_sub(before), ok)
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let path = PathBuf::from(args.first().ok_or(
        "usage: cargo bench -p coin-log-bench --bench crate_vs_ours -- FILE.mcap [ROUNDS] (see the doc)",
    )?);
    let rounds: usize = args.get(1).map_or(Ok(3), |r| r.parse())?;
    let (crate_peak, _) =
        claimed_string_peak(|b| mcap::parse_record(op::METADATA_INDEX, b).is_ok());
    println!(
        "a 30-byte metadata index record whose name claims 4 GiB: mcap::parse_record raises the peak \
         address space by {:.0} MiB",
        crate_peak as f64 / f64::from(1 << 20)
    );
    let mut recording = Recording::default();
    let (_, error) = coin_log_mcap::read(&path, &mut recording);
    if let Some(e) = error {
        return Err(format!("{}: {e}", path.display()).into());
    }
    let messages = recording.headers.len() as f64;
    println!(
        "{}: {} messages, {} bytes of message data; {rounds} rounds, medians",
        path.display(),
        recording.headers.len(),
        recording.data.len()
    );

    let out = std::cell::RefCell::new(Vec::with_capacity(400 << 20));
    let r = &recording;
    race(
        "write (in memory)",
        rounds,
        &mut [
            Variant::new("coin_log_mcap::McapWriter, 1 worker", || {
                write_ours(r, 1, &mut out.borrow_mut())
            }),
            Variant::new("mcap::Writer, compression_threads(0)", || {
                write_crate(r, 0, &mut out.borrow_mut())
            }),
            Variant::new("coin_log_mcap::McapWriter, 2 workers", || {
                write_ours(r, 2, &mut out.borrow_mut())
            }),
            Variant::new("mcap::Writer, compression_threads(1)", || {
                write_crate(r, 1, &mut out.borrow_mut())
            }),
            Variant::new("mcap::Writer, compression_threads(2)", || {
                write_crate(r, 2, &mut out.borrow_mut())
            }),
        ],
        messages,
        "M msg/s",
    )?;
    drop(out);
    drop(recording);

    let bytes = std::fs::read(&path)?;
    let count = |r: Result<(u64, u64)>| r.map(|(m, _)| m);
    race(
        "read (file in the page cache; MessageStream: in memory)",
        rounds,
        &mut [
            Variant::new("coin_log_mcap::read (every check)", || {
                count(read_ours(&path))
            }),
            Variant::new("mcap sans-io LinearReader + parse_record", || {
                count(read_crate_linear(&path))
            }),
            Variant::new("mcap::MessageStream", || count(read_crate_stream(&bytes))),
        ],
        messages,
        "M msg/s",
    )?;

    let chunks = chunk_records(&path)?;
    race(
        "parse (decompressed records in memory)",
        rounds,
        &mut [
            Variant::new("this crate's record types", || parse_ours(&chunks)),
            Variant::new("mcap::parse_record", || parse_crate(&chunks)),
        ],
        messages,
        "M msg/s",
    )?;
    drop(chunks);

    let repeat = 101;
    race(
        "summary (statistics, channels, chunk indexes, metadata), 101 repeats",
        rounds,
        &mut [
            Variant::new("coin_log_mcap::read_summary (from the file)", || {
                (0..repeat).try_fold(0, |n, _| Ok(n + summary_ours(&path)?))
            }),
            Variant::new("mcap::Summary::read + read::metadata (in memory)", || {
                (0..repeat).try_fold(0, |n, _| Ok(n + summary_crate(&bytes)?))
            }),
        ],
        f64::from(repeat) * 1e3,
        "k reads/s",
    )?;

    Ok(())
}
