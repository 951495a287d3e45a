//! The throughput bench (`bench throughput`): how fast `record`, `verify` and `export` run on the real
//! channel set and code paths, in how much memory, against the bound the machine sets. (What the
//! integration itself costs, and one RHS evaluation, are criterion's micro-benchmarks: `cargo bench -p
//! coin-log-bench`.)
//!
//! Workloads, each repeated and reported as the median:
//! - **record**: `coin-log record wobble` with the seven channels omega, angles, quaternion, position,
//!   contact, reaction, energy at 1 kHz with zstd ([`workload_scene`]); its `--json` summary gives the
//!   wall time and the peak RSS ([`RecordRun`]);
//! - **compression bound**: the time to zstd-compress the same JSON message bytes (read back from that
//!   file) in chunks of the recorder's size with the recorder's own [`ChunkCompressor`], on one thread
//!   as each compression worker does ([`compression_bound`]); the ratio record time / bound says how close
//!   recording is to what compression alone costs;
//! - **verify**: `coin-log verify --json` of that file, every check on ([`VerifyRun`]);
//! - **export**: `coin-log export --json` of that file, one CSV table per channel ([`ExportRun`]).
//!
//! Record and verify run at two durations, so that their peak RSS shows whether memory grows with the
//! length of the run. Each runs in its own process so that its peak RSS is its own: the `coin-log bench
//! throughput` command starts them and fills in [`RecordRun`] and [`VerifyRun`]; this module defines the
//! workloads, measures what runs in-process (the bound), turns the runs into rows
//! ([`DurationRuns::rows`]) and formats them ([`table`], [`csv`]).

use super::median;
use coin_log::format::{Channel, Encoding};
use coin_log::record::COMPRESSION_THREADS;
use coin_log::scene::{self, presets, FlagOverrides, Scene};
use coin_log::verify::coverage;
use coin_log_mcap::{
    self, ChunkCompressor, Compression, MessageHeader, Visitor, DEFAULT_CHUNK_SIZE, ZSTD_LEVEL,
};
use std::fmt;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The scene of the record and verify workloads.
pub const SCENE: &str = "wobble";
/// The seven channels of the throughput workload, in the format's order.
pub const CHANNELS: [Channel; 7] = [
    Channel::Omega,
    Channel::Angles,
    Channel::Quaternion,
    Channel::Position,
    Channel::Contact,
    Channel::Reaction,
    Channel::Energy,
];
/// Samples per time unit of the record workload (1 kHz).
pub const RATE: f64 = 1000.0;
/// Uncompressed bytes per chunk: the recorder's ([`DEFAULT_CHUNK_SIZE`]).
pub const CHUNK_SIZE: usize = DEFAULT_CHUNK_SIZE;
/// The throughput targets.
pub mod targets {
    /// Recording, messages per second.
    pub const RECORD_MESSAGES_PER_SECOND: f64 = 3e6;
    /// Record time over the compression bound.
    pub const BOUND_RATIO: f64 = 2.0;
    /// Verify, messages per second.
    pub const VERIFY_MESSAGES_PER_SECOND: f64 = 2e6;
    /// Peak RSS of record, verify and export \[bytes\].
    pub const PEAK_RSS_BYTES: f64 = 64.0 * 1024.0 * 1024.0;
}

/// A target and which side of it is good.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// The measured value should be at least this.
    AtLeast(f64),
    /// The measured value should be below this.
    Below(f64),
    /// The measured value should be at most this.
    AtMost(f64),
}

impl Target {
    /// Whether `value` meets the target.
    #[must_use]
    pub fn met(self, value: f64) -> bool {
        match self {
            Self::AtLeast(t) => value >= t,
            Self::Below(t) => value < t,
            Self::AtMost(t) => value <= t,
        }
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::AtLeast(t) => write!(f, "≥ {t:e}"),
            Self::Below(t) => write!(f, "< {t:e}"),
            Self::AtMost(t) => write!(f, "≤ {t:e}"),
        }
    }
}

/// One measured quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct ThroughputRow {
    /// The workload (`record wobble 100 u @ 1 kHz`, `integrate dop853 wobble 30 u`, ...).
    pub workload: String,
    /// What is measured (`messages/s`, `peak RSS`, ...).
    pub quantity: String,
    /// The median over the repeats.
    pub value: f64,
    /// Unit of `value` (`1/s`, `B`, `s`, ...).
    pub unit: String,
    /// Issue 9's target, when it sets one.
    pub target: Option<Target>,
    /// Anything needed to read the value (settings, counts).
    pub note: String,
}

impl ThroughputRow {
    /// Whether the value meets its target (`None` without one).
    #[must_use]
    pub fn met(&self) -> Option<bool> {
        self.target.map(|t| t.met(self.value))
    }
}

/// The bench's result.
#[derive(Debug, Clone, PartialEq)]
pub struct ThroughputReport {
    /// Cores available to this process (`std::thread::available_parallelism`).
    pub cores: usize,
    /// The rows, workload by workload.
    pub rows: Vec<ThroughputRow>,
}

impl ThroughputReport {
    /// The report of `rows`, with the cores available to this process.
    #[must_use]
    pub fn new(rows: Vec<ThroughputRow>) -> Self {
        Self {
            cores: std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get),
            rows,
        }
    }
}

/// Why a part of the throughput bench could not run.
#[derive(Debug, thiserror::Error)]
pub enum ThroughputError {
    /// The workload's scene does not resolve (a bug: the built-in scene and these settings are valid).
    #[error("the record workload at duration {duration}: {reason}")]
    Workload {
        /// Its duration \[time units\].
        duration: f64,
        /// What is wrong.
        reason: String,
    },
    /// The recording could not be read back for the compression bound.
    #[error("reading back `{path}`: {detail}")]
    ReadBack {
        /// The file.
        path: String,
        /// Why.
        detail: String,
    },
    /// zstd failed.
    #[error("zstd compression failed: {0}")]
    Compress(std::io::Error),
    /// Rows were asked of a duration without a record, bound and verify run.
    #[error("no record, bound and verify runs at duration {duration}")]
    NoRuns {
        /// The duration \[time units\].
        duration: f64,
    },
}

/// The `--channels` value of the workload.
#[must_use]
pub fn channel_list() -> String {
    CHANNELS
        .iter()
        .map(|c| c.name())
        .collect::<Vec<_>>()
        .join(",")
}

/// The record workload of `duration` time units as a scene: [`SCENE`] with [`CHANNELS`] at [`RATE`],
/// the scene `coin-log record` resolves from the workload's flags.
///
/// # Errors
/// [`ThroughputError::Workload`] if the scene does not validate (e.g. a duration that is not positive), or
/// is too short for `verify` to judge its recording.
pub fn workload_scene(duration: f64) -> Result<Scene, ThroughputError> {
    let invalid = |reason: String| ThroughputError::Workload { duration, reason };
    let file = presets::preset(SCENE).ok_or_else(|| invalid(format!("no built-in `{SCENE}`")))?;
    let flags = FlagOverrides {
        duration: Some(duration),
        rate: Some(RATE),
        channels: Some(CHANNELS.iter().map(|c| c.name().to_string()).collect()),
        ..FlagOverrides::default()
    };
    let scene = scene::resolve(&file, &flags).map_err(|e| invalid(e.to_string()))?;
    // The workload verifies every recording: a duration too short for verify to judge (1e-9 time units:
    // one sample) is refused here, not by the first child `verify` after the record runs.
    // The sentence's advice names record's flags; the bench's rate is fixed, so its own advice replaces it.
    match coverage(&scene).first() {
        Some(why) => Err(invalid(format!(
            "verify could not judge the recording: {}; give a longer duration",
            why.rsplit_once("; ")
                .map_or(why.as_str(), |(reason, _)| reason)
        ))),
        None => Ok(scene),
    }
}

/// One record run, as its `--json` summary reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordRun {
    /// Messages written.
    pub messages: u64,
    /// File size \[bytes\].
    pub bytes: u64,
    /// The recorder's wall time \[s\].
    pub seconds: f64,
    /// Its peak RSS \[bytes\], if reported.
    pub peak_rss: Option<u64>,
}

/// One export run (`coin-log export --json` of the recording: one CSV table per channel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExportRun {
    /// Wall time of the export process \[s\].
    pub seconds: f64,
    /// Its peak RSS \[bytes\], if reported.
    pub peak_rss: Option<u64>,
}

/// One verify run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifyRun {
    /// Wall time of the verify process \[s\].
    pub seconds: f64,
    /// Its peak RSS \[bytes\], if reported.
    pub peak_rss: Option<u64>,
}

/// The compression bound of one file: its JSON message bytes and the time zstd takes on them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Bound {
    /// Messages read back.
    pub messages: u64,
    /// Their JSON bytes.
    pub json_bytes: u64,
    /// Compressed bytes.
    pub compressed_bytes: u64,
    /// Time spent compressing \[s\] (reading the file back is not counted).
    pub seconds: f64,
}

/// Collects message bytes into chunks and compresses each, timing only the compression.
struct Compressing {
    compressor: ChunkCompressor,
    chunk: Vec<u8>,
    out: Vec<u8>,
    bound: Bound,
    error: Option<std::io::Error>,
}

impl Compressing {
    fn flush(&mut self) {
        if self.chunk.is_empty() || self.error.is_some() {
            return;
        }
        let start = Instant::now();
        let result = self.compressor.compress(&self.chunk, &mut self.out);
        self.bound.seconds += start.elapsed().as_secs_f64();
        match result {
            Ok(()) => self.bound.compressed_bytes += self.out.len() as u64,
            Err(e) => self.error = Some(e),
        }
        self.chunk.clear();
    }
}

impl Visitor for Compressing {
    fn message(&mut self, _: &MessageHeader, data: &[u8]) -> ControlFlow<()> {
        self.bound.messages += 1;
        self.bound.json_bytes += data.len() as u64;
        self.chunk.extend_from_slice(data);
        if self.chunk.len() >= CHUNK_SIZE {
            self.flush();
        }
        if self.error.is_some() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// The compression bound of the recording at `path`: its JSON message bytes compressed in
/// [`CHUNK_SIZE`] pieces by the recorder's own [`ChunkCompressor`] (zstd at [`ZSTD_LEVEL`]), on one thread
/// as each of the recorder's [`COMPRESSION_THREADS`] workers does.
///
/// # Errors
/// [`ThroughputError`] if the file cannot be read back or zstd fails.
pub fn compression_bound(path: &Path) -> Result<Bound, ThroughputError> {
    let mut visitor = Compressing {
        compressor: ChunkCompressor::new(Compression::Zstd),
        chunk: Vec::with_capacity(CHUNK_SIZE + (CHUNK_SIZE >> 2)),
        out: Vec::new(),
        bound: Bound::default(),
        error: None,
    };
    let (_, error) = coin_log_mcap::read(path, &mut visitor);
    visitor.flush();
    if let Some(e) = visitor.error {
        return Err(ThroughputError::Compress(e));
    }
    if let Some(e) = error {
        return Err(ThroughputError::ReadBack {
            path: path.display().to_string(),
            detail: e.detail,
        });
    }
    Ok(visitor.bound)
}

/// The recording of `duration` in `dir`.
#[must_use]
pub fn recording_path(dir: &Path, duration: f64) -> PathBuf {
    dir.join(format!("throughput-{duration}.mcap"))
}

#[allow(clippy::cast_precision_loss)]
fn rate(count: u64, seconds: f64) -> f64 {
    count as f64 / seconds
}

#[allow(clippy::cast_precision_loss)]
fn as_f64(x: u64) -> f64 {
    x as f64
}

fn row(
    workload: &str,
    quantity: &str,
    value: f64,
    unit: &str,
    target: Option<Target>,
    note: &str,
) -> ThroughputRow {
    ThroughputRow {
        workload: workload.to_string(),
        quantity: quantity.to_string(),
        value,
        unit: unit.to_string(),
        target,
        note: note.to_string(),
    }
}

/// The median of the peak RSS values reported \[bytes\]; NaN when none was.
fn median_peak(peaks: impl Iterator<Item = Option<u64>>) -> f64 {
    let v: Vec<f64> = peaks.flatten().map(as_f64).collect();
    if v.is_empty() {
        f64::NAN
    } else {
        median(&v)
    }
}

/// What the repeats of the record, bound and verify workloads measured at one duration.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DurationRuns {
    /// The workloads' duration \[time units\].
    pub duration: f64,
    /// The recordings' message encoding.
    pub encoding: Encoding,
    /// The record runs, one per repeat.
    pub records: Vec<RecordRun>,
    /// The compression bounds of their recordings.
    pub bounds: Vec<Bound>,
    /// The verify runs of their recordings.
    pub verifies: Vec<VerifyRun>,
    /// The export runs of their recordings.
    pub exports: Vec<ExportRun>,
}

impl DurationRuns {
    /// No runs yet at `duration`.
    #[must_use]
    pub fn new(duration: f64) -> Self {
        Self {
            duration,
            ..Self::default()
        }
    }

    /// The rows of the record, bound and verify workloads: medians over the repeats; counts and sizes of
    /// the last repeat (every repeat writes the same file).
    ///
    /// # Errors
    /// [`ThroughputError::NoRuns`] when any of the three lists is empty.
    pub fn rows(&self) -> Result<Vec<ThroughputRow>, ThroughputError> {
        let (Some(record), Some(bound), false, false) = (
            self.records.last(),
            self.bounds.last(),
            self.verifies.is_empty(),
            self.exports.is_empty(),
        ) else {
            return Err(ThroughputError::NoRuns {
                duration: self.duration,
            });
        };
        let record_s = median(&self.records.iter().map(|r| r.seconds).collect::<Vec<_>>());
        let bound_s = median(&self.bounds.iter().map(|b| b.seconds).collect::<Vec<_>>());
        let mut rows = self.record_rows(record, bound, record_s);
        rows.extend(self.bound_rows(bound, bound_s, record_s));
        rows.extend(self.verify_rows(record.messages));
        rows.extend(self.export_rows(record.messages));
        Ok(rows)
    }

    /// Messages/s and peak RSS of the export workload.
    fn export_rows(&self, messages: u64) -> Vec<ThroughputRow> {
        let export_s = median(&self.exports.iter().map(|v| v.seconds).collect::<Vec<_>>());
        let workload = format!("export {} u, one CSV per channel", self.duration);
        vec![
            row(
                &workload,
                "messages/s",
                rate(messages, export_s),
                "1/s",
                None,
                &format!("{export_s:.3} s wall of the export process"),
            ),
            row(
                &workload,
                "peak RSS",
                median_peak(self.exports.iter().map(|v| v.peak_rss)),
                "B",
                Some(Target::Below(targets::PEAK_RSS_BYTES)),
                "VmHWM of the export process",
            ),
        ]
    }

    /// Messages/s, MB/s, file size and peak RSS of the record workload.
    fn record_rows(&self, last: &RecordRun, bound: &Bound, record_s: f64) -> Vec<ThroughputRow> {
        let duration = self.duration;
        let messages = last.messages;
        let (workload, what) = match self.encoding {
            Encoding::Json => (
                format!("record {SCENE} {duration} u @ 1 kHz, 7 channels, zstd"),
                "JSON",
            ),
            Encoding::Protobuf => (
                format!("record {SCENE} {duration} u @ 1 kHz, 7 channels, zstd, protobuf"),
                "Protobuf",
            ),
        };
        let counts = format!("{messages} messages, {} {what} bytes", bound.json_bytes);
        vec![
            row(
                &workload,
                "messages/s",
                rate(messages, record_s),
                "1/s",
                Some(Target::AtLeast(targets::RECORD_MESSAGES_PER_SECOND)),
                &format!("{counts}, {record_s:.3} s"),
            ),
            row(
                &workload,
                &format!("{what} MB/s"),
                as_f64(bound.json_bytes) / record_s / 1e6,
                "MB/s",
                None,
                "uncompressed message bytes per second",
            ),
            row(
                &workload,
                "file MB/s",
                as_f64(last.bytes) / record_s / 1e6,
                "MB/s",
                None,
                "file bytes per second",
            ),
            row(
                &workload,
                "file size",
                as_f64(last.bytes),
                "B",
                None,
                &format!(
                    "{:.1} B/message, {what}/file {:.2}",
                    as_f64(last.bytes) / as_f64(messages),
                    as_f64(bound.json_bytes) / as_f64(last.bytes)
                ),
            ),
            row(
                &workload,
                "peak RSS",
                median_peak(self.records.iter().map(|r| r.peak_rss)),
                "B",
                Some(Target::Below(targets::PEAK_RSS_BYTES)),
                "VmHWM of the record process",
            ),
        ]
    }

    /// The compression bound and the record time against it.
    fn bound_rows(&self, bound: &Bound, bound_s: f64, record_s: f64) -> Vec<ThroughputRow> {
        let workload = format!(
            "zstd bound {} u (level {ZSTD_LEVEL}, {} KiB chunks, 1 thread; recorder: {COMPRESSION_THREADS} worker(s))",
            self.duration,
            CHUNK_SIZE >> 10
        );
        vec![
            row(
                &workload,
                "compression time",
                bound_s,
                "s",
                None,
                &format!(
                    "{:.0} MB/s, ratio {:.2}",
                    as_f64(bound.json_bytes) / bound_s / 1e6,
                    as_f64(bound.json_bytes) / as_f64(bound.compressed_bytes)
                ),
            ),
            row(
                &workload,
                "record time / bound",
                record_s / bound_s,
                "",
                Some(Target::AtMost(targets::BOUND_RATIO)),
                "",
            ),
        ]
    }

    /// Messages/s and peak RSS of the verify workload.
    fn verify_rows(&self, messages: u64) -> Vec<ThroughputRow> {
        let verify_s = median(&self.verifies.iter().map(|v| v.seconds).collect::<Vec<_>>());
        let workload = format!("verify {} u, every check", self.duration);
        vec![
            row(
                &workload,
                "messages/s",
                rate(messages, verify_s),
                "1/s",
                Some(Target::AtLeast(targets::VERIFY_MESSAGES_PER_SECOND)),
                &format!("{verify_s:.3} s wall of the verify process"),
            ),
            row(
                &workload,
                "peak RSS",
                median_peak(self.verifies.iter().map(|v| v.peak_rss)),
                "B",
                Some(Target::Below(targets::PEAK_RSS_BYTES)),
                "VmHWM of the verify process",
            ),
        ]
    }
}

/// The CSV header of `bench throughput`.
pub const CSV_HEADER: &str = "workload,quantity,value,unit,target,met,note";

/// The rows as CSV with [`CSV_HEADER`]; values as shortest round-trip numbers.
#[must_use]
pub fn csv(report: &ThroughputReport) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for r in &report.rows {
        let fields = [
            r.workload.clone(),
            r.quantity.clone(),
            super::table::number(Some(r.value)),
            r.unit.clone(),
            r.target.map_or_else(String::new, |t| t.to_string()),
            r.met().map_or_else(String::new, |m| m.to_string()),
            r.note.clone(),
        ];
        out.push_str(&coin_log::csv::record(&fields));
    }
    out
}

/// A value in its unit for people: rates as `2.41 M/s`, bytes as MiB, short times in µs or ns.
#[must_use]
pub fn human(value: f64, unit: &str) -> String {
    if !value.is_finite() {
        return "-".into();
    }
    match unit {
        "1/s" => format!("{:.3} M/s", value / 1e6),
        "B" => format!("{:.1} MiB", value / f64::from(1 << 20)),
        "s" if value < 1e-6 => format!("{:.1} ns", value * 1e9),
        "s" if value < 1e-3 => format!("{:.1} µs", value * 1e6),
        "s" => format!("{value:.3} s"),
        "" => format!("{value:.2}"),
        other => format!("{value:.1} {other}"),
    }
}

fn human_target(target: Target, unit: &str) -> String {
    match target {
        Target::AtLeast(t) => format!("≥ {}", human(t, unit)),
        Target::Below(t) => format!("< {}", human(t, unit)),
        Target::AtMost(t) => format!("≤ {}", human(t, unit)),
    }
}

/// The rows as a text table.
#[must_use]
pub fn table(report: &ThroughputReport) -> String {
    let header = ["workload", "quantity", "median", "target", "met", "note"];
    let body: Vec<Vec<String>> = report
        .rows
        .iter()
        .map(|r| {
            vec![
                r.workload.clone(),
                r.quantity.clone(),
                human(r.value, &r.unit),
                r.target
                    .map_or_else(|| "-".into(), |t| human_target(t, &r.unit)),
                r.met()
                    .map_or_else(|| "-".into(), |m| if m { "yes" } else { "NO" }.into()),
                r.note.clone(),
            ]
        })
        .collect();
    super::table::render(&header, &body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_say_which_side_is_good() {
        assert!(Target::AtLeast(2.0).met(2.0));
        assert!(!Target::Below(2.0).met(2.0));
        assert!(Target::AtMost(2.0).met(2.0));
    }
}
