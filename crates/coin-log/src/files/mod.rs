//! The files coin-log reads ([`input`]: regular files only, bounded) and writes ([`output`]: a temporary file
//! moved into place), by one policy for every command (format.md: Commands, Inputs and outputs).

pub mod input;
pub mod output;

pub use input::{
    absent_or_plain, absent_or_regular, open_regular, read_regular, read_toml, InputError,
    InputKind,
};
pub use output::{
    dangling_link, make_readable, Attribute, Output, OutputError, OutputFolder, Policy,
};

use std::borrow::Cow;
use std::path::Path;

/// A path for a message: its text (lossy for bytes that are not UTF-8) with control characters escaped
/// (`\n`, `\u{1b}`), so that a crafted name cannot break a line or drive the terminal.
#[must_use]
pub fn shown(path: &Path) -> String {
    escaped(&path.to_string_lossy()).into_owned()
}

/// `text` with its control characters escaped as [`shown`] does (for paths already held as text).
#[must_use]
pub fn escaped(text: &str) -> Cow<'_, str> {
    if !text.contains(char::is_control) {
        return Cow::Borrowed(text);
    }
    let each = |c: char| {
        if c.is_control() {
            c.escape_default().to_string()
        } else {
            c.to_string()
        }
    };
    Cow::Owned(text.chars().map(each).collect())
}

/// The most characters of a name or a quoted line that a message or a table shows: crafted inputs held
/// 70 000 to 1 000 000 (a topic, a line of TOML), which printed megabytes of one message.
pub const SHOWN_CHARS: usize = 200;

/// A name a file holds (a topic, a schema, a description) as a message or a table shows it: control
/// characters escaped ([`escaped`]), cut to [`SHOWN_CHARS`] characters.
#[must_use]
pub fn shown_name(text: &str) -> String {
    cut(&escaped(text), SHOWN_CHARS).into_owned()
}

/// `text` cut to `max` characters, with `…` where it was cut.
#[must_use]
pub fn cut(text: &str, max: usize) -> Cow<'_, str> {
    match text.char_indices().nth(max) {
        Some((at, _)) => format!("{}…", &text[..at]).into(),
        None => text.into(),
    }
}
