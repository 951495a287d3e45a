//! The reading half of the reader's pipeline: a worker thread runs the `mcap` crate's sans-io
//! `LinearReader` (records, magic, data and summary CRCs, the end), decompresses each chunk whole and
//! checks its size and CRC, and hands the records over in batches through a bounded channel.
//! Consumer and worker split a read's CPU time 74/26 (verify) and 22/78 (info) (perf samples per thread,
//! 2.1 M-message wobble file): with a second core free, the overlap takes the smaller share off the clock.
//!
//! A batch holds record bodies and decompressed chunks back to back, and [`Event`]s pointing into them in
//! file order; errors travel as events in their place. At most [`POOL`] batches exist (see `budget`); one
//! larger than [`BATCH_BYTES`] is filled only when every other batch is back, and shrunk when it returns.
//! When the consumer stops it drops its receiver, and the worker ends at its next send.

use crate::budget::MAX_RECORD_BYTES;
use crate::records::{ChunkRecord, Record, WireError};
use mcap::records::{op, ChunkHeader};
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use std::io::{self, Read};
use std::ops::Range;
use std::sync::mpsc::{Receiver, SyncSender};

/// Bytes asked of the file per read.
const READ_BLOCK: usize = 1 << 18;
/// A batch is handed over once its bytes and events reach this (about one decompressed chunk).
const BATCH_BYTES: usize = 1 << 20;
/// What an event counts towards [`BATCH_BYTES`], so that a flood of empty records fills batches too.
const EVENT_COST: usize = std::mem::size_of::<Event>();
/// Batches in the channel between the threads: enough to keep both busy.
pub(crate) const QUEUE: usize = 4;
/// Batches in existence: the queue's, the one being filled and the one being walked.
pub(crate) const POOL: usize = QUEUE + 2;

/// One step of the read, in file order.
#[derive(Debug)]
pub(crate) enum Event {
    /// A top-level record other than a chunk; `body` is in [`Batch::bytes`].
    Record { opcode: u8, body: Range<usize> },
    /// A chunk (`len`: its record's body length), its records decompressed into [`Batch::bytes`] and
    /// their size and CRC checked.
    Chunk {
        len: u64,
        header: ChunkHeader,
        records: Range<usize>,
    },
    /// A chunk that cannot be read (`header`: when it could be parsed); nothing follows.
    BadChunk {
        len: u64,
        header: Option<ChunkHeader>,
        error: ChunkError,
    },
    /// The top-level reader failed (bad magic, truncation, data or summary CRC, lengths); nothing
    /// follows.
    OuterError(McapError),
    /// The file could not be read: the message for the user; nothing follows.
    Io(String),
}

/// Why a chunk's records cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub(crate) enum ChunkError {
    /// Its header runs past the record.
    #[error(transparent)]
    Malformed(WireError),
    /// It declares more than [`MAX_RECORD_BYTES`] of records.
    #[error("it declares {0} bytes of records")]
    TooLarge(u64),
    /// The text is [`McapError::UnsupportedCompression`]'s.
    #[error("Unsupported compression format `{0}`")]
    Unsupported(String),
    #[error("its records cannot be decompressed: {0}")]
    Decompress(String),
    #[error("its records decompress to {got} bytes, its header claims {declared}")]
    Short { got: u64, declared: u64 },
    #[error("its records decompress to more than the {declared} bytes its header claims")]
    Long { declared: u64 },
    #[error("CRC {calculated:#010x} of its records does not match the stored {saved:#010x}")]
    Crc { saved: u32, calculated: u32 },
}

/// Record bodies and decompressed chunks back to back, and the events that point into them, in order.
#[derive(Debug, Default)]
pub(crate) struct Batch {
    pub(crate) bytes: Vec<u8>,
    pub(crate) events: Vec<Event>,
}

impl Batch {
    fn push(&mut self, data: &[u8]) -> Range<usize> {
        let start = self.bytes.len();
        self.bytes.extend_from_slice(data);
        start..self.bytes.len()
    }

    fn full(&self) -> bool {
        self.bytes.len() + self.events.len() * EVENT_COST >= BATCH_BYTES
    }
}

/// The worker's batches: the one being filled, the spent ones back from the consumer, and the two
/// channel ends.
struct Batches {
    to_consumer: SyncSender<Batch>,
    recycled: Receiver<Batch>,
    current: Batch,
    spare: Vec<Batch>,
    /// Batches made so far (at most [`POOL`]).
    made: usize,
}

impl Batches {
    /// A batch to fill: a spare one, a new one while fewer than [`POOL`] exist, or the next to come
    /// back; `None` when the consumer has gone.
    fn fresh(&mut self) -> Option<Batch> {
        while let Ok(b) = self.recycled.try_recv() {
            self.spare.push(b);
        }
        let mut b = match self.spare.pop() {
            Some(b) => b,
            None if self.made < POOL => {
                self.made += 1;
                Batch::default()
            }
            None => self.recycled.recv().ok()?,
        };
        b.bytes.clear();
        b.events.clear();
        // A batch that held a large record gives its memory back.
        if b.bytes.capacity() > 2 * BATCH_BYTES {
            b.bytes.shrink_to(BATCH_BYTES + BATCH_BYTES / 4);
        }
        Some(b)
    }

    /// Sends the current batch and starts another; `None` when the consumer has gone.
    fn hand_over(&mut self) -> Option<()> {
        let next = self.fresh()?;
        let full = std::mem::replace(&mut self.current, next);
        self.to_consumer.send(full).ok()
    }

    /// Makes room for `size` more bytes: hands the batch over when full, and before something larger
    /// than a batch, waits until every other batch is back, so that one such exists at a time.
    fn room_for(&mut self, size: u64) -> Option<()> {
        if self.current.full() {
            self.hand_over()?;
        }
        if size > BATCH_BYTES as u64 {
            if !self.current.events.is_empty() {
                self.hand_over()?;
            }
            while self.spare.len() + 1 < self.made {
                self.spare.push(self.recycled.recv().ok()?);
            }
        }
        Some(())
    }
}

/// Reads an MCAP stream of `file_len` bytes from `source` and sends its records to the consumer, ending
/// after the last record, the first error, or when the consumer hangs up.
pub(crate) fn produce(
    mut source: impl Read,
    file_len: u64,
    to_consumer: SyncSender<Batch>,
    recycled: Receiver<Batch>,
) {
    let limit = usize::try_from(file_len.min(MAX_RECORD_BYTES)).unwrap_or(usize::MAX);
    let mut outer = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_emit_chunks(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(limit),
    );
    let mut batches = Batches {
        to_consumer,
        recycled,
        current: Batch::default(),
        spare: Vec::new(),
        made: 1,
    };
    let mut decompressor = Decompressor::default();
    let mut read_so_far: u64 = 0;
    while let Some(event) = outer.next_event() {
        match event {
            Ok(LinearReadEvent::ReadRequest(need)) => {
                let buf = outer.insert(need.max(READ_BLOCK));
                match source.read(buf) {
                    Ok(n) => {
                        read_so_far += n as u64;
                        outer.notify_read(n);
                    }
                    Err(e) => {
                        let detail = format!("read error at byte {read_so_far}: {e}");
                        batches.current.events.push(Event::Io(detail));
                        break;
                    }
                }
            }
            Ok(LinearReadEvent::Record { opcode, data }) => {
                let event = if opcode == op::CHUNK {
                    chunk(data, &mut batches, &mut decompressor)
                } else {
                    batches.room_for(data.len() as u64).map(|()| Event::Record {
                        opcode,
                        body: batches.current.push(data),
                    })
                };
                let Some(event) = event else {
                    return;
                };
                let stop = matches!(event, Event::BadChunk { .. });
                batches.current.events.push(event);
                if stop {
                    break;
                }
            }
            Err(e) => {
                batches.current.events.push(Event::OuterError(e));
                break;
            }
        }
    }
    let _ = batches.to_consumer.send(batches.current);
}

/// Decompresses the chunk record `data` into the current batch (making room first); `None` when the
/// consumer has gone.
fn chunk(data: &[u8], batches: &mut Batches, decompressor: &mut Decompressor) -> Option<Event> {
    let len = data.len() as u64;
    let bad = |header, error| Some(Event::BadChunk { len, header, error });
    let chunk = match ChunkRecord::parse_body(data) {
        Ok(chunk) => chunk,
        Err(e) => return bad(None, ChunkError::Malformed(e)),
    };
    let declared = chunk.header.uncompressed_size;
    if declared > MAX_RECORD_BYTES {
        return bad(Some(chunk.header), ChunkError::TooLarge(declared));
    }
    batches.room_for(declared)?;
    let bytes = &mut batches.current.bytes;
    let start = bytes.len();
    match decompressor.run(&chunk, bytes) {
        Ok(()) => Some(Event::Chunk {
            len,
            header: chunk.header,
            records: start..bytes.len(),
        }),
        Err(error) => {
            bytes.truncate(start);
            bad(Some(chunk.header), error)
        }
    }
}

/// The chunk decompressors, kept from chunk to chunk.
#[derive(Default)]
struct Decompressor {
    zstd: Option<zstd::bulk::Decompressor<'static>>,
}

impl Decompressor {
    /// Appends the chunk's records to `out`, decompressed with a limit of one byte past the declared
    /// size, and checks their size and CRC.
    fn run(&mut self, chunk: &ChunkRecord<'_>, out: &mut Vec<u8>) -> Result<(), ChunkError> {
        let h = &chunk.header;
        let stored = chunk.records;
        let declared = h.uncompressed_size;
        let start = out.len();
        // At most MAX_RECORD_BYTES + 1: checked by the caller.
        let room = usize::try_from(declared)
            .unwrap_or(usize::MAX)
            .saturating_add(1);
        out.reserve_exact(room);
        let decompress = |e: io::Error| ChunkError::Decompress(e.to_string());
        match h.compression.as_str() {
            "" => out.extend_from_slice(&stored[..stored.len().min(room)]),
            "zstd" => {
                let zstd = match &mut self.zstd {
                    Some(z) => z,
                    None => self
                        .zstd
                        .insert(zstd::bulk::Decompressor::new().map_err(decompress)?),
                };
                let mut at = io::Cursor::new(&mut *out);
                at.set_position(start as u64);
                if let Err(e) = zstd.decompress_to_buffer(stored, &mut at) {
                    let too_small = e
                        .get_ref()
                        .and_then(|e| e.downcast_ref::<zstd::Error>())
                        .is_some_and(|e| {
                            e.is(zstd::zstd_safe::zstd_sys::ZSTD_ErrorCode::ZSTD_error_dstSize_tooSmall)
                        });
                    return Err(if too_small {
                        ChunkError::Long { declared }
                    } else {
                        decompress(e)
                    });
                }
            }
            "lz4" => {
                let decoder = lz4::Decoder::new(stored).map_err(decompress)?;
                decoder
                    .take(room as u64)
                    .read_to_end(out)
                    .map_err(decompress)?;
            }
            other => return Err(ChunkError::Unsupported(other.to_string())),
        }
        let got = (out.len() - start) as u64;
        if got < declared {
            return Err(ChunkError::Short { got, declared });
        }
        if got > declared {
            return Err(ChunkError::Long { declared });
        }
        let calculated = crc32fast::hash(&out[start..]);
        if h.uncompressed_crc != 0 && calculated != h.uncompressed_crc {
            return Err(ChunkError::Crc {
                saved: h.uncompressed_crc,
                calculated,
            });
        }
        Ok(())
    }
}
