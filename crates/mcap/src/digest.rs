//! An order-sensitive 64-bit digest, for the reader's checks that compare what a file says (indexes,
//! repeated definitions) with what it holds, in constant memory.

/// Order-sensitive 64-bit digest of a sequence of integers or of a byte string (not cryptographic: it
/// guards against mistakes and corruption, which CRCs also catch, not against an adversary).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Digest(pub(crate) u64);

impl Default for Digest {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Digest {
    /// The digest of `bytes` and their length.
    pub(crate) fn of(bytes: &[u8]) -> Self {
        let mut d = Self::default();
        d.push(bytes.len() as u64);
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            d.push(u64::from_le_bytes(w));
        }
        d
    }

    /// Folds in `v`.
    pub(crate) fn push(&mut self, v: u64) {
        self.0 = (self.0 ^ v).wrapping_mul(0x0100_0000_01b3);
        self.0 ^= self.0 >> 29;
    }
}
