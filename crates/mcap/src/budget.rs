//! The reader's memory budget: reading a file takes at most [`READ_MEMORY_BOUND`] bytes, whatever the file
//! says or holds. What would take more is refused as [`ReadErrorKind::TooLarge`], with the figure.
//!
//! One constant sets it, [`MAX_RECORD_BYTES`], the largest record the reader accepts (any record; a chunk
//! counts twice: its stored records and what they decompress to). The bound follows from the pipeline
//! (the `prefetch` module), with `MAX` for `MAX_RECORD_BYTES`:
//! - the top-level reader's buffer holds one record and a read block, and may double as it grows to a
//!   record's size: 2 × (`MAX` + 256 KiB);
//! - of the six batches between the two threads, one at a time may hold a record or a decompressed chunk
//!   larger than a batch (the producer waits for every other batch to come back before it fills one),
//!   `MAX` + 3 MiB; the other five hold under 2 MiB of records and 1 MiB of events each, 4.5 MiB with
//!   their vectors' growth;
//! - the schemas, channels and metadata the reader keeps and hands to the visitor: `MAX`, each counted at
//!   its size plus [`MAP_ENTRY_COST`] per map entry ([`Kept`]);
//! - the record being parsed: its owned fields (at most its size, `MAX`), and at most
//!   [`MAX_MAP_ENTRIES`](crate::records::MAX_MAP_ENTRIES) entries per map (6.5 MiB);
//! - the rest: the program (6 MiB), the threads, the zstd and lz4 contexts, the tables keyed by channel
//!   or schema id (at most 65536 entries each) and the visitor's state per channel, within 40 MiB.
//!
//! That is 5 × `MAX` + 72.5 MiB; the bound states 5 × `MAX` + 80 MiB. Measured (tests/it/read_budget.rs):
//! verify, info, export and plot peak at 6 to 38 MiB on the crafted files of issue 25 and at 34 MiB on a
//! file of chunks at the limit.
//!
//! Decompression never trusts a chunk's declared size: it stops one byte past it, and a chunk that
//! decompresses to more or fewer bytes than it declares is corrupt.

use crate::reader::{ReadError, ReadErrorKind};

/// The largest record the reader accepts \[bytes\]: 16 MiB, 16 times the chunks coin-log, the Python and
/// TypeScript writers and the `mcap` crate write by default (1 MiB), so that re-chunked files and
/// messages of a few MiB read, while a crafted length costs at most this much.
pub const MAX_RECORD_BYTES: u64 = 16 << 20;

/// The reader's peak memory, at most \[bytes\]: 5 × [`MAX_RECORD_BYTES`] + 80 MiB = 160 MiB. The
/// top-level reader's buffer (twice the limit, as it grows), one batch holding a record at the limit,
/// the schemas, channels and metadata kept (the limit), the record being parsed (the limit), and a
/// fixed part: the other batches, the program, the threads, the tables keyed by id.
pub const READ_MEMORY_BOUND: u64 = 5 * MAX_RECORD_BYTES + (80 << 20);

/// What a map entry of a kept record counts beyond its strings \[bytes\]: a `BTreeMap<String, String>`
/// entry is two 24-byte `String`s in a node, with the node's share and the allocations' rounding.
pub(crate) const MAP_ENTRY_COST: u64 = 128;

/// [`MAX_RECORD_BYTES`] as it is shown in messages.
pub(crate) fn limit() -> String {
    format!("{MAX_RECORD_BYTES} bytes ({} MiB)", MAX_RECORD_BYTES >> 20)
}

/// The schemas, channels and metadata the reader keeps, counted against [`MAX_RECORD_BYTES`].
#[derive(Debug, Default, Clone)]
pub(crate) struct Kept {
    bytes: u64,
}

impl Kept {
    /// Counts a record of `len` bytes with `entries` map entries, kept or handed over at byte `at`.
    ///
    /// # Errors
    /// [`ReadErrorKind::TooLarge`] once the total exceeds [`MAX_RECORD_BYTES`].
    pub(crate) fn charge(&mut self, len: u64, entries: usize, at: u64) -> Result<(), ReadError> {
        self.bytes = self
            .bytes
            .saturating_add(len)
            .saturating_add(MAP_ENTRY_COST.saturating_mul(entries as u64));
        if self.bytes > MAX_RECORD_BYTES {
            return Err(ReadError::new(
                ReadErrorKind::TooLarge,
                format!(
                    "the schemas, channels and metadata read up to byte {at} take more than the {} \
                     this reader keeps of them",
                    limit()
                ),
            ));
        }
        Ok(())
    }
}
