//! `record --encoding protobuf`: every built-in scene verifies exactly as its JSON recording does (same
//! verdict, same check values to the last bit), the bytes are reproducible, the Foxglove messages carry the
//! same frames and drawing as the JSON ones, export gives the same tables, and verify names what is wrong
//! with a damaged Protobuf file (negative controls).
// The helpers outside #[test] functions read files they just wrote: a failure there is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::record::{coin_log_text, read_back, record_scene, scene_names};
use crate::support::writers::rewrite_protobuf;
use coin_log::format::messages::put_double;
use coin_log::verify::{verify_file, CheckId, Options, Status};
use foxglove::messages::{
    CubePrimitive, CylinderPrimitive, FrameTransform, LinePrimitive, Pose, SceneEntity, SceneUpdate,
};
use prost::Message;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::Path;

/// Records `scene` in both encodings into `dir` (`<scene>.json.mcap`, `<scene>.protobuf.mcap`).
fn record_both(dir: &Path, scene: &str, extra: &[&str]) -> [std::path::PathBuf; 2] {
    ["json", "protobuf"].map(|encoding| {
        let sub = dir.join(encoding);
        std::fs::create_dir_all(&sub).unwrap();
        record_scene(
            &sub,
            scene,
            &[&["--encoding", encoding][..], extra].concat(),
        )
    })
}

#[test]
fn every_built_in_scene_verifies_the_same_in_both_encodings() {
    let dir = tempfile::tempdir().unwrap();
    for scene in scene_names() {
        // Ten time units keep the suite fast; runs that end at an event end earlier.
        let [json, protobuf] = record_both(dir.path(), &scene, &["--duration", "10"]);
        let (a, b) = (
            verify_file(&json, &Options::default()),
            verify_file(&protobuf, &Options::default()),
        );
        assert_eq!(
            b.exit_code, 0,
            "{scene}: the Protobuf recording does not verify: {b:?}"
        );
        assert_eq!(
            (a.verdict, a.exit_code),
            (b.verdict, b.exit_code),
            "{scene}"
        );
        for (x, y) in a.checks.iter().zip(&b.checks) {
            assert_eq!((x.id, x.status), (y.id, y.status), "{scene}");
            // The same f64s go through the same checks: equal to the last bit.
            assert_eq!(
                x.value.map(f64::to_bits),
                y.value.map(f64::to_bits),
                "{scene} {:?}: JSON {:?} vs Protobuf {:?}",
                x.id,
                x.value,
                y.value
            );
            assert_eq!(x.tolerance.map(f64::to_bits), y.tolerance.map(f64::to_bits));
        }
        let sizes = [&json, &protobuf].map(|p| std::fs::metadata(p).unwrap().len());
        println!(
            "{scene:<18} JSON {:>9} B, Protobuf {:>9} B",
            sizes[0], sizes[1]
        );
    }
}

#[test]
fn a_protobuf_recording_is_the_same_bytes_every_time_and_says_its_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let a = record_scene(dir.path(), "circle-plus", &["--encoding", "protobuf"]);
    let first = std::fs::read(&a).unwrap();
    let b = record_scene(dir.path(), "circle-plus", &["--encoding", "protobuf"]);
    assert!(first == std::fs::read(&b).unwrap(), "two recordings differ");
    let file = read_back(&first);
    for channel in file.summary.channels.values() {
        assert_eq!(channel.message_encoding, "protobuf", "{}", channel.topic);
        let schema = channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "protobuf", "{}", schema.name);
        // A serialized FileDescriptorSet that declares the schema's type.
        let set = prost_types::FileDescriptorSet::decode(&schema.data[..]).unwrap();
        let declared = set.file.iter().any(|f| {
            f.message_type
                .iter()
                .any(|m| format!("{}.{}", f.package(), m.name()) == schema.name)
        });
        assert!(declared, "{} does not declare its type", schema.name);
    }
    let (code, out, _) = coin_log_text(&["info", a.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0);
    let info: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(info["files"][0]["encoding"], "protobuf");
    // A run longer than Foxglove's 32-bit seconds is refused before anything is written, with the way out;
    // the same run in JSON is fine (negative control).
    let long = [
        "record",
        "wobble",
        "--duration",
        "5e9",
        "--rate",
        "0.01",
        "--dry-run",
        "--encoding",
    ];
    let (code, _, err) = coin_log_text(&[&long[..], &["protobuf"]].concat());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("run.duration = 5000000000") && err.contains("--encoding json"),
        "{err}"
    );
    let (code, _, err) = coin_log_text(&[&long[..], &["json"]].concat());
    assert_eq!(code, 0, "{err}");
    // A bad value names the choices (clap), exit 2.
    let (code, _, err) = coin_log_text(&["record", "wobble", "--encoding", "cbor", "--dry-run"]);
    assert_eq!(code, 2);
    assert!(err.contains("json") && err.contains("protobuf"), "{err}");
}

fn vector(x: f64, y: f64, z: f64) -> Value {
    json!({"x": x, "y": y, "z": z})
}

fn pose(p: Option<&Pose>) -> Value {
    let p = p.cloned().unwrap_or_default();
    let (t, q) = (
        p.position.unwrap_or_default(),
        p.orientation.unwrap_or_default(),
    );
    json!({"position": vector(t.x, t.y, t.z), "orientation": {"x": q.x, "y": q.y, "z": q.z, "w": q.w}})
}

fn color(c: Option<&foxglove::messages::Color>) -> Value {
    let c = c.cloned().unwrap_or_default();
    json!({"r": c.r, "g": c.g, "b": c.b, "a": c.a})
}

fn cube(c: &CubePrimitive) -> Value {
    let s = c.size.unwrap_or_default();
    json!({"pose": pose(c.pose.as_ref()), "size": vector(s.x, s.y, s.z), "color": color(c.color.as_ref())})
}

fn cylinder(c: &CylinderPrimitive) -> Value {
    let s = c.size.unwrap_or_default();
    json!({"pose": pose(c.pose.as_ref()), "size": vector(s.x, s.y, s.z), "bottom_scale": c.bottom_scale,
           "top_scale": c.top_scale, "color": color(c.color.as_ref())})
}

fn line(l: &LinePrimitive) -> Value {
    let points: Vec<Value> = l.points.iter().map(|p| vector(p.x, p.y, p.z)).collect();
    json!({"type": l.r#type, "pose": pose(l.pose.as_ref()), "thickness": l.thickness,
           "scale_invariant": l.scale_invariant, "points": points, "color": color(l.color.as_ref()),
           "colors": [], "indices": []})
}

fn time(t: Option<foxglove::messages::Timestamp>) -> Value {
    let t = t.unwrap_or_default();
    json!({"sec": t.sec(), "nsec": t.nsec()})
}

fn entity(e: &SceneEntity) -> Value {
    let lifetime = e.lifetime.unwrap_or_default();
    json!({"timestamp": time(e.timestamp), "frame_id": e.frame_id, "id": e.id,
           "lifetime": {"sec": lifetime.sec(), "nsec": lifetime.nsec()}, "frame_locked": e.frame_locked,
           "metadata": [], "arrows": [], "cubes": e.cubes.iter().map(cube).collect::<Vec<_>>(), "spheres": [],
           "cylinders": e.cylinders.iter().map(cylinder).collect::<Vec<_>>(),
           "lines": e.lines.iter().map(line).collect::<Vec<_>>(), "triangles": [], "texts": [], "models": []})
}

/// A decoded Protobuf Foxglove message in the shape of coin-log's JSON of the same message.
fn as_json(schema: &str, data: &[u8]) -> Value {
    if schema == "foxglove.FrameTransform" {
        let m = FrameTransform::decode(data).unwrap();
        let (t, q) = (
            m.translation.unwrap_or_default(),
            m.rotation.unwrap_or_default(),
        );
        return json!({"timestamp": time(m.timestamp), "parent_frame_id": m.parent_frame_id,
            "child_frame_id": m.child_frame_id, "translation": vector(t.x, t.y, t.z),
            "rotation": {"x": q.x, "y": q.y, "z": q.z, "w": q.w}});
    }
    let m = SceneUpdate::decode(data).unwrap();
    let deletions: Vec<Value> = m
        .deletions
        .iter()
        .map(|d| json!({"timestamp": time(d.timestamp), "type": d.r#type, "id": d.id}))
        .collect();
    json!({"deletions": deletions, "entities": m.entities.iter().map(entity).collect::<Vec<_>>()})
}

/// Equal as JSON values, numbers compared as f64 (so 0 == 0.0 == -0.0: proto3 does not write a zero,
/// and a −0 comes back as 0).
fn same(a: &Value, b: &Value, path: &str) -> Result<(), String> {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) if x.as_f64() == y.as_f64() => Ok(()),
        (Value::Object(x), Value::Object(y)) => {
            let keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            for k in keys {
                let missing = Value::Null;
                same(
                    x.get(k).unwrap_or(&missing),
                    y.get(k).unwrap_or(&missing),
                    &format!("{path}.{k}"),
                )?;
            }
            Ok(())
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .try_for_each(|(i, (p, q))| same(p, q, &format!("{path}[{i}]"))),
        _ if a == b => Ok(()),
        _ => Err(format!("{path}: JSON {a} vs Protobuf {b}")),
    }
}

#[test]
fn the_foxglove_messages_carry_the_same_frames_and_drawing_in_both_encodings() {
    let dir = tempfile::tempdir().unwrap();
    let [json, protobuf] = record_both(dir.path(), "wobble", &["--duration", "8"]);
    let (a, b) = (
        read_back(&std::fs::read(json).unwrap()),
        read_back(&std::fs::read(protobuf).unwrap()),
    );
    assert_eq!(a.messages.len(), b.messages.len());
    let mut compared: BTreeMap<String, usize> = BTreeMap::new();
    for (x, y) in a.messages.iter().zip(&b.messages) {
        assert_eq!((&x.topic, x.log_time), (&y.topic, y.log_time));
        if !x.schema_name.starts_with("foxglove.") {
            continue;
        }
        let expected: Value = serde_json::from_slice(&x.data).unwrap();
        let got = as_json(&y.schema_name, &y.data);
        if let Err(e) = same(&expected, &got, &x.topic) {
            panic!("{} at {} ns: {e}", x.topic, x.log_time);
        }
        *compared.entry(x.topic.clone()).or_default() += 1;
    }
    for topic in [
        "/tf",
        "/tf_static",
        "/scene",
        "/scene/follow",
        "/scene/table",
        "/scene/track/0",
    ] {
        assert!(
            compared.get(topic).copied().unwrap_or(0) > 0,
            "no {topic} compared: {compared:?}"
        );
    }
    // Negative control: a coin mark one hundredth off is told apart.
    let mut m = SceneUpdate::decode(&b.on_topic("/scene")[0].data[..]).unwrap();
    let c = &mut m.entities[0].cubes[0];
    c.size.as_mut().unwrap().x += 0.01;
    let expected: Value = serde_json::from_slice(&a.on_topic("/scene")[0].data).unwrap();
    let err = same(
        &expected,
        &as_json("foxglove.SceneUpdate", &m.encode_to_vec()),
        "/scene",
    );
    assert!(err.unwrap_err().contains("size.x"));
}

#[test]
fn export_gives_the_same_tables_from_both_encodings() {
    let dir = tempfile::tempdir().unwrap();
    let paths = record_both(dir.path(), "circle-plus", &["--duration", "5"]);
    let tables = paths.map(|p| {
        let out = p.with_extension("csv.d");
        let (code, _, err) = coin_log_text(&[
            "export",
            p.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        out
    });
    let mut names: Vec<_> = std::fs::read_dir(&tables[0])
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert!(names.len() >= 10, "{names:?}");
    for name in names {
        let [x, y] =
            [&tables[0], &tables[1]].map(|d| std::fs::read_to_string(d.join(&name)).unwrap());
        assert_eq!(x.lines().count(), y.lines().count(), "{name:?}");
        for (p, q) in x.lines().zip(y.lines()) {
            // Cells equal as text, or as numbers where a −0 came back as 0 (see `same`).
            for (u, v) in p.split(',').zip(q.split(',')) {
                let equal = u == v
                    || matches!((u.parse::<f64>(), v.parse::<f64>()), (Ok(a), Ok(b)) if a == b);
                assert!(equal, "{name:?}: {p} vs {q}");
            }
        }
    }
}

/// The report of `path`: its exit code and the integrity check's reason.
fn judged(path: &Path) -> (u8, Status, String) {
    let r = verify_file(path, &Options::default());
    let integrity = r.check(CheckId::Integrity).cloned();
    let reason = integrity
        .as_ref()
        .map(|c| c.reason.clone())
        .unwrap_or_default();
    let status = integrity.map_or(Status::Skip, |c| c.status);
    (
        r.exit_code,
        status,
        format!("{reason} {}", r.problem.unwrap_or_default()),
    )
}

#[test]
fn verify_names_what_is_wrong_with_a_damaged_protobuf_file() {
    let dir = tempfile::tempdir().unwrap();
    let src = record_scene(
        dir.path(),
        "wobble",
        &["--encoding", "protobuf", "--duration", "5"],
    );
    let out = dir.path().join("damaged.mcap");
    let keep = |_: &str, d: &[u8]| d.to_vec();
    let protobuf = |_: &str| "protobuf";
    // The control: an untouched copy by another writer verifies.
    rewrite_protobuf(&src, &out, keep, protobuf, |_, _, _| {});
    let (code, status, reason) = judged(&out);
    assert_eq!((code, status), (0, Status::Pass), "{reason}");

    // A NaN in one energy message (field 2, `total`, appended: the last value wins).
    rewrite_protobuf(&src, &out, keep, protobuf, |topic, i, data| {
        if topic == "/coin/energy" && i == 7 {
            put_double(data, 2, f64::NAN);
        }
    });
    let (code, status, reason) = judged(&out);
    assert_eq!((code, status), (1, Status::Fail), "{reason}");
    assert!(
        reason.contains("/coin/energy") && reason.contains("`total` = NaN"),
        "{reason}"
    );

    // A message cut short.
    rewrite_protobuf(&src, &out, keep, protobuf, |topic, i, data| {
        if topic == "/coin/omega" && i == 3 {
            data.truncate(data.len() - 3);
        }
    });
    let (_, status, reason) = judged(&out);
    assert_eq!(status, Status::Fail);
    assert!(reason.contains("not a valid Protobuf message"), "{reason}");

    // A Foxglove message that is not one.
    rewrite_protobuf(&src, &out, keep, protobuf, |topic, i, data| {
        if topic == "/tf" && i == 2 {
            *data = vec![0xff; 5];
        }
    });
    let (_, status, reason) = judged(&out);
    assert_eq!(status, Status::Fail);
    assert!(
        reason.contains("/tf: message at") && reason.contains("Protobuf"),
        "{reason}"
    );

    // A channel that says JSON over a Protobuf schema.
    let json_omega = |topic: &str| {
        if topic == "/coin/omega" {
            "json"
        } else {
            "protobuf"
        }
    };
    rewrite_protobuf(&src, &out, keep, json_omega, |_, _, _| {});
    let (_, status, reason) = judged(&out);
    assert_eq!(status, Status::Fail);
    assert!(
        reason.contains("message encoding \"json\", not \"protobuf\""),
        "{reason}"
    );

    // A descriptor that lacks a field the messages need.
    let no_psi = |name: &str, d: &[u8]| {
        let mut set = prost_types::FileDescriptorSet::decode(d).unwrap();
        if name == "coin_log.Angles" {
            set.file[0].message_type[0]
                .field
                .retain(|f| f.name() != "psi");
        }
        set.encode_to_vec()
    };
    rewrite_protobuf(&src, &out, no_psi, protobuf, |_, _, _| {});
    let (_, status, reason) = judged(&out);
    assert_eq!(status, Status::Fail);
    assert!(reason.contains("does not declare field `psi`"), "{reason}");

    // The physics checks read the Protobuf values: E one part in a million off fails `energy`.
    rewrite_protobuf(&src, &out, keep, protobuf, |topic, i, data| {
        if topic == "/coin/energy" && i == 100 {
            // Field 1 (t) is bytes 0..9; field 2's value (`total`) follows its key at byte 9.
            let total = f64::from_le_bytes(data[10..18].try_into().unwrap());
            put_double(data, 2, total * (1.0 + 1e-6));
        }
    });
    let r = verify_file(&out, &Options::default());
    let energy = r.check(CheckId::Energy).unwrap();
    assert_eq!(energy.status, Status::Fail, "{energy:?}");
}
