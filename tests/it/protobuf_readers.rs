//! Protobuf recordings (`record --encoding protobuf`, docs/format.md: Encodings) read by real tools:
//!
//! - the Python `mcap` package with `mcap-protobuf-support`'s DecoderFactory (Google's `protobuf` runtime)
//!   and `@mcap/core` with `protobufjs` (`Root.fromDescriptor`, as Foxglove's app decodes Protobuf):
//!   `scripts/readers/protobuf_check.py` and `protobuf_check.mjs`. For every built-in scene, each decodes
//!   every message of a short Protobuf recording and dumps every field; the two dumps must be equal, and
//!   equal to the JSON recording of the same scene field by field: the `coin_log.*` numbers bit for bit
//!   (the same f64s), the `foxglove.*` messages with every field (transforms, scene entities);
//! - Rerun (`rerun mcap convert`, read back with the SDK: `scripts/readers/rerun_check.py`): the entities,
//!   the coin's transforms and the numeric channels.
//!
//! Negative controls: a truncated message and a wrong descriptor make both readers fail, and a value
//! changed by one unit in the last place makes the comparison with the JSON recording fail.
//! The tools are installed by `scripts/test`; a missing one fails the test (never skips it).

// Helpers outside #[test] functions (reading dumps, damaging files) fail the test by unwrap, as meant.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::other_writers::{node_readers, python};
use crate::support::process::{run_tool, Tool};
use crate::support::record::{coin_log_text, read_messages, scene_names};
use crate::support::repo;
use crate::support::writers::rewrite_protobuf;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Simulated time of each recording: every channel and topic is written at t = 0 and then at the scene's
/// rate, so one time unit gives tens to a thousand messages per channel and keeps the test to seconds.
const DURATION: &str = "1";

/// Records `scene` twice in `dir`: `<scene>.mcap` in Protobuf and `<scene>.json.mcap` in JSON.
fn record_both(dir: &Path, scene: &str) -> (PathBuf, PathBuf) {
    let pb = dir.join(format!("{scene}.mcap"));
    let json = dir.join(format!("{scene}.json.mcap"));
    for (path, encoding) in [(&pb, "protobuf"), (&json, "json")] {
        let (code, out, err) = coin_log_text(&[
            "record",
            scene,
            "--duration",
            DURATION,
            "--encoding",
            encoding,
            "-o",
            path.to_str().unwrap(),
        ]);
        assert_eq!(
            code, 0,
            "coin-log record {scene} --encoding {encoding}: {out}{err}"
        );
    }
    (pb, json)
}

/// What one reader said: success, and its output (its dump is in the dump folder).
struct ReaderRun {
    ok: bool,
    text: String,
}

/// Runs the Python and the Node Protobuf readers on `files` (at once), dumping into `dump`.
fn run_readers(files: &[PathBuf], dump: &Path) -> [ReaderRun; 2] {
    let command = |program: PathBuf, script: PathBuf| {
        let mut c = Command::new(program);
        c.arg(script).arg("--dump").arg(dump).args(files);
        c
    };
    let mut py = command(python(), repo().join("scripts/readers/protobuf_check.py"));
    let mut node = command(
        PathBuf::from("node"),
        node_readers().join("protobuf_check.mjs"),
    );
    [
        Tool::start(&mut py, "run scripts/test"),
        Tool::start(&mut node, "install Node.js 20 and run scripts/test"),
    ]
    .map(|tool| {
        let o = tool.finish();
        ReaderRun {
            ok: o.status.success(),
            text: o.stdout + &o.stderr,
        }
    })
}

/// One dumped message: topic, log time, decoded message (every field; doubles as bit patterns).
#[derive(Debug, Clone, PartialEq)]
struct Dumped {
    topic: String,
    log_time: u64,
    message: Value,
}

fn load_dump(path: &Path) -> Vec<Dumped> {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e} (the reader wrote no dump)", path.display()));
    text.lines()
        .map(|line| {
            let v: Value = serde_json::from_str(line).unwrap();
            Dumped {
                topic: v["topic"].as_str().unwrap().to_string(),
                log_time: v["log_time"].as_str().unwrap().parse().unwrap(),
                message: v["message"].clone(),
            }
        })
        .collect()
}

/// The dumps of `file` by the Python and the Node reader.
fn dumps(dump: &Path, file: &Path) -> (Vec<Dumped>, Vec<Dumped>) {
    let name = file.file_name().unwrap().to_str().unwrap();
    (
        load_dump(&dump.join(format!("{name}.jsonl"))),
        load_dump(&dump.join(format!("{name}.node.jsonl"))),
    )
}

/// Decodes a dumped double (16 hex digits of its bit pattern).
fn double_bits(text: &str) -> Option<u64> {
    (text.len() == 16)
        .then(|| u64::from_str_radix(text, 16).ok())
        .flatten()
}

/// Whether a dumped Protobuf value is its type's default (what proto3 leaves off the wire).
fn is_default(v: &Value) -> bool {
    match v {
        Value::Null => true,
        Value::Bool(b) => !b,
        Value::String(s) => s.is_empty() || s == "0" || s == "0000000000000000",
        Value::Array(a) => a.is_empty(),
        Value::Object(o) => o.values().all(is_default),
        Value::Number(_) => false,
    }
}

/// The JSON key of a Protobuf field: Foxglove's JSON writes `google.protobuf.Timestamp` / `Duration`
/// `{seconds, nanos}` as `{sec, nsec}`; every other field has the same name in both encodings.
fn json_key(field: &str) -> &str {
    match field {
        "seconds" => "sec",
        "nanos" => "nsec",
        other => other,
    }
}

/// Differences between a message of the JSON recording and the same message decoded from Protobuf, and
/// the number of `-0.0` in the JSON that Protobuf carries as `+0.0`: proto3 leaves a zero double off the
/// wire and prost (which writes the `foxglove.*` messages) treats −0.0 as zero, so only the sign of a zero is
/// allowed to differ, and only where `allow_signed_zero`.
fn compare(
    json: &Value,
    proto: &Value,
    at: &str,
    allow_signed_zero: bool,
    out: &mut Vec<String>,
    signed_zeros: &mut usize,
) {
    match (json, proto) {
        (Value::Object(j), Value::Object(p)) => {
            for (field, pv) in p {
                let key = json_key(field);
                match j.get(key) {
                    Some(jv) => compare(
                        jv,
                        pv,
                        &format!("{at}.{key}"),
                        allow_signed_zero,
                        out,
                        signed_zeros,
                    ),
                    None if is_default(pv) => {}
                    None => out.push(format!("{at}.{key}: absent in JSON, {pv} in Protobuf")),
                }
            }
            for key in j.keys() {
                if !p.keys().any(|f| json_key(f) == key) {
                    out.push(format!(
                        "{at}.{key}: in the JSON message, not a field of the Protobuf message"
                    ));
                }
            }
        }
        (j, Value::Null) if j.is_null() || (j.is_object() && json_all_zero(j)) => {}
        (Value::Array(j), Value::Array(p)) if j.len() == p.len() => {
            for (i, (jv, pv)) in j.iter().zip(p).enumerate() {
                compare(
                    jv,
                    pv,
                    &format!("{at}[{i}]"),
                    allow_signed_zero,
                    out,
                    signed_zeros,
                );
            }
        }
        (Value::Number(n), Value::String(s)) => {
            let as_integer = s.parse::<i128>().ok();
            let integer_ok = as_integer.is_some()
                && (n.as_i64().map(i128::from) == as_integer
                    || n.as_u64().map(i128::from) == as_integer);
            let x = n.as_f64().unwrap();
            let double_ok = double_bits(s) == Some(x.to_bits());
            let signed_zero =
                allow_signed_zero && x == 0.0 && x.is_sign_negative() && double_bits(s) == Some(0);
            if signed_zero {
                *signed_zeros += 1;
            } else if !(integer_ok || double_ok) {
                let shown = double_bits(s)
                    .map(|b| format!("{:e} (bits {s})", f64::from_bits(b)))
                    .unwrap_or_else(|| s.clone());
                out.push(format!(
                    "{at}: JSON {x:e} (bits {:016x}), Protobuf {shown}",
                    x.to_bits()
                ));
            }
        }
        (j, p) if j == p => {}
        (j, p) => out.push(format!("{at}: JSON {j}, Protobuf {p}")),
    }
}

/// A JSON object whose numbers are all zero (what an unset Protobuf message means).
fn json_all_zero(v: &Value) -> bool {
    match v {
        Value::Object(o) => o.values().all(json_all_zero),
        Value::Number(n) => n.as_f64() == Some(0.0),
        Value::Null => true,
        _ => false,
    }
}

/// What comparing a Protobuf dump with the JSON recording of the same scene found.
#[derive(Default)]
struct Comparison {
    /// Messages compared, per topic.
    counts: BTreeMap<String, usize>,
    /// Differences, each naming topic, log time and field (at most 20 kept).
    differences: Vec<String>,
    /// −0.0 of the JSON read as +0.0 from Protobuf, on `foxglove.*` topics.
    signed_zeros: usize,
}

/// The messages of one topic: (log time, message).
type Timeline<'a> = Vec<(u64, &'a Value)>;

/// Compares, topic by topic and in order, every message of the JSON recording with its Protobuf dump.
fn compare_with_json(json: &[(String, u64, Value)], dump: &[Dumped]) -> Comparison {
    let mut c = Comparison::default();
    let mut by_topic: BTreeMap<&str, (Timeline<'_>, Timeline<'_>)> = BTreeMap::new();
    for (topic, t, v) in json {
        by_topic.entry(topic).or_default().0.push((*t, v));
    }
    for d in dump {
        by_topic
            .entry(&d.topic)
            .or_default()
            .1
            .push((d.log_time, &d.message));
    }
    for (topic, (j, p)) in &by_topic {
        c.counts.insert((*topic).to_string(), p.len());
        if j.len() != p.len() {
            c.differences.push(format!(
                "{topic}: {} messages in JSON, {} decoded from Protobuf",
                j.len(),
                p.len()
            ));
            continue;
        }
        // The coin_log.* doubles are written with their sign; Foxglove's messages go through prost.
        let foxglove = !topic.starts_with("/coin/");
        for ((jt, jv), (pt, pv)) in j.iter().zip(p) {
            let at = format!("{topic} at {jt} ns");
            if jt != pt {
                c.differences
                    .push(format!("{at}: Protobuf message at log time {pt}"));
                continue;
            }
            compare(
                jv,
                pv,
                &at,
                foxglove,
                &mut c.differences,
                &mut c.signed_zeros,
            );
        }
    }
    c.differences.truncate(20);
    c
}

fn first_difference(a: &[Dumped], b: &[Dumped]) -> String {
    if a.len() != b.len() {
        return format!("{} messages against {}", a.len(), b.len());
    }
    a.iter()
        .zip(b)
        .find(|(x, y)| x != y)
        .map(|(x, y)| format!("{x:?}\nagainst\n{y:?}"))
        .unwrap_or_default()
}

#[test]
fn python_and_node_decode_every_scene_like_the_json_recording() {
    let dir = tempfile::tempdir().unwrap();
    let dump = dir.path().join("dump");
    std::fs::create_dir(&dump).unwrap();
    let scenes = scene_names();
    assert!(scenes.len() >= 10, "{scenes:?}");
    let pairs: Vec<(String, PathBuf, PathBuf)> = scenes
        .iter()
        .map(|s| {
            let (pb, json) = record_both(dir.path(), s);
            (s.clone(), pb, json)
        })
        .collect();
    let files: Vec<PathBuf> = pairs.iter().map(|(_, pb, _)| pb.clone()).collect();
    let [py, node] = run_readers(&files, &dump);
    println!(
        "--- mcap + mcap-protobuf-support (protobuf_check.py)\n{}",
        py.text
    );
    println!(
        "--- @mcap/core + protobufjs (protobuf_check.mjs)\n{}",
        node.text
    );
    let passed = format!("{} passed, 0 failed", files.len());
    assert!(
        py.ok && py.text.contains(&passed),
        "Python refused a file:\n{}",
        py.text
    );
    assert!(
        node.ok && node.text.contains(&passed),
        "Node refused a file:\n{}",
        node.text
    );

    let mut failures = Vec::new();
    for (scene, pb, json) in &pairs {
        let (py_dump, node_dump) = dumps(&dump, pb);
        // Two independent Protobuf runtimes (Google's upb, protobufjs) must agree on every field.
        if py_dump != node_dump {
            failures.push(format!(
                "{scene}: the Python and Node decodings differ: {}",
                first_difference(&py_dump, &node_dump)
            ));
            continue;
        }
        let json_messages = read_messages(json);
        let c = compare_with_json(&json_messages, &py_dump);
        let topics: BTreeSet<&str> = json_messages.iter().map(|(t, _, _)| t.as_str()).collect();
        println!(
            "{scene}: {} messages on {} topics equal to the JSON recording ({} −0.0 read as +0.0 on foxglove.* topics)",
            py_dump.len(),
            topics.len(),
            c.signed_zeros
        );
        for t in ["/tf", "/scene", "/coin/omega", "/coin/energy"] {
            assert!(
                c.counts.get(t).copied().unwrap_or(0) > 0,
                "{scene}: no message on {t}"
            );
        }
        if !c.differences.is_empty() {
            failures.push(format!("{scene}:\n  {}", c.differences.join("\n  ")));
        }
        // The coin's transform and a scene entity, named: the general comparison covers them, this says so.
        let coin = py_dump
            .iter()
            .find(|d| d.topic == "/tf" && d.message["child_frame_id"] == "coin")
            .unwrap_or_else(|| panic!("{scene}: no transform of the coin frame"));
        for part in ["translation", "rotation"] {
            assert!(
                coin.message[part].is_object(),
                "{scene}: coin transform without {part}: {:?}",
                coin.message
            );
        }
        let scene_update = py_dump.iter().find(|d| d.topic == "/scene").unwrap();
        let ids: Vec<&str> = scene_update.message["entities"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["id"].as_str().unwrap())
            .collect();
        assert!(ids.contains(&"coin"), "{scene}: scene entities {ids:?}");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The output of a reader for one file: whether it passed, and its lines about that file.
fn verdict<'a>(text: &'a str, file: &Path) -> (bool, String) {
    let name = file.to_str().unwrap();
    let is_verdict = |l: &str| l.starts_with("ok   ") || l.starts_with("FAIL ");
    let mut lines = text
        .lines()
        .skip_while(|l| !(is_verdict(l) && l.contains(name)));
    let first = lines
        .next()
        .unwrap_or_else(|| panic!("no verdict on {name} in:\n{text}"));
    let rest: Vec<&'a str> = lines
        .take_while(|l| !(is_verdict(l) || l.contains(" passed, ")))
        .collect();
    (
        first.starts_with("ok   "),
        format!("{first}\n{}", rest.join("\n")),
    )
}

/// How [`damaged_copy`] changes a file.
#[derive(Debug, Clone, Copy)]
enum Damage {
    /// The 4th `/coin/energy` message loses its last 3 bytes (inside its last double).
    TruncatedMessage,
    /// The descriptor of `coin_log.AngularVelocity` names fields 2 and 3 `y` and `x` (swapped).
    SwappedDescriptor,
    /// Field 2 of the 3rd `/coin/energy` message changed by one unit in the last place.
    OneUlp,
}

/// Copies the Protobuf recording `src` to `dst` (the mcap crate's writer, every schema, channel and message
/// as they are, through [`rewrite_protobuf`]) with one `damage`.
fn damaged_copy(src: &Path, dst: &Path, damage: Damage) {
    use prost::Message as _;
    let damaged = std::cell::Cell::new(false);
    let schema = |name: &str, data: &[u8]| {
        if !matches!(damage, Damage::SwappedDescriptor) || name != "coin_log.AngularVelocity" {
            return data.to_vec();
        }
        let mut set = prost_types::FileDescriptorSet::decode(data).unwrap();
        let fields = &mut set.file[0].message_type[0].field;
        assert_eq!(fields[1].name.as_deref(), Some("x"), "{fields:?}");
        assert_eq!(fields[2].name.as_deref(), Some("y"), "{fields:?}");
        fields[1].name = Some("y".into());
        fields[1].json_name = Some("y".into());
        fields[2].name = Some("x".into());
        fields[2].json_name = Some("x".into());
        damaged.set(true);
        set.encode_to_vec()
    };
    let edit = |topic: &str, index: usize, data: &mut Vec<u8>| match damage {
        Damage::TruncatedMessage if topic == "/coin/energy" && index == 3 => {
            data.truncate(data.len() - 3);
            damaged.set(true);
        }
        Damage::OneUlp if topic == "/coin/energy" && index == 2 => {
            // Field 2 (a double: key 0x11, then 8 little-endian bytes) follows field 1 (9 bytes).
            assert_eq!(
                data[9],
                (2 << 3) | 1,
                "field 2 of /coin/energy is a double after t: {data:?}"
            );
            let x = f64::from_le_bytes(data[10..18].try_into().unwrap());
            let next = f64::from_bits(x.to_bits() + 1);
            data[10..18].copy_from_slice(&next.to_le_bytes());
            damaged.set(true);
        }
        _ => {}
    };
    rewrite_protobuf(src, dst, schema, |_| "protobuf", edit);
    assert!(
        damaged.get(),
        "{damage:?} found nothing to damage in {}",
        src.display()
    );
}

#[test]
fn a_truncated_message_or_a_wrong_descriptor_fails_both_readers_and_one_ulp_fails_the_comparison() {
    let dir = tempfile::tempdir().unwrap();
    let dump = dir.path().join("dump");
    std::fs::create_dir(&dump).unwrap();
    let (pb, json) = record_both(dir.path(), "wobble");
    let damages = [
        Damage::TruncatedMessage,
        Damage::SwappedDescriptor,
        Damage::OneUlp,
    ];
    let files: Vec<PathBuf> = damages
        .iter()
        .map(|d| {
            let path = dir.path().join(format!("{d:?}.mcap"));
            damaged_copy(&pb, &path, *d);
            path
        })
        .collect();
    let [py, node] = run_readers(&files, &dump);
    println!(
        "--- protobuf_check.py\n{}--- protobuf_check.mjs\n{}",
        py.text, node.text
    );
    let json_messages = read_messages(&json);
    for (reader, run) in [("Python", &py), ("Node", &node)] {
        assert!(!run.ok, "{reader} passed damaged files:\n{}", run.text);
        let (ok, text) = verdict(&run.text, &files[0]);
        assert!(
            !ok && text.contains("/coin/energy") && text.contains("does not decode"),
            "{reader}, truncated message:\n{text}"
        );
        let (ok, text) = verdict(&run.text, &files[1]);
        assert!(
            !ok && text.contains("descriptor declares"),
            "{reader}, swapped descriptor:\n{text}"
        );
        // A changed value is still a valid message: only the comparison with what coin-log wrote sees it.
        let (ok, text) = verdict(&run.text, &files[2]);
        assert!(ok, "{reader}, one ulp: a valid file:\n{text}");
    }
    for (i, file) in files.iter().enumerate().skip(1) {
        let (py_dump, node_dump) = dumps(&dump, file);
        assert_eq!(
            py_dump,
            node_dump,
            "{}",
            first_difference(&py_dump, &node_dump)
        );
        let c = compare_with_json(&json_messages, &py_dump);
        println!("{:?}: {:?}", damages[i], c.differences);
        let expected = match damages[i] {
            Damage::SwappedDescriptor => "/coin/omega at 0 ns.x".to_string(),
            _ => {
                let third = json_messages
                    .iter()
                    .filter(|m| m.0 == "/coin/energy")
                    .nth(2)
                    .unwrap();
                format!("/coin/energy at {} ns.", third.1)
            }
        };
        assert!(
            c.differences.iter().any(|d| d.starts_with(&expected)),
            "{:?}: the comparison must name {expected}: {:?}",
            damages[i],
            c.differences
        );
    }
    // The undamaged recording compares equal (the control of the control).
    let clean_dump = dir.path().join("clean");
    std::fs::create_dir(&clean_dump).unwrap();
    let [py, _] = run_readers(std::slice::from_ref(&pb), &clean_dump);
    assert!(py.ok, "{}", py.text);
    let c = compare_with_json(&json_messages, &dumps(&clean_dump, &pb).0);
    assert!(c.differences.is_empty(), "{:?}", c.differences);
}

/// Runs `rerun_check.py` (`rerun mcap convert`, then the .rrd read back with the Rerun SDK) on `file`.
fn rerun(file: &Path, rrd: &Path) -> Value {
    let o = run_tool(
        Command::new(python())
            .arg(repo().join("scripts/readers/rerun_check.py"))
            .arg(file)
            .arg(rrd),
        "run scripts/test",
    );
    let err = &o.stderr;
    assert!(o.status.success(), "rerun_check.py failed:\n{err}");
    println!("--- rerun_check.py\n{err}");
    serde_json::from_str(&o.stdout)
        .unwrap_or_else(|e| panic!("rerun_check.py printed no JSON ({e})"))
}

/// The log time of a row of `rerun_check.py`'s output (a decimal string).
fn log_time_of(row: &Value) -> Option<u64> {
    row["log_time"].as_str().and_then(|s| s.parse().ok())
}

/// `x` stored as Rerun stores transforms: a 32-bit float (round to nearest), read back as f64.
fn as_f32(x: f64) -> f64 {
    f64::from(x as f32)
}

/// Differences between what Rerun made of a Protobuf recording (`doc`, from `rerun_check.py`) and the JSON
/// recording of the same scene: the transforms of the coin (and of the table) to f32, the numeric
/// channels bit for bit; each difference names topic, log time and field.
fn compare_rerun(doc: &Value, json: &[(String, u64, Value)]) -> Vec<String> {
    let mut out = Vec::new();
    let mut by_topic: BTreeMap<&str, Vec<(u64, &Value)>> = BTreeMap::new();
    for (topic, t, v) in json {
        by_topic.entry(topic).or_default().push((*t, v));
    }
    for (topic, messages) in &by_topic {
        if topic.starts_with("/coin/") {
            let empty = Vec::new();
            let rows = doc["messages"][topic].as_array().unwrap_or(&empty);
            if rows.len() != messages.len() {
                out.push(format!(
                    "{topic}: {} rows in Rerun, {} messages in JSON",
                    rows.len(),
                    messages.len()
                ));
                continue;
            }
            for ((t, m), row) in messages.iter().zip(rows) {
                let at = format!("{topic} at {t} ns");
                if log_time_of(row) != Some(*t) {
                    out.push(format!("{at}: Rerun row at {}", row["log_time"]));
                }
                let fields = m.as_object().unwrap();
                if fields.len() != row["fields"].as_object().map_or(0, |f| f.len()) {
                    out.push(format!("{at}: Rerun fields {}, JSON {m}", row["fields"]));
                }
                for (k, v) in fields {
                    let bits = v.as_f64().unwrap().to_bits();
                    if double_bits(row["fields"][k].as_str().unwrap_or("")) != Some(bits) {
                        out.push(format!(
                            "{at}.{k}: Rerun {}, JSON {v} (bits {bits:016x})",
                            row["fields"][k]
                        ));
                    }
                }
            }
        } else if doc["transforms"].get(topic).is_some() {
            let rows = doc["transforms"][topic].as_array().unwrap();
            if rows.len() != messages.len() {
                out.push(format!(
                    "{topic}: {} transforms in Rerun, {} messages in JSON",
                    rows.len(),
                    messages.len()
                ));
                continue;
            }
            for ((t, m), row) in messages.iter().zip(rows) {
                let at = format!(
                    "{topic} at {t} ns ({} → {})",
                    m["parent_frame_id"], m["child_frame_id"]
                );
                if log_time_of(row) != Some(*t)
                    || row["parent"] != m["parent_frame_id"]
                    || row["child"] != m["child_frame_id"]
                {
                    out.push(format!("{at}: Rerun row {row}"));
                    continue;
                }
                for (part, rerun_part, axes) in [
                    ("translation", "translation", &["x", "y", "z"][..]),
                    ("rotation", "quaternion", &["x", "y", "z", "w"][..]),
                ] {
                    for (i, axis) in axes.iter().enumerate() {
                        let want = as_f32(m[part][axis].as_f64().unwrap());
                        // Rerun leaves an all-zero translation unset: zero.
                        let got = row[rerun_part].get(i).map_or(Some(0.0), Value::as_f64);
                        if got != Some(want) {
                            out.push(format!(
                                "{at}: {part}.{axis} Rerun {got:?}, JSON as f32 {want:e}"
                            ));
                        }
                    }
                }
            }
        }
    }
    out.truncate(20);
    out
}

#[test]
fn rerun_converts_a_recording_into_the_coins_transforms_and_numeric_series() {
    let dir = tempfile::tempdir().unwrap();
    let (pb, json) = record_both(dir.path(), "wobble");
    let doc = rerun(&pb, &dir.path().join("wobble.rrd"));
    let json_messages = read_messages(&json);
    let topics: BTreeSet<&str> = json_messages.iter().map(|(t, _, _)| t.as_str()).collect();
    println!("Rerun {}: entities {}", doc["rerun"], doc["entities"]);
    // Every topic becomes the entity of the same path (Rerun's MCAP importer).
    for topic in &topics {
        assert!(
            doc["entities"].get(*topic).is_some(),
            "no entity {topic} in Rerun's {}",
            doc["entities"]
        );
    }
    // The transforms (foxglove.FrameTransform → Transform3D) and the coin_log.* messages (Protobuf
    // reflection: one struct component `<schema>:message` of f64 fields, for time-series views).
    assert_eq!(
        doc["entities"]["/tf"],
        serde_json::json!([
            "Transform3D:child_frame",
            "Transform3D:parent_frame",
            "Transform3D:quaternion",
            "Transform3D:translation"
        ])
    );
    assert_eq!(
        doc["entities"]["/coin/energy"],
        serde_json::json!(["coin_log.Energy:message"])
    );
    let coin = doc["transforms"]["/tf"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["child"] == "coin")
        .count();
    assert!(coin > 50, "{coin} transforms of the coin");
    let differences = compare_rerun(&doc, &json_messages);
    assert!(
        differences.is_empty(),
        "Rerun against the JSON recording:\n{}",
        differences.join("\n")
    );

    // Negative control: one transform value off by one f32 ulp, and one energy value off by one f64 ulp.
    let mut bad = doc.clone();
    let row = bad["transforms"]["/tf"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|r| r["child"] == "coin")
        .unwrap();
    let x = row["translation"][0].as_f64().unwrap() as f32;
    row["translation"][0] = serde_json::json!(f64::from(f32::from_bits(x.to_bits() + 1)));
    let total = &mut bad["messages"]["/coin/energy"][3]["fields"]["total"];
    let bits = double_bits(total.as_str().unwrap()).unwrap();
    *total = Value::String(format!("{:016x}", bits + 1));
    let differences = compare_rerun(&bad, &json_messages);
    assert_eq!(differences.len(), 2, "{differences:?}");
    assert!(
        differences[0].contains("/coin/energy") && differences[0].contains(".total"),
        "{differences:?}"
    );
    assert!(
        differences[1].contains("/tf") && differences[1].contains("translation.x"),
        "{differences:?}"
    );
}

/// `scripts/rerun_blueprint.py` writes a blueprint that Rerun's own check accepts (it checks its plotted
/// fields against `schemas/` first); the same check refuses the file cut in half.
#[test]
fn the_rerun_blueprint_is_one_rerun_accepts() {
    let dir = tempfile::tempdir().unwrap();
    let rbl = dir.path().join("coin-log.rbl");
    let o = run_tool(
        Command::new(python())
            .arg(repo().join("scripts/rerun_blueprint.py"))
            .arg(&rbl),
        "run scripts/test",
    );
    assert!(o.status.success(), "{}", o.stderr);
    let rerun = python().with_file_name("rerun");
    let verify = |path: &Path| {
        let o = run_tool(
            Command::new(&rerun).args(["rrd", "verify"]).arg(path),
            "run scripts/test",
        );
        (o.status.success(), o.stdout + &o.stderr)
    };
    let (ok, text) = verify(&rbl);
    assert!(ok, "rerun rrd verify refused the blueprint:\n{text}");
    let bytes = std::fs::read(&rbl).unwrap();
    let cut = dir.path().join("cut.rbl");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let (ok, text) = verify(&cut);
    assert!(!ok, "rerun rrd verify accepted half a blueprint:\n{text}");
}
