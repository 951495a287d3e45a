//! A pipelined, deterministic, chunked MCAP writer ([`McapWriter`]).
//!
//! Ours rather than `mcap::Writer` (0.26), which streams every record through a zstd context on the
//! calling thread and cannot hand a finished chunk away. On the 7 M-message workload (crate_vs_ours'
//! "write" race: in memory, zstd level 1, 1 MiB chunks, medians of 3 alternating rounds at load 7 on 2
//! cores) this writer took 3.81 s with 1 worker (2.94 s with 2), `mcap::Writer` 6.07, 5.93 and 7.72 s
//! with 0, 1 and 2 compression threads: 1.56 to 2.03 times as long. It would also change every
//! recording's bytes.

use crate::records::{chunk_index, len32, ChunkRecord, MessageRecord, Record, MAGIC};
use crate::summary::widen;
use mcap::records::{
    Channel, ChunkHeader, ChunkIndex, DataEnd, Footer, Header, MessageHeader, MessageIndex,
    MessageIndexEntry, Metadata, MetadataIndex, Statistics, SummaryOffset,
};
use mcap::Schema;
use std::collections::BTreeMap;
use std::io::{self, BufWriter, Write};
use std::mem;
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::thread::JoinHandle;

/// The default of [`WriterOptions::chunk_size`] \[bytes of uncompressed records\], as the `mcap`
/// crate's.
pub const DEFAULT_CHUNK_SIZE: usize = 1 << 20;

/// The zstd level of [`Compression::Zstd`] chunks: faster and smaller than zstd's default level 3 on
/// coin-log's JSON (seven-channel wobble run: 3.9× vs 3.5× smaller, about 1.3× faster).
pub const ZSTD_LEVEL: i32 = 1;

/// lz4's fast default, as in the `mcap` crate.
const LZ4_LEVEL: u32 = 0;

/// Chunks a worker may hold (one being compressed, one queued) before the calling thread waits.
const IN_FLIGHT_PER_WORKER: usize = 2;

const OUTPUT_BUFFER: usize = 1 << 16;

coin_log_names::named_enum! {
    /// How chunks are compressed; the name is the one of `--compression` and of the recording's metadata.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    pub enum Compression: "compression" {
        /// zstd at [`ZSTD_LEVEL`] (the default).
        #[default]
        Zstd = "zstd",
        /// An lz4 frame (fast level, linked blocks, content checksum, no block checksums).
        Lz4 = "lz4",
        /// Stored uncompressed.
        None = "none",
    }
}

impl Compression {
    /// The `compression` string of the Chunk and ChunkIndex records.
    #[must_use]
    pub fn mcap_name(self) -> &'static str {
        match self {
            Self::None => "",
            _ => self.name(),
        }
    }
}

/// How to write a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WriterOptions {
    /// Chunk compression.
    pub compression: Compression,
    /// A chunk is closed once its uncompressed records reach this many bytes (at least 1).
    pub chunk_size: usize,
    /// Compression worker threads; 0 compresses on the writer's own thread. The bytes do not depend on
    /// it.
    pub workers: usize,
    /// The Header's `library`.
    pub library: String,
}

impl WriterOptions {
    /// Options with the given compression and library string, [`DEFAULT_CHUNK_SIZE`] and one worker.
    #[must_use]
    pub fn new(compression: Compression, library: impl Into<String>) -> Self {
        Self {
            compression,
            chunk_size: DEFAULT_CHUNK_SIZE,
            workers: 1,
            library: library.into(),
        }
    }
}

/// Writing the file failed; the output is unusable.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum WriteError {
    /// The output refused a write (disk full, file gone, …).
    #[error(transparent)]
    Io(#[from] io::Error),
    /// zstd or lz4 failed on a chunk (in practice only when out of memory).
    #[error("compressing an MCAP chunk failed")]
    Compress(#[source] io::Error),
    /// A compression worker thread ended without answering (it panicked).
    #[error("an MCAP compression worker stopped unexpectedly")]
    WorkerLost,
    /// An earlier call failed; the file cannot be completed.
    #[error("the MCAP writer failed earlier; the file cannot be completed")]
    AlreadyFailed,
    /// More schemas or channels (`what`) than ids.
    #[error("too many {what} for one MCAP file (at most 65535)")]
    TooMany { what: &'static str },
    /// A message on a channel id that [`McapWriter::add_channel`] never returned.
    #[error("a message on channel {channel_id}, which was never added")]
    UnknownChannel { channel_id: u16 },
    /// A channel whose schema id [`McapWriter::add_schema`] never returned.
    #[error("a channel refers to schema {schema_id}, which was never added")]
    UnknownSchema { schema_id: u16 },
    /// A string, byte array or map longer than an MCAP length field (u32) can say.
    #[error("a {what} of {len} bytes is too long for an MCAP record")]
    TooLong { what: &'static str, len: usize },
}

/// What the calling thread knows about a chunk; reused from chunk to chunk.
#[derive(Debug, Default)]
struct ChunkMeta {
    /// (earliest, latest) log time, None before the first message.
    bounds: Option<(u64, u64)>,
    /// Per channel (index = id − 1), its message index.
    indexes: Vec<MessageIndex>,
}

impl ChunkMeta {
    fn clear(&mut self) {
        self.bounds = None;
        for index in &mut self.indexes {
            index.records.clear();
        }
    }
}

/// A chunk on its way to a worker and back, its buffers then reused: its records and what the calling
/// thread knows of them, to which the worker adds their CRC-32 and them compressed (empty for
/// [`Compression::None`]).
struct Job {
    records: Vec<u8>,
    meta: ChunkMeta,
    compressed: Vec<u8>,
    crc: u32,
    result: io::Result<()>,
}

impl Job {
    /// The records' CRC-32 and them compressed: a worker's part, or the writer's without one.
    fn compress(&mut self, compressor: &mut ChunkCompressor) {
        self.crc = crc32fast::hash(&self.records);
        self.result = compressor.compress(&self.records, &mut self.compressed);
    }
}

struct Worker {
    jobs: Sender<Job>,
    done: Receiver<Job>,
    thread: JoinHandle<()>,
}

/// The compression threads. Dropping stops and joins them (a worker finishes at most its current chunk).
struct Workers(Vec<Worker>);

impl Workers {
    /// Up to `count` workers: as many as the system gives. It may refuse a thread (its limit on processes
    /// or threads, met by many writers at once); with none, the writer compresses on its own thread, to
    /// the same bytes.
    fn spawn(count: usize, compression: Compression) -> Self {
        let mut workers = Self(Vec::with_capacity(count));
        for number in 0..count {
            let (job_sender, job_receiver) = mpsc::channel::<Job>();
            let (done_sender, done_receiver) = mpsc::channel::<Job>();
            let spawned = std::thread::Builder::new()
                .name(format!("mcap-compress-{number}"))
                .spawn(move || compress_chunks(compression, &job_receiver, &done_sender));
            let Ok(thread) = spawned else { break };
            workers.0.push(Worker {
                jobs: job_sender,
                done: done_receiver,
                thread,
            });
        }
        workers
    }

    fn len(&self) -> usize {
        self.0.len()
    }

    /// Stops and joins every worker; `WorkerLost` if one had panicked.
    fn stop(&mut self) -> Result<(), WriteError> {
        let mut lost = false;
        for worker in self.0.drain(..) {
            // Closing both channels ends the worker's loop after its current chunk, if any.
            drop((worker.jobs, worker.done));
            lost |= worker.thread.join().is_err();
        }
        if lost {
            Err(WriteError::WorkerLost)
        } else {
            Ok(())
        }
    }
}

impl Drop for Workers {
    fn drop(&mut self) {
        let _ = self.stop();
    }
}

/// A worker's loop: compress each chunk it is sent, send it back, until either channel closes.
fn compress_chunks(compression: Compression, jobs: &Receiver<Job>, done: &Sender<Job>) {
    let mut compressor = ChunkCompressor::new(compression);
    while let Ok(mut job) = jobs.recv() {
        job.compress(&mut compressor);
        if done.send(job).is_err() {
            break;
        }
    }
}

/// Compresses whole chunks as the writer's workers do, public so that a benchmark can time compression
/// alone.
pub struct ChunkCompressor {
    compression: Compression,
    /// Created at the first zstd chunk, then reused.
    zstd: Option<zstd::bulk::Compressor<'static>>,
}

impl ChunkCompressor {
    /// A compressor for `compression`.
    #[must_use]
    pub fn new(compression: Compression) -> Self {
        Self {
            compression,
            zstd: None,
        }
    }

    /// Replaces `out` with the compressed `records` (leaves it empty for [`Compression::None`]); fails
    /// with the compressor's error (in practice only when out of memory).
    pub fn compress(&mut self, records: &[u8], out: &mut Vec<u8>) -> io::Result<()> {
        out.clear();
        match self.compression {
            Compression::None => Ok(()),
            Compression::Zstd => {
                let compressor = match &mut self.zstd {
                    Some(c) => c,
                    None => self.zstd.insert(zstd::bulk::Compressor::new(ZSTD_LEVEL)?),
                };
                out.reserve(zstd::compress_bound(records.len()));
                compressor.compress_to_buffer(records, out)?;
                Ok(())
            }
            Compression::Lz4 => {
                // The same frame parameters as the `mcap` crate's lz4 chunks: no block checksums (the
                // chunk CRC covers the data), lz4's defaults otherwise.
                let mut encoder = lz4::EncoderBuilder::new()
                    .level(LZ4_LEVEL)
                    .block_checksum(lz4::liblz4::BlockChecksum::NoBlockChecksum)
                    .build(mem::take(out))?;
                encoder.write_all(records)?;
                let (buffer, result) = encoder.finish();
                *out = buffer;
                result
            }
        }
    }
}

/// The output, its position and a running CRC-32 (the data section's, then the summary's).
struct Output<W: Write> {
    inner: BufWriter<W>,
    position: u64,
    crc: crc32fast::Hasher,
}

impl<W: Write> Output<W> {
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.inner.write_all(bytes)?;
        self.crc.update(bytes);
        self.position += bytes.len() as u64;
        Ok(())
    }

    /// Writes `records` as one summary group (nothing for none) and notes where it went.
    fn group<'a, R: Record<'a>>(
        &mut self,
        records: &[R],
        groups: &mut Vec<SummaryOffset>,
    ) -> Result<(), WriteError> {
        let mut b = Vec::new();
        for record in records {
            record.encode_record(&mut b)?;
        }
        if !b.is_empty() {
            groups.push(SummaryOffset {
                group_opcode: R::OPCODE,
                group_start: self.position,
                group_length: b.len() as u64,
            });
            self.write_all(&b)?;
        }
        Ok(())
    }
}

/// A chunked, indexed MCAP writer whose chunks are compressed on worker threads, in the layout of
/// docs/format.md ("Files"); the file is complete only after [`finish`](Self::finish).
///
/// The calling thread fills the open chunk; a full one ([`WriterOptions::chunk_size`]) goes to a worker
/// (CRC and compression in one call), and the calling thread writes finished chunks in order, at most two
/// per worker in flight. Each chunk is compressed alone with fixed parameters, so neither the worker count
/// nor timing changes a byte. An I/O error surfaces from the call that met it, a compression error or a
/// lost worker from the next call that collects a chunk; after any error every call fails.
#[must_use = "an MCAP file is complete only after `finish`"]
pub struct McapWriter<W: Write> {
    out: Output<W>,
    compression: Compression,
    chunk_size: usize,
    /// The open chunk's records and what is known about them.
    chunk: Vec<u8>,
    meta: ChunkMeta,
    workers: Workers,
    /// Compresses on this thread when the system gave no worker.
    compressor: ChunkCompressor,
    /// Chunks sent since the start (chunk n goes to worker n mod workers), and of them not written yet.
    dispatched: usize,
    in_flight: usize,
    /// Jobs back from the workers, for their buffers.
    free: Vec<Job>,
    /// Reused for records written outside chunks.
    scratch: Vec<u8>,
    /// Schema id n is `schemas[n − 1]`; channel id n is `channels[n − 1]`.
    schemas: Vec<Schema<'static>>,
    channels: Vec<Channel>,
    /// Messages per channel (index = id − 1).
    message_counts: Vec<u64>,
    bounds: Option<(u64, u64)>,
    chunk_indexes: Vec<ChunkIndex>,
    metadata_indexes: Vec<MetadataIndex>,
    failed: bool,
}

impl<W: Write> McapWriter<W> {
    /// Writes the magic and the Header record and starts the compression workers; fails if the header
    /// is too long or cannot be written.
    pub fn new(writer: W, options: &WriterOptions) -> Result<Self, WriteError> {
        let chunk_size = options.chunk_size.max(1);
        let workers = Workers::spawn(options.workers, options.compression);
        let mut this = Self {
            out: Output {
                inner: BufWriter::with_capacity(OUTPUT_BUFFER, writer),
                position: 0,
                crc: crc32fast::Hasher::new(),
            },
            compression: options.compression,
            chunk_size,
            chunk: Vec::with_capacity(chunk_capacity(chunk_size)),
            meta: ChunkMeta::default(),
            in_flight: 0,
            workers,
            compressor: ChunkCompressor::new(options.compression),
            dispatched: 0,
            free: Vec::new(),
            scratch: Vec::new(),
            schemas: Vec::new(),
            channels: Vec::new(),
            message_counts: Vec::new(),
            bounds: None,
            chunk_indexes: Vec::new(),
            metadata_indexes: Vec::new(),
            failed: false,
        };
        let mut header = MAGIC.to_vec();
        Header {
            profile: String::new(),
            library: options.library.clone(),
        }
        .encode_record(&mut header)?;
        this.guard(|w| Ok(w.out.write_all(&header)?))?;
        Ok(this)
    }

    /// Registers a schema and returns its id (1, 2, …); a schema equal to an earlier one gets its id.
    /// The Schema record goes into the open chunk (and into the summary). Fails past 65535 schemas or for
    /// a field too long for MCAP.
    pub fn add_schema(
        &mut self,
        name: &str,
        encoding: &str,
        data: &[u8],
    ) -> Result<u16, WriteError> {
        self.check()?;
        let same = |s: &Schema<'_>| s.name == name && s.encoding == encoding && *s.data == *data;
        if let Some(s) = self.schemas.iter().find(|s| same(s)) {
            return Ok(s.id);
        }
        let id = u16::try_from(self.schemas.len() + 1)
            .map_err(|_| WriteError::TooMany { what: "schemas" })?;
        let schema = Schema {
            id,
            name: name.to_string(),
            encoding: encoding.to_string(),
            data: data.to_vec().into(),
        };
        // Encoded aside first: a field too long must not leave half a record in the chunk.
        let mut record = Vec::new();
        schema.encode_record(&mut record)?;
        self.chunk.extend_from_slice(&record);
        self.schemas.push(schema);
        Ok(id)
    }

    /// Registers a channel and returns its id (1, 2, …); a channel equal to an earlier one gets its id.
    /// `schema_id` is 0 (no schema) or an id from [`add_schema`](Self::add_schema). The Channel record
    /// goes into the open chunk (and into the summary). Fails for an unknown schema, past 65535
    /// channels, or for a field too long for MCAP.
    pub fn add_channel(
        &mut self,
        schema_id: u16,
        topic: &str,
        message_encoding: &str,
        metadata: &BTreeMap<String, String>,
    ) -> Result<u16, WriteError> {
        self.check()?;
        if usize::from(schema_id) > self.schemas.len() {
            return Err(WriteError::UnknownSchema { schema_id });
        }
        let same = |c: &Channel| {
            (
                c.schema_id,
                c.topic.as_str(),
                c.message_encoding.as_str(),
                &c.metadata,
            ) == (schema_id, topic, message_encoding, metadata)
        };
        if let Some(c) = self.channels.iter().find(|c| same(c)) {
            return Ok(c.id);
        }
        let id = u16::try_from(self.channels.len() + 1)
            .map_err(|_| WriteError::TooMany { what: "channels" })?;
        let channel = Channel {
            id,
            schema_id,
            topic: topic.to_string(),
            message_encoding: message_encoding.to_string(),
            metadata: metadata.clone(),
        };
        let mut record = Vec::new();
        channel.encode_record(&mut record)?;
        self.chunk.extend_from_slice(&record);
        self.meta.indexes.push(MessageIndex {
            channel_id: id,
            records: Vec::new(),
        });
        self.channels.push(channel);
        self.message_counts.push(0);
        Ok(id)
    }

    /// Appends a Message record to the open chunk; hands the chunk to a worker once it is full. Fails
    /// for an unknown channel or when writing an earlier chunk fails.
    #[inline]
    pub fn write_message(
        &mut self,
        channel_id: u16,
        sequence: u32,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), WriteError> {
        self.check()?;
        let index = usize::from(channel_id).wrapping_sub(1);
        let Some(count) = self.message_counts.get_mut(index) else {
            return Err(WriteError::UnknownChannel { channel_id });
        };
        *count += 1;
        self.bounds = Some(widen(self.bounds, log_time));
        self.meta.bounds = Some(widen(self.meta.bounds, log_time));
        self.meta.indexes[index].records.push(MessageIndexEntry {
            log_time,
            offset: self.chunk.len() as u64,
        });
        let header = MessageHeader {
            channel_id,
            sequence,
            log_time,
            publish_time,
        };
        MessageRecord { header, data }.encode_record(&mut self.chunk)?;
        if self.chunk.len() >= self.chunk_size {
            self.guard(Self::dispatch)?;
        }
        Ok(())
    }

    /// Writes a Metadata record to the data section, after every chunk so far (the open chunk is closed
    /// and written first).
    pub fn write_metadata(
        &mut self,
        name: &str,
        metadata: &BTreeMap<String, String>,
    ) -> Result<(), WriteError> {
        self.check()?;
        self.guard(|w| {
            w.drain()?;
            let mut record = mem::take(&mut w.scratch);
            record.clear();
            Metadata {
                name: name.to_string(),
                metadata: metadata.clone(),
            }
            .encode_record(&mut record)?;
            let offset = w.out.position;
            let written = w.out.write_all(&record);
            w.metadata_indexes.push(MetadataIndex {
                offset,
                length: record.len() as u64,
                name: name.to_string(),
            });
            w.scratch = record;
            Ok(written?)
        })
    }

    /// Writes the open chunk, waits for the workers, writes DataEnd, the summary section, the footer and
    /// the closing magic, flushes, and returns the output with the file's length in bytes.
    pub fn finish(mut self) -> Result<(W, u64), WriteError> {
        self.check()?;
        self.guard(|w| {
            w.drain()?;
            w.workers.stop()?;
            w.write_summary()
        })?;
        let length = self.out.position;
        let inner = self
            .out
            .inner
            .into_inner()
            .map_err(|e| WriteError::Io(e.into_error()))?;
        Ok((inner, length))
    }

    fn check(&self) -> Result<(), WriteError> {
        if self.failed {
            Err(WriteError::AlreadyFailed)
        } else {
            Ok(())
        }
    }

    /// Runs `f`, marking the writer failed if it fails.
    fn guard<T>(
        &mut self,
        f: impl FnOnce(&mut Self) -> Result<T, WriteError>,
    ) -> Result<T, WriteError> {
        let result = f(self);
        if result.is_err() {
            self.failed = true;
        }
        result
    }

    /// Hands the open chunk (if it holds anything) to the next worker, first writing the oldest chunks
    /// while too many are in flight, then any that are already done.
    fn dispatch(&mut self) -> Result<(), WriteError> {
        if self.chunk.is_empty() {
            return Ok(());
        }
        while self.in_flight > 0 && self.in_flight >= self.workers.len() * IN_FLIGHT_PER_WORKER {
            self.collect(true)?;
        }
        let mut job = self.free.pop().unwrap_or_else(|| Job {
            records: Vec::with_capacity(chunk_capacity(self.chunk_size)),
            meta: ChunkMeta::default(),
            compressed: Vec::new(),
            crc: 0,
            result: Ok(()),
        });
        mem::swap(&mut job.records, &mut self.chunk);
        mem::swap(&mut job.meta, &mut self.meta);
        for channel in &self.channels[self.meta.indexes.len()..] {
            self.meta.indexes.push(MessageIndex {
                channel_id: channel.id,
                records: Vec::new(),
            });
        }
        if self.workers.len() == 0 {
            job.compress(&mut self.compressor);
            return self.written(job);
        }
        let worker = &self.workers.0[self.dispatched % self.workers.len()];
        worker.jobs.send(job).map_err(|_| WriteError::WorkerLost)?;
        self.in_flight += 1;
        self.dispatched += 1;
        while self.collect(false)? {}
        Ok(())
    }

    /// Sends the open chunk and writes every chunk in flight.
    fn drain(&mut self) -> Result<(), WriteError> {
        self.dispatch()?;
        while self.collect(true)? {}
        Ok(())
    }

    /// Writes the oldest chunk in flight if it is done (waiting for it if `wait`); false if there was
    /// none or it is not done.
    fn collect(&mut self, wait: bool) -> Result<bool, WriteError> {
        if self.in_flight == 0 {
            return Ok(false);
        }
        // The oldest chunk in flight went to the worker of its number.
        let worker = &self.workers.0[(self.dispatched - self.in_flight) % self.workers.len()];
        let job = if wait {
            worker.done.recv().map_err(|_| WriteError::WorkerLost)?
        } else {
            match worker.done.try_recv() {
                Ok(job) => job,
                Err(TryRecvError::Empty) => return Ok(false),
                Err(TryRecvError::Disconnected) => return Err(WriteError::WorkerLost),
            }
        };
        self.in_flight -= 1;
        self.written(job)?;
        Ok(true)
    }

    /// Writes a compressed chunk and keeps its buffers.
    fn written(&mut self, mut job: Job) -> Result<(), WriteError> {
        if let Err(e) = mem::replace(&mut job.result, Ok(())) {
            return Err(WriteError::Compress(e));
        }
        self.write_chunk(&job)?;
        job.records.clear();
        job.compressed.clear();
        job.meta.clear();
        self.free.push(job);
        Ok(())
    }

    /// Writes a Chunk record and its MessageIndex records, and notes its ChunkIndex.
    fn write_chunk(&mut self, job: &Job) -> Result<(), WriteError> {
        let Job {
            records,
            meta,
            compressed,
            crc,
            ..
        } = job;
        let stored = match self.compression {
            Compression::None => records,
            Compression::Zstd | Compression::Lz4 => compressed,
        };
        let (message_start_time, message_end_time) = meta.bounds.unwrap_or((0, 0));
        let header = ChunkHeader {
            message_start_time,
            message_end_time,
            uncompressed_size: records.len() as u64,
            uncompressed_crc: *crc,
            compression: self.compression.mcap_name().to_string(),
            compressed_size: stored.len() as u64,
        };
        let start = self.out.position;
        let mut index = chunk_index(&header, start, 0);
        let mut buffer = mem::take(&mut self.scratch);
        buffer.clear();
        let chunk = ChunkRecord {
            header,
            records: stored,
        };
        chunk.encode_record(&mut buffer)?;
        index.chunk_length = buffer.len() as u64;
        for i in meta.indexes.iter().filter(|i| !i.records.is_empty()) {
            let at = start + buffer.len() as u64;
            index.message_index_offsets.insert(i.channel_id, at);
            i.encode_record(&mut buffer)?;
        }
        index.message_index_length = buffer.len() as u64 - index.chunk_length;
        let written = self.out.write_all(&buffer);
        self.chunk_indexes.push(index);
        self.scratch = buffer;
        Ok(written?)
    }

    /// DataEnd, the summary section (each group listed by a SummaryOffset record), the footer and the
    /// closing magic.
    fn write_summary(&mut self) -> Result<(), WriteError> {
        let data_section_crc = mem::take(&mut self.out.crc).finalize();
        let mut b = Vec::new();
        DataEnd { data_section_crc }.encode_record(&mut b)?;
        self.out.write_all(&b)?;

        // The summary CRC starts at the summary's first byte, after DataEnd.
        self.out.crc = crc32fast::Hasher::new();
        let summary_start = self.out.position;
        let statistics = [self.statistics()?];
        let mut groups = Vec::new();
        self.out.group(&self.schemas, &mut groups)?;
        self.out.group(&self.channels, &mut groups)?;
        self.out.group(&statistics, &mut groups)?;
        self.out.group(&self.chunk_indexes, &mut groups)?;
        self.out.group(&self.metadata_indexes, &mut groups)?;

        let summary_offset_start = self.out.position;
        b.clear();
        for group in &groups {
            group.encode_record(&mut b)?;
        }
        Footer {
            summary_start,
            summary_offset_start,
            summary_crc: 0,
        }
        .encode_record(&mut b)?;
        // The summary CRC covers the footer up to its CRC field.
        let crc_at = b.len() - 4;
        self.out.write_all(&b[..crc_at])?;
        let summary_crc = mem::take(&mut self.out.crc).finalize();
        b.truncate(crc_at);
        b.extend_from_slice(&summary_crc.to_le_bytes());
        b.extend_from_slice(MAGIC);
        self.out.write_all(&b[crc_at..])?;
        Ok(())
    }

    fn statistics(&self) -> Result<Statistics, WriteError> {
        let (message_start_time, message_end_time) = self.bounds.unwrap_or((0, 0));
        Ok(Statistics {
            message_count: self.message_counts.iter().sum(),
            schema_count: u16::try_from(self.schemas.len())
                .map_err(|_| WriteError::TooMany { what: "schemas" })?,
            channel_count: len32(self.channels.len(), "channel count")?,
            attachment_count: 0,
            metadata_count: len32(self.metadata_indexes.len(), "metadata count")?,
            chunk_count: len32(self.chunk_indexes.len(), "chunk count")?,
            message_start_time,
            message_end_time,
            channel_message_counts: (1..)
                .zip(&self.message_counts)
                .filter(|(_, &n)| n > 0)
                .map(|(id, &n)| (id, n))
                .collect(),
        })
    }
}

/// A chunk buffer's initial capacity: the chunk size plus room for the message that crosses it.
fn chunk_capacity(chunk_size: usize) -> usize {
    chunk_size.saturating_add(chunk_size / 8).min(1 << 30)
}
