//! The reading half of the reader's pipeline: a worker thread reads the file, checks the data and
//! summary CRCs, decompresses each chunk and checks its CRC, and hands the records over in batches through
//! a bounded channel, while the calling thread walks the records and runs the visitor.
//!
//! A batch holds copies of whole records back to back and a list of [`Event`]s pointing into them, in file
//! order; errors travel as events in their place, so the consumer sees exactly the sequence a
//! single-threaded reader would. Memory stays bounded: at most [`QUEUE`] + 2 batches exist, each about
//! [`BATCH_BYTES`] plus one record, and spent batches are sent back to be refilled rather than reallocated.
//! When the consumer stops (an error, or its visitor breaks) it drops its receiver and the worker ends at
//! its next send.

use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use std::io::Read;
use std::ops::Range;
use std::sync::mpsc::{Receiver, SyncSender};

use mcap::records::op;

/// Bytes asked of the file per read (larger reads than the reader's minimum requests).
const READ_BLOCK: usize = 1 << 18;
/// Smallest record-length limit inside chunks (a chunk's records may decompress beyond the file's size).
const MIN_CHUNK_RECORD_LIMIT: usize = 1 << 24;
/// A batch is handed over once it holds this many bytes (about one decompressed chunk).
pub(crate) const BATCH_BYTES: usize = 1 << 20;
/// Batches in flight between the threads: enough to keep both busy, few enough to bound memory.
pub(crate) const QUEUE: usize = 4;

/// One step of the read, in file order.
#[derive(Debug)]
pub(crate) enum Event {
    /// A top-level record (chunks included, whole and compressed) and its bytes in the batch.
    Outer {
        /// Record opcode.
        opcode: u8,
        /// Its body in [`Batch::bytes`].
        body: Range<usize>,
    },
    /// A record inside the current chunk, decompressed.
    Inner {
        /// Record opcode.
        opcode: u8,
        /// Its body in [`Batch::bytes`].
        body: Range<usize>,
    },
    /// The current chunk's records are all read (its CRC, if any, matched).
    ChunkEnd,
    /// The top-level reader failed (bad magic, truncation, data or summary CRC, lengths).
    OuterError(McapError),
    /// Reading inside the current chunk failed (decompression, chunk CRC, a malformed record).
    InnerError(McapError),
    /// The file could not be read; the message for the user.
    Io(String),
}

/// Records and the events that point into them.
#[derive(Debug, Default)]
pub(crate) struct Batch {
    /// Record bodies back to back.
    pub(crate) bytes: Vec<u8>,
    /// What happened, in order.
    pub(crate) events: Vec<Event>,
}

impl Batch {
    fn push(&mut self, data: &[u8]) -> Range<usize> {
        let start = self.bytes.len();
        self.bytes.extend_from_slice(data);
        start..self.bytes.len()
    }

    fn full(&self) -> bool {
        self.bytes.len() >= BATCH_BYTES
    }
}

/// The worker's end: where batches go and where spent ones come back.
pub(crate) struct Producer {
    /// Filled batches, to the consumer.
    pub(crate) to_consumer: SyncSender<Batch>,
    /// Spent batches, from the consumer.
    pub(crate) recycled: Receiver<Batch>,
}

impl Producer {
    fn fresh(&self) -> Batch {
        match self.recycled.try_recv() {
            Ok(mut b) => {
                b.bytes.clear();
                b.events.clear();
                b
            }
            Err(_) => Batch {
                bytes: Vec::with_capacity(BATCH_BYTES + (BATCH_BYTES >> 2)),
                events: Vec::new(),
            },
        }
    }

    /// Sends `batch` and returns an empty one; `None` when the consumer has gone.
    fn hand_over(&self, batch: Batch) -> Option<Batch> {
        self.to_consumer.send(batch).ok()?;
        Some(self.fresh())
    }
}

/// Reads an MCAP stream of `file_len` bytes from `source` and sends its records to the consumer, ending
/// after the last record, the first error, or when the consumer hangs up.
pub(crate) fn produce(mut source: impl Read, file_len: u64, producer: &Producer) {
    let limit = usize::try_from(file_len).unwrap_or(usize::MAX);
    let mut outer = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_emit_chunks(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(limit),
    );
    let mut inner = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_validate_chunk_crcs(true)
            .with_record_length_limit(limit.max(MIN_CHUNK_RECORD_LIMIT)),
    );
    let mut batch = producer.fresh();
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
                        batch
                            .events
                            .push(Event::Io(format!("read error at byte {read_so_far}: {e}")));
                        break;
                    }
                }
            }
            Ok(LinearReadEvent::Record { opcode, data }) => {
                let body = batch.push(data);
                batch.events.push(Event::Outer { opcode, body });
                if opcode == op::CHUNK {
                    feed_chunk(&mut inner, opcode, data);
                    match chunk_records(&mut inner, batch, producer) {
                        Some((b, true)) => batch = b,
                        Some((b, false)) => {
                            batch = b;
                            break;
                        }
                        None => return,
                    }
                }
                if batch.full() {
                    match producer.hand_over(batch) {
                        Some(b) => batch = b,
                        None => return,
                    }
                }
            }
            Err(e) => {
                batch.events.push(Event::OuterError(e));
                break;
            }
        }
    }
    let _ = producer.to_consumer.send(batch);
}

/// Gives the chunk record to the inner reader, which decompresses it as a stream.
fn feed_chunk(inner: &mut LinearReader, opcode: u8, data: &[u8]) {
    let total = 9 + data.len();
    let buf = inner.insert(total);
    buf[0] = opcode;
    buf[1..9].copy_from_slice(&(data.len() as u64).to_le_bytes());
    buf[9..].copy_from_slice(data);
    inner.notify_read(total);
}

/// Copies the chunk's records into batches. Returns the batch being filled and whether reading goes on
/// (false after an error), or `None` when the consumer has gone.
fn chunk_records(
    inner: &mut LinearReader,
    mut batch: Batch,
    producer: &Producer,
) -> Option<(Batch, bool)> {
    while let Some(event) = inner.next_event() {
        match event {
            // The chunk is used up: the reader wants the next one.
            Ok(LinearReadEvent::ReadRequest(_)) => break,
            Ok(LinearReadEvent::Record { opcode, data }) => {
                let body = batch.push(data);
                batch.events.push(Event::Inner { opcode, body });
                if batch.full() {
                    batch = producer.hand_over(batch)?;
                }
            }
            Err(e) => {
                batch.events.push(Event::InnerError(e));
                return Some((batch, false));
            }
        }
    }
    batch.events.push(Event::ChunkEnd);
    Some((batch, true))
}
