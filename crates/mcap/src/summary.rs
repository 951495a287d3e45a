//! What a file says about itself without reading its data section: the header's library, the summary
//! section (statistics, schemas, channels, chunk indexes, metadata indexes) and the metadata records the
//! metadata indexes point at. A few seeks and a few KiB of reading, whatever the file's length, so that
//! `coin-log info` is instant on a file of gigabytes.
//!
//! The summary is taken as the file states it, its CRC checked; nothing here checks it against the data
//! section (the streaming [`read`](super::read) does that). Records are parsed by [`wire`] (bounds-checked,
//! borrowing), and every length is checked against the file size before anything is allocated for it.

use super::reader::{ReadError, ReadErrorKind};
use super::wire::{self, Cursor};
use mcap::records::op;
use std::collections::BTreeMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// MCAP's magic bytes, at both ends of a file.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
/// Largest header or metadata record read through the summary \[bytes\] (a coin-log metadata record is a
/// few KiB; one larger than this is read by the streaming pass instead).
const MAX_RECORD: u64 = 1 << 26;

/// One channel as the summary lists it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChannelSummary {
    /// Channel id.
    pub id: u16,
    /// Topic.
    pub topic: String,
    /// Schema name (`""` without a schema).
    pub schema_name: String,
    /// Message encoding.
    pub message_encoding: String,
    /// Messages on the channel, from the statistics.
    pub messages: u64,
    /// The schema id the channel record names (resolved into `schema_name`).
    schema_id_of: u16,
}

/// A file's self-description, from its summary section.
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

fn io_error(e: &std::io::Error) -> ReadError {
    ReadError {
        kind: ReadErrorKind::Io,
        detail: format!("cannot read: {e}"),
        read_before: String::new(),
    }
}

fn corrupt(detail: String) -> ReadError {
    ReadError {
        kind: ReadErrorKind::Corrupt,
        detail,
        read_before: String::new(),
    }
}

/// Reads the summary of the MCAP file at `path`. `Ok(None)` when the file has no summary section, its
/// summary has no statistics record, or it is larger than 64 MiB (then only a streaming pass
/// can tell what the file holds).
///
/// # Errors
/// [`ReadError`] if the file cannot be read, is not MCAP, or its footer, summary (CRC included) or a
/// record it points at is malformed.
pub fn read_summary(path: &Path) -> Result<Option<Summary>, ReadError> {
    let meta = std::fs::metadata(path).map_err(|e| io_error(&e))?;
    if meta.is_dir() {
        return Err(ReadError {
            kind: ReadErrorKind::Io,
            detail: "is a directory, not an MCAP file".into(),
            read_before: String::new(),
        });
    }
    let file_len = meta.len();
    let mut file = std::fs::File::open(path).map_err(|e| io_error(&e))?;
    let library = header_library(&mut file, file_len)?;
    let Some(section) = summary_section(&mut file, file_len)? else {
        return Ok(None);
    };
    let mut records = SummaryRecords::default();
    records.parse(&section.bytes, section.start)?;
    if !records.statistics {
        return Ok(None);
    }
    let mut out = records.summary;
    out.file_len = file_len;
    out.library = library;
    out.channels.sort_by_key(|c| c.id);
    for c in &mut out.channels {
        c.messages = records.counts.get(&c.id).copied().unwrap_or(0);
        if let Some(name) = records.schemas.get(&c.schema_id_of) {
            c.schema_name.clone_from(name);
        }
    }
    records.metadata_indexes.sort_unstable();
    for &(offset, length) in &records.metadata_indexes {
        out.metadata
            .push(metadata_at(&mut file, file_len, offset, length)?);
    }
    Ok(Some(out))
}

/// The summary section's bytes and where they start.
struct Section {
    start: u64,
    bytes: Vec<u8>,
}

/// Bytes of the footer record and the end magic.
const FOOTER_AND_MAGIC: u64 = 1 + 8 + 8 + 8 + 4 + 8;

/// The summary section (from `summary_start` to the footer), its CRC checked; `None` when the footer says
/// there is none or it is larger than [`MAX_RECORD`].
fn summary_section(file: &mut std::fs::File, file_len: u64) -> Result<Option<Section>, ReadError> {
    if file_len < 8 + FOOTER_AND_MAGIC {
        return Err(corrupt(format!(
            "{file_len} bytes: too short for an MCAP file with a footer"
        )));
    }
    let footer_at = file_len - FOOTER_AND_MAGIC;
    let footer = bytes_at(file, file_len, footer_at, FOOTER_AND_MAGIC)?;
    if &footer[29..] != MAGIC || footer[0] != op::FOOTER {
        return Err(corrupt(
            "no MCAP footer and end magic at the end of the file (truncated?)".into(),
        ));
    }
    let word = |at: usize| {
        let mut w = [0u8; 8];
        w.copy_from_slice(&footer[at..at + 8]);
        u64::from_le_bytes(w)
    };
    let (summary_start, crc) = (
        word(9),
        u32::from_le_bytes([footer[25], footer[26], footer[27], footer[28]]),
    );
    if summary_start == 0 {
        return Ok(None);
    }
    if summary_start < 8 || summary_start > footer_at {
        return Err(corrupt(format!(
            "the footer's summary_start {summary_start} is outside the file"
        )));
    }
    if footer_at - summary_start > MAX_RECORD {
        return Ok(None);
    }
    let bytes = bytes_at(file, file_len, summary_start, footer_at - summary_start)?;
    if crc != 0 {
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&bytes);
        hasher.update(&footer[..25]);
        let computed = hasher.finalize();
        if computed != crc {
            return Err(corrupt(format!(
                "corrupt summary section: CRC {computed:#010x} does not match the stored {crc:#010x}"
            )));
        }
    }
    Ok(Some(Section {
        start: summary_start,
        bytes,
    }))
}

/// What the summary's records say, gathered while they are parsed.
#[derive(Default)]
struct SummaryRecords {
    summary: Summary,
    statistics: bool,
    schemas: BTreeMap<u16, String>,
    counts: BTreeMap<u16, u64>,
    metadata_indexes: Vec<(u64, u64)>,
}

impl SummaryRecords {
    /// Walks the records of the summary section `bytes` (which starts at byte `start` of the file).
    fn parse(&mut self, bytes: &[u8], start: u64) -> Result<(), ReadError> {
        let mut c = Cursor::new(bytes);
        while !c.rest().is_empty() {
            let at = start + (bytes.len() - c.rest().len()) as u64;
            let err =
                |e: wire::WireError| corrupt(format!("malformed summary record at byte {at}: {e}"));
            let opcode = c.u8("opcode").map_err(err)?;
            let len = c.u64("record length").map_err(err)?;
            let body = c.take(len, "record").map_err(err)?;
            self.record(opcode, body).map_err(err)?;
        }
        Ok(())
    }

    fn record(&mut self, opcode: u8, body: &[u8]) -> Result<(), wire::WireError> {
        let mut c = Cursor::new(body);
        match opcode {
            op::SCHEMA => {
                let id = c.u16("id")?;
                let name = c.string("name")?.unwrap_or("").to_string();
                self.schemas.insert(id, name);
            }
            op::CHANNEL => {
                let id = c.u16("id")?;
                let schema_id = c.u16("schema_id")?;
                let topic = c.string("topic")?.unwrap_or("").to_string();
                let message_encoding = c.string("message_encoding")?.unwrap_or("").to_string();
                if !self.summary.channels.iter().any(|ch| ch.id == id) {
                    self.summary.channels.push(ChannelSummary {
                        id,
                        topic,
                        schema_name: String::new(),
                        message_encoding,
                        messages: 0,
                        schema_id_of: schema_id,
                    });
                }
            }
            op::STATISTICS => self.statistics_record(&mut c)?,
            op::CHUNK_INDEX => self.chunk_index(&mut c)?,
            op::METADATA_INDEX => {
                let offset = c.u64("offset")?;
                let length = c.u64("length")?;
                self.metadata_indexes.push((offset, length));
            }
            _ => {}
        }
        Ok(())
    }

    fn statistics_record(&mut self, c: &mut Cursor<'_>) -> Result<(), wire::WireError> {
        let messages = c.u64("message_count")?;
        let _schemas = c.u16("schema_count")?;
        let _channels = c.u32("channel_count")?;
        let _attachments = c.u32("attachment_count")?;
        let _metadata = c.u32("metadata_count")?;
        let _chunks = c.u32("chunk_count")?;
        let start = c.u64("message_start_time")?;
        let end = c.u64("message_end_time")?;
        let counts = &mut self.counts;
        wire::for_each_entry(c, "channel_message_counts", |e| {
            counts.insert(e.u16("channel_id")?, e.u64("count")?);
            Ok(())
        })?;
        self.statistics = true;
        self.summary.messages = messages;
        self.summary.time_range = (messages > 0).then_some((start, end));
        Ok(())
    }

    fn chunk_index(&mut self, c: &mut Cursor<'_>) -> Result<(), wire::WireError> {
        let _start_time = c.u64("message_start_time")?;
        let _end_time = c.u64("message_end_time")?;
        let _offset = c.u64("chunk_start_offset")?;
        let _length = c.u64("chunk_length")?;
        wire::for_each_entry(c, "message_index_offsets", |e| {
            e.u16("channel_id")?;
            e.u64("offset")?;
            Ok(())
        })?;
        let _index_length = c.u64("message_index_length")?;
        let compression = String::from_utf8_lossy(c.bytes("compression")?).into_owned();
        let s = &mut self.summary;
        s.compressed_bytes += c.u64("compressed_size")?;
        s.uncompressed_bytes += c.u64("uncompressed_size")?;
        *s.compressions.entry(compression).or_insert(0) += 1;
        s.chunks += 1;
        Ok(())
    }
}

/// Reads `length` bytes at `offset`, checked against the file's size and [`MAX_RECORD`].
fn bytes_at(
    file: &mut std::fs::File,
    file_len: u64,
    offset: u64,
    length: u64,
) -> Result<Vec<u8>, ReadError> {
    if length > MAX_RECORD || offset.checked_add(length).is_none_or(|end| end > file_len) {
        return Err(corrupt(format!(
            "a record of {length} bytes at byte {offset} does not fit in the file's {file_len} bytes"
        )));
    }
    file.seek(SeekFrom::Start(offset))
        .map_err(|e| io_error(&e))?;
    let mut buf = vec![0; usize::try_from(length).unwrap_or(0)];
    file.read_exact(&mut buf).map_err(|e| io_error(&e))?;
    Ok(buf)
}

/// The magic and the header record's `library`.
fn header_library(file: &mut std::fs::File, file_len: u64) -> Result<String, ReadError> {
    let not_mcap = || ReadError {
        kind: ReadErrorKind::NotMcap,
        detail: "not an MCAP file (it does not start with the MCAP magic bytes)".into(),
        read_before: String::new(),
    };
    if file_len < 17 {
        return Err(not_mcap());
    }
    let start = bytes_at(file, file_len, 0, 17)?;
    if &start[..8] != MAGIC || start[8] != op::HEADER {
        return Err(not_mcap());
    }
    let mut len = [0u8; 8];
    len.copy_from_slice(&start[9..17]);
    let body = bytes_at(file, file_len, 17, u64::from_le_bytes(len))?;
    let mut c = Cursor::new(&body);
    let err = |e: wire::WireError| corrupt(format!("malformed header record: {e}"));
    let _profile = c.string("profile").map_err(err)?;
    Ok(c.string("library").map_err(err)?.unwrap_or("").to_string())
}

/// The metadata record of `length` bytes at `offset` (opcode and length prefix included).
fn metadata_at(
    file: &mut std::fs::File,
    file_len: u64,
    offset: u64,
    length: u64,
) -> Result<(String, BTreeMap<String, String>), ReadError> {
    let record = bytes_at(file, file_len, offset, length)?;
    if record.len() < 9 || record[0] != op::METADATA {
        return Err(corrupt(format!(
            "the metadata index points at byte {offset}, where there is no metadata record"
        )));
    }
    let mut c = Cursor::new(&record[9..]);
    let err =
        |e: wire::WireError| corrupt(format!("malformed metadata record at byte {offset}: {e}"));
    let name = c.string("name").map_err(err)?.unwrap_or("").to_string();
    let mut entries = BTreeMap::new();
    wire::for_each_entry(&mut c, "metadata", |e| {
        let k = e.string("key")?.unwrap_or("");
        let v = e.string("value")?.unwrap_or("");
        entries.insert(k.to_string(), v.to_string());
        Ok(())
    })
    .map_err(err)?;
    Ok((name, entries))
}
