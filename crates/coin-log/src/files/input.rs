//! What a path given as an input may be (format.md: Commands, Inputs and outputs): a regular file, looked at
//! before it is opened, so that nothing blocks or reads without end. An MCAP file is read by seeking, so it
//! cannot be a stream.

use super::output::kind_of;
use std::fs::{self, File, Metadata};
use std::io::{self, Read};
use std::path::Path;

/// The largest scene or sweep file read \[bytes\]: scenes are a few kB of TOML (the built-ins are under
/// 2 kB), so 1 MiB leaves room for any hand-written scene, or a sweep axis of ~10⁵ listed values, while
/// bounding what a wrong path can make the tool read.
pub const SCENE_MAX_BYTES: u64 = 1 << 20;

/// The first bytes of every MCAP file.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// What an input is read as, for the rules and the words of a refusal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// A TOML scene file, read whole.
    Scene,
    /// A TOML sweep file, read whole.
    Sweep,
    /// An MCAP file, read by seeking.
    Mcap,
}

/// Why an input path is refused. The message does not name the path: the caller puts it first.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(String);

fn what(kind: InputKind) -> &'static str {
    match kind {
        InputKind::Scene => "a scene file",
        InputKind::Sweep => "a sweep file",
        InputKind::Mcap => "an MCAP file",
    }
}

/// The names of standard input as a file.
const STDIN_PATHS: [&str; 3] = ["/dev/stdin", "/dev/fd/0", "/proc/self/fd/0"];

/// Checks that `path` names a regular file (following links), without opening it; returns its metadata.
/// Refuses `-`, a path that cannot be looked at, a folder, a pipe, a device or a socket.
pub fn check(path: &Path, kind: InputKind) -> Result<Metadata, InputError> {
    if path.as_os_str() == "-" {
        return Err(InputError(
            "reading standard input is not offered (`-`): save the input to a file and give its path (a \
             file named `-` is `./-`)"
                .into(),
        ));
    }
    let stdin = STDIN_PATHS.iter().any(|s| path == Path::new(s));
    if kind == InputKind::Mcap {
        return coin_log_mcap::regular_file(path, stdin).map_err(|e| InputError(e.detail));
    }
    let meta = fs::metadata(path).map_err(|source| InputError(source.to_string()))?;
    if meta.is_dir() {
        return Err(InputError(format!("is a directory, not {}", what(kind))));
    }
    if !meta.is_file() {
        return Err(InputError(format!(
            "is {}{}, not a regular file: {} is read whole, and a pipe or device may never end; save it \
             to a file and give its path",
            if stdin { "standard input, " } else { "" },
            kind_of(&meta),
            what(kind)
        )));
    }
    Ok(meta)
}

/// Reads the scene or sweep file at `path` as text: a regular file ([`check`]) of at most
/// [`SCENE_MAX_BYTES`] (the bound holds while reading too, for files that grow or whose size the system
/// does not report, like `/proc` files), that can be read and is UTF-8.
pub fn read_toml(path: &Path, kind: InputKind) -> Result<String, InputError> {
    check(path, kind)?;
    let mut bytes = Vec::new();
    let read = File::open(path)
        .and_then(|f| f.take(SCENE_MAX_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|source| InputError(source.to_string()))?;
    // A recording given where its scene was meant: said so, not "not UTF-8 … iconv" or "too large".
    if bytes.starts_with(MCAP_MAGIC) {
        return Err(InputError(format!(
            "is an MCAP recording, not {}{}",
            what(kind),
            if kind == InputKind::Scene {
                ": `coin-log info --scene FILE > scene.toml` writes the scene it was recorded from"
            } else {
                ""
            }
        )));
    }
    // The size first: a large file is refused for its size, wherever its first non-UTF-8 byte is.
    if read as u64 > SCENE_MAX_BYTES {
        let bytes = fs::metadata(path).map_or(read as u64, |m| m.len().max(read as u64));
        return Err(InputError(format!(
            "holds more than {SCENE_MAX_BYTES} bytes (at least {bytes}), more than {} may (they are a few kB \
             of TOML): is this the file you meant?",
            what(kind)
        )));
    }
    String::from_utf8(bytes).map_err(|e| not_utf8(e.as_bytes(), e.utf8_error().valid_up_to(), kind))
}

/// Where the text stops being UTF-8 (the system's "stream did not contain valid UTF-8" said neither where
/// nor what to do).
fn not_utf8(bytes: &[u8], valid: usize, kind: InputKind) -> InputError {
    let before = String::from_utf8_lossy(&bytes[..valid]);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    InputError(format!(
        "is not UTF-8 text: byte 0x{:02x} at line {line}, column {column} is not UTF-8; {} is TOML, which \
         is UTF-8: save it as UTF-8 (e.g. `iconv -f latin1 -t utf-8`), or check that this is the file you \
         meant",
        bytes[valid],
        what(kind)
    ))
}

/// Ok if `path` is absent or a regular file (following links): for the files a command keeps in a folder
/// of its own (a sweep's journal, plan and catalogue parts), which a crafted folder could replace with a
/// pipe that blocks an open or a device that never ends. Else [`io::ErrorKind::InvalidInput`] naming what
/// the path is instead, or the error of looking at it.
pub fn absent_or_regular(path: &Path) -> io::Result<()> {
    match fs::metadata(path) {
        Ok(meta) if meta.is_file() => Ok(()),
        Ok(meta) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("is {}, not a regular file: move it away", kind_of(&meta)),
        )),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// Ok if `path` is absent or a regular file itself, not a link to one: for the files a command writes in a
/// folder of its own (a sweep's journal, catalogue and summary), where through a link an append would go
/// to the file it points to and a move into place would replace the link with a plain file. Errors as
/// [`absent_or_regular`], and [`io::ErrorKind::InvalidInput`] for a symbolic link.
pub fn absent_or_plain(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_symlink() => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "is a symbolic link (to `{}`), not a regular file: move it away",
                fs::read_link(path).map_or_else(|_| "?".into(), |to| to.display().to_string())
            ),
        )),
        _ => absent_or_regular(path),
    }
}

/// Opens the file at `path` for reading, if [`absent_or_regular`] allows (its error, or the open's).
pub fn open_regular(path: &Path) -> io::Result<File> {
    absent_or_regular(path).and_then(|()| File::open(path))
}

/// Reads the file at `path` as text, opened by [`open_regular`] (its error, or the read's: not UTF-8).
pub fn read_regular(path: &Path) -> io::Result<String> {
    let mut text = String::new();
    open_regular(path)?.read_to_string(&mut text)?;
    Ok(text)
}
