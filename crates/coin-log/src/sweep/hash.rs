//! SHA-256 of the run files (the catalogue's `sha256`) and of the sweep's description (its identity).

use sha2::{Digest, Sha256};
use std::path::Path;

/// SHA-256 of `bytes`, as 64 lowercase hex digits.
#[must_use]
pub fn sha256_hex(bytes: &[u8]) -> String {
    format!("{:x}", Sha256::digest(bytes))
}

/// SHA-256 of the file at `path` and its length, read once in bounded memory.
pub(crate) fn sha256_file(path: &Path) -> std::io::Result<(String, u64)> {
    let mut hasher = Sha256::new();
    let len = std::io::copy(&mut crate::files::open_regular(path)?, &mut hasher)?;
    Ok((format!("{:x}", hasher.finalize()), len))
}
