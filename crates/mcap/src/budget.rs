//! The reader's memory budget, [`READ_MEMORY_BOUND`]: what would take more is refused as
//! [`ReadErrorKind::TooLarge`], with the figure.

use crate::reader::{ReadError, ReadErrorKind};

/// The largest record the reader accepts \[bytes\]: 16 MiB, 16 times the chunks coin-log, the Python and
/// TypeScript writers and the `mcap` crate write by default (1 MiB), so that re-chunked files and
/// messages of a few MiB read, while a crafted length costs at most this much.
pub const MAX_RECORD_BYTES: u64 = 16 << 20;

/// The reader's peak memory, at most \[bytes\], whatever the file says or holds: 5 × `MAX` + 80 MiB =
/// 160 MiB, with `MAX` for [`MAX_RECORD_BYTES`] (a chunk counts twice: stored and decompressed). Parts:
/// - the top-level reader's buffer, one record and a read block, doubling as it grows: 2 × (`MAX` +
///   256 KiB);
/// - of the six batches between the reader's two threads, the one at a time that may hold a record or
///   decompressed chunk larger than a batch: `MAX` + 3 MiB; the other five, 4.5 MiB each;
/// - the schemas, channels and metadata kept and handed to the visitor: `MAX`, each counted at its size
///   plus `MAP_ENTRY_COST` per map entry;
/// - the record being parsed: `MAX`, and at most `MAX_MAP_ENTRIES` entries per map (6.5 MiB);
/// - the program (6 MiB), threads, zstd and lz4 contexts, tables keyed by channel or schema id (65536
///   entries at most) and the visitor's state per channel: within 40 MiB.
///
/// That is 5 × `MAX` + 72.5 MiB. Measured (tests/it/read_budget.rs): verify, info, export and plot peak
/// at 6 to 38 MiB on the crafted files of issue 25 and at 34 MiB on a file of chunks at the limit.
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
    /// Counts a record of `len` bytes with `entries` map entries, kept or handed over at byte `at`;
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
                     this reader keeps of them (a schema counts once more with each channel that uses \
                     it)",
                    limit()
                ),
            ));
        }
        Ok(())
    }
}
