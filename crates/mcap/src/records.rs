//! Every MCAP record this crate reads or writes, each declared once: a type (`mcap::records`' where it
//! fits) and its field list, from which `codec!` makes both parser and encoder. Public (hidden) only for
//! the bench `crates/bench/benches/crate_vs_ours.rs`.
//!
//! Parsing is bounded: every length is checked against what the record holds before anything is
//! allocated, so a record never costs more than its size (plus `MAX_MAP_ENTRIES`, 65 536, entries per map).
//! `mcap::parse_record` reserves what a string claims: 4 GiB for a 30-byte metadata index record.

use mcap::records::{
    op, ChunkHeader, ChunkIndex, DataEnd, Footer, Header, MessageHeader, MessageIndex,
    MessageIndexEntry, Metadata, MetadataIndex, Statistics, SummaryOffset,
};
use mcap::Schema;
use std::borrow::Cow;
use std::collections::BTreeMap;

use crate::WriteError;

pub(crate) const MAGIC: &[u8] = mcap::MAGIC;
pub(crate) const MAGIC_LEN: u64 = 8;
/// Bytes before every record's body: its opcode and its body's length (u64).
pub(crate) const PREFIX_LEN: u64 = 9;
/// Bytes of the footer record, prefix included (body: summary start, summary offset start, CRC).
pub(crate) const FOOTER_LEN: u64 = PREFIX_LEN + 8 + 8 + 4;
/// Most entries a map field may hold: a coin-log metadata record has about 30, an id-keyed map at most
/// 65536. It bounds a parsed map's memory (about 100 bytes per entry beyond its strings), which the
/// record's size does not: an entry of two empty strings is 8 bytes in the file.
pub(crate) const MAX_MAP_ENTRIES: usize = 1 << 16;

/// A record body that does not hold what its fields declare.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    #[error("field `{field}` needs {needed} bytes but the record has {available} left")]
    Short {
        field: &'static str,
        needed: u64,
        available: u64,
    },
    #[error("`{field}` has more than {MAX_MAP_ENTRIES} entries, more than this reader accepts")]
    TooManyEntries { field: &'static str },
}

/// A cursor over one record body.
#[derive(Debug, Clone)]
pub(crate) struct Cursor<'a> {
    data: &'a [u8],
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Self { data }
    }

    /// Bytes not read yet.
    pub(crate) fn rest(&self) -> &'a [u8] {
        self.data
    }

    #[inline]
    pub(crate) fn take(&mut self, n: u64, field: &'static str) -> Result<&'a [u8], WireError> {
        let Some(n) = usize::try_from(n).ok().filter(|&n| n <= self.data.len()) else {
            return Err(WireError::Short {
                field,
                needed: n,
                available: self.data.len() as u64,
            });
        };
        let (head, tail) = self.data.split_at(n);
        self.data = tail;
        Ok(head)
    }

    /// A u32-length-prefixed run of bytes.
    pub(crate) fn bytes(&mut self, field: &'static str) -> Result<&'a [u8], WireError> {
        let len = u32::parse(self, field)?;
        self.take(u64::from(len), field)
    }

    /// The next whole record: its opcode and body.
    pub(crate) fn record(&mut self) -> Result<(u8, &'a [u8]), WireError> {
        let (opcode, len) = self.prefix()?;
        Ok((opcode, self.take(len, "record")?))
    }

    /// The next record prefix: its opcode and body length.
    pub(crate) fn prefix(&mut self) -> Result<(u8, u64), WireError> {
        Ok((
            u8::parse(self, "opcode")?,
            u64::parse(self, "record length")?,
        ))
    }
}

/// A value of a record field: how it is parsed from, and encoded into, a record body.
pub(crate) trait Field<'a>: Sized {
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError>;
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError>;
}

macro_rules! integer_fields {
    ($($t:ty),*) => {$(
        impl Field<'_> for $t {
            #[inline]
            fn parse(c: &mut Cursor<'_>, field: &'static str) -> Result<Self, WireError> {
                let bytes = c.take(std::mem::size_of::<$t>() as u64, field)?;
                let mut le = [0u8; std::mem::size_of::<$t>()];
                le.copy_from_slice(bytes);
                Ok(<$t>::from_le_bytes(le))
            }
            #[inline]
            fn encode(&self, out: &mut Vec<u8>, _: &'static str) -> Result<(), WriteError> {
                out.extend_from_slice(&self.to_le_bytes());
                Ok(())
            }
        }
    )*};
}
integer_fields!(u8, u16, u32, u64);

/// `len` as an MCAP length or count field (u32); `what`: what it measures, for the error.
pub(crate) fn len32(len: usize, what: &'static str) -> Result<u32, WriteError> {
    u32::try_from(len).map_err(|_| WriteError::TooLong { what, len })
}

/// Bytes with a u32 length prefix (MCAP `Bytes` within a record), borrowed.
impl<'a> Field<'a> for Cow<'a, [u8]> {
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError> {
        Ok(Cow::Borrowed(c.bytes(field)?))
    }
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError> {
        len32(self.len(), field)?.encode(out, field)?;
        out.extend_from_slice(self);
        Ok(())
    }
}

/// An MCAP `String`; invalid UTF-8 is replaced (U+FFFD), as a lenient reader shows it.
impl<'a> Field<'a> for String {
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError> {
        let bytes = Cow::<[u8]>::parse(c, field)?;
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError> {
        Cow::Borrowed(self.as_bytes()).encode(out, field)
    }
}

/// Bytes with a u64 length prefix (an attachment's data), borrowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct LongBytes<'a>(pub(crate) &'a [u8]);

impl<'a> Field<'a> for LongBytes<'a> {
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError> {
        let len = u64::parse(c, field)?;
        Ok(Self(c.take(len, field)?))
    }
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError> {
        (self.0.len() as u64).encode(out, field)?;
        out.extend_from_slice(self.0);
        Ok(())
    }
}

/// A u32-byte-length-prefixed run of entries, each parsed by `entry`, at most [`MAX_MAP_ENTRIES`].
fn entries<'a>(
    c: &mut Cursor<'a>,
    field: &'static str,
    mut entry: impl FnMut(&mut Cursor<'a>) -> Result<(), WireError>,
) -> Result<(), WireError> {
    let mut inner = Cursor::new(c.bytes(field)?);
    for _ in 0..MAX_MAP_ENTRIES {
        if inner.rest().is_empty() {
            return Ok(());
        }
        entry(&mut inner)?;
    }
    if inner.rest().is_empty() {
        Ok(())
    } else {
        Err(WireError::TooManyEntries { field })
    }
}

/// Encodes `items` with a u32 byte-length prefix.
fn encode_entries<T>(
    out: &mut Vec<u8>,
    field: &'static str,
    items: impl Iterator<Item = T>,
    mut entry: impl FnMut(&mut Vec<u8>, T) -> Result<(), WriteError>,
) -> Result<(), WriteError> {
    let at = out.len();
    out.extend_from_slice(&[0; 4]);
    for item in items {
        entry(out, item)?;
    }
    let len = len32(out.len() - at - 4, field)?;
    out[at..at + 4].copy_from_slice(&len.to_le_bytes());
    Ok(())
}

/// An MCAP `Map<K, V>` (a later duplicate key replaces the earlier one, as lenient readers do).
impl<'a, K, V> Field<'a> for BTreeMap<K, V>
where
    K: Field<'a> + Ord,
    V: Field<'a>,
{
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError> {
        let mut map = BTreeMap::new();
        entries(c, field, |e| {
            let k = K::parse(e, field)?;
            map.insert(k, V::parse(e, field)?);
            Ok(())
        })?;
        Ok(map)
    }
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError> {
        encode_entries(out, field, self.iter(), |out, (k, v)| {
            k.encode(out, field)?;
            v.encode(out, field)
        })
    }
}

/// An MCAP `Array<T>` of fixed-size entries (message index entries).
impl<'a> Field<'a> for Vec<MessageIndexEntry> {
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError> {
        // Unlimited: an entry costs in memory what it costs in the record.
        let mut inner = Cursor::new(c.bytes(field)?);
        let mut list = Vec::with_capacity(inner.rest().len() / 16);
        while !inner.rest().is_empty() {
            list.push(MessageIndexEntry::parse(&mut inner, field)?);
        }
        Ok(list)
    }
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError> {
        encode_entries(out, field, self.iter(), |out, e| e.encode(out, field))
    }
}

/// Field-by-field parsing and encoding of a struct from its field list, in file order: the one place a
/// layout is written down. `$ty = $opcode, "$name"` also makes it a [`Record`].
macro_rules! codec {
    ($ty:ty { $($field:ident),* $(,)? }) => {
        impl<'a> Field<'a> for $ty {
            #[inline]
            fn parse(c: &mut Cursor<'a>, _: &'static str) -> Result<Self, WireError> {
                Ok(Self { $($field: Field::parse(c, stringify!($field))?),* })
            }
            #[inline]
            fn encode(&self, out: &mut Vec<u8>, _: &'static str) -> Result<(), WriteError> {
                $(Field::encode(&self.$field, out, stringify!($field))?;)*
                Ok(())
            }
        }
    };
    ($ty:ty = $opcode:expr, $name:literal { $($field:ident),* $(,)? }) => {
        codec!($ty { $($field),* });
        record!($ty = $opcode, $name);
    };
}

/// Makes a type with a [`Field`] codec a [`Record`] of `$opcode`.
macro_rules! record {
    ($ty:ty = $opcode:expr, $name:literal) => {
        impl<'a> Record<'a> for $ty {
            const OPCODE: u8 = $opcode;
            const NAME: &'static str = $name;
            #[inline]
            fn parse_body(body: &'a [u8]) -> Result<Self, WireError> {
                Self::parse(&mut Cursor::new(body), $name)
            }
            #[inline]
            fn encode_body(&self, out: &mut Vec<u8>) -> Result<(), WriteError> {
                self.encode(out, $name)
            }
        }
    };
}

/// An MCAP record: its opcode, its name in messages ("chunk index"), and its body's codec.
pub trait Record<'a>: Sized {
    const OPCODE: u8;
    const NAME: &'static str;

    /// Parses a record body (bytes after the fields are ignored: MCAP lets records grow).
    fn parse_body(body: &'a [u8]) -> Result<Self, WireError>;

    fn encode_body(&self, out: &mut Vec<u8>) -> Result<(), WriteError>;

    /// Appends the whole record: opcode, length, body.
    #[inline]
    fn encode_record(&self, out: &mut Vec<u8>) -> Result<(), WriteError> {
        let at = out.len();
        out.extend_from_slice(&[Self::OPCODE, 0, 0, 0, 0, 0, 0, 0, 0]);
        self.encode_body(out)?;
        let len = (out.len() - at) as u64 - PREFIX_LEN;
        out[at + 1..at + 9].copy_from_slice(&len.to_le_bytes());
        Ok(())
    }
}

codec!(Header = op::HEADER, "header" { profile, library });
codec!(Footer = op::FOOTER, "footer" { summary_start, summary_offset_start, summary_crc });
codec!(Schema<'a> = op::SCHEMA, "schema" { id, name, encoding, data });
codec!(mcap::records::Channel = op::CHANNEL, "channel" {
    id, schema_id, topic, message_encoding, metadata
});
codec!(MessageIndexEntry { log_time, offset });
codec!(MessageIndex = op::MESSAGE_INDEX, "message index" { channel_id, records });
codec!(ChunkIndex = op::CHUNK_INDEX, "chunk index" {
    message_start_time, message_end_time, chunk_start_offset, chunk_length, message_index_offsets,
    message_index_length, compression, compressed_size, uncompressed_size
});
codec!(Statistics = op::STATISTICS, "statistics" {
    message_count, schema_count, channel_count, attachment_count, metadata_count, chunk_count,
    message_start_time, message_end_time, channel_message_counts
});
codec!(Metadata = op::METADATA, "metadata" { name, metadata });
codec!(MetadataIndex = op::METADATA_INDEX, "metadata index" { offset, length, name });
codec!(SummaryOffset = op::SUMMARY_OFFSET, "summary offset" {
    group_opcode, group_start, group_length
});
codec!(DataEnd = op::DATA_END, "data end" { data_section_crc });
codec!(MessageHeader {
    channel_id,
    sequence,
    log_time,
    publish_time
});
codec!(ChunkHeader {
    message_start_time,
    message_end_time,
    uncompressed_size,
    uncompressed_crc,
    compression,
    compressed_size
});

/// Bytes of a message header: channel id, sequence, log time, publish time.
const MESSAGE_HEADER_LEN: usize = 2 + 4 + 8 + 8;

/// A message record: its header, then its data, to the end of the record.
///
/// Parsing it is the streaming reader's hot path: every record of the 7 M-message workload, decompressed
/// beforehand, took 0.127 s with this codec and 0.469 s with `mcap::parse_record` (crate_vs_ours'
/// "parse" race, medians of 3 alternating rounds at load 7 on 2 cores).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MessageRecord<'a> {
    pub header: MessageHeader,
    pub(crate) data: &'a [u8],
}

impl<'a> Field<'a> for MessageRecord<'a> {
    #[inline]
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError> {
        let header = MessageHeader::parse(c, field)?;
        Ok(Self {
            header,
            data: c.rest(),
        })
    }
    #[inline]
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError> {
        // One allocation check for the whole record: the writer's hot path.
        out.reserve(MESSAGE_HEADER_LEN + self.data.len());
        self.header.encode(out, field)?;
        out.extend_from_slice(self.data);
        Ok(())
    }
}

record!(MessageRecord<'a> = op::MESSAGE, "message");

/// A chunk record: its header, then `compressed_size` bytes of (compressed) records.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct ChunkRecord<'a> {
    pub(crate) header: ChunkHeader,
    /// The records as stored (padding may follow them in the record).
    pub(crate) records: &'a [u8],
}

impl<'a> Field<'a> for ChunkRecord<'a> {
    fn parse(c: &mut Cursor<'a>, field: &'static str) -> Result<Self, WireError> {
        let header = ChunkHeader::parse(c, field)?;
        let records = c.take(header.compressed_size, "records")?;
        Ok(Self { header, records })
    }
    fn encode(&self, out: &mut Vec<u8>, field: &'static str) -> Result<(), WriteError> {
        self.header.encode(out, field)?;
        out.extend_from_slice(self.records);
        Ok(())
    }
}

record!(ChunkRecord<'a> = op::CHUNK, "chunk");

/// The chunk index entry of a chunk with `header` at byte `chunk_start_offset`, its record
/// `chunk_length` bytes long, before its message indexes are listed.
pub(crate) fn chunk_index(
    header: &ChunkHeader,
    chunk_start_offset: u64,
    chunk_length: u64,
) -> ChunkIndex {
    ChunkIndex {
        message_start_time: header.message_start_time,
        message_end_time: header.message_end_time,
        chunk_start_offset,
        chunk_length,
        message_index_offsets: BTreeMap::new(),
        message_index_length: 0,
        compression: header.compression.clone(),
        compressed_size: header.compressed_size,
        uncompressed_size: header.uncompressed_size,
    }
}

/// An attachment record: its times, name and media type, `data`, and the CRC-32 of every byte before the
/// CRC (0: not computed). Only read, for its framing and its CRC: coin-log writes none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct AttachmentRecord<'a> {
    pub(crate) log_time: u64,
    pub(crate) create_time: u64,
    pub(crate) name: String,
    pub(crate) media_type: String,
    pub(crate) data: LongBytes<'a>,
    pub(crate) crc: u32,
}

impl AttachmentRecord<'_> {
    /// Bytes of the body that the CRC covers: every field before it.
    pub(crate) fn crc_covered_len(&self) -> usize {
        8 + 8 + 4 + self.name.len() + 4 + self.media_type.len() + 8 + self.data.0.len()
    }
}

codec!(AttachmentRecord<'a> = op::ATTACHMENT, "attachment" {
    log_time, create_time, name, media_type, data, crc
});

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Encodes `r`, checks that it parses back, and returns its body (leaked: a test's few bytes).
    fn round_trip<T: Record<'static> + PartialEq + std::fmt::Debug>(r: &T) -> &'static [u8] {
        let mut out = Vec::new();
        r.encode_record(&mut out).unwrap();
        let (opcode, body) = Cursor::new(out.leak()).record().unwrap();
        assert_eq!(opcode, T::OPCODE);
        assert_eq!(&T::parse_body(body).unwrap(), r);
        body
    }

    #[test]
    fn records_parse_back_to_what_was_encoded() {
        round_trip(&Footer {
            summary_start: 1,
            summary_offset_start: 2,
            summary_crc: 3,
        });
        round_trip(&Statistics {
            message_count: 9,
            channel_message_counts: BTreeMap::from([(1, 4), (7, 5)]),
            ..Statistics::default()
        });
        round_trip(&Metadata {
            name: "coin-log".into(),
            metadata: BTreeMap::from([("k".into(), "v".into()), ("a".into(), String::new())]),
        });
        round_trip(&MessageIndex {
            channel_id: 3,
            records: vec![MessageIndexEntry {
                log_time: 5,
                offset: 6,
            }],
        });
    }

    #[test]
    fn an_attachment_parses_back_and_its_crc_covers_all_but_the_crc() {
        let a = AttachmentRecord {
            log_time: 1,
            create_time: 2,
            name: "note".into(),
            media_type: "text/plain".into(),
            data: LongBytes(b"hello"),
            crc: 7,
        };
        assert_eq!(a.crc_covered_len(), round_trip(&a).len() - 4);
    }

    #[test]
    fn the_footer_is_as_long_as_declared() {
        let body = round_trip(&Footer::default());
        assert_eq!(PREFIX_LEN + body.len() as u64, FOOTER_LEN);
    }

    #[test]
    fn a_string_claiming_more_than_the_record_is_an_error_not_an_allocation() {
        let mut body = u32::MAX.to_le_bytes().to_vec();
        body.extend_from_slice(b"abc");
        let err = String::parse(&mut Cursor::new(&body), "name").unwrap_err();
        assert_eq!(
            err,
            WireError::Short {
                field: "name",
                needed: u64::from(u32::MAX),
                available: 3
            }
        );
    }

    #[test]
    fn a_map_with_more_entries_than_the_limit_is_refused() {
        let mut entries = Vec::new();
        for _ in 0..=MAX_MAP_ENTRIES {
            entries.extend_from_slice(&[0; 8]);
        }
        let mut body = "m".to_string().into_bytes();
        body.splice(0..0, 1u32.to_le_bytes());
        body.extend_from_slice(&(entries.len() as u32).to_le_bytes());
        body.extend_from_slice(&entries);
        let err = Metadata::parse_body(&body).unwrap_err();
        assert_eq!(err, WireError::TooManyEntries { field: "metadata" });
    }

    #[test]
    fn a_message_is_split_from_its_data() {
        let mut body = vec![7, 0, 1, 0, 0, 0];
        body.extend_from_slice(&5u64.to_le_bytes());
        body.extend_from_slice(&6u64.to_le_bytes());
        body.extend_from_slice(b"{}");
        let m = MessageRecord::parse_body(&body).unwrap();
        let h = m.header;
        assert_eq!(
            (h.channel_id, h.sequence, h.log_time, h.publish_time),
            (7, 1, 5, 6)
        );
        assert_eq!(m.data, b"{}");
    }
}
