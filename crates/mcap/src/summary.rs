//! What a file says about itself without reading its data section: the header's library, the summary
//! section and the metadata records it indexes, in a few seeks whatever the file's length. The summary
//! is taken as stated (its CRC checked; the streaming [`read`](super::read) checks it against the data),
//! and held to the reader's budget. On the 7 M-message workload's file this took 0.13 ms with its seeks,
//! `mcap::Summary::read` and `mcap::read::metadata` 0.28 ms over the file in memory (crate_vs_ours'
//! "summary" race, medians of 3 rounds of 101 reads).

use crate::budget::{Kept, MAX_RECORD_BYTES};
use crate::early_metadata::{self, MAX_EARLY};
use crate::reader::{self, bad_crc, corrupt, io_error, not_mcap, wire_error, ReadError};
use crate::records::{Cursor, Record, WireError, FOOTER_LEN, MAGIC, MAGIC_LEN, PREFIX_LEN};
use mcap::records::{op, Channel, ChunkIndex, Footer, Header, MetadataIndex, Statistics};
use mcap::Schema;
use std::collections::BTreeMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// One channel as the summary lists it: its `id`, `topic`, `schema_name` (`""` without a schema),
/// `message_encoding` and the `messages` on it (from the statistics).
#[derive(Debug, Clone, PartialEq, Eq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct ChannelSummary {
    pub id: u16,
    pub topic: String,
    pub schema_name: String,
    pub message_encoding: String,
    pub messages: u64,
}

/// What a file holds: from its summary section ([`read_summary`]), or as counted by the streaming pass
/// ([`Structure::summary`](crate::Structure::summary)).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Summary {
    /// File size \[bytes\].
    pub file_len: u64,
    /// The header record's `library`.
    pub library: String,
    /// Messages in the file.
    pub messages: u64,
    /// Earliest and latest message log time \[ns\]; `None` without messages.
    pub time_range: Option<(u64, u64)>,
    /// Channels, by id.
    pub channels: Vec<ChannelSummary>,
    /// Chunks.
    pub chunks: u64,
    /// Chunks by compression name (`""` for uncompressed chunks).
    pub compressions: BTreeMap<String, u64>,
    /// The chunks' records, compressed \[bytes\].
    pub compressed_bytes: u64,
    /// The chunks' records, uncompressed \[bytes\].
    pub uncompressed_bytes: u64,
    /// Metadata records, in file order: name and entries.
    pub metadata: Vec<(String, BTreeMap<String, String>)>,
}

/// `bounds` (earliest, latest) widened to include the time `t`.
#[inline]
pub(crate) fn widen(bounds: Option<(u64, u64)>, t: u64) -> (u64, u64) {
    match bounds {
        None => (t, t),
        Some((start, end)) => (start.min(t), end.max(t)),
    }
}

/// Reads the summary of the MCAP file at `path`. `Ok(None)` when the file has no summary section, its
/// summary has no statistics record or lists fewer channels, schemas, chunk indexes or metadata indexes
/// than its statistics count (MCAP makes each group optional: the Python writer can leave out the
/// channels and schemas, or the chunk or metadata indexes), or it is larger than the largest record the
/// reader accepts. Fails if the file cannot be read, is not MCAP, or its footer, summary (CRC included)
/// or a record it points at is malformed or beyond the reader's budget.
pub fn read_summary(path: &Path) -> Result<Option<Summary>, ReadError> {
    let (mut file, file_len) = reader::open(path)?;
    let Some(library) = header_library(&mut file, file_len)? else {
        return Ok(None);
    };
    let Some((start, bytes)) = summary_section(&mut file, file_len, true)? else {
        return Ok(None);
    };
    let mut records = SummaryRecords::default();
    records.parse(&bytes, start)?;
    if !records.statistics || !records.complete() {
        return Ok(None);
    }
    let mut out = records.summary;
    out.file_len = file_len;
    out.library = library;
    for (schema_id, mut c) in records.channels.into_values() {
        c.messages = records.counts.get(&c.id).copied().unwrap_or(0);
        if let Some(name) = records.schemas.get(&schema_id) {
            c.schema_name.clone_from(name);
        }
        out.channels.push(c);
    }
    let indexes = records.metadata_indexes;
    let Some(found) =
        early_metadata::read_indexed(&mut file, file_len, indexes, &mut Kept::default())?
    else {
        return Err(corrupt(
            "a metadata index entry points at no metadata record of its length".into(),
        ));
    };
    out.metadata = found
        .into_iter()
        .map(|m| (m.record.name, m.record.metadata))
        .collect();
    Ok(Some(out))
}

/// Where the summary section starts and its bytes (up to the footer), its CRC checked if `check_crc`;
/// `None` when the footer says there is none or it is larger than the reader accepts.
pub(crate) fn summary_section(
    file: &mut (impl Read + Seek),
    file_len: u64,
    check_crc: bool,
) -> Result<Option<(u64, Vec<u8>)>, ReadError> {
    if file_len < MAGIC_LEN + FOOTER_LEN + MAGIC_LEN {
        return Err(corrupt(format!(
            "{file_len} bytes: too short for an MCAP file with a footer"
        )));
    }
    let end = bytes_at(file, file_len, file_len - MAGIC_LEN, MAGIC_LEN)?;
    let Some((footer, footer_at)) = footer(file, file_len).filter(|_| end == MAGIC) else {
        return Err(corrupt(
            "no MCAP footer and end magic at the end of the file (truncated?)".into(),
        ));
    };
    let summary_start = footer.summary_start;
    if summary_start == 0 {
        return Ok(None);
    }
    if summary_start < MAGIC_LEN || summary_start > footer_at {
        return Err(corrupt(format!(
            "the footer's summary_start {summary_start} is outside the file"
        )));
    }
    if footer_at - summary_start > MAX_RECORD_BYTES {
        return Ok(None);
    }
    // The summary CRC covers the summary and the footer up to its CRC field.
    let crc_end = footer_at + FOOTER_LEN - 4;
    let mut bytes = bytes_at(file, file_len, summary_start, crc_end - summary_start)?;
    let computed = crc32fast::hash(&bytes);
    if check_crc && footer.summary_crc != 0 && computed != footer.summary_crc {
        return Err(bad_crc("summary", computed, footer.summary_crc));
    }
    bytes.truncate(usize::try_from(footer_at - summary_start).unwrap_or(0));
    Ok(Some((summary_start, bytes)))
}

/// The footer of the MCAP file of `len` bytes and where it starts, if it has a readable one.
fn footer(source: &mut (impl Read + Seek), len: u64) -> Option<(Footer, u64)> {
    let at = len.checked_sub(MAGIC_LEN + FOOTER_LEN)?;
    let body = record_at(source, len, at, FOOTER_LEN, op::FOOTER)?;
    Some((Footer::parse_body(&body).ok()?, at))
}

/// The body of the record at `at` if it is an `opcode` record of `length` bytes, prefix included.
pub(crate) fn record_at(
    source: &mut (impl Read + Seek),
    file_len: u64,
    at: u64,
    length: u64,
    opcode: u8,
) -> Option<Vec<u8>> {
    let mut record = bytes_at(source, file_len, at, length).ok()?;
    if Cursor::new(&record).prefix().ok()? != (opcode, length - PREFIX_LEN) {
        return None;
    }
    record.drain(..PREFIX_LEN as usize);
    Some(record)
}

/// The (offset, length) of the summary's first [`MAX_EARLY`] MetadataIndex records, its CRC unchecked
/// (a malformed entry is skipped, a record running past the summary ends the list); `None` when the
/// file has no summary that the reader accepts.
pub(crate) fn metadata_indexes(
    source: &mut (impl Read + Seek),
    len: u64,
) -> Option<Vec<(u64, u64)>> {
    let (_, bytes) = summary_section(source, len, false).ok()??;
    let mut c = Cursor::new(&bytes);
    let mut found = Vec::new();
    while let Ok((opcode, body)) = c.record() {
        if opcode == op::METADATA_INDEX && found.len() < MAX_EARLY {
            found.extend(MetadataIndex::parse_body(body).map(|i| (i.offset, i.length)));
        }
    }
    Some(found)
}

/// What the summary's records say, gathered while they are parsed.
#[derive(Default)]
struct SummaryRecords {
    summary: Summary,
    statistics: bool,
    /// The first record of each channel id, with the schema id it names.
    channels: BTreeMap<u16, (u16, ChannelSummary)>,
    schemas: BTreeMap<u16, String>,
    counts: BTreeMap<u16, u64>,
    metadata_indexes: Vec<(u64, u64)>,
    /// The statistics' schema, channel, chunk and metadata counts.
    stated: [u64; 4],
}

impl SummaryRecords {
    /// The summary lists as many schemas, channels, chunk indexes and metadata indexes as its statistics
    /// count (or more: a repeated record is not the summary's to judge here).
    fn complete(&self) -> bool {
        let listed = [
            self.schemas.len() as u64,
            self.channels.len() as u64,
            self.summary.chunks,
            self.metadata_indexes.len() as u64,
        ];
        listed
            .iter()
            .zip(self.stated)
            .all(|(&n, stated)| n >= stated)
    }

    /// Walks the records of the summary section `bytes` (which starts at byte `start` of the file).
    fn parse(&mut self, bytes: &[u8], start: u64) -> Result<(), ReadError> {
        let mut c = Cursor::new(bytes);
        while !c.rest().is_empty() {
            let at = start + (bytes.len() - c.rest().len()) as u64;
            let err = |e: WireError| wire_error("summary", at, &e);
            let (opcode, body) = c.record().map_err(err)?;
            self.record(opcode, body).map_err(err)?;
        }
        Ok(())
    }

    fn record(&mut self, opcode: u8, body: &[u8]) -> Result<(), WireError> {
        match opcode {
            op::SCHEMA => {
                let s = Schema::parse_body(body)?;
                self.schemas.insert(s.id, s.name);
            }
            op::CHANNEL => {
                let c = Channel::parse_body(body)?;
                let channel = ChannelSummary {
                    id: c.id,
                    topic: c.topic,
                    schema_name: String::new(),
                    message_encoding: c.message_encoding,
                    messages: 0,
                };
                self.channels.entry(c.id).or_insert((c.schema_id, channel));
            }
            op::STATISTICS => {
                let s = Statistics::parse_body(body)?;
                self.counts = s.channel_message_counts;
                self.statistics = true;
                self.stated = [
                    u64::from(s.schema_count),
                    u64::from(s.channel_count),
                    u64::from(s.chunk_count),
                    u64::from(s.metadata_count),
                ];
                self.summary.messages = s.message_count;
                self.summary.time_range =
                    (s.message_count > 0).then_some((s.message_start_time, s.message_end_time));
            }
            op::CHUNK_INDEX => {
                let i = ChunkIndex::parse_body(body)?;
                let s = &mut self.summary;
                s.compressed_bytes += i.compressed_size;
                s.uncompressed_bytes += i.uncompressed_size;
                *s.compressions.entry(i.compression).or_insert(0) += 1;
                s.chunks += 1;
            }
            op::METADATA_INDEX => {
                let i = MetadataIndex::parse_body(body)?;
                self.metadata_indexes.push((i.offset, i.length));
            }
            _ => {}
        }
        Ok(())
    }
}

/// Reads `length` bytes at `offset`, checked against the file's size and the largest record accepted.
pub(crate) fn bytes_at(
    file: &mut (impl Read + Seek),
    file_len: u64,
    offset: u64,
    length: u64,
) -> Result<Vec<u8>, ReadError> {
    if length > MAX_RECORD_BYTES + FOOTER_LEN
        || offset.checked_add(length).is_none_or(|end| end > file_len)
    {
        return Err(corrupt(format!(
            "a record of {length} bytes at byte {offset} does not fit in the file's {file_len} bytes"
        )));
    }
    file.seek(SeekFrom::Start(offset)).map_err(io_error)?;
    let mut buf = vec![0; usize::try_from(length).unwrap_or(0)];
    file.read_exact(&mut buf).map_err(io_error)?;
    Ok(buf)
}

/// The magic and the header record's `library`; `None` when the file starts with the magic but not
/// with a whole header record (the streaming pass says what is wrong).
fn header_library(file: &mut std::fs::File, file_len: u64) -> Result<Option<String>, ReadError> {
    let start = bytes_at(file, file_len, 0, file_len.min(MAGIC_LEN + PREFIX_LEN))?;
    let magic = start.len().min(MAGIC.len());
    if start[..magic] != MAGIC[..magic] {
        return Err(not_mcap());
    }
    match Cursor::new(&start[magic..]).prefix() {
        Ok((op::HEADER, len)) if len <= MAX_RECORD_BYTES => {
            let body = bytes_at(file, file_len, MAGIC_LEN + PREFIX_LEN, len)?;
            let header = Header::parse_body(&body)
                .map_err(|e| corrupt(format!("malformed header record: {e}")))?;
            Ok(Some(header.library))
        }
        _ => Ok(None),
    }
}
