//! The streaming MCAP reader: one pass over the file, in memory bounded by
//! [`READ_MEMORY_BOUND`](crate::READ_MEMORY_BOUND). A worker thread (`prefetch`) reads, decompresses and
//! checks chunks; this thread walks the records in file order, keeping what the structural checks need
//! as running digests rather than lists.
//!
//! Ours rather than the `mcap` crate's readers: on the 7 M-message workload (crate_vs_ours' "read" race,
//! file in the page cache, medians of 3 alternating rounds at load 7 on 2 cores) this reader, every check
//! included, took 1.31 s; the crate's sans-io `LinearReader` (which still splits the file into records
//! here) with `mcap::parse_record`, checking only CRCs, 2.34 s, and `mcap::MessageStream` 2.33 s.

use crate::budget::{self, Kept, MAX_RECORD_BYTES};
use crate::digest::Digest;
use crate::early_metadata::{self, Lookahead, ScanEnd};
use crate::findings::BoundedFindings;
use crate::prefetch::{self, Batch, ChunkError, Event};
use crate::records::{
    chunk_index, AttachmentRecord, Cursor, MessageRecord, Record, WireError, MAGIC_LEN, PREFIX_LEN,
};
use crate::summary::{widen, ChannelSummary, Summary};
use mcap::records::{
    op, Channel, ChunkHeader, ChunkIndex, Footer, Header, MessageHeader, MessageIndex, Metadata,
    MetadataIndex, Statistics, SummaryOffset,
};
use mcap::{McapError, Schema};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::fmt;
use std::io::{Read, Seek, SeekFrom};
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::mpsc::{self, Receiver, SyncSender};

/// How many metadata records and summary groups are remembered for the index checks (more are counted).
const MAX_REMEMBERED: usize = 1024;
/// A file cut inside a record claiming more than this (1 TiB) is reported as corrupt, not truncated.
const PLAUSIBLE_RECORD: u64 = 1 << 40;

/// What the caller does with records.
pub trait Visitor {
    /// A channel record (its first definition only), with the schema it names: `None` for schema id 0
    /// or an id that no schema record before it defines.
    fn channel(
        &mut self,
        _id: u16,
        _topic: &str,
        _message_encoding: &str,
        _schema: Option<&Schema<'_>>,
    ) {
    }
    /// A metadata record with its entries. Every metadata record the summary indexes (or, in a file
    /// without one, every one a scan of the top-level records finds) comes before the first message,
    /// wherever it sits in the file; each comes once.
    fn metadata(&mut self, _name: &str, _entries: &BTreeMap<String, String>) {}
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
    /// A record, a chunk, or its schemas, channels and metadata together, exceed
    /// [`MAX_RECORD_BYTES`](crate::MAX_RECORD_BYTES).
    TooLarge,
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
    read_before: String,
}

impl ReadError {
    pub(crate) fn new(kind: ReadErrorKind, detail: impl Into<String>) -> Self {
        Self {
            kind,
            detail: detail.into(),
            read_before: String::new(),
        }
    }

    /// A read's outcome as every command takes it: `Err` when the file cannot be read at all (`Io`,
    /// `NotMcap`); else the failure that broke it off part way (`Truncated`, `Corrupt`, `TooLarge`), what
    /// came before it being usable, or `None` when it was read to its end or the visitor stopped.
    pub fn broken_off(error: Option<Self>) -> Result<Option<Self>, Self> {
        match error {
            Some(e) if matches!(e.kind, ReadErrorKind::Io | ReadErrorKind::NotMcap) => Err(e),
            Some(e) if e.kind == ReadErrorKind::Stopped => Ok(None),
            broken => Ok(broken),
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
    /// What was read, in the terms of [`read_summary`](crate::read_summary): the channels as first
    /// defined, with the messages counted on each; its `metadata` stays empty (the visitor is given them).
    pub summary: Summary,
    /// Structural problems (indexes, statistics, summary).
    pub problems: BoundedFindings,
}

/// Per channel, the digest of the (log time, offset) entries its message index must list.
#[derive(Debug, Default, Clone, Copy)]
struct IndexDigest {
    count: u64,
    digest: Digest,
}

/// One chunk while it and its message indexes are read: the chunk index entry they make, to compare
/// with the summary's, and the offset of the next record in the decompressed records.
#[derive(Debug)]
struct ChunkBook {
    index: ChunkIndex,
    offset: u64,
    /// (earliest, latest) log time of its messages.
    bounds: Option<(u64, u64)>,
    per_channel: BTreeMap<u16, IndexDigest>,
}

/// The digest of a chunk index entry (the chunk's own, or a chunk index record's).
fn index_digest(i: &ChunkIndex) -> Digest {
    let mut d = Digest::default();
    for v in [
        i.chunk_start_offset,
        i.chunk_length,
        i.message_start_time,
        i.message_end_time,
        Digest::of(i.compression.as_bytes()).0,
        i.compressed_size,
        i.uncompressed_size,
    ] {
        d.push(v);
    }
    for (c, o) in &i.message_index_offsets {
        d.push(u64::from(*c));
        d.push(*o);
    }
    d.push(i.message_index_length);
    d
}

#[derive(Debug, Default)]
struct Book {
    s: Summary,
    problems: BoundedFindings,
    ahead: Lookahead,
    /// Digests of the metadata records passed on early, by offset: the stream does not pass them again.
    early: BTreeMap<u64, Digest>,
    kept: Kept,
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
    /// The digest of each schema's record, and the schema for the channels that name it.
    schemas: BTreeMap<u16, (Digest, Schema<'static>)>,
    /// The digest of each channel's first record, and the channel as the summary lists it.
    channels: BTreeMap<u16, (Digest, ChannelSummary)>,
    /// (offset, length, name digest) of metadata records and of metadata index entries.
    metadata: Vec<(u64, u64, Digest)>,
    metadata_count: u64,
    metadata_indexes: Vec<(u64, u64, Digest)>,
    attachment_count: u64,
    /// (opcode, start, length) of the summary's groups and of its summary offset records.
    groups: Vec<(u8, u64, u64)>,
    summary_offsets: Vec<(u8, u64, u64)>,
    statistics: u64,
}

pub(crate) fn corrupt(detail: String) -> ReadError {
    ReadError::new(ReadErrorKind::Corrupt, detail)
}

/// The `section` ("data" or "summary") whose CRC `computed` does not match the `stored` one.
pub(crate) fn bad_crc(section: &str, computed: u32, stored: u32) -> ReadError {
    corrupt(format!(
        "corrupt {section} section: CRC {computed:#010x} does not match the stored {stored:#010x}"
    ))
}

pub(crate) fn not_mcap() -> ReadError {
    ReadError::new(
        ReadErrorKind::NotMcap,
        "not an MCAP file (it does not start with the MCAP magic bytes)",
    )
}

pub(crate) fn io_error(e: std::io::Error) -> ReadError {
    ReadError::new(ReadErrorKind::Io, format!("cannot read: {e}"))
}

/// A file that ends at byte `len`, `place` (`, inside the MCAP end magic`).
fn truncated(len: u64, place: &str) -> ReadError {
    let detail = format!("truncated: the file ends at byte {len}{place}");
    ReadError::new(ReadErrorKind::Truncated, detail)
}

pub(crate) fn wire_error(what: &str, at: u64, e: &WireError) -> ReadError {
    corrupt(format!("malformed {what} record at byte {at}: {e}"))
}

/// Parses the body `data` of the record at `at` as an `R`.
fn parse<'a, R: Record<'a>>(data: &'a [u8], at: u64) -> Result<R, ReadError> {
    R::parse_body(data).map_err(|e| wire_error(R::NAME, at, &e))
}

/// Reads `path` to its end, passing records to `visitor`. The [`Structure`] is returned in both cases, so
/// that a truncated or corrupt file still reports how far it was read.
pub fn read(path: &Path, visitor: &mut impl Visitor) -> (Structure, Option<ReadError>) {
    read_with_progress(path, visitor, &|_| {})
}

/// [`read`], calling `progress` (from the reading thread) with the bytes read so far.
pub fn read_with_progress(
    path: &Path,
    visitor: &mut impl Visitor,
    progress: &(dyn Fn(u64) + Sync),
) -> (Structure, Option<ReadError>) {
    match open(path) {
        Ok((file, len)) => {
            let (s, e) = read_from(
                Counting {
                    inner: file,
                    read: 0,
                    progress,
                },
                len,
                visitor,
            );
            (s, e.map(|e| changed_size(path, len, e)))
        }
        Err(e) => (Structure::default(), Some(e)),
    }
}

/// `e`, or, when the file at `path` is no longer `len` bytes long, that it changed while it was read: a
/// file cut or grown under the reader breaks off where its old length no longer holds, which reads as a
/// wrong record length or a truncation of a file that was whole.
fn changed_size(path: &Path, len: u64, mut e: ReadError) -> ReadError {
    if !matches!(e.kind, ReadErrorKind::Truncated | ReadErrorKind::Corrupt) {
        return e;
    }
    if let Some(now) = std::fs::metadata(path)
        .ok()
        .map(|m| m.len())
        .filter(|&n| n != len)
    {
        e.detail = format!(
            "the file changed size while it was read ({len} bytes when opened, {now} now): read it \
             again once nothing writes it (the read stopped with: {})",
            e.detail
        );
    }
    e
}

/// A reader that reports its position.
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

/// Reads an MCAP file of `len` bytes from `source` (see [`read`]), seekable so that the metadata records
/// can be looked up before the stream.
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
        return (book.structure(), Some(e));
    }
    book.ahead = match early_metadata::find(&mut source, len, &mut book.kept) {
        Ok(ahead) => ahead,
        Err(e) => return (book.structure(), Some(e)),
    };
    for m in std::mem::take(&mut book.ahead.metadata) {
        book.early.insert(m.at, m.digest);
        visitor.metadata(&m.record.name, &m.record.metadata);
    }
    let error = match source.seek(SeekFrom::Start(0)) {
        Ok(_) => read_into(source, len, visitor, &mut book).err(),
        Err(e) => Some(io_error(e)),
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
    (book.structure(), error)
}

/// Opens the regular file at `path` and gives its length.
pub(crate) fn open(path: &Path) -> Result<(std::fs::File, u64), ReadError> {
    let len = regular_file(path, false)?.len();
    let file = std::fs::File::open(path).map_err(io_error)?;
    Ok((file, len))
}

/// The metadata of `path` if it is a regular file (links followed), looked at without opening it: an MCAP
/// file is read by seeking. `stdin`: the path names standard input (the refusal says so). Fails
/// ([`ReadErrorKind::Io`]) if the path cannot be looked at or is not a regular file.
pub fn regular_file(path: &Path, stdin: bool) -> Result<std::fs::Metadata, ReadError> {
    let meta = std::fs::metadata(path).map_err(io_error)?;
    if meta.is_dir() {
        return Err(ReadError::new(
            ReadErrorKind::Io,
            "is a directory, not an MCAP file",
        ));
    }
    if !meta.is_file() {
        return Err(ReadError::new(
            ReadErrorKind::Io,
            format!(
                "is {}not a regular file (a pipe, socket or device): an MCAP file is read by seeking \
                 to its summary and metadata, which a stream cannot do; save it to a file first",
                if stdin { "standard input, " } else { "" }
            ),
        ));
    }
    Ok(meta)
}

/// Tries more to start the reading thread when the system refuses it, [`SPAWN_PAUSE`] apart: 2 s in all.
const SPAWN_RETRIES: u32 = 100;
const SPAWN_PAUSE: std::time::Duration = std::time::Duration::from_millis(20);

fn read_into(
    file: impl Read + Send,
    file_len: u64,
    visitor: &mut impl Visitor,
    book: &mut Book,
) -> Result<(), ReadError> {
    book.s.file_len = file_len;
    book.pos = MAGIC_LEN;
    let (to_consumer, batches) = mpsc::sync_channel(prefetch::QUEUE);
    // Room for every batch, so that handing one back never blocks.
    let (to_producer, recycled) = mpsc::sync_channel(prefetch::POOL);
    // Taken by the thread that starts; left for the next try by one the system refuses.
    let inputs = std::sync::Mutex::new(Some((file, to_consumer, recycled)));
    std::thread::scope(|scope| {
        let produce = || {
            let taken = inputs.lock().map(|mut i| i.take());
            if let Ok(Some((file, to_consumer, recycled))) = taken {
                prefetch::produce(file, file_len, to_consumer, recycled);
            }
        };
        // The system may refuse a thread (its limit on processes or threads, EAGAIN), often for as long
        // as others of the same user run: tried again for a while, then an error, never a panic.
        let mut spawned = std::thread::Builder::new().spawn_scoped(scope, produce);
        for _ in 0..SPAWN_RETRIES {
            if spawned.is_ok() {
                break;
            }
            std::thread::sleep(SPAWN_PAUSE);
            spawned = std::thread::Builder::new().spawn_scoped(scope, produce);
        }
        let worker = spawned.map_err(|e| {
            ReadError::new(
                ReadErrorKind::Io,
                format!("cannot start the reading thread: {e}"),
            )
        })?;
        // `consume` owns the receiver, so that when it returns early or unwinds, a worker blocked on the
        // full queue wakes with an error and ends, and this scope can join it.
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

/// The checking half of the pipeline: walks the worker's batches in file order.
fn consume(
    batches: Receiver<Batch>,
    to_producer: SyncSender<Batch>,
    visitor: &mut impl Visitor,
    book: &mut Book,
) -> Result<(), ReadError> {
    while let Ok(batch) = batches.recv() {
        let walked = book.walk(&batch, visitor);
        // Every batch goes back: the worker counts them (see `prefetch`).
        let _ = to_producer.try_send(batch);
        walked?;
    }
    Ok(())
}

impl Book {
    fn structure(self) -> Structure {
        let counts = &self.channel_counts;
        let channels = self
            .channels
            .into_values()
            .map(|(_, c)| ChannelSummary {
                messages: counts.get(&c.id).copied().unwrap_or(0),
                ..c
            })
            .collect();
        Structure {
            summary: Summary { channels, ..self.s },
            problems: self.problems,
        }
    }

    fn walk(&mut self, batch: &Batch, visitor: &mut impl Visitor) -> Result<(), ReadError> {
        for event in &batch.events {
            match event {
                Event::Record { opcode, body } => {
                    let data = &batch.bytes[body.clone()];
                    let at = self.enter(*opcode, data.len() as u64);
                    self.record(*opcode, data, at, None, visitor)?;
                }
                Event::Chunk {
                    len,
                    header,
                    records,
                } => {
                    let at = self.enter(op::CHUNK, *len);
                    self.chunk_record(header, at, *len);
                    self.chunk_records(&batch.bytes[records.clone()], visitor)?;
                }
                Event::BadChunk { len, header, error } => {
                    let at = self.enter(op::CHUNK, *len);
                    if let Some(header) = header {
                        self.chunk_record(header, at, *len);
                    }
                    return Err(self.chunk_error(at, error));
                }
                Event::OuterError(e) => return Err(self.classify(e)),
                Event::Io(detail) => return Err(ReadError::new(ReadErrorKind::Io, detail.clone())),
            }
        }
        Ok(())
    }

    /// Moves past a top-level record with a body of `len` bytes, closing the chunk it ends (any record
    /// but a message index) and noting the summary group it extends; returns where it starts.
    fn enter(&mut self, opcode: u8, len: u64) -> u64 {
        let at = self.pos;
        let size = PREFIX_LEN + len;
        self.pos += size;
        if opcode != op::MESSAGE_INDEX {
            self.close_chunk();
        }
        if self.in_summary && opcode != op::FOOTER {
            // Contiguous runs of one opcode form a group (what a summary offset points at).
            let room = self.groups.len() < MAX_REMEMBERED;
            match self.groups.last_mut() {
                Some((o, start, len)) if *o == opcode && *start + *len == at => *len += size,
                _ if room => self.groups.push((opcode, at, size)),
                _ => {}
            }
            if self.summary_start.is_none() {
                self.summary_start = Some(at);
            }
        }
        at
    }

    fn classify(&self, e: &McapError) -> ReadError {
        let at = self.pos;
        let messages = self.s.messages;
        let len = self.s.file_len;
        let before = format!("judged the {messages} messages read before it");
        let read = format!("judged the {messages} messages read");
        match e {
            McapError::BadMagic if at == MAGIC_LEN && messages == 0 && !self.data_end_seen => {
                not_mcap()
            }
            McapError::UnexpectedEof if at <= MAGIC_LEN && !self.ahead.magic_prefix => {
                ReadError::new(
                    ReadErrorKind::NotMcap,
                    format!("not an MCAP file ({len} bytes, shorter than an MCAP header)"),
                )
            }
            McapError::UnexpectedEof if len < MAGIC_LEN => {
                truncated(len, ", inside the MCAP magic it starts with")
            }
            McapError::UnexpectedEof if self.footer_seen => {
                truncated(len, ", inside the MCAP end magic").after(read)
            }
            McapError::UnexpectedEof => self.past_end(at, None).after(before),
            McapError::RecordTooLarge {
                opcode,
                len: claimed,
            } => {
                let what = format!("record (opcode {opcode:#04x})");
                let end = at.saturating_add(PREFIX_LEN).saturating_add(*claimed);
                // Within the file but beyond the budget: refused, not corrupt.
                let error = if *claimed > MAX_RECORD_BYTES && end <= len {
                    let detail = format!(
                        "the {what} at byte {at} is {claimed} bytes long, more than the {} this \
                         reader accepts in one record",
                        budget::limit()
                    );
                    ReadError::new(ReadErrorKind::TooLarge, detail)
                } else {
                    self.past_end(at, Some((*claimed, what)))
                };
                error.after(before)
            }
            McapError::BadDataCrc { saved, calculated } => {
                bad_crc("data", *calculated, *saved).after(read)
            }
            McapError::BadSummaryCrc { saved, calculated } => {
                bad_crc("summary", *calculated, *saved).after(read)
            }
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
        if !self.ahead.ends_with_magic && plausible {
            let place = match (len == MAGIC_LEN, at >= len) {
                (true, _) => ", right after the MCAP magic".to_string(),
                (false, true) => ", after a whole record".to_string(),
                (false, false) => format!(" inside the record that starts at byte {at}"),
            };
            return truncated(len, &format!("{place}, before the MCAP footer"));
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
        match self.ahead.scan_end? {
            ScanEnd::Cut { at, claimed } => {
                Some(self.past_end(at, claimed.map(|c| (c, "record".to_string()))))
            }
            ScanEnd::Malformed { at } => Some(corrupt(format!(
                "malformed MCAP at byte {at}: the record there cannot be read"
            ))),
        }
    }

    fn problem(&mut self, p: impl FnOnce() -> String) {
        self.problems.push_with(p);
    }

    fn close_chunk(&mut self) {
        let Some(chunk) = self.chunk.take() else {
            return;
        };
        let (i, start) = (&chunk.index, chunk.index.chunk_start_offset);
        let (s, e) = (i.message_start_time, i.message_end_time);
        if let Some((a, b)) = chunk.bounds.filter(|&b| b != (s, e)) {
            self.problem(|| {
                format!("chunk at byte {start}: header says messages span {s}..{e} ns, they span {a}..{b} ns")
            });
        }
        let missing: Vec<u16> = chunk
            .per_channel
            .keys()
            .filter(|c| !i.message_index_offsets.contains_key(c))
            .copied()
            .collect();
        if !missing.is_empty() {
            self.problem(|| {
                format!("chunk at byte {start}: no message index for channel(s) {missing:?}")
            });
        }
        self.chunk_digest.push(index_digest(&chunk.index).0);
        self.s.chunks += 1;
    }

    fn chunk_record(&mut self, header: &ChunkHeader, at: u64, len: u64) {
        let s = &mut self.s;
        *s.compressions
            .entry(header.compression.clone())
            .or_insert(0) += 1;
        s.compressed_bytes += header.compressed_size;
        s.uncompressed_bytes += header.uncompressed_size;
        self.chunk = Some(ChunkBook {
            index: chunk_index(header, at, PREFIX_LEN + len),
            offset: 0,
            bounds: None,
            per_channel: BTreeMap::new(),
        });
    }

    /// The records of the current chunk, decompressed.
    fn chunk_records(
        &mut self,
        records: &[u8],
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let mut c = Cursor::new(records);
        while !c.rest().is_empty() {
            let (at, offset) = self
                .chunk
                .as_ref()
                .map_or((0, 0), |c| (c.index.chunk_start_offset, c.offset));
            let (opcode, data) = c.record().map_err(|e| {
                corrupt(format!(
                    "corrupt chunk at byte {at}: a record inside it runs past its end ({e})"
                ))
                .after(format!("judged the {} messages read", self.s.messages))
            })?;
            if let Some(c) = self.chunk.as_mut() {
                c.offset += PREFIX_LEN + data.len() as u64;
            }
            // Messages straight to `message`: the hot path, kept short.
            if opcode == op::MESSAGE {
                self.message(data, at, Some(offset), visitor)?;
            } else {
                self.record(opcode, data, at, Some(offset), visitor)?;
            }
        }
        Ok(())
    }

    fn chunk_error(&self, at: u64, e: &ChunkError) -> ReadError {
        let error = match e {
            ChunkError::Malformed(e) => wire_error("chunk", at, e),
            ChunkError::TooLarge(declared) => ReadError::new(
                ReadErrorKind::TooLarge,
                format!(
                    "the chunk at byte {at} declares {declared} bytes of records, more than the {} \
                     this reader accepts in one chunk",
                    budget::limit()
                ),
            ),
            e => corrupt(format!("corrupt chunk at byte {at}: {e}")),
        };
        let messages = self.s.messages;
        error.after(format!("judged the {messages} messages read before it"))
    }

    fn message(
        &mut self,
        data: &[u8],
        at: u64,
        chunk_offset: Option<u64>,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let MessageRecord { header, data } = parse(data, at)?;
        self.s.messages += 1;
        *self.channel_counts.entry(header.channel_id).or_insert(0) += 1;
        let t = header.log_time;
        self.s.time_range = Some(widen(self.s.time_range, t));
        if let (Some(offset), Some(chunk)) = (chunk_offset, self.chunk.as_mut()) {
            chunk.bounds = Some(widen(chunk.bounds, t));
            let d = chunk.per_channel.entry(header.channel_id).or_default();
            d.count += 1;
            d.digest.push(t);
            d.digest.push(offset);
        }
        match visitor.message(&header, data) {
            ControlFlow::Continue(()) => Ok(()),
            ControlFlow::Break(()) => Err(ReadError::new(ReadErrorKind::Stopped, "")),
        }
    }

    fn message_index(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let index: MessageIndex = parse(data, at)?;
        let mut found = IndexDigest::default();
        for e in &index.records {
            found.count += 1;
            found.digest.push(e.log_time);
            found.digest.push(e.offset);
        }
        let channel = index.channel_id;
        let Some(chunk) = self.chunk.as_mut() else {
            self.problem(|| format!("message index at byte {at} follows no chunk"));
            return Ok(());
        };
        chunk.index.message_index_offsets.insert(channel, at);
        chunk.index.message_index_length += PREFIX_LEN + data.len() as u64;
        let expected = chunk.per_channel.get(&channel).copied().unwrap_or_default();
        if expected.count != found.count || expected.digest != found.digest {
            let start = chunk.index.chunk_start_offset;
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

    /// The record at `at`, top-level or (`chunk_offset`: where in its records) inside the current chunk,
    /// where the records that only stand at the top level are ignored.
    fn record(
        &mut self,
        opcode: u8,
        data: &[u8],
        at: u64,
        chunk_offset: Option<u64>,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        match opcode {
            op::MESSAGE => self.message(data, at, chunk_offset, visitor),
            op::HEADER | op::MESSAGE_INDEX | op::FOOTER | op::DATA_END
                if chunk_offset.is_some() =>
            {
                Ok(())
            }
            op::HEADER => {
                let header: Header = parse(data, at)?;
                self.s.library = header.library;
                Ok(())
            }
            op::MESSAGE_INDEX => self.message_index(data, at),
            op::FOOTER => self.footer(data, at),
            op::DATA_END => {
                self.data_end_seen = true;
                self.in_summary = true;
                Ok(())
            }
            op::SCHEMA => self.schema(data, at),
            op::CHANNEL => self.channel(data, at, visitor),
            op::METADATA => self.metadata(data, at, visitor),
            op::ATTACHMENT => {
                self.attachment_count += 1;
                let a: AttachmentRecord = parse(data, at)?;
                let found = crc32fast::hash(&data[..a.crc_covered_len()]);
                if a.crc != 0 && a.crc != found {
                    let (name, stored) = (a.name, a.crc);
                    self.problem(|| {
                        format!(
                            "attachment `{name}` at byte {at}: CRC {found:#010x} of its data does not \
                             match the stored {stored:#010x}"
                        )
                    });
                }
                Ok(())
            }
            op::CHUNK_INDEX => {
                // Folded into the digest that must match the chunks' own.
                let i: ChunkIndex = parse(data, at)?;
                self.chunk_index_digest.push(index_digest(&i).0);
                self.chunk_indexes += 1;
                Ok(())
            }
            op::METADATA_INDEX => {
                let i: MetadataIndex = parse(data, at)?;
                if self.metadata_indexes.len() < MAX_REMEMBERED {
                    let name = Digest::of(i.name.as_bytes());
                    self.metadata_indexes.push((i.offset, i.length, name));
                }
                Ok(())
            }
            op::STATISTICS => {
                self.statistics += 1;
                let statistics = parse(data, at)?;
                self.check_statistics(&statistics);
                Ok(())
            }
            op::SUMMARY_OFFSET => {
                let o: SummaryOffset = parse(data, at)?;
                if self.summary_offsets.len() < MAX_REMEMBERED {
                    self.summary_offsets
                        .push((o.group_opcode, o.group_start, o.group_length));
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// A schema record: kept at its first definition (for the channels that name it), compared with it
    /// afterwards (summary or chunk repeats are allowed; other bytes under its id are not).
    fn schema(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let schema: Schema<'_> = parse(data, at)?;
        let (id, d) = (schema.id, Digest::of(data));
        match self.schemas.get(&id) {
            Some((earlier, _)) if *earlier != d => self.redefined("schema", id, &schema.name, at),
            Some(_) => {}
            None => {
                self.kept.charge(PREFIX_LEN + data.len() as u64, 0, at)?;
                let owned = Schema {
                    id,
                    name: schema.name,
                    encoding: schema.encoding,
                    data: Cow::Owned(schema.data.into_owned()),
                };
                self.schemas.insert(id, (d, owned));
            }
        }
        Ok(())
    }

    /// A channel record: passed on with its schema at its first definition, compared with it afterwards.
    fn channel(
        &mut self,
        data: &[u8],
        at: u64,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let c: Channel = parse(data, at)?;
        let d = Digest::of(data);
        match self.channels.get(&c.id) {
            Some((earlier, _)) if *earlier != d => self.redefined("channel", c.id, &c.topic, at),
            Some(_) => {}
            None => {
                let schema = self
                    .schemas
                    .get(&c.schema_id)
                    .map(|(_, s)| s)
                    .filter(|_| c.schema_id != 0);
                // The visitor may keep a copy of the schema with each channel.
                let size =
                    PREFIX_LEN + data.len() as u64 + schema.map_or(0, |s| s.data.len() as u64);
                self.kept.charge(size, c.metadata.len(), at)?;
                visitor.channel(c.id, &c.topic, &c.message_encoding, schema);
                // Summarised only once passed on: a channel refused by the budget is not listed.
                let summary = ChannelSummary {
                    id: c.id,
                    schema_name: schema.map(|s| s.name.clone()).unwrap_or_default(),
                    topic: c.topic,
                    message_encoding: c.message_encoding,
                    messages: 0,
                };
                self.channels.insert(c.id, (d, summary));
            }
        }
        Ok(())
    }

    /// The `what` (schema, channel) `id` named `name` at byte `at` differs from its first definition.
    fn redefined(&mut self, what: &str, id: u16, name: &str, at: u64) {
        self.problem(|| {
            format!("{what} {id} `{name}` at byte {at} differs from its earlier definition")
        });
    }

    /// A metadata record: passed on, and remembered (up to [`MAX_REMEMBERED`]) for the metadata indexes.
    fn metadata(
        &mut self,
        data: &[u8],
        at: u64,
        visitor: &mut impl Visitor,
    ) -> Result<(), ReadError> {
        let m: Metadata = parse(data, at)?;
        self.metadata_count += 1;
        let length = PREFIX_LEN + data.len() as u64;
        if self.metadata.len() < MAX_REMEMBERED {
            self.metadata
                .push((at, length, Digest::of(m.name.as_bytes())));
        }
        match self.early.get(&at) {
            // Passed on before the stream; the bytes read then must be these.
            Some(early) => {
                if Digest::of(data) != *early {
                    let name = m.name;
                    self.problem(|| {
                        format!(
                            "metadata record `{name}` at byte {at} changed while the file was read"
                        )
                    });
                }
            }
            None => {
                self.kept.charge(length, m.metadata.len(), at)?;
                visitor.metadata(&m.name, &m.metadata);
            }
        }
        Ok(())
    }

    fn check_statistics(&mut self, claimed: &Statistics) {
        let (start, end) = self.s.time_range.unwrap_or((0, 0));
        let real: [(&str, u64, u64); 8] = [
            ("message_count", claimed.message_count, self.s.messages),
            (
                "schema_count",
                u64::from(claimed.schema_count),
                self.schemas.len() as u64,
            ),
            (
                "channel_count",
                u64::from(claimed.channel_count),
                self.channels.len() as u64,
            ),
            (
                "attachment_count",
                u64::from(claimed.attachment_count),
                self.attachment_count,
            ),
            (
                "metadata_count",
                u64::from(claimed.metadata_count),
                self.metadata_count,
            ),
            ("chunk_count", u64::from(claimed.chunk_count), self.s.chunks),
            ("message_start_time", claimed.message_start_time, start),
            ("message_end_time", claimed.message_end_time, end),
        ];
        for (name, claimed, counted) in real {
            if claimed != counted {
                self.problem(|| format!("statistics: {name} = {claimed}, the file has {counted}"));
            }
        }
        if claimed.channel_message_counts != self.channel_counts {
            let list = |m: &BTreeMap<u16, u64>| m.iter().map(|(k, v)| (*k, *v)).collect::<Vec<_>>();
            let (counts, real_counts) = (
                list(&claimed.channel_message_counts),
                list(&self.channel_counts),
            );
            self.problem(|| {
                format!(
                    "statistics: channel message counts {counts:?} differ from the real {real_counts:?}"
                )
            });
        }
    }

    fn footer(&mut self, data: &[u8], at: u64) -> Result<(), ReadError> {
        let footer: Footer = parse(data, at)?;
        self.footer_seen = true;
        let real_start = self.summary_start.unwrap_or(0);
        let summary_start = footer.summary_start;
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
        let summary_offset_start = footer.summary_offset_start;
        if summary_offset_start != real_offsets {
            self.problem(|| {
                format!("footer: summary_offset_start = {summary_offset_start}, the summary offsets start at byte {real_offsets}")
            });
        }
        Ok(())
    }

    fn finish(&mut self) {
        self.close_chunk();
        if self.summary_start.is_none() {
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
