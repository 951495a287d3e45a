//! What a user does with a recording after it is written (format.md: info, export, plot): see what is in
//! it ([`info`]), get its channels out as tables ([`export`]), draw a one-page overview ([`plot`]). The
//! format's channel list and message fields drive the reading, so a channel or field added to the format
//! needs no change here. Nothing here judges a file; that is `verify`'s job.

pub mod export;
pub mod info;
pub mod plot;

use crate::format::fields::FieldReader;

/// The exact decimal text of a log time in ns as seconds (`1500000000` → `1.5`, `10000000` → `0.01`,
/// `0` → `0`): no rounding, so it reads back as the f64 nearest to the log time.
#[must_use]
pub fn seconds_text(ns: u64) -> String {
    let (sec, nsec) = (ns / 1_000_000_000, ns % 1_000_000_000);
    if nsec == 0 {
        return sec.to_string();
    }
    let fraction = format!("{nsec:09}");
    format!("{sec}.{}", fraction.trim_end_matches('0'))
}

/// Reads message `data` of `topic` (log time `log_time` ns) with `reader` into `values`, resized to its
/// fields; `Err` is the sentence saying why it cannot be read (export's and plot's alike).
fn read_values(
    reader: &FieldReader,
    data: &[u8],
    values: &mut Vec<f64>,
    (topic, log_time): (&str, u64),
) -> Result<(), String> {
    values.clear();
    values.resize(reader.fields().len(), 0.0);
    reader
        .read(data, values)
        .map_err(|e| unreadable(topic, log_time, e))
}

/// `{topic}: the message at log time {log_time} ns {reason}`.
fn unreadable(topic: &str, log_time: u64, reason: impl std::fmt::Display) -> String {
    format!("{topic}: the message at log time {log_time} ns {reason}")
}
