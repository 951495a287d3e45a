//! SHA-256 of the run files (the catalogue's `sha256`) and of the sweep's description (its identity).

use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::Path;

/// Read buffer of [`sha256_file`].
const BUFFER: usize = 1 << 16;

/// SHA-256 of `bytes`, as 64 lowercase hex digits.
#[must_use]
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// SHA-256 of the file at `path` and its length, read once in bounded memory.
///
/// # Errors
/// The file cannot be read, or is not a regular file.
pub fn sha256_file(path: &Path) -> std::io::Result<(String, u64)> {
    let mut file = crate::files::open_regular(path)?;
    let mut hasher = Sha256::new();
    let mut buffer = vec![0; BUFFER];
    let mut len = 0;
    loop {
        let n = file.read(&mut buffer)?;
        if n == 0 {
            return Ok((hex(&hasher.finalize()), len));
        }
        hasher.update(&buffer[..n]);
        len += n as u64;
    }
}

fn hex(bytes: &[u8]) -> String {
    use std::fmt::Write;
    bytes.iter().fold(String::with_capacity(64), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hash_of_abc_is_the_fips_example() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
