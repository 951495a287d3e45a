//! A file's messages in log-time order, through the chunk indexes of its summary: for a reader that needs
//! the messages of several channels side by side when the writer put them far apart in the file (all of
//! one channel, then the next, as the Python writer does with channels registered at their first message,
//! and the `mcap` crate's `Writer::write` when given them so). The `mcap` crate's `IndexedReader` merges
//! the chunks; this module bounds what it holds at once.

use crate::budget::MAX_RECORD_BYTES;
use crate::reader::{corrupt, io_error, wire_error, ReadError, ReadErrorKind};
use crate::records::{Cursor, Record};
use crate::summary::summary_section;
use mcap::records::{op, ChunkIndex, MessageHeader};
use mcap::sans_io::indexed_reader::{
    IndexedReadEvent, IndexedReader, IndexedReaderOptions, ReadOrder,
};
use std::io::{Read, Seek, SeekFrom};

/// The decompressed chunks a log-time read holds at once, at most \[bytes\]: 2 × [`MAX_RECORD_BYTES`] =
/// 32 MiB. The rest of what it holds: the crate's index of their messages (24 bytes per message record of
/// at least 31 bytes, in a vector that may have doubled: under 50 MiB), the compressed chunk being read
/// (16 MiB) and the chunk indexes (8 MiB): 106 MiB, within [`READ_MEMORY_BOUND`](crate::READ_MEMORY_BOUND)
/// with its 40 MiB for the program and the caller, the streaming read's buffers being freed by then.
pub const ORDERED_CHUNK_BYTES: u64 = 2 * MAX_RECORD_BYTES;

/// Most chunk indexes a log-time read takes (about 0.5 KiB each with their message index offsets).
const MAX_CHUNKS: usize = 16_384;

/// Calls `on_message` with every message of the chunks of the MCAP file of `len` bytes in `source`, in
/// log-time order (the file's order among equal times). Returns how many: `None` when the file has no
/// summary listing its chunks (a summary is optional; messages outside chunks are not listed either, so
/// a caller compares the count with the file's). Fails if the summary or a chunk cannot be read or is
/// corrupt, and ([`ReadErrorKind::TooLarge`]) if the chunks that overlap in time would hold more than
/// [`ORDERED_CHUNK_BYTES`] at once.
pub fn read_in_log_time_order(
    mut source: impl Read + Seek,
    len: u64,
    on_message: &mut impl FnMut(&MessageHeader, &[u8]),
) -> Result<Option<u64>, ReadError> {
    let Some(chunk_indexes) = chunk_indexes(&mut source, len)? else {
        return Ok(None);
    };
    let held = held_at_once(&chunk_indexes);
    if held > ORDERED_CHUNK_BYTES {
        return Err(ReadError::new(
            ReadErrorKind::TooLarge,
            format!(
                "reading its messages in log-time order would hold {held} bytes of chunks at once \
                 (chunks that overlap in time), more than the {ORDERED_CHUNK_BYTES} bytes ({} MiB) \
                 allowed",
                ORDERED_CHUNK_BYTES >> 20
            ),
        ));
    }
    let summary = mcap::Summary {
        chunk_indexes,
        ..mcap::Summary::default()
    };
    let options = IndexedReaderOptions::new()
        .with_order(ReadOrder::LogTime)
        .with_record_length_limit(usize::try_from(MAX_RECORD_BYTES).unwrap_or(usize::MAX));
    let crate_error = |e: mcap::McapError| corrupt(format!("in log-time order: {e}"));
    let mut reader = IndexedReader::new_with_options(&summary, options).map_err(crate_error)?;
    let (mut buf, mut count) = (Vec::new(), 0);
    while let Some(event) = reader.next_event() {
        match event.map_err(crate_error)? {
            IndexedReadEvent::ReadChunkRequest { offset, length } => {
                source.seek(SeekFrom::Start(offset)).map_err(io_error)?;
                buf.resize(length, 0);
                source.read_exact(&mut buf).map_err(io_error)?;
                reader
                    .insert_chunk_record_data(offset, &buf)
                    .map_err(crate_error)?;
            }
            IndexedReadEvent::Message { header, data } => {
                on_message(&header, data);
                count += 1;
            }
        }
    }
    Ok(Some(count))
}

/// The summary's chunk indexes; `None` without a summary or when it lists no chunk.
fn chunk_indexes(
    source: &mut (impl Read + Seek),
    len: u64,
) -> Result<Option<Vec<ChunkIndex>>, ReadError> {
    let Some((start, bytes)) = summary_section(source, len, true)? else {
        return Ok(None);
    };
    let mut c = Cursor::new(&bytes);
    let mut found = Vec::new();
    while !c.rest().is_empty() {
        let at = start + (bytes.len() - c.rest().len()) as u64;
        let err = |e| wire_error("summary", at, &e);
        let (opcode, body) = c.record().map_err(err)?;
        if opcode == op::CHUNK_INDEX {
            if found.len() == MAX_CHUNKS {
                return Err(ReadError::new(
                    ReadErrorKind::TooLarge,
                    format!(
                        "its summary lists more than {MAX_CHUNKS} chunks to read in log-time order"
                    ),
                ));
            }
            found.push(ChunkIndex::parse_body(body).map_err(err)?);
        }
    }
    Ok((!found.is_empty()).then_some(found))
}

/// The most bytes of decompressed chunks the crate's reader holds at once: it takes a chunk in when the
/// messages reach its first time and gives its slot back after its last message, and a slot keeps the
/// largest chunk it held, so at most (the most chunks whose time ranges share an instant) × (the largest
/// chunk).
fn held_at_once(indexes: &[ChunkIndex]) -> u64 {
    // (time, 0 = a chunk begins | 1 = one ends): at equal times the beginnings count first.
    let mut edges: Vec<(u64, u8)> = indexes
        .iter()
        .flat_map(|i| [(i.message_start_time, 0), (i.message_end_time, 1)])
        .collect();
    edges.sort_unstable();
    let (mut open, mut most) = (0u64, 0u64);
    for (_, end) in edges {
        if end == 0 {
            open += 1;
            most = most.max(open);
        } else {
            open = open.saturating_sub(1);
        }
    }
    let largest = indexes.iter().map(|i| i.uncompressed_size).max();
    most.saturating_mul(largest.unwrap_or(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunk(start: u64, end: u64, size: u64) -> ChunkIndex {
        ChunkIndex {
            message_start_time: start,
            message_end_time: end,
            chunk_start_offset: 0,
            chunk_length: 0,
            message_index_offsets: std::collections::BTreeMap::new(),
            message_index_length: 0,
            compression: String::new(),
            compressed_size: size,
            uncompressed_size: size,
        }
    }

    /// The most chunks sharing an instant times the largest chunk: chunks that only touch at one time
    /// share it; disjoint ones do not add up.
    #[test]
    fn held_at_once_counts_the_chunks_that_overlap_in_time() {
        assert_eq!(held_at_once(&[]), 0);
        let apart = [chunk(0, 10, 1), chunk(11, 20, 4), chunk(21, 30, 2)];
        assert_eq!(held_at_once(&apart), 4);
        let grouped = [chunk(0, 10, 1), chunk(5, 15, 4), chunk(20, 30, 2)];
        assert_eq!(held_at_once(&grouped), 8);
        let touching = [chunk(0, 10, 3), chunk(10, 20, 3), chunk(20, 20, 1)];
        assert_eq!(held_at_once(&touching), 6);
    }
}
