//! `coin-log info` (docs/format.md: info): what a file holds, from the file alone: from its summary
//! section when it has one ([`coin_log_mcap::read_summary`], a few seeks), else from one streaming pass
//! that describes a file breaking off part way up to the break. The summary is taken as the file states
//! it: `verify` is what checks it.

use crate::format::channels::{Topic, ROS_STRING_WIRE};
use crate::format::{ResultMetadata, RunMetadata, RESULT_METADATA_NAME, RUN_METADATA_NAME};
use crate::scene::SceneFile;
use coin_log_mcap::{self, ChannelSummary, MessageHeader, ReadError, Visitor};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};
use std::ops::ControlFlow;
use std::path::Path;

/// One channel of a file (an entry of `info --json`'s `channels`).
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelReport {
    pub topic: String,
    /// Schema name (`""` without a schema).
    pub schema: String,
    pub message_encoding: String,
    pub messages: u64,
    /// Messages per second of log time (per time unit of a coin-log scene) over the file's time span:
    /// (messages − 1) / span; `None` with fewer than two messages or a zero span.
    pub rate: Option<f64>,
}

coin_log_names::named_enum! {
    /// Where [`FileInfo`] was read from.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum Source: "source" {
        /// The summary section (statistics, chunk indexes, metadata index).
        Summary = "summary",
        /// A streaming pass over the whole file (it has no usable summary).
        Scan = "scan",
    }
}

/// What a file holds.
#[derive(Debug, Clone, PartialEq)]
pub struct FileInfo {
    /// Sizes, counts, channels and metadata records, as the summary section states them or the streaming
    /// pass found them.
    pub summary: coin_log_mcap::Summary,
    /// Where this was read from.
    pub source: Source,
    /// The `coin-log` record, or why it is missing or unusable.
    pub run: Result<RunMetadata, String>,
    /// The `coin-log.result` record, or why it is missing or unusable.
    pub result: Result<ResultMetadata, String>,
    /// The stored scene as a file (for its description and duration), when it parses.
    pub scene: Option<SceneFile>,
    /// Why the file could not be read to its end (then the rest describes what came before), or why its
    /// summary was not used (a damaged one: the whole file was read instead).
    pub problem: Option<String>,
    /// The file was read to its end (from its summary, or by a streaming pass that did not break off).
    pub read_to_end: bool,
}

impl FileInfo {
    /// The compression of the file's chunks as a word: `zstd`, `lz4`, `none`, `mixed (...)`, or `no
    /// chunks`.
    #[must_use]
    pub fn compression(&self) -> String {
        let name = |c: &str| if c.is_empty() { "none" } else { c }.to_string();
        let compressions = &self.summary.compressions;
        match compressions.len() {
            0 => "no chunks".into(),
            1 => compressions.keys().map(|c| name(c)).collect(),
            _ => format!(
                "mixed ({})",
                compressions
                    .iter()
                    .map(|(c, n)| format!("{} × {n}", name(c)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }

    /// The message encoding of the file's channels: `json`, `protobuf`, `mixed (json, protobuf)`, or `no
    /// channels`.
    #[must_use]
    pub fn encoding(&self) -> String {
        match self.encodings(|_| true).as_slice() {
            [] => "no channels".into(),
            [one] => (*one).to_string(),
            more => format!("mixed ({})", more.join(", ")),
        }
    }

    /// The message encoding `coin-log record` was given for this file (`--encoding`): that of every channel
    /// but `/rerun/robot_description`, which `record` writes in CDR in every file (Rerun's URDF decoder
    /// reads no other form); otherwise as [`Self::encoding`].
    #[must_use]
    pub fn recorded_encoding(&self) -> String {
        let robot = Topic::RerunRobot.name();
        let cdr = |c: &ChannelSummary| c.topic == robot && c.message_encoding == ROS_STRING_WIRE.2;
        match self.encodings(|c| !cdr(c)).as_slice() {
            [one] => (*one).to_string(),
            _ => self.encoding(),
        }
    }

    /// The distinct message encodings of the channels `keep` keeps, sorted.
    fn encodings(&self, keep: impl Fn(&ChannelSummary) -> bool) -> Vec<&str> {
        let channels = self.summary.channels.iter().filter(|c| keep(c));
        let set: BTreeSet<&str> = channels.map(|c| c.message_encoding.as_str()).collect();
        set.into_iter().collect()
    }

    /// The channels, by id, with their message rates.
    #[must_use]
    pub fn channels(&self) -> Vec<ChannelReport> {
        let s = &self.summary;
        s.channels
            .iter()
            .map(|c| ChannelReport {
                topic: c.topic.clone(),
                schema: c.schema_name.clone(),
                message_encoding: c.message_encoding.clone(),
                messages: c.messages,
                rate: rate(c.messages, s.time_range),
            })
            .collect()
    }

    /// The contract's JSON object of this file (format.md: info --json), `path` as given.
    #[must_use]
    pub fn json<'a>(&'a self, path: &'a str) -> impl Serialize + 'a {
        let run = self.run.as_ref().ok();
        let s = &self.summary;
        FileJson {
            path,
            file_size: s.file_len,
            library: &s.library,
            read_from: self.source.name(),
            coin_log: run.is_some(),
            format_version: run.map(|r| r.format_version.as_str()),
            tool_version: run.map(|r| r.tool_version.as_str()),
            description: self.scene.as_ref().and_then(|s| s.description.as_deref()),
            messages: s.messages,
            start_time: s.time_range.map(|r| seconds(r.0)),
            end_time: s.time_range.map(|r| seconds(r.1)),
            chunks: s.chunks,
            compression: self.compression(),
            encoding: self.encoding(),
            compressed_bytes: s.compressed_bytes,
            uncompressed_bytes: s.uncompressed_bytes,
            channels: self.channels(),
            body: run.map(|r| BodyJson {
                mass: r.mass,
                radius: r.radius,
                gravity: r.gravity,
                inertia_x: r.inertia_x,
                inertia_z: r.inertia_z,
                friction: r.friction,
                time_unit: r.time_unit,
            }),
            run: run.map(|r| RunJson {
                duration: self.scene.as_ref().and_then(|s| s.run.as_ref()?.duration),
                rate: r.rate,
                integrator: r.integrator.name(),
                rtol: r.rtol,
                atol: r.atol,
                step: r.step,
                steady_kind: r.steady_kind.map(|k| k.to_string()),
                phi_dot: r.phi_dot,
                psi_dot: r.psi_dot,
                r_g: r.r_g,
                r_c: r.r_c,
            }),
            result: self.result.as_ref().ok().map(|r| ResultJson {
                termination: r.termination.name(),
                termination_time: r.termination_time,
                steps: r.steps,
                rhs_evaluations: r.rhs_evaluations,
                rejected_steps: r.rejected_steps,
            }),
            scene: run.map(|r| r.scene.as_str()),
            problem: self.problem.as_deref(),
        }
    }
}

/// Log time \[ns\] as seconds.
#[allow(clippy::cast_precision_loss)]
fn seconds(ns: u64) -> f64 {
    ns as f64 / 1e9
}

/// The `info --json` object of one file; its keys are format.md's (info --json).
#[derive(Debug, Serialize)]
struct FileJson<'a> {
    path: &'a str,
    file_size: u64,
    library: &'a str,
    read_from: &'static str,
    coin_log: bool,
    format_version: Option<&'a str>,
    tool_version: Option<&'a str>,
    description: Option<&'a str>,
    messages: u64,
    start_time: Option<f64>,
    end_time: Option<f64>,
    chunks: u64,
    compression: String,
    encoding: String,
    compressed_bytes: u64,
    uncompressed_bytes: u64,
    channels: Vec<ChannelReport>,
    body: Option<BodyJson>,
    run: Option<RunJson>,
    result: Option<ResultJson>,
    scene: Option<&'a str>,
    problem: Option<&'a str>,
}

/// `body` of [`FileJson`]: the stored body parameters.
#[derive(Debug, Serialize)]
struct BodyJson {
    mass: f64,
    radius: f64,
    gravity: f64,
    inertia_x: f64,
    inertia_z: f64,
    friction: Option<f64>,
    time_unit: f64,
}

/// `run` of [`FileJson`]: the stored run settings.
#[derive(Debug, Serialize)]
struct RunJson {
    duration: Option<f64>,
    rate: f64,
    integrator: &'static str,
    rtol: f64,
    atol: f64,
    step: f64,
    steady_kind: Option<String>,
    phi_dot: Option<f64>,
    psi_dot: Option<f64>,
    r_g: Option<f64>,
    r_c: Option<f64>,
}

/// `result` of [`FileJson`]: how the run ended.
#[derive(Debug, Serialize)]
struct ResultJson {
    termination: &'static str,
    termination_time: f64,
    steps: u64,
    rhs_evaluations: u64,
    rejected_steps: u64,
}

/// Why a file could not be described at all.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct InfoError(pub String);

/// Describes the file at `path`: from its summary when it has one, else by one streaming pass.
///
/// # Errors
/// [`InfoError`] if the file cannot be opened, is not MCAP, or breaks off before anything is known.
pub fn info(path: &Path) -> Result<FileInfo, InfoError> {
    let damaged = match coin_log_mcap::read_summary(path) {
        Ok(Some(summary)) => return Ok(from_summary(summary)),
        // No summary: the streaming pass says what the file holds (and where it breaks).
        Ok(None) => None,
        // A damaged one: the same pass, and the problem names the summary first.
        Err(e) => ReadError::broken_off(Some(e)).map_err(|e| InfoError(e.detail))?,
    };
    let mut info = scan(path)?;
    if let Some(e) = damaged {
        let damaged = format!(
            "the summary section is damaged ({}), so the whole file was read instead",
            e.detail
        );
        info.problem = Some(match info.problem.take() {
            Some(p) => format!("{damaged}; {p}"),
            None => damaged,
        });
    }
    Ok(info)
}

/// The `coin-log` and `coin-log.result` records among `metadata` (the first of each name).
fn records(
    metadata: &[(String, BTreeMap<String, String>)],
) -> (Result<RunMetadata, String>, Result<ResultMetadata, String>) {
    let find = |name: &str| metadata.iter().find(|(n, _)| n == name).map(|(_, e)| e);
    let run = find(RUN_METADATA_NAME).map_or_else(
        || Err("no `coin-log` metadata record: not a coin-log file".to_string()),
        |e| RunMetadata::from_map(e).map_err(|e| e.to_string()),
    );
    let result = find(RESULT_METADATA_NAME).map_or_else(
        || Err("no `coin-log.result` metadata record: the run did not finish writing".to_string()),
        |e| ResultMetadata::from_map(e).map_err(|e| e.to_string()),
    );
    (run, result)
}

/// (n − 1) / span in messages per second.
#[allow(clippy::cast_precision_loss)]
fn rate(messages: u64, time_range: Option<(u64, u64)>) -> Option<f64> {
    let (start, end) = time_range?;
    (messages >= 2 && end > start).then(|| (messages - 1) as f64 / seconds(end - start))
}

fn from_summary(summary: coin_log_mcap::Summary) -> FileInfo {
    let (run, result) = records(&summary.metadata);
    let scene = run
        .as_ref()
        .ok()
        .and_then(|r| toml::from_str(&r.scene).ok());
    FileInfo {
        summary,
        source: Source::Summary,
        run,
        result,
        scene,
        problem: None,
        read_to_end: true,
    }
}

/// What the streaming pass gathers beyond the reader's own summary: the metadata records.
#[derive(Default)]
struct Scan {
    metadata: Vec<(String, BTreeMap<String, String>)>,
}

impl Visitor for Scan {
    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        self.metadata.push((name.to_string(), entries.clone()));
    }
    fn message(&mut self, _: &MessageHeader, _: &[u8]) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

fn scan(path: &Path) -> Result<FileInfo, InfoError> {
    let mut v = Scan::default();
    let (s, error) = coin_log_mcap::read(path, &mut v);
    let problem = ReadError::broken_off(error)
        .map_err(|e| InfoError(e.detail))?
        .map(|e| e.detail);
    let summary = coin_log_mcap::Summary {
        metadata: v.metadata,
        ..s.summary
    };
    Ok(FileInfo {
        source: Source::Scan,
        read_to_end: problem.is_none(),
        problem,
        ..from_summary(summary)
    })
}
