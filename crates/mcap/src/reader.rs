//! The streaming MCAP reader: one pass over the file in memory bounded by the largest record
//! (never by the file's length).
//!
//! Reading is a two-thread pipeline (the private `prefetch` module): a worker runs the mcap crate's sans-io
//! `LinearReader` over the file (chunks whole, so that file offsets are known), feeds each chunk to a
//! second reader that decompresses it and checks its CRC, and hands the records over in batches; this
//! thread walks them in file order. Along the way it keeps what the structural checks need as running
//! digests rather than lists: per chunk and channel a hash of the (log time, offset) pairs its message
//! index must list, a hash of every chunk's index entry, the real counts for the statistics record, the
//! summary's groups for the summary offsets. Every length is checked against the file's size before
//! anything is allocated for it.

use super::prefetch::{self, Batch, Event};
use super::prelude::{self, Prelude, ScanEnd};
use super::problems::Problems;
use super::wire::{self, Cursor, MessageHeader, WireError};
use mcap::records::op;
use mcap::McapError;
use std::collections::BTreeMap;
use std::fmt;
use std::io::{Read, Seek, SeekFrom};
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::mpsc::{self, Receiver, SyncSender};

/// Bytes of an opcode and a record length.
const RECORD_PREFIX: u64 = 9;
/// MCAP magic length.
const MAGIC_LEN: u64 = 8;
/// How many metadata records and summary groups are remembered for the index checks (more are counted).
const MAX_REMEMBERED: usize = 1024;
/// A record claiming more than this (1 TiB) is not one any writer makes: a file cut inside it is not the
/// prefix of a plausible MCAP, so it is reported as corrupt rather than truncated.
const PLAUSIBLE_RECORD: u64 = 1 << 40;

/// What the caller does with records.
pub trait Visitor {
    /// A schema record (from the data section or a chunk; summary repeats are compared, not passed on).
    fn schema(&mut self, id: u16, name: &str, encoding: &str, data: &[u8]);
    /// A channel record (first definition only).
    fn channel(&mut self, id: u16, schema_id: u16, topic: &str, message_encoding: &str);
    /// A metadata record with its entries. Every metadata record the summary indexes (or, in a file
    /// without one, every one a scan of the top-level records finds) comes before the first message,
    /// wherever it sits in the file; each comes once.
    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>);
    /// The header record's library string.
    fn library(&mut self, library: &str);
    /// A message; `Break` stops reading (e.g. the file is not one the caller understands).
    fn message(&mut self, header: &MessageHeader, data: &[u8]) -> ControlFlow<()>;
}

/// Why a file could not be read to its end.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReadErrorKind {
    /// It cannot be opened or read (missing, a directory, permissions).
    Io,
    /// It is not MCAP at all (empty, wrong magic).
    NotMcap,
    /// It ends before the MCAP end.
    Truncated,
    /// A CRC, a length or a record is wrong.
    Corrupt,
    /// The visitor stopped reading.
    Stopped,
}

/// A file that could not be read to its end, with where and how many messages came before.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReadError {
    /// What kind of failure.
    pub kind: ReadErrorKind,
    /// What is wrong and where, for the user (without the path).
    pub detail: String,
    /// What the visitor was given before it (`judged the 8008 messages read before it`); empty when the
    /// failure came before the stream reached it.
    pub read_before: String,
}

impl ReadError {
    fn new(kind: ReadErrorKind, detail: impl Into<String>) -> Self {
        Self {
            kind,
            detail: detail.into(),
            read_before: String::new(),
        }
    }

    fn after(mut self, read_before: String) -> Self {
        self.read_before = read_before;
        self
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.detail)?;
        if !self.read_before.is_empty() {
            write!(f, "; {}", self.read_before)?;
        }
        Ok(())
    }
}

/// What the structural pass found.
#[derive(Debug, Default)]
pub struct Structure {
    /// File size \[bytes\].
    pub file_len: u64,
    /// Messages read.
    pub messages: u64,
    /// Chunks read.
    pub chunks: u64,
    /// Structural problems (indexes, statistics, summary).
    pub problems: Problems,
    /// Whether a summary section, statistics and chunk indexes were present.
    pub has_summary: bool,
    /// The `library` of the header record.
    pub library: String,
    /// Chunks by compression name (`""` for uncompressed chunks).
    pub compressions: BTreeMap<String, u64>,
    /// The chunks' records, compressed \[bytes\].
    pub compressed_bytes: u64,
    /// The chunks' records, uncompressed \[bytes\].
    pub uncompressed_bytes: u64,
}

/// What a schema or channel record is, given the ones seen before with the same id.
enum Definition {
    /// The first record with this id.
    New,
    /// The same bytes again (summary or chunk repeats are allowed).
    Repeated,
    /// Different bytes under an id already defined.
    Different,
}

/// Classifies the record `data` with `id` against `seen` (by digest), remembering it when new.
fn definition(seen: &mut BTreeMap<u16, Digest>, id: u16, data: &[u8]) -> Definition {
    let mut d = Digest::default();
    d.push_bytes(data);
    match seen.get(&id) {
        Some(earlier) if *earlier != d => Definition::Different,
        Some(_) => Definition::Repeated,
        None => {
            seen.insert(id, d);
            Definition::New
        }
    }
}

/// Order-sensitive 64-bit digest of a sequence of integers (not cryptographic: it guards against mistakes
/// and corruption, which CRCs also catch, not against an adversary).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Digest(u64);

impl Default for Digest {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Digest {
    fn push(&mut self, v: u64) {
        self.0 = (self.0 ^ v).wrapping_mul(0x0100_0000_01b3);
        self.0 ^= self.0 >> 29;
    }
    fn push_bytes(&mut self, b: &[u8]) {
        self.push(b.len() as u64);
        for chunk in b.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.push(u64::from_le_bytes(w));
        }
    }
}

/// Per channel, the digest of the (log time, offset) entries its message index must list.
#[derive(Debug, Default, Clone, Copy)]
struct IndexDigest {
    count: u64,
    digest: Digest,
}

/// One chunk while it and its message indexes are read.
#[derive(Debug, Default)]
struct ChunkBook {
    start: u64,
    length: u64,
    message_start_time: u64,
    message_end_time: u64,
    uncompressed_size: u64,
    compressed_size: u64,
    compression: Digest,
    /// Offset of the next record in the decompressed records.
    offset: u64,
    min_time: Option<u64>,
    max_time: u64,
    per_channel: BTreeMap<u16, IndexDigest>,
    index_offsets: BTreeMap<u16, u64>,
    index_length: u64,
    /// Messages read before this chunk (for error messages).
    messages_before: u64,
}

impl ChunkBook {
    fn index_digest(&self) -> Digest {
        let mut d = Digest::default();
        d.push(self.start);
        d.push(self.length);
        d.push(self.message_start_time);
        d.push(self.message_end_time);
        d.push(self.compression.0);
        d.push(self.compressed_size);
        d.push(self.uncompressed_size);
        for (c, o) in &self.index_offsets {
            d.push(u64::from(*c));
            d.push(*o);
        }
        d.push(self.index_length);
        d
    }
}

#[derive(Debug, Default)]
struct Book {
    s: Structure,
    /// What was found before the stream (metadata passed on early, the file's ends).
    prelude: Prelude,
    /// Digests of the metadata records passed on early, by offset: the stream does not pass them again.
    early: BTreeMap<u64, Digest>,
    pos: u64,
    in_summary: bool,
    summary_start: Option<u64>,
    data_end_seen: bool,
    footer_seen: bool,
    chunk: Option<ChunkBook>,
    chunk_digest: Digest,
    chunk_index_digest: Digest,
    chunk_indexes: u64,
    channel_counts: BTreeMap<u16, u64>,
    schemas: BTreeMap<u16, Digest>,
    channels: BTreeMap<u16, Digest>,
    metadata: Vec<(u64, u64, String)>,
    metadata_count: u64,
    metadata_indexes: Vec<(u64, u64, String)>,
    attachment_count: u64,
    min_time: Option<u64>,
    max_time: u64,
    groups: Vec<(u8, u64, u64)>,
    summary_offsets: Vec<(u8, u64, u64)>,
    statistics: u64,
}

fn corrupt(detail: String) -> ReadError {
    ReadError::new(ReadErrorKind::Corrupt, detail)
}

/// The message for a file that ends at byte `len` inside (or just before) the record at `at`.
fn truncated(len: u64, at: u64) -> String {
    if len == MAGIC_LEN {
        format!(
            "truncated: the file ends at byte {len}, right after the MCAP magic, before the MCAP footer"
        )
    } else if at >= len {
        format!(
            "truncated: the file ends at byte {len}, after a whole record, before the MCAP footer"
        )
    } else {
        format!(
            "truncated: the file ends at byte {len} inside the record that starts at byte {at}, \
             before the MCAP footer"
        )
    }
}

fn wire_error(what: &str, at: u64, e: WireError) -> ReadError {
    corrupt(format!("malformed {what} record at byte {at}: {e}"))
}

/// Reads `path` to its end, passing records to `visitor`. The [`Structure`] is returned in both cases, so
/// that a truncated or corrupt file still reports how far it was read.
pub fn read(path: &Path, visitor: &mut impl Visitor) -> (Structure, Option<ReadError>) {
    match open(path) {
        Ok((file, len)) => read_from(file, len, visitor),
        Err(e) => (Structure::default(), Some(e)),
    }
}

/// [`read`], calling `progress` with the number of bytes read from the file so far (from the reading
/// thread, at every block of a few hundred KiB), e.g. for a progress bar.
pub fn read_with_progress(
    path: &Path,
    visitor: &mut impl Visitor,
    progress: &(dyn Fn(u64) + Sync),
) -> (Structure, Option<ReadError>) {
    match open(path) {
        Ok((file, len)) => read_from(
            Counting {
                inner: file,
                read: 0,
                progress,
            },
            len,
            visitor,
        ),
        Err(e) => (Structure::default(), Some(e)),
    }
}

/// A reader that reports how far into the file it is (bytes read, or the position after a seek).
struct Counting<'a, R> {
    inner: R,
    read: u64,
    progress: &'a (dyn Fn(u64) + Sync),
}

impl<R: Read> Read for Counting<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        (self.progress)(self.read);
        Ok(n)
    }
}

impl<R: Seek> Seek for Counting<'_, R> {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        let at = self.inner.seek(pos)?;
        self.read = at;
        Ok(at)
    }
}

/// Reads an MCAP file of `len` bytes from `source` (see [`read`]). The source must be seekable: the
/// metadata records are looked up (through the summary, or by a scan of the top-level records) before the
/// stream starts at byte 0.
pub fn read_from(
    mut source: impl Read + Seek + Send,
    len: u64,
    visitor: &mut impl Visitor,
) -> (Structure, Option<ReadError>) {
    let mut book = Book::default();
    if len == 0 {
        let e = ReadError::new(
            ReadErrorKind::NotMcap,
            "empty file (0 bytes), not an MCAP file",
        );
        return (book.s, Some(e));
    }
    book.prelude = prelude::find(&mut source, len);
    for m in &book.prelude.metadata {
        let mut d = Digest::default();
        d.push_bytes(&m.body);
        book.early.insert(m.at, d);
        visitor.metadata(&m.name, &m.entries);
    }
    let error = match source.seek(SeekFrom::Start(0)) {
        Ok(_) => read_into(source, len, visitor, &mut book).err(),
        Err(e) => Some(ReadError::new(
            ReadErrorKind::Io,
            format!("cannot read: {e}"),
        )),
    };
    let error = match error {
        // The visitor stopped before the stream reached the place where the scan found the file cut
        // short or broken: that is what is wrong with the file.
        Some(e) if e.kind == ReadErrorKind::Stopped => book.scan_error().or(Some(e)),
        other => other,
    };
    if error.is_none() {
        book.finish();
    }
    (book.s, error)
}

fn open(path: &Path) -> Result<(std::fs::File, u64), ReadError> {
    let io = |e: std::io::Error| ReadError::new(ReadErrorKind::Io, format!("cannot read: {e}"));
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(ReadError::new(
            ReadErrorKind::Io,
            "is a directory, not an MCAP file",
        ));
    }
    if !meta.is_file() {
        return Err(ReadError::new(
            ReadErrorKind::Io,
            "is not a regular file (a pipe, socket or device): an MCAP file is read by seeking to its \
             summary and metadata, which a stream cannot do; save it to a file first",
        ));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    Ok((file, meta.len()))
}

fn read_into(
    file: impl Read + Send,
    file_len: u64,
    visitor: &mut impl Visitor,
    book: &mut Book,
) -> Result<(), ReadError> {
    book.s.file_len = file_len;
    book.pos = MAGIC_LEN;
    let (to_consumer, batches) = mpsc::sync_channel(prefetch::QUEUE);
    let (to_producer, recycled) = mpsc::sync_channel(prefetch::QUEUE + 2);
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            prefetch::produce(
                file,
                file_len,
                &prefetch::Producer {
                    to_consumer,
                    recycled,
                },
            );
        });
        // `consume` owns the receiving end: when it returns early (an error, or the visitor stopped) or
        // unwinds, the receiver is dropped, so a worker blocked sending into the full queue wakes with an
        // error and ends, and this scope can join it. Holding the receiver here instead would leave both
        // threads waiting for each other.
        let result = consume(batches, to_producer, visitor, book);
        match worker.join() {
            Ok(()) => result,
            Err(_) => Err(ReadError::new(
                ReadErrorKind::Corrupt,
                "the reading thread failed (a bug in this tool on this input: please report it with the file)",
            )),
        }
    })
}

/// The checking half of the pipeline: walks the worker's events in file order. Takes both ends of its
/// channels by value, so that they close when it returns (see [`read_into`]).
fn consume(
    batches: Receiver<Batch>,
    to_producer: SyncSender<Batch>,
    visitor: &mut impl Visitor,
    book: &mut Book,
) -> Result<(), ReadError> {
    while let Ok(batch) = batches.recv() {
        for event in &batch.events {
            match event {
                Event::Outer { opcode, body } => {
                    let data = &batch.bytes[body.clone()];
                    let at = book.pos;
                    book.pos += RECORD_PREFIX + data.len() as u64;
                    book.top_level(*opcode, data, at, visitor)?;
                }
                Event::Inner { opcode, body } => {
                    book.chunk_inner(*opcode, &batch.bytes[body.clone()], visitor)?;
                }
                Event::ChunkEnd => book.chunk_end()?,
                Event::InnerError(e) => return Err(book.chunk_error(e)),
                Event::OuterError(e) => return Err(book.classify(e)),
                Event::Io(detail) => return Err(ReadError::new(ReadErrorKind::Io, detail.clone())),
            }
        }
        // The worker reuses the batch if it has room for it; otherwise it is freed here.
        let _ = to_producer.try_send(batch);
    }
    Ok(())
}

impl Book {
    fn classify(&self, e: &McapError) -> ReadError {
        let at = self.pos;
        let messages = self.s.messages;
        let len = self.s.file_len;
        let before = format!("judged the {messages} messages read before it");
        let read = format!("judged the {messages} messages read");
        match e {
            McapError::BadMagic if at == MAGIC_LEN && messages == 0 && !self.data_end_seen => {
                ReadError::new(
                    ReadErrorKind::NotMcap,
                    "not an MCAP file (it does not start with the MCAP magic bytes)",
                )
            }
            McapError::UnexpectedEof if at <= MAGIC_LEN && !self.prelude.magic_prefix => {
                ReadError::new(
                    ReadErrorKind::NotMcap,
                    format!("not an MCAP file ({len} bytes, shorter than an MCAP header)"),
                )
            }
            McapError::UnexpectedEof if len < MAGIC_LEN => ReadError::new(
                ReadErrorKind::Truncated,
                format!(
                    "truncated: the file ends at byte {len}, inside the MCAP magic it starts with"
                ),
            ),
            McapError::UnexpectedEof if self.footer_seen => ReadError::new(
                ReadErrorKind::Truncated,
                format!("truncated: the file ends at byte {len}, inside the MCAP end magic"),
            )
            .after(read),
            McapError::UnexpectedEof => self.past_end(at, None).after(before),
            McapError::RecordTooLarge {
                opcode,
                len: claimed,
            } => self
                .past_end(
                    at,
                    Some((*claimed, format!("record (opcode {opcode:#04x})"))),
                )
                .after(before),
            McapError::ChunkTooLarge(claimed) => self
                .past_end(at, Some((*claimed, "chunk".into())))
                .after(before),
            McapError::BadDataCrc { saved, calculated } => corrupt(format!(
                "corrupt data section: CRC {calculated:#010x} does not match the stored \
                 {saved:#010x}"
            ))
            .after(read),
            McapError::BadSummaryCrc { saved, calculated } => corrupt(format!(
                "corrupt summary section: CRC {calculated:#010x} does not match the stored \
                 {saved:#010x}"
            ))
            .after(read),
            McapError::BytesAfterEndMagic => corrupt(format!(
                "{} bytes follow the MCAP end magic",
                len.saturating_sub(at)
            )),
            other => corrupt(format!("malformed MCAP at byte {at}: {other}")).after(before),
        }
    }

    /// The record at `at` runs past the end of the file (`claim`: the length it claims, when that is why
    /// the reader stopped, and what it is). The file is a truncated MCAP unless it ends with the MCAP magic
    /// (then it is whole and a length is wrong) or the claim is beyond any plausible record.
    fn past_end(&self, at: u64, claim: Option<(u64, String)>) -> ReadError {
        let len = self.s.file_len;
        let plausible = claim.as_ref().is_none_or(|(c, _)| *c <= PLAUSIBLE_RECORD);
        if !self.prelude.ends_with_magic && plausible {
            return ReadError::new(ReadErrorKind::Truncated, truncated(len, at));
        }
        corrupt(match claim {
            Some((claimed, what)) => format!(
                "{what} at byte {at} claims {claimed} bytes, more than the file's {len}: the file \
                 is corrupt or crafted"
            ),
            None => format!(
                "corrupt: the record at byte {at} runs past the end of the file, which ends with the \
                 MCAP magic, so a record length is wrong"
            ),
        })
    }

    /// What the scan before the stream found wrong, when it found the file cut short or broken.
    fn scan_error(&self) -> Option<ReadError> {
        match self.prelude.scan_end? {
            ScanEnd::Cut { at, claimed } => {
                Some(self.past_end(at, claimed.map(|c| (c, "record".to_string()))))
            }
            ScanEnd::Malformed { at } => Some(corrupt(format!(
                "malformed MCAP at byte {at}: the record there cannot be read"
            ))),
        }
    }

    fn problem(&mut self, p: impl FnOnce() -> String) {
        self.s.problems.push_with(p);
    }

    fn close_chunk(&mut self) {
        let Some(chunk) = self.chunk.take() else {
            return;
        };
        if chunk
            .min_time
            .is_some_and(|t| t != chunk.message_start_time)
            || (chunk.min_time.is_some() && chunk.max_time != chunk.message_end_time)
        {
            let (s, e) = (chunk.message_start_time, chunk.message_end_time);
            let (a, b) = (chunk.min_time.unwrap_or(0), chunk.max_time);
            self.problem(|| {
                format!("chunk at byte {}: header says messages span {s}..{e} ns, they span {a}..{b} ns", chunk.start)
            });
        }
        let missing: Vec<u16> = chunk
            .per_channel
            .keys()
            .filter(|c| !chunk.index_offsets.contains_key(c))
            .copied()
            .collect();
        if !missing.is_empty() {
            self.problem(|| {
                format!(
                    "chunk at byte {}: no message index for channel(s) {missing:?}",
                    chunk.start
                )
            });
        }
        self.chunk_digest.push(chunk.index_digest().0);
        self.s.chunks += 1;
    }

    fn top_level(
        &mut self,
        opcode: u8,
        data: &[u8],
        at: u64,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        if opcode != op::MESSAGE_INDEX {
            self.close_chunk();
        }
        if self.in_summary && opcode != op::FOOTER {
            // Contiguous runs of one opcode form a group (what a summary offset points at).
            let size = RECORD_PREFIX + data.len() as u64;
            let extends = matches!(self.groups.last(), Some((o, start, len)) if *o == opcode && start + len == at);
            if extends {
                if let Some(group) = self.groups.last_mut() {
                    group.2 += size;
                }
            } else if self.groups.len() < MAX_REMEMBERED {
                self.groups.push((opcode, at, size));
            }
            if self.summary_start.is_none() {
                self.summary_start = Some(at);
            }
        }
        match opcode {
            op::HEADER => {
                let mut c = Cursor::new(data);
                let _profile = c
                    .string("profile")
                    .map_err(|e| wire_error("header", at, e))?;
                let library = c
                    .string("library")
                    .map_err(|e| wire_error("header", at, e))?;
                let library = library.unwrap_or("(not UTF-8)");
                self.s.library = library.to_string();
                visitor.library(library);
            }
            op::CHUNK => self.chunk_record(data, at)?,
            op::MESSAGE_INDEX => self.message_index(data, at)?,
            op::FOOTER => self.footer(data, at)?,
            op::DATA_END => {
                self.data_end_seen = true;
                self.in_summary = true;
            }
            _ => self.record(opcode, data, at, visitor)?,
        }
        Ok(())
    }

    fn chunk_record(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let header = wire::chunk_header(data).map_err(|e| wire_error("chunk", at, e))?;
        let mut compression = Digest::default();
        compression.push_bytes(header.compression);
        let name = String::from_utf8_lossy(header.compression).into_owned();
        *self.s.compressions.entry(name).or_insert(0) += 1;
        self.s.compressed_bytes += header.compressed_size;
        self.s.uncompressed_bytes += header.uncompressed_size;
        self.chunk = Some(ChunkBook {
            start: at,
            length: RECORD_PREFIX + data.len() as u64,
            message_start_time: header.message_start_time,
            message_end_time: header.message_end_time,
            uncompressed_size: header.uncompressed_size,
            compressed_size: header.compressed_size,
            compression,
            messages_before: self.s.messages,
            ..ChunkBook::default()
        });
        Ok(())
    }

    /// A record inside the current chunk.
    fn chunk_inner(
        &mut self,
        opcode: u8,
        data: &[u8],
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let (at, offset) = self.chunk.as_ref().map_or((0, 0), |c| (c.start, c.offset));
        if let Some(c) = self.chunk.as_mut() {
            c.offset += RECORD_PREFIX + data.len() as u64;
        }
        if opcode == op::MESSAGE {
            self.message(data, at, Some(offset), visitor)
        } else {
            self.record(opcode, data, at, visitor)
        }
    }

    /// The current chunk's records are read: they must fill its claimed size.
    fn chunk_end(&self) -> Result<(), ReadError> {
        let (at, got, expected) = self
            .chunk
            .as_ref()
            .map_or((0, 0, 0), |c| (c.start, c.offset, c.uncompressed_size));
        if got != expected {
            return Err(corrupt(format!(
                "corrupt chunk at byte {at}: its records decompress to {got} bytes, its header claims \
                 {expected}"
            )));
        }
        Ok(())
    }

    fn chunk_error(&self, e: &McapError) -> ReadError {
        let (at, before) = self
            .chunk
            .as_ref()
            .map_or((0, 0), |c| (c.start, c.messages_before));
        let read = self.s.messages;
        let inside = read - before;
        match e {
            McapError::BadChunkCrc { saved, calculated } => corrupt(format!(
                "corrupt chunk at byte {at}: CRC {calculated:#010x} of its records does not match \
                 the stored {saved:#010x}"
            ))
            .after(format!(
                "judged the {read} messages read ({inside} of them from this chunk)"
            )),
            other => corrupt(format!("corrupt chunk at byte {at}: {other}"))
                .after(format!("judged the {read} messages read before it")),
        }
    }

    fn message(
        &mut self,
        data: &[u8],
        at: u64,
        chunk_offset: Option<u64>,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let (header, body) = wire::message(data).map_err(|e| wire_error("message", at, e))?;
        self.s.messages += 1;
        *self.channel_counts.entry(header.channel_id).or_insert(0) += 1;
        let t = header.log_time;
        self.min_time = Some(self.min_time.map_or(t, |m| m.min(t)));
        self.max_time = self.max_time.max(t);
        if let (Some(offset), Some(chunk)) = (chunk_offset, self.chunk.as_mut()) {
            chunk.min_time = Some(chunk.min_time.map_or(t, |m| m.min(t)));
            chunk.max_time = chunk.max_time.max(t);
            let d = chunk.per_channel.entry(header.channel_id).or_default();
            d.count += 1;
            d.digest.push(t);
            d.digest.push(offset);
        }
        match visitor.message(&header, body) {
            ControlFlow::Continue(()) => Ok(()),
            ControlFlow::Break(()) => Err(ReadError::new(ReadErrorKind::Stopped, "")),
        }
    }

    fn message_index(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let mut c = Cursor::new(data);
        let err = |e| wire_error("message index", at, e);
        let channel = c.u16("channel_id").map_err(err)?;
        let mut found = IndexDigest::default();
        wire::for_each_entry(&mut c, "records", |e| {
            let log_time = e.u64("log_time")?;
            let offset = e.u64("offset")?;
            found.count += 1;
            found.digest.push(log_time);
            found.digest.push(offset);
            Ok(())
        })
        .map_err(err)?;
        let Some(chunk) = self.chunk.as_mut() else {
            self.problem(|| format!("message index at byte {at} follows no chunk"));
            return Ok(());
        };
        chunk.index_offsets.insert(channel, at);
        chunk.index_length += RECORD_PREFIX + data.len() as u64;
        let expected = chunk.per_channel.get(&channel).copied().unwrap_or_default();
        if expected.count != found.count || expected.digest != found.digest {
            let start = chunk.start;
            self.problem(|| {
                format!(
                    "message index of channel {channel} for the chunk at byte {start} lists {} \
                     entries that do not match the chunk's {} messages (log time, offset)",
                    found.count, expected.count
                )
            });
        }
        Ok(())
    }

    /// A record outside the chunk bookkeeping: definitions, metadata and the summary's records.
    fn record(
        &mut self,
        opcode: u8,
        data: &[u8],
        at: u64,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        match opcode {
            op::MESSAGE => self.message(data, at, None, visitor),
            op::SCHEMA => self.schema(data, at, visitor),
            op::CHANNEL => self.channel(data, at, visitor),
            op::METADATA => self.metadata(data, at, visitor),
            op::ATTACHMENT => {
                self.attachment_count += 1;
                Ok(())
            }
            op::CHUNK_INDEX => self.chunk_index(data, at),
            op::METADATA_INDEX => self.metadata_index(data, at),
            op::STATISTICS => {
                self.statistics += 1;
                self.check_statistics(&mut Cursor::new(data))
                    .map_err(|e| wire_error("statistics", at, e))
            }
            op::SUMMARY_OFFSET => self.summary_offset(data, at),
            _ => Ok(()),
        }
    }

    /// A schema record: passed on at its first definition, compared with it afterwards.
    fn schema(
        &mut self,
        data: &[u8],
        at: u64,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let mut c = Cursor::new(data);
        let err = |e| wire_error("schema", at, e);
        let id = c.u16("id").map_err(err)?;
        let name = c.string("name").map_err(err)?.unwrap_or("");
        let encoding = c.string("encoding").map_err(err)?.unwrap_or("");
        let body = c.bytes("data").map_err(err)?;
        match definition(&mut self.schemas, id, data) {
            Definition::New => visitor.schema(id, name, encoding, body),
            Definition::Repeated => {}
            Definition::Different => {
                self.problem(|| {
                    format!("schema {id} `{name}` at byte {at} differs from its earlier definition")
                });
            }
        }
        Ok(())
    }

    /// A channel record: passed on at its first definition, compared with it afterwards.
    fn channel(
        &mut self,
        data: &[u8],
        at: u64,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let mut c = Cursor::new(data);
        let err = |e| wire_error("channel", at, e);
        let id = c.u16("id").map_err(err)?;
        let schema_id = c.u16("schema_id").map_err(err)?;
        let topic = c.string("topic").map_err(err)?.unwrap_or("");
        let encoding = c.string("message_encoding").map_err(err)?.unwrap_or("");
        match definition(&mut self.channels, id, data) {
            Definition::New => visitor.channel(id, schema_id, topic, encoding),
            Definition::Repeated => {}
            Definition::Different => {
                self.problem(|| {
                    format!(
                        "channel {id} `{topic}` at byte {at} differs from its earlier definition"
                    )
                });
            }
        }
        Ok(())
    }

    /// A metadata record: passed on, and remembered (up to [`MAX_REMEMBERED`]) for the metadata indexes.
    fn metadata(
        &mut self,
        data: &[u8],
        at: u64,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let (name, entries) =
            prelude::parse_metadata(data).map_err(|e| wire_error("metadata", at, e))?;
        self.metadata_count += 1;
        if self.metadata.len() < MAX_REMEMBERED {
            self.metadata
                .push((at, RECORD_PREFIX + data.len() as u64, name.clone()));
        }
        match self.early.get(&at) {
            // Passed on before the stream; the bytes read then must be these.
            Some(early) => {
                let mut d = Digest::default();
                d.push_bytes(data);
                if d != *early {
                    self.problem(|| {
                        format!(
                            "metadata record `{name}` at byte {at} changed while the file was read"
                        )
                    });
                }
            }
            None => visitor.metadata(&name, &entries),
        }
        Ok(())
    }

    /// A chunk index record: folded into the digest that must match the chunks' own.
    fn chunk_index(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let mut c = Cursor::new(data);
        let err = |e| wire_error("chunk index", at, e);
        let mut d = Digest::default();
        let start_time = c.u64("message_start_time").map_err(err)?;
        let end_time = c.u64("message_end_time").map_err(err)?;
        let start = c.u64("chunk_start_offset").map_err(err)?;
        let length = c.u64("chunk_length").map_err(err)?;
        let mut offsets = Vec::new();
        wire::for_each_entry(&mut c, "message_index_offsets", |e| {
            offsets.push((e.u16("channel_id")?, e.u64("offset")?));
            Ok(())
        })
        .map_err(err)?;
        offsets.sort_unstable();
        let index_length = c.u64("message_index_length").map_err(err)?;
        let compression = c.bytes("compression").map_err(err)?;
        let compressed = c.u64("compressed_size").map_err(err)?;
        let uncompressed = c.u64("uncompressed_size").map_err(err)?;
        let mut comp = Digest::default();
        comp.push_bytes(compression);
        for v in [
            start,
            length,
            start_time,
            end_time,
            comp.0,
            compressed,
            uncompressed,
        ] {
            d.push(v);
        }
        for (ch, o) in offsets {
            d.push(u64::from(ch));
            d.push(o);
        }
        d.push(index_length);
        self.chunk_index_digest.push(d.0);
        self.chunk_indexes += 1;
        Ok(())
    }

    /// A metadata index record, remembered (up to [`MAX_REMEMBERED`]) to compare with the records.
    fn metadata_index(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let mut c = Cursor::new(data);
        let err = |e| wire_error("metadata index", at, e);
        let offset = c.u64("offset").map_err(err)?;
        let length = c.u64("length").map_err(err)?;
        let name = c.string("name").map_err(err)?.unwrap_or("").to_string();
        if self.metadata_indexes.len() < MAX_REMEMBERED {
            self.metadata_indexes.push((offset, length, name));
        }
        Ok(())
    }

    /// A summary offset record, remembered (up to [`MAX_REMEMBERED`]) to compare with the summary's groups.
    fn summary_offset(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let mut c = Cursor::new(data);
        let err = |e| wire_error("summary offset", at, e);
        let entry = (
            c.u8("group_opcode").map_err(err)?,
            c.u64("group_start").map_err(err)?,
            c.u64("group_length").map_err(err)?,
        );
        if self.summary_offsets.len() < MAX_REMEMBERED {
            self.summary_offsets.push(entry);
        }
        Ok(())
    }

    fn check_statistics(&mut self, c: &mut Cursor<'_>) -> Result<(), WireError> {
        let message_count = c.u64("message_count")?;
        let schema_count = c.u16("schema_count")?;
        let channel_count = c.u32("channel_count")?;
        let attachment_count = c.u32("attachment_count")?;
        let metadata_count = c.u32("metadata_count")?;
        let chunk_count = c.u32("chunk_count")?;
        let start = c.u64("message_start_time")?;
        let end = c.u64("message_end_time")?;
        let mut counts = Vec::new();
        wire::for_each_entry(c, "channel_message_counts", |e| {
            counts.push((e.u16("channel_id")?, e.u64("count")?));
            Ok(())
        })?;
        let real: [(&str, u64, u64); 8] = [
            ("message_count", message_count, self.s.messages),
            (
                "schema_count",
                u64::from(schema_count),
                self.schemas.len() as u64,
            ),
            (
                "channel_count",
                u64::from(channel_count),
                self.channels.len() as u64,
            ),
            (
                "attachment_count",
                u64::from(attachment_count),
                self.attachment_count,
            ),
            (
                "metadata_count",
                u64::from(metadata_count),
                self.metadata_count,
            ),
            ("chunk_count", u64::from(chunk_count), self.s.chunks),
            ("message_start_time", start, self.min_time.unwrap_or(0)),
            ("message_end_time", end, self.max_time),
        ];
        for (name, claimed, counted) in real {
            if claimed != counted {
                self.problem(|| format!("statistics: {name} = {claimed}, the file has {counted}"));
            }
        }
        counts.sort_unstable();
        let real_counts: Vec<(u16, u64)> =
            self.channel_counts.iter().map(|(k, v)| (*k, *v)).collect();
        if counts != real_counts {
            self.problem(|| {
                format!(
                    "statistics: channel message counts {counts:?} differ from the real {real_counts:?}"
                )
            });
        }
        Ok(())
    }

    fn footer(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let mut c = Cursor::new(data);
        let err = |e| wire_error("footer", at, e);
        let summary_start = c.u64("summary_start").map_err(err)?;
        let summary_offset_start = c.u64("summary_offset_start").map_err(err)?;
        self.footer_seen = true;
        let real_start = self.summary_start.unwrap_or(0);
        if summary_start != real_start {
            self.problem(|| {
                format!("footer: summary_start = {summary_start}, the summary starts at byte {real_start}")
            });
        }
        let real_offsets = self
            .groups
            .iter()
            .find(|g| g.0 == op::SUMMARY_OFFSET)
            .map_or(0, |g| g.1);
        if summary_offset_start != real_offsets {
            self.problem(|| {
                format!("footer: summary_offset_start = {summary_offset_start}, the summary offsets start at byte {real_offsets}")
            });
        }
        Ok(())
    }

    fn finish(&mut self) {
        self.close_chunk();
        self.s.has_summary = self.summary_start.is_some();
        if !self.s.has_summary {
            self.problem(|| "no summary section (no statistics, no indexes)".into());
            return;
        }
        if self.statistics == 0 {
            self.problem(|| "the summary has no statistics record".into());
        }
        if self.chunk_indexes != self.s.chunks || self.chunk_index_digest != self.chunk_digest {
            let (n, m) = (self.s.chunks, self.chunk_indexes);
            self.problem(|| {
                format!("chunk indexes do not match the chunks ({n} chunks in the data section, {m} chunk indexes; offsets, sizes, times or message index offsets differ)")
            });
        }
        if self.metadata.len() < MAX_REMEMBERED && self.metadata != self.metadata_indexes {
            let (n, m) = (self.metadata.len(), self.metadata_indexes.len());
            self.problem(|| {
                format!("metadata indexes do not match the metadata records ({n} records, {m} index entries)")
            });
        }
        // An empty group (length 0) is valid MCAP: the Python writer lists one for each kind of record it
        // has none of, placed where the group would have started, between two groups.
        let boundary = |p: u64| self.groups.iter().any(|g| g.1 == p || g.1 + g.2 == p);
        let bad: Vec<(u8, u64, u64)> = self
            .summary_offsets
            .iter()
            .filter(|o| !(self.groups.contains(o) || (o.2 == 0 && boundary(o.1))))
            .copied()
            .collect();
        if !bad.is_empty() {
            self.problem(|| {
                format!("summary offsets {bad:?} (opcode, start, length) point at no group of the summary")
            });
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::writer::{Compression, McapWriter, WriterOptions};
    use super::*;
    use std::io::Cursor as IoCursor;
    use std::time::Duration;

    /// Generous deadline of the hang tests: reading these few MiB takes milliseconds.
    const DEADLINE: Duration = Duration::from_secs(20);

    /// An uncompressed file of `messages` 1 KiB messages in 64 KiB chunks (many more batches than the
    /// prefetch queue holds), with a metadata record `late` written after the first `late_after` messages.
    fn file(messages: u32, late_after: u32) -> Vec<u8> {
        let mut options = WriterOptions::new(Compression::None, "test");
        options.chunk_size = 1 << 16;
        let mut w = McapWriter::new(IoCursor::new(Vec::new()), &options).unwrap();
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
        fn schema(&mut self, _: u16, _: &str, _: &str, _: &[u8]) {}
        fn channel(&mut self, _: u16, _: u16, _: &str, _: &str) {}
        fn metadata(&mut self, name: &str, _: &BTreeMap<String, String>) {
            self.events
                .push(format!("metadata {name} after {} messages", self.messages));
        }
        fn library(&mut self, _: &str) {}
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
    fn read_with_deadline(
        bytes: Vec<u8>,
        stop_at: u64,
    ) -> (Recorder, Structure, Option<ReadError>) {
        let (done, result) = mpsc::channel();
        std::thread::spawn(move || {
            let mut v = Recorder {
                stop_at,
                ..Recorder::default()
            };
            let len = bytes.len() as u64;
            let (s, e) = read_from(IoCursor::new(bytes), len, &mut v);
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
}
