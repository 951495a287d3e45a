//! Before the stream: the file's metadata records, wherever they sit (docs/format.md, "Files from other
//! MCAP writers"), and what its ends look like. They are found through the summary's MetadataIndex
//! records, one seek each, or, without them, by a scan of the top-level records that reads each 9-byte
//! prefix and seeks past the body (metadata never sit inside chunks). Both read each byte at most once and
//! count what they keep against the budget. Nothing here is trusted: a record that is not what the index
//! says sends the search to the scan, an I/O error ends it; the stream reports both.

use crate::budget::{Kept, MAX_RECORD_BYTES};
use crate::digest::Digest;
use crate::reader::ReadError;
use crate::records::{Cursor, Record, MAGIC, MAGIC_LEN, PREFIX_LEN};
use crate::summary::{bytes_at, metadata_indexes, record_at};
use mcap::records::{op, Metadata};
use std::io::{self, Read, Seek, SeekFrom};

/// Most metadata records passed on ahead of the stream (further ones come with the stream).
pub(crate) const MAX_EARLY: usize = 1024;

/// One metadata record found ahead of the stream, its offset, and its body's digest (to recognise it in
/// the stream).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct FoundMetadata {
    pub(crate) at: u64,
    pub(crate) digest: Digest,
    pub(crate) record: Metadata,
}

/// How the search ended without reaching the end of the data section.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ScanEnd {
    /// The file ends inside the record at `at` (or exactly where one should start); `claimed`: its
    /// length, when its prefix is whole.
    Cut { at: u64, claimed: Option<u64> },
    /// The record at `at` is not a well-formed metadata record or has an impossible length.
    Malformed { at: u64 },
}

/// What was learned before the stream.
#[derive(Debug, Default)]
pub(crate) struct Lookahead {
    /// In file order.
    pub(crate) metadata: Vec<FoundMetadata>,
    /// The first bytes of the file are the MCAP magic, or its beginning when the file is shorter.
    pub(crate) magic_prefix: bool,
    /// The file ends with the MCAP magic (its last 8 bytes, not those of the start).
    pub(crate) ends_with_magic: bool,
    /// The records were found through the summary's metadata index.
    pub(crate) indexed: bool,
    /// Where the scan stopped early, when it ran and did.
    pub(crate) scan_end: Option<ScanEnd>,
}

/// Looks for the metadata records of the MCAP file of `len` bytes in `source` (see the module doc),
/// counting them in `kept` (an error when they exceed the budget). Leaves the source at an unspecified
/// position.
pub(crate) fn find(
    source: &mut (impl Read + Seek),
    len: u64,
    kept: &mut Kept,
) -> Result<Lookahead, ReadError> {
    let mut p = Lookahead::default();
    let Ok(head) = bytes_at(source, len, 0, len.min(MAGIC_LEN)) else {
        return Ok(p);
    };
    p.magic_prefix = head == MAGIC[..head.len()];
    if len < MAGIC_LEN || !p.magic_prefix {
        return Ok(p);
    }
    // The end magic is a second copy: a file of 8 to 15 bytes holds only the first.
    p.ends_with_magic = len >= 2 * MAGIC_LEN
        && bytes_at(source, len, len - MAGIC_LEN, MAGIC_LEN).is_ok_and(|tail| tail == MAGIC);
    let indexes = p.ends_with_magic.then(|| metadata_indexes(source, len));
    if let Some(indexes) = indexes.flatten().filter(|i| !i.is_empty()) {
        // Counted aside: if the index proves untrustworthy, the scan counts them again.
        let mut found = kept.clone();
        if let Some(metadata) = read_indexed(source, len, indexes, &mut found)? {
            p.indexed = true;
            p.metadata = metadata;
            *kept = found;
            return Ok(p);
        }
        // An index entry points at no metadata record of its length (e.g. @mcap/core 2.2's unchunked
        // writer records the offset of the messages it still buffers): the scan finds them where they are.
    }
    p.scan_end = scan(source, len, &mut p.metadata, kept)?;
    Ok(p)
}

/// Reads the record prefix at the reader's position: (opcode, body length), or `None` at a short read.
fn prefix(r: &mut impl Read) -> Option<(u8, u64)> {
    let mut b = [0u8; PREFIX_LEN as usize];
    r.read_exact(&mut b).ok()?;
    Cursor::new(&b).prefix().ok()
}

/// Reads the metadata records the index points at: in file order, each once, never two that overlap
/// (so that no byte is read twice), each checked to be a metadata record of the indexed length, and
/// counted in `kept` (an error when they exceed the budget). `None` when an entry points at no such
/// record (a repeated entry counts as valid).
pub(crate) fn read_indexed(
    source: &mut (impl Read + Seek),
    len: u64,
    mut indexes: Vec<(u64, u64)>,
    kept: &mut Kept,
) -> Result<Option<Vec<FoundMetadata>>, ReadError> {
    indexes.sort_unstable();
    indexes.dedup();
    let mut out: Vec<FoundMetadata> = Vec::new();
    let mut free_from = MAGIC_LEN;
    for (at, length) in indexes {
        let end = at.saturating_add(length);
        if at < free_from || length > PREFIX_LEN + MAX_RECORD_BYTES {
            return Ok(None);
        }
        let record = record_at(source, len, at, length, op::METADATA);
        let Some(m) = record.and_then(|body| parsed(at, &body)) else {
            return Ok(None);
        };
        kept.charge(length, m.record.metadata.len(), at)?;
        out.push(m);
        free_from = end;
    }
    Ok(Some(out))
}

/// The metadata record at `at` whose body is `body`, if it parses.
fn parsed(at: u64, body: &[u8]) -> Option<FoundMetadata> {
    let record = Metadata::parse_body(body).ok()?;
    let digest = Digest::of(body);
    Some(FoundMetadata { at, digest, record })
}

/// Walks the top-level records from the header to DataEnd (or the footer), reading metadata records into
/// `found` and skipping everything else; returns where it stopped if the file ends or a record is
/// impossible first.
fn scan(
    source: &mut (impl Read + Seek),
    len: u64,
    found: &mut Vec<FoundMetadata>,
    kept: &mut Kept,
) -> Result<Option<ScanEnd>, ReadError> {
    if source.seek(SeekFrom::Start(MAGIC_LEN)).is_err() {
        return Ok(None);
    }
    let mut r = io::BufReader::new(source);
    let mut at = MAGIC_LEN;
    loop {
        if at == len {
            return Ok(Some(ScanEnd::Cut { at, claimed: None }));
        }
        let Some((opcode, body_len)) = prefix(&mut r) else {
            return Ok(Some(if len - at < PREFIX_LEN {
                ScanEnd::Cut { at, claimed: None }
            } else {
                ScanEnd::Malformed { at }
            }));
        };
        let end = (at + PREFIX_LEN).saturating_add(body_len);
        if end > len {
            let claimed = Some(body_len);
            return Ok(Some(ScanEnd::Cut { at, claimed }));
        }
        match opcode {
            op::DATA_END | op::FOOTER => return Ok(None),
            // One too large to read: the stream refuses it where it stands.
            op::METADATA if body_len > MAX_RECORD_BYTES => return Ok(None),
            op::METADATA if found.len() < MAX_EARLY => {
                let mut body = vec![0; usize::try_from(body_len).unwrap_or(0)];
                let read = r.read_exact(&mut body);
                let Some(m) = read.ok().and_then(|()| parsed(at, &body)) else {
                    return Ok(Some(ScanEnd::Malformed { at }));
                };
                kept.charge(PREFIX_LEN + body_len, m.record.metadata.len(), at)?;
                found.push(m);
            }
            _ => {
                let Ok(skip) = i64::try_from(body_len) else {
                    return Ok(Some(ScanEnd::Malformed { at }));
                };
                if r.seek_relative(skip).is_err() {
                    return Ok(None);
                }
            }
        }
        at = end;
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::records::FOOTER_LEN;
    use mcap::records::{DataEnd, Footer, Header, MetadataIndex};
    use std::collections::BTreeMap;
    use std::io::Cursor as IoCursor;

    fn encoded<'a>(r: &impl Record<'a>) -> Vec<u8> {
        let mut out = Vec::new();
        r.encode_record(&mut out).unwrap();
        out
    }

    /// What [`find`] learns of the file `f`.
    fn look(f: &[u8]) -> Lookahead {
        find(&mut IoCursor::new(f), f.len() as u64, &mut Kept::default()).unwrap()
    }

    fn metadata() -> Vec<u8> {
        encoded(&Metadata {
            name: "coin-log".into(),
            metadata: BTreeMap::from([("k".into(), "v".into())]),
        })
    }

    fn index(offset: u64, length: u64) -> Vec<u8> {
        let name = "coin-log".into();
        encoded(&MetadataIndex {
            offset,
            length,
            name,
        })
    }

    fn footer(summary_start: u64) -> Vec<u8> {
        let mut f = encoded(&Footer {
            summary_start,
            ..Footer::default()
        });
        f.extend(MAGIC);
        f
    }

    /// Magic, header, a fake chunk of `chunk` bytes, a metadata record, DataEnd; with a summary holding a
    /// metadata index when `indexed`, then the footer and the end magic.
    fn file(chunk: usize, indexed: bool) -> (Vec<u8>, u64) {
        let mut f = MAGIC.to_vec();
        f.extend(encoded(&Header {
            profile: String::new(),
            library: "test".into(),
        }));
        f.push(op::CHUNK);
        f.extend((chunk as u64).to_le_bytes());
        f.extend(vec![0u8; chunk]);
        let at = f.len() as u64;
        let m = metadata();
        let m_len = m.len() as u64;
        f.extend(m);
        f.extend(encoded(&DataEnd::default()));
        let summary_start = f.len() as u64;
        if indexed {
            f.extend(index(at, m_len));
        }
        f.extend(footer(if indexed { summary_start } else { 0 }));
        (f, at)
    }

    #[test]
    fn a_late_metadata_record_is_found_through_the_index_and_by_the_scan() {
        for indexed in [true, false] {
            let (f, at) = file(5000, indexed);
            let p = look(&f);
            assert_eq!(p.indexed, indexed);
            assert!(p.ends_with_magic && p.magic_prefix && p.scan_end.is_none());
            assert_eq!(p.metadata.len(), 1, "indexed {indexed}");
            assert_eq!(p.metadata[0].at, at);
            assert_eq!(p.metadata[0].record.name, "coin-log");
            assert_eq!(p.metadata[0].record.metadata["k"], "v");
        }
    }

    #[test]
    fn a_cut_file_is_scanned_up_to_the_cut() {
        let (f, _) = file(5000, true);
        // Cut inside the chunk (after the magic and the 21-byte header record): its claimed length runs
        // past the end.
        let p = look(&f[..3000]);
        assert!(!p.ends_with_magic && p.metadata.is_empty());
        assert_eq!(
            p.scan_end,
            Some(ScanEnd::Cut {
                at: 8 + 21,
                claimed: Some(5000)
            })
        );
        // Cut inside a record prefix, and inside the magic.
        let p = look(&f[..12]);
        assert_eq!(
            p.scan_end,
            Some(ScanEnd::Cut {
                at: 8,
                claimed: None
            })
        );
        let p = look(&f[..5]);
        assert!(p.magic_prefix && p.scan_end.is_none());
    }

    #[test]
    fn index_entries_pointing_at_the_same_bytes_are_read_once() {
        let (mut f, at) = file(10, false);
        // Rebuild the summary with 1000 index entries for the same record, and a footer pointing at it.
        let tail = f.len() - 8 - FOOTER_LEN as usize;
        f.truncate(tail);
        let summary_start = f.len() as u64;
        let m_len = metadata().len() as u64;
        for _ in 0..1000 {
            f.extend(index(at, m_len));
        }
        f.extend(footer(summary_start));
        let p = look(&f);
        assert!(p.indexed);
        assert_eq!(p.metadata.len(), 1);
    }

    #[test]
    fn an_index_entry_pointing_elsewhere_sends_the_search_to_the_scan() {
        let (mut f, at) = file(64, true);
        // Point the index entry at the chunk instead of the metadata record.
        let tail = f.len() - 8 - FOOTER_LEN as usize;
        let entry = (tail - 9 - 8 - 8 - 4 - 8) + 9;
        f[entry..entry + 8].copy_from_slice(&29u64.to_le_bytes());
        let p = look(&f);
        assert!(!p.indexed);
        assert_eq!(p.metadata.len(), 1);
        assert_eq!(p.metadata[0].at, at);
    }
}
