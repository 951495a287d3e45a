//! `coin-log export` (docs/format.md: export): a file's channels as CSV tables in one streaming pass, in
//! memory bounded by a few records and one write buffer per table. Every value is read exactly and
//! written by ryu, so it equals the file's bit for bit.

use super::{read_values, seconds_text, unreadable};
use crate::csv;
use crate::files::shown_name;
use crate::format::fields::FieldReader;
use crate::format::Channel;
use crate::format::Encoding;
use coin_log_mcap::{self, MessageHeader, ReadError, Schema, Visitor};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::{self, BufWriter, Write};
use std::ops::ControlFlow;
use std::path::Path;

/// Write buffer per table.
const BUFFER: usize = 1 << 16;

/// How the tables are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// One table per channel.
    #[default]
    PerChannel,
    /// One table of samples joined on t.
    Wide,
}

/// The name of the wide table.
pub const WIDE_TABLE: &str = "samples.csv";

/// The columns of `/tf`'s table.
pub const TF_COLUMNS: [&str; 10] = [
    "t",
    "parent_frame_id",
    "child_frame_id",
    "translation.x",
    "translation.y",
    "translation.z",
    "rotation.x",
    "rotation.y",
    "rotation.z",
    "rotation.w",
];

/// One table written.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Table {
    /// File name (`omega.csv`).
    pub name: String,
    /// The topics it holds.
    pub topics: Vec<String>,
    /// Its header.
    pub columns: Vec<String>,
    /// Rows below the header.
    pub rows: u64,
}

/// A channel not exported, and why.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Skipped {
    pub topic: String,
    pub reason: String,
}

/// What an export wrote (`export --json` prints it).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct ExportSummary {
    /// The tables, in the order they were opened.
    pub tables: Vec<Table>,
    /// Channels left out.
    pub skipped: Vec<Skipped>,
    /// Messages read.
    pub messages: u64,
}

/// Why an export stopped. Tables opened before it may hold part of the data: the caller discards them.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ExportError(pub String);

fn written(table: &str, e: &io::Error) -> ExportError {
    ExportError(format!("writing `{table}`: {e}"))
}

fn join_failed(e: &str) -> ExportError {
    ExportError(format!(
        "cannot join the channels into one table: {e}; export one table per channel instead (without --wide)"
    ))
}

/// What each channel id is exported as.
#[derive(Clone, Copy)]
enum Target {
    /// A `coin_log.*` channel: its table (per channel) or its place in the wide row, and the index of
    /// its reader in `Exporter::readers`.
    Flat {
        channel: Channel,
        table: Option<usize>,
        reader: usize,
    },
    /// `/tf`, flattened into its table; Protobuf or JSON.
    Tf { table: usize, protobuf: bool },
    /// Not exported.
    Skip,
}

/// An open table.
struct Open<W: Write> {
    out: BufWriter<W>,
    table: Table,
}

/// The row being assembled in the wide layout.
struct Row {
    log_time: u64,
    t: f64,
    values: Vec<(Channel, Vec<f64>)>,
}

/// The wide table's state.
#[derive(Default)]
struct Wide {
    /// The columns' channels, fixed when the first row is written.
    channels: Option<Vec<(Channel, &'static [&'static str])>>,
    row: Option<Row>,
}

struct Exporter<'a, W: Write> {
    layout: Layout,
    open: &'a mut dyn FnMut(&str) -> io::Result<W>,
    /// The field readers of the flat channels.
    readers: Vec<FieldReader>,
    targets: BTreeMap<u16, Target>,
    tables: Vec<Open<W>>,
    skipped: Vec<Skipped>,
    wide: Wide,
    values: Vec<f64>,
    line: csv::Line,
    messages: u64,
    error: Option<ExportError>,
}

/// Exports the file at `path` as CSV tables, each written to what `open(name)` returns (the CLI opens a
/// temporary file in the output folder). `progress` is called with the bytes read so far.
///
/// # Errors
/// [`ExportError`] if the file cannot be read to its end, a message does not fit its schema, the wide
/// layout cannot join the channels, or a table cannot be written.
pub fn export<W: Write>(
    path: &Path,
    layout: Layout,
    open: &mut dyn FnMut(&str) -> io::Result<W>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<ExportSummary, ExportError> {
    let mut e = Exporter {
        layout,
        open,
        readers: Vec::new(),
        targets: BTreeMap::new(),
        tables: Vec::new(),
        skipped: Vec::new(),
        wide: Wide::default(),
        values: Vec::new(),
        line: csv::Line::default(),
        messages: 0,
        error: None,
    };
    let (_, read_error) = coin_log_mcap::read_with_progress(path, &mut e, progress);
    if let Some(err) = e.error.take() {
        return Err(err);
    }
    if let Some(err) = ReadError::broken_off(read_error).map_err(|e| ExportError(e.detail))? {
        return Err(ExportError(format!(
            "{}; nothing exported (`coin-log verify` says more about the file)",
            err.detail
        )));
    }
    e.finish()
}

impl<W: Write> Exporter<'_, W> {
    /// Opens table `name` with `columns` and writes its header.
    fn open_table(&mut self, name: &str, topic: &str, columns: Vec<String>) -> Option<usize> {
        // Two channels of one topic (legal MCAP: two publishers), or topics that differ only where
        // the name does not show it, would write one file twice.
        if let Some(other) = self.tables.iter().find(|o| o.table.name == name) {
            let first = shown_name(&other.table.topics.join(", "));
            let which = if other.table.topics == [topic] {
                format!("two channels of the topic {first}")
            } else {
                format!("the topics {first} and {}", shown_name(topic))
            };
            self.fail(ExportError(format!(
                "{which} would both be exported as `{name}`, and a table holds one channel; export a \
                 copy of the file without one of them"
            )));
            return None;
        }
        let opened = (self.open)(name).and_then(|w| {
            let mut out = BufWriter::with_capacity(BUFFER, w);
            out.write_all(csv::record(&columns).as_bytes())
                .map(|()| out)
        });
        let out = opened.inspect_err(|e| self.fail(written(name, e))).ok()?;
        self.tables.push(Open {
            out,
            table: Table {
                name: name.to_string(),
                topics: vec![topic.to_string()],
                columns,
                rows: 0,
            },
        });
        Some(self.tables.len() - 1)
    }

    fn fail(&mut self, e: ExportError) {
        self.error.get_or_insert(e);
    }

    fn skip(&mut self, topic: &str, reason: &str) -> Target {
        self.skipped.push(Skipped {
            topic: topic.to_string(),
            reason: reason.to_string(),
        });
        Target::Skip
    }

    /// What a channel with this topic and schema (name, encoding, bytes) becomes.
    fn target(&mut self, topic: &str, schema: Option<&Schema<'_>>) -> Target {
        let (schema, encoding, data) = schema.map_or(("", "", &[][..]), |s| {
            (s.name.as_str(), s.encoding.as_str(), &s.data[..])
        });
        let Some(channel) = Channel::from_topic(topic) else {
            return self.skip(topic, "not a coin-log channel");
        };
        if channel == Channel::Rerun {
            return self.skip(
                topic,
                "the drawing again for Rerun (the coin, the table, the track); the track's points are /coin/contact",
            );
        }
        // Every frame-transform topic (/tf, /tf_static, /scene/follow) is flattened into a table named
        // after the topic, so that two topics of one channel never share a file.
        if schema == Channel::Tf.schema_name() && matches!(channel, Channel::Tf | Channel::Scene) {
            let name = format!("{}.csv", topic.trim_start_matches('/').replace('/', "_"));
            return match self.layout {
                Layout::PerChannel => {
                    let columns = TF_COLUMNS.iter().map(ToString::to_string).collect();
                    let protobuf =
                        Encoding::from_schema_encoding(encoding) == Some(Encoding::Protobuf);
                    match self.open_table(&name, topic, columns) {
                        Some(table) => Target::Tf { table, protobuf },
                        None => Target::Skip,
                    }
                }
                Layout::Wide => self.skip(
                    topic,
                    &format!(
                        "frame transforms are not one per sample; export per channel for {name}"
                    ),
                ),
            };
        }
        if schema != channel.schema_name() {
            return self.skip(
                topic,
                &format!(
                    "its schema is `{schema}`, not coin-log's `{}`",
                    channel.schema_name()
                ),
            );
        }
        let Some(t) = channel.message_type() else {
            return self.skip(
                topic,
                "display geometry (the coin, the table, pieces of the track); the track's points are /coin/contact",
            );
        };
        let reader = match FieldReader::new(encoding, t, data) {
            Ok((r, _)) => r,
            Err(e) => return self.skip(topic, &e.to_string()),
        };
        let table = match self.layout {
            Layout::PerChannel => {
                let columns = reader.fields().iter().map(ToString::to_string).collect();
                let name = format!("{}.csv", channel.name());
                match self.open_table(&name, topic, columns) {
                    Some(table) => Some(table),
                    None => return Target::Skip,
                }
            }
            Layout::Wide => None,
        };
        self.readers.push(reader);
        Target::Flat {
            channel,
            table,
            reader: self.readers.len() - 1,
        }
    }

    /// Ends `self.line` and writes it as a row of table `table`.
    fn write_line(&mut self, table: usize) {
        let open = &mut self.tables[table];
        open.table.rows += 1;
        if let Err(e) = open.out.write_all(self.line.finish().as_bytes()) {
            let e = written(&open.table.name, &e);
            self.fail(e);
        }
    }

    fn flat(
        &mut self,
        h: &MessageHeader,
        data: &[u8],
        channel: Channel,
        table: Option<usize>,
        reader: usize,
    ) {
        let at = (channel.topic(), h.log_time);
        if let Err(e) = read_values(&self.readers[reader], data, &mut self.values, at) {
            return self.fail(ExportError(e));
        }
        let Some(table) = table else {
            return self.join(h.log_time, channel);
        };
        self.line.clear();
        for v in &self.values {
            self.line.number(*v);
        }
        self.write_line(table);
    }

    fn tf(&mut self, h: &MessageHeader, data: &[u8], table: usize, protobuf: bool) {
        let (ns, parent, child, values) = match transform_row(data, protobuf) {
            Ok(row) => row,
            Err(e) => {
                let reason = format!("is not a foxglove.FrameTransform: {e}");
                // The table's one topic: /tf, /tf_static or /scene/follow (all three said /tf).
                let topic = self.tables[table].table.topics.join(", ");
                return self.fail(ExportError(unreadable(&topic, h.log_time, reason)));
            }
        };
        self.line.clear();
        self.line.text(&seconds_text(ns));
        self.line.text(&parent).text(&child);
        for v in values {
            self.line.number(v);
        }
        self.write_line(table);
    }
}

/// The wide layout: messages of one log time form a row, written when a later log time arrives.
impl<W: Write> Exporter<'_, W> {
    fn join(&mut self, log_time: u64, channel: Channel) {
        let t = self.values[0];
        let later = self
            .wide
            .row
            .as_ref()
            .is_some_and(|r| log_time > r.log_time);
        if later {
            self.flush_row();
        }
        let values = self.values[1..].to_vec();
        let Some(row) = self.wide.row.as_mut() else {
            self.wide.row = Some(Row {
                log_time,
                t,
                values: vec![(channel, values)],
            });
            return;
        };
        let err = if log_time < row.log_time {
            // The message it follows may be another channel's: name it (the file may well be in time
            // order per channel, as a rewrite grouped by channel is).
            let before = row.values.last().map_or("", |(c, _)| c.topic());
            Some(format!(
                "{} has a message at log time {log_time} ns after one at {} ns on {before}: the messages are not in time order",
                channel.topic(),
                row.log_time
            ))
        } else if row.values.iter().any(|(c, _)| *c == channel) {
            Some(format!(
                "{} has two messages at log time {log_time} ns",
                channel.topic()
            ))
        } else if t.to_bits() != row.t.to_bits() {
            Some(format!(
                "at log time {log_time} ns, {} has t = {t} where the sample has t = {}",
                channel.topic(),
                row.t
            ))
        } else {
            row.values.push((channel, values));
            None
        };
        if let Some(e) = err {
            self.fail(join_failed(&e));
        }
    }

    /// Writes the pending row (and, before the first, the header).
    fn flush_row(&mut self) {
        let Some(row) = self.wide.row.take() else {
            return;
        };
        if self.wide.channels.is_none() {
            let mut channels: Vec<(Channel, &'static [&'static str])> = self
                .targets
                .values()
                .filter_map(|t| match t {
                    Target::Flat {
                        channel, reader, ..
                    } => Some((*channel, self.readers[*reader].fields())),
                    _ => None,
                })
                .collect();
            channels.sort_by_key(|(c, _)| *c);
            let mut columns = vec!["t".to_string()];
            for (c, fields) in &channels {
                columns.extend(fields[1..].iter().map(|f| format!("{}.{f}", c.name())));
            }
            let topics: Vec<String> = channels.iter().map(|(c, _)| c.topic().into()).collect();
            if let Some(table) = self.open_table(WIDE_TABLE, "", columns) {
                self.tables[table].table.topics = topics;
            }
            self.wide.channels = Some(channels);
        }
        let Some(channels) = self.wide.channels.as_ref() else {
            return;
        };
        if let Some((c, _)) = row
            .values
            .iter()
            .find(|(c, _)| !channels.iter().any(|(k, _)| k == c))
        {
            let e = format!(
                "{} first appears at log time {} ns, after the table's columns were fixed by the first sample",
                c.topic(),
                row.log_time
            );
            return self.fail(join_failed(&e));
        }
        self.line.clear();
        self.line.number(row.t);
        for (c, fields) in channels {
            let found = row.values.iter().find(|(k, _)| k == c);
            for i in 0..fields.len() - 1 {
                match found {
                    Some((_, v)) => self.line.number(v[i]),
                    None => self.line.empty(),
                };
            }
        }
        if !self.tables.is_empty() {
            self.write_line(0);
        }
    }

    /// Flushes the last row and every table.
    fn finish(mut self) -> Result<ExportSummary, ExportError> {
        self.flush_row();
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.tables.is_empty() {
            let why = if self.skipped.is_empty() {
                "the file has no coin-log channel with messages".to_string()
            } else {
                // A crafted file's 65 535 channels of 1 MB topics would make a message of gigabytes.
                const LISTED: usize = 8;
                let mut skipped: Vec<String> = self
                    .skipped
                    .iter()
                    .take(LISTED)
                    .map(|k| format!("{}: {}", shown_name(&k.topic), k.reason))
                    .collect();
                if self.skipped.len() > LISTED {
                    skipped.push(format!("and {} more", self.skipped.len() - LISTED));
                }
                format!(
                    "no channel of the file makes a table ({})",
                    skipped.join("; ")
                )
            };
            return Err(ExportError(format!("nothing to export: {why}")));
        }
        let mut tables = Vec::new();
        for open in self.tables {
            let Open { mut out, table } = open;
            out.flush().map_err(|e| written(&table.name, &e))?;
            tables.push(table);
        }
        Ok(ExportSummary {
            tables,
            skipped: self.skipped,
            messages: self.messages,
        })
    }
}

impl<W: Write> Visitor for Exporter<'_, W> {
    fn channel(&mut self, id: u16, topic: &str, _: &str, schema: Option<&Schema<'_>>) {
        let target = self.target(topic, schema);
        self.targets.insert(id, target);
    }
    fn message(&mut self, h: &MessageHeader, data: &[u8]) -> ControlFlow<()> {
        self.messages += 1;
        match self.targets.get(&h.channel_id).copied() {
            Some(Target::Flat {
                channel,
                table,
                reader,
            }) => self.flat(h, data, channel, table, reader),
            Some(Target::Tf { table, protobuf }) => self.tf(h, data, table, protobuf),
            Some(Target::Skip) => {}
            None => {
                let topic = format!("channel {}", h.channel_id);
                let reason = "is on a channel that no channel record declares";
                self.fail(ExportError(unreadable(&topic, h.log_time, reason)));
            }
        }
        if self.error.is_some() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// A `foxglove.FrameTransform` as its table's row: the timestamp \[ns\], the parent and child frames, the
/// translation and rotation (absent Protobuf sub-messages read as zeros, as proto3 defines them).
fn transform_row(data: &[u8], protobuf: bool) -> Result<(u64, String, String, [f64; 7]), String> {
    let ns = |sec: u64, nsec: u32| {
        sec.saturating_mul(1_000_000_000)
            .saturating_add(u64::from(nsec))
    };
    if protobuf {
        use prost::Message;
        let m = foxglove::messages::FrameTransform::decode(data).map_err(|e| e.to_string())?;
        let time = m.timestamp.unwrap_or_default();
        let tr = m.translation.unwrap_or_default();
        let ro = m.rotation.unwrap_or_default();
        let values = [tr.x, tr.y, tr.z, ro.x, ro.y, ro.z, ro.w];
        let ns = ns(u64::from(time.sec()), time.nsec());
        return Ok((ns, m.parent_frame_id, m.child_frame_id, values));
    }
    let m: FrameTransform = serde_json::from_slice(data).map_err(|e| e.to_string())?;
    let (tr, ro) = (m.translation, m.rotation);
    let values = [tr.x, tr.y, tr.z, ro.x, ro.y, ro.z, ro.w];
    let ns = ns(m.timestamp.sec, m.timestamp.nsec);
    Ok((ns, m.parent_frame_id, m.child_frame_id, values))
}

/// The fields of `foxglove.FrameTransform` that the table holds (others are ignored).
#[derive(Deserialize)]
struct FrameTransform {
    timestamp: Time,
    parent_frame_id: String,
    child_frame_id: String,
    translation: Vector3,
    rotation: Quaternion,
}

#[derive(Deserialize)]
struct Time {
    sec: u64,
    nsec: u32,
}

#[derive(Deserialize)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Deserialize)]
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}
