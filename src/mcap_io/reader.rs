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
use super::problems::Problems;
use super::wire::{self, Cursor, MessageHeader, WireError};
use mcap::records::op;
use mcap::McapError;
use std::collections::BTreeMap;
use std::fmt;
use std::io::Read;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::mpsc::{self, Receiver, SyncSender};

/// Bytes of an opcode and a record length.
const RECORD_PREFIX: u64 = 9;
/// MCAP magic length.
const MAGIC_LEN: u64 = 8;
/// How many metadata records and summary groups are remembered for the index checks (more are counted).
const MAX_REMEMBERED: usize = 1024;

/// What the caller does with records.
pub trait Visitor {
    /// A schema record (from the data section or a chunk; summary repeats are compared, not passed on).
    fn schema(&mut self, id: u16, name: &str, encoding: &str, data: &[u8]);
    /// A channel record (first definition only).
    fn channel(&mut self, id: u16, schema_id: u16, topic: &str, message_encoding: &str);
    /// A metadata record with its entries.
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
    /// The message for the user (without the path).
    pub detail: String,
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.detail)
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
    ReadError {
        kind: ReadErrorKind::Corrupt,
        detail,
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

/// A reader that reports how many bytes went through it.
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

/// Reads an MCAP stream of `len` bytes from `source` (see [`read`]).
pub fn read_from(
    source: impl Read + Send,
    len: u64,
    visitor: &mut impl Visitor,
) -> (Structure, Option<ReadError>) {
    let mut book = Book::default();
    let error = if len == 0 {
        Some(ReadError {
            kind: ReadErrorKind::NotMcap,
            detail: "empty file (0 bytes), not an MCAP file".into(),
        })
    } else {
        read_into(source, len, visitor, &mut book).err()
    };
    if error.is_none() {
        book.finish();
    }
    (book.s, error)
}

fn open(path: &Path) -> Result<(std::fs::File, u64), ReadError> {
    let io = |e: std::io::Error| ReadError {
        kind: ReadErrorKind::Io,
        detail: format!("cannot read: {e}"),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(ReadError {
            kind: ReadErrorKind::Io,
            detail: "is a directory, not an MCAP file".into(),
        });
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
        scope.spawn(move || {
            prefetch::produce(
                file,
                file_len,
                &prefetch::Producer {
                    to_consumer,
                    recycled,
                },
            );
        });
        // Returning drops `batches`, which ends the worker at its next send.
        consume(&batches, &to_producer, visitor, book)
    })
}

/// The checking half of the pipeline: walks the worker's events in file order.
fn consume(
    batches: &Receiver<Batch>,
    to_producer: &SyncSender<Batch>,
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
                Event::Io(detail) => {
                    return Err(ReadError {
                        kind: ReadErrorKind::Io,
                        detail: detail.clone(),
                    })
                }
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
        match e {
            McapError::BadMagic if at == MAGIC_LEN && messages == 0 && !self.data_end_seen => {
                ReadError {
                    kind: ReadErrorKind::NotMcap,
                    detail: "not an MCAP file (it does not start with the MCAP magic bytes)".into(),
                }
            }
            McapError::UnexpectedEof if at <= MAGIC_LEN => ReadError {
                kind: ReadErrorKind::NotMcap,
                detail: format!("not an MCAP file ({len} bytes, shorter than an MCAP header)"),
            },
            McapError::UnexpectedEof => ReadError {
                kind: ReadErrorKind::Truncated,
                detail: format!(
                    "truncated: the file ends at byte {len} inside the record that starts at byte \
                     {at}, before the MCAP footer; judged the {messages} messages read before it"
                ),
            },
            McapError::RecordTooLarge { opcode, len: claimed } => corrupt(format!(
                "record (opcode {opcode:#04x}) at byte {at} claims {claimed} bytes, more than the \
                 file's {len}: the file is corrupt or crafted; judged the {messages} messages read \
                 before it"
            )),
            McapError::ChunkTooLarge(claimed) => corrupt(format!(
                "chunk at byte {at} claims {claimed} bytes, more than the file's {len}: the file is \
                 corrupt or crafted; judged the {messages} messages read before it"
            )),
            McapError::BadDataCrc { saved, calculated } => corrupt(format!(
                "corrupt data section: CRC {calculated:#010x} does not match the stored \
                 {saved:#010x}; judged the {messages} messages read"
            )),
            McapError::BadSummaryCrc { saved, calculated } => corrupt(format!(
                "corrupt summary section: CRC {calculated:#010x} does not match the stored \
                 {saved:#010x}; judged the {messages} messages read"
            )),
            McapError::BytesAfterEndMagic => corrupt(format!(
                "{} bytes follow the MCAP end magic",
                len.saturating_sub(at)
            )),
            other => corrupt(format!(
                "malformed MCAP at byte {at}: {other}; judged the {messages} messages read before it"
            )),
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
        corrupt(match e {
            McapError::BadChunkCrc { saved, calculated } => format!(
                "corrupt chunk at byte {at}: CRC {calculated:#010x} of its records does not match \
                 the stored {saved:#010x}; judged the {read} messages read ({inside} of them from \
                 this chunk)"
            ),
            other => format!(
                "corrupt chunk at byte {at}: {other}; judged the {read} messages read before it"
            ),
        })
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
            ControlFlow::Break(()) => Err(ReadError {
                kind: ReadErrorKind::Stopped,
                detail: String::new(),
            }),
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
        let mut c = Cursor::new(data);
        let err = |e| wire_error("metadata", at, e);
        let name = c.string("name").map_err(err)?.unwrap_or("").to_string();
        let mut entries = BTreeMap::new();
        wire::for_each_entry(&mut c, "metadata", |e| {
            let k = e.string("key")?.unwrap_or("");
            let v = e.string("value")?.unwrap_or("");
            entries.insert(k.to_string(), v.to_string());
            Ok(())
        })
        .map_err(err)?;
        self.metadata_count += 1;
        if self.metadata.len() < MAX_REMEMBERED {
            self.metadata
                .push((at, RECORD_PREFIX + data.len() as u64, name.clone()));
        }
        visitor.metadata(&name, &entries);
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
        let bad: Vec<(u8, u64, u64)> = self
            .summary_offsets
            .iter()
            .filter(|o| !self.groups.contains(o))
            .copied()
            .collect();
        if !bad.is_empty() {
            self.problem(|| {
                format!("summary offsets {bad:?} (opcode, start, length) point at no group of the summary")
            });
        }
    }
}
