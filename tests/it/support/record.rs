//! Reading a recording back, a validator for our flat JSON schemas, and running the binary.
// Test helpers are not #[test] functions, so clippy.toml's allow-unwrap-in-tests and allow-expect-in-tests
// do not reach them; a failed unwrap or expect here is a failed test, which is what we want.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::process::run_within;
use super::repo;
use coin_log::record::{self, RecordOptions, RecordSummary};
use coin_log::scene::Scene;
use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// Records `scene` with `options` into memory with the library's recorder: the file's bytes and the
/// summary.
pub fn record_to_memory(scene: &Scene, options: &RecordOptions) -> (Vec<u8>, RecordSummary) {
    let mut cursor = Cursor::new(Vec::new());
    let stop = AtomicBool::new(false);
    let summary =
        record::record(scene, options, &mut cursor, &stop, |_| {}).expect("recording succeeds");
    (cursor.into_inner(), summary)
}

/// One message as read back.
#[derive(Debug, Clone)]
pub struct ReadMessage {
    pub topic: String,
    pub schema_name: String,
    pub log_time: u64,
    pub publish_time: u64,
    pub sequence: u32,
    pub data: Vec<u8>,
}

/// A recording read back with the mcap crate.
#[derive(Debug)]
pub struct ReadBack {
    pub messages: Vec<ReadMessage>,
    pub summary: mcap::Summary,
    /// Metadata records by name, with their offsets in the file.
    pub metadata: BTreeMap<String, (u64, BTreeMap<String, String>)>,
    /// Schema name → schema data.
    pub schemas: BTreeMap<String, Vec<u8>>,
}

impl ReadBack {
    pub fn topics(&self) -> Vec<String> {
        let mut topics: Vec<String> = self
            .summary
            .channels
            .values()
            .map(|c| c.topic.clone())
            .collect();
        topics.sort();
        topics
    }

    pub fn on_topic(&self, topic: &str) -> Vec<&ReadMessage> {
        self.messages.iter().filter(|m| m.topic == topic).collect()
    }
}

pub fn read_back(bytes: &[u8]) -> ReadBack {
    let summary = mcap::Summary::read(bytes)
        .expect("summary readable")
        .expect("file has a summary");
    let mut messages = Vec::new();
    for m in mcap::MessageStream::new(bytes).expect("message stream") {
        let m = m.expect("message readable");
        messages.push(ReadMessage {
            topic: m.channel.topic.clone(),
            schema_name: m
                .channel
                .schema
                .as_ref()
                .map(|s| s.name.clone())
                .unwrap_or_default(),
            log_time: m.log_time,
            publish_time: m.publish_time,
            sequence: m.sequence,
            data: m.data.into_owned(),
        });
    }
    let mut metadata = BTreeMap::new();
    for index in &summary.metadata_indexes {
        let record = mcap::read::metadata(bytes, index).expect("metadata readable");
        metadata.insert(record.name.clone(), (index.offset, record.metadata));
    }
    let schemas = summary
        .schemas
        .values()
        .map(|s| (s.name.clone(), s.data.to_vec()))
        .collect();
    ReadBack {
        messages,
        summary,
        metadata,
        schemas,
    }
}

/// Every message of the MCAP file at `path` as (topic, log time, JSON value), in file order; asserts that
/// each publish time equals its log time.
pub fn read_messages(path: &Path) -> Vec<(String, u64, serde_json::Value)> {
    read_back(&std::fs::read(path).unwrap())
        .messages
        .into_iter()
        .map(|m| {
            assert_eq!(m.log_time, m.publish_time);
            (
                m.topic,
                m.log_time,
                serde_json::from_slice(&m.data).unwrap(),
            )
        })
        .collect()
}

/// The bytes of `schemas/<name>.json`.
pub fn schema_file(name: &str) -> Vec<u8> {
    let path = repo().join("schemas").join(format!("{name}.json"));
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Validates a message against one of our flat schemas: an object, every property of the schema present,
/// every value a JSON number, no property the schema does not declare (`additionalProperties: false`).
pub fn validate_flat(schema: &serde_json::Value, message: &[u8]) -> Result<(), String> {
    let value: serde_json::Value =
        serde_json::from_slice(message).map_err(|e| format!("not JSON: {e}"))?;
    let object = value.as_object().ok_or("not an object")?;
    if schema["type"] != "object" {
        return Err("schema is not an object schema".into());
    }
    if schema["additionalProperties"] != false {
        return Err("schema allows additional properties".into());
    }
    let properties = schema["properties"]
        .as_object()
        .ok_or("schema has no properties")?;
    let required: Vec<&str> = schema["required"]
        .as_array()
        .ok_or("schema has no required list")?
        .iter()
        .filter_map(|v| v.as_str())
        .collect();
    for (name, spec) in properties {
        if spec["type"] != "number" {
            return Err(format!("schema property `{name}` is not a number"));
        }
        if !required.contains(&name.as_str()) {
            return Err(format!("schema property `{name}` is not required"));
        }
    }
    for name in &required {
        match object.get(*name) {
            None => return Err(format!("missing field `{name}`")),
            Some(v) if !v.is_number() => {
                return Err(format!("field `{name}` = {v} is not a number"))
            }
            Some(_) => {}
        }
    }
    for name in object.keys() {
        if !properties.contains_key(name) {
            return Err(format!("extra field `{name}`"));
        }
    }
    Ok(())
}

/// The `coin-log` binary cargo built for these tests.
pub fn exe() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_coin-log"))
}

/// Runs the binary with `args` in `dir`.
pub fn coin_log<S: AsRef<OsStr>>(dir: &Path, args: &[S]) -> Output {
    Command::new(exe())
        .args(args)
        .current_dir(dir)
        .output()
        .expect("coin-log runs")
}

/// Runs the binary with `args` in the repository root; returns the exit code (−1 if a signal ended the
/// process), stdout and stderr as text.
pub fn coin_log_text(args: &[&str]) -> (i32, String, String) {
    let out = coin_log(&repo(), args);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// How long a `verify` child may run before it counts as hung: a hang detector, generous (the files of
/// the tests take milliseconds to read), never a speed test.
pub const HANG_DEADLINE: Duration = Duration::from_secs(20);

/// Runs the binary with `args` in the repository root like [`coin_log_text`], but kills it and fails the
/// test if it has not exited within `deadline`.
pub fn coin_log_within(deadline: Duration, args: &[&str]) -> (i32, String, String) {
    let done = run_within(Command::new(exe()).args(args).current_dir(repo()), deadline);
    (done.code(), done.stdout, done.stderr)
}

/// The top-level records of the MCAP file `bytes`, in order: (opcode, offset, body length), up to the
/// footer (the end magic is not a record).
pub fn top_level_records(bytes: &[u8]) -> Vec<(u8, usize, usize)> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 9 <= bytes.len() - 8 {
        let op = bytes[at];
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        out.push((op, at, len));
        at += 9 + len;
    }
    out
}

/// Records built-in scene `scene` with the real recorder (`coin-log record`), plus `extra` flags.
pub fn record_scene(dir: &Path, scene: &str, extra: &[&str]) -> PathBuf {
    let path = dir.join(format!("{scene}.mcap"));
    let mut args = vec!["record", scene, "-o", path.to_str().unwrap(), "--overwrite"];
    args.extend_from_slice(extra);
    let (code, out, err) = coin_log_text(&args);
    assert_eq!(code, 0, "coin-log record {scene}: {out}{err}");
    path
}

/// The built-in scene names (`coin-log scenes`).
pub fn scene_names() -> Vec<String> {
    let (code, out, err) = coin_log_text(&["scenes"]);
    assert_eq!(code, 0, "{err}");
    out.lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}

/// File names in `dir`, sorted (hidden temporary files included).
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("readable folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
