//! The helpers of the integration tests: [`vectors`] and [`physics`] for the model tests, [`newton_euler`]
//! (a second, independent model), [`writers`] (MCAP files written straight from the model, and rewritten
//! with a defect), [`record`] (reading files back, running the binary), [`process`] (child processes
//! under a deadline), `other_writers` (recordings rewritten by the Python and TypeScript MCAP writers;
//! feature `external-readers`), [`crafted`] (files crafted to cost a reader memory) and [`rss`] (a
//! child's peak memory); here the repository's paths and an output that fails like a full disk.

pub mod crafted;
pub mod newton_euler;
#[cfg(feature = "external-readers")]
pub mod other_writers;
pub mod physics;
pub mod process;
pub mod record;
#[cfg(target_os = "linux")]
pub mod rss;
pub mod vectors;
pub mod writers;

use std::io::{Cursor, Seek, SeekFrom, Write};
use std::path::PathBuf;

/// `program` run as a user other than root where the tests run as root (`setpriv` to nobody, 65534), so
/// that permissions and limits on processes bind as they do for users; as a user, as that user.
pub fn unprivileged(program: &std::path::Path) -> std::process::Command {
    let root = std::process::Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout == b"0\n");
    if !root {
        return std::process::Command::new(program);
    }
    let mut command = std::process::Command::new("setpriv");
    command
        .args(["--reuid=65534", "--regid=65534", "--clear-groups"])
        .arg(program);
    command
}

/// Makes a named pipe at `path` (the tests put pipes where a file is read or written, to show it is
/// refused without blocking).
pub fn mkfifo(path: &std::path::Path) {
    let status = std::process::Command::new("mkfifo").arg(path).status();
    assert!(
        status.is_ok_and(|s| s.success()),
        "mkfifo {}",
        path.display()
    );
}

/// Files given an attribute by `chattr` (`+i` immutable, `+a` append-only), cleared again when dropped,
/// however the test ends (an immutable file cannot be deleted with its temporary folder).
#[derive(Default)]
pub struct Attributes(Vec<PathBuf>);

impl Attributes {
    /// `chattr flag path`; false where the system refuses it (not root, a file system without
    /// attributes).
    pub fn set(&mut self, flag: &str, path: &std::path::Path) -> bool {
        let set = std::process::Command::new("chattr")
            .arg(flag)
            .arg(path)
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if set {
            self.0.push(path.to_path_buf());
        }
        set
    }
}

impl Drop for Attributes {
    fn drop(&mut self) {
        for path in &self.0 {
            let _ = std::process::Command::new("chattr")
                .args(["-i", "-a"])
                .arg(path)
                .status();
        }
    }
}

/// The repository root (cargo also runs the tests there).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The committed recordings, `datasets/*.mcap`, sorted.
pub fn dataset_files() -> Vec<PathBuf> {
    let dir = repo().join("datasets");
    let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut files: Vec<PathBuf> = entries
        .map(|e| {
            e.unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
                .path()
        })
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .collect();
    files.sort();
    files
}

/// An output that refuses any write past `limit` bytes, like a full disk (seekable, for writers that go
/// back to patch what they wrote).
pub struct FailingWriter {
    inner: Cursor<Vec<u8>>,
    limit: u64,
}

impl FailingWriter {
    /// An empty output with room for `limit` bytes.
    pub fn new(limit: u64) -> Self {
        Self {
            inner: Cursor::new(Vec::new()),
            limit,
        }
    }

    /// The bytes written.
    pub fn into_bytes(self) -> Vec<u8> {
        self.inner.into_inner()
    }
}

impl Write for FailingWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.inner.position() + buf.len() as u64 > self.limit {
            return Err(std::io::Error::new(
                std::io::ErrorKind::StorageFull,
                "no space left on device (test)",
            ));
        }
        self.inner.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for FailingWriter {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.inner.seek(pos)
    }
}

/// A resolved scene's `[run]` holds the settings its integrator uses and none it ignores: rtol and atol
/// for an adaptive method, the step for a fixed-step one (docs/format.md: Metadata records).
pub fn assert_uses_its_settings(name: &str, text: &str) {
    let adaptive =
        text.contains("integrator = \"dop853\"") || text.contains("integrator = \"dopri5\"");
    for (key, used) in [
        ("rtol =", adaptive),
        ("atol =", adaptive),
        ("step =", !adaptive),
    ] {
        assert_eq!(
            text.contains(key),
            used,
            "{name}: `{key}` present iff used in\n{text}"
        );
    }
}
