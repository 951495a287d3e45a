//! Independent readers in CI (issue 6): every committed dataset and a fresh recording are read with
//! `@mcap/core`'s indexed reader (the library Foxglove uses; `scripts/readers/check.mjs`) and with the
//! Python `mcap` package (`scripts/readers/check.py`): all messages decoded, counts equal to the statistics,
//! `foxglove.*` messages valid against `@foxglove/schemas`, `coin_log.*` against `schemas/`.
//! A negative control proves the readers refuse a file that breaks the schema.
//!
//! The tools are installed by `scripts/test`; a missing one fails the test (never skips it).

// Test helpers outside #[test] functions panic on any setup failure by design.
#![allow(clippy::unwrap_used)]

use coin_log::integrate::{Flow, Rk4, RunSettings};
use coin_log::model::{
    centre, contact_point, energy, orientation, reaction, Branch, Coin, CoinParams, State, Steady,
    SteadyKind,
};
use coin_log::record::messages::{
    Angles, AngularVelocity, EnergyMessage, Position, QuaternionMessage, ReactionMessage,
};
use coin_log::record::{
    schema_bytes, Channel, Foxglove3d, FoxgloveBatch, MESSAGE_ENCODING, SCHEMA_ENCODING,
};
use coin_log::simulation::{simulate, CoinEvents};
use coin_log::units::log_time;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn python() -> PathBuf {
    let p = repo().join(".venv/bin/python");
    assert!(
        p.exists(),
        "{} is missing: run scripts/test (it creates the venv with the Python `mcap` and `jsonschema` packages)",
        p.display()
    );
    p
}

fn node_readers() -> PathBuf {
    let dir = repo().join("scripts/readers");
    assert!(
        dir.join("node_modules/@mcap/core").exists(),
        "scripts/readers/node_modules is missing: run scripts/test (it runs `npm ci` there)"
    );
    dir
}

/// Runs both readers on `files`; returns (success, output) of each.
fn run_readers(files: &[PathBuf]) -> [(bool, String); 2] {
    let node = Command::new("node")
        .arg(node_readers().join("check.mjs"))
        .args(files)
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run `node` ({e}): install Node.js 20 and run scripts/test")
        });
    let py = Command::new(python())
        .arg(repo().join("scripts/readers/check.py"))
        .args(files)
        .output()
        .unwrap_or_else(|e| panic!("cannot run the venv's python ({e}): run scripts/test"));
    [node, py].map(|o| {
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        (o.status.success(), text)
    })
}

/// How the helper damages a file, for negative controls.
#[derive(Clone, Copy, PartialEq)]
enum Damage {
    None,
    /// One SceneUpdate entity without its required `metadata`.
    SceneEntityWithoutMetadata,
    /// One energy message with a field the schema does not declare.
    EnergyWithExtraField,
}

/// Records a steady circle (θ₀ = 0.3, ω_Z = 1, + branch) for `duration` at 100 samples per time unit with
/// the library's pieces (model, rk4, messages, Foxglove output) straight into an MCAP file.
fn record_circle(path: &Path, duration: f64, damage: Damage) {
    let coin = Coin::new(CoinParams::unit_disk());
    let steady = Steady::new(
        &coin,
        SteadyKind::Circle {
            theta: 0.3,
            omega_z: 1.0,
            branch: Branch::Plus,
        },
    )
    .unwrap();
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .chunk_size(Some(64 * 1024))
        .create(file)
        .unwrap();
    let mut ids = BTreeMap::new();
    let channels = [
        Channel::Omega,
        Channel::Angles,
        Channel::Quaternion,
        Channel::Position,
        Channel::Contact,
        Channel::Reaction,
        Channel::Energy,
        Channel::Tf,
        Channel::Scene,
    ];
    for c in channels {
        let schema = w
            .add_schema(
                c.schema_name(),
                SCHEMA_ENCODING,
                schema_bytes(c.schema_name()).unwrap(),
            )
            .unwrap();
        let id = w
            .add_channel(schema, c.topic(), MESSAGE_ENCODING, &BTreeMap::new())
            .unwrap();
        ids.insert(c, id);
    }
    w.write_metadata(&mcap::records::Metadata {
        name: "coin-log".into(),
        metadata: BTreeMap::from([("format_version".to_string(), "1".to_string())]),
    })
    .unwrap();
    let mut fox = Foxglove3d::new(&coin, 0.05, true, true);
    let mut batch = FoxgloveBatch::default();
    let mut buf = Vec::new();
    let mut sequence = 0u32;
    let mut damaged = false;
    let settings = RunSettings {
        t0: 0.0,
        t_end: duration,
        sample_interval: 0.01,
    };
    let events = CoinEvents::new(coin, 1e-4, None);
    let mut rk4 = Rk4::new(1e-3);
    simulate(
        &coin,
        &mut rk4,
        &steady.state,
        &settings,
        &events,
        |t, y| {
            let s = State::from_array(y);
            let lt = log_time(t).unwrap();
            let mut write = |c: Channel, data: &[u8]| {
                sequence += 1;
                w.write_to_known_channel(
                    &mcap::records::MessageHeader {
                        channel_id: ids[&c],
                        sequence,
                        log_time: lt,
                        publish_time: lt,
                    },
                    data,
                )
                .unwrap();
            };
            let g = centre(&coin, &s);
            let p = contact_point(&coin, &s);
            let q = orientation(&s);
            let e = energy(&coin, &s);
            let r = reaction(&coin, &s);
            let msgs: [(Channel, &Writer); 7] = [
                (Channel::Omega, &|b| {
                    AngularVelocity {
                        t,
                        x: s.omega_x,
                        y: s.omega_y,
                        z: s.omega_z,
                    }
                    .write_json(b)
                    .unwrap()
                }),
                (Channel::Angles, &|b| {
                    Angles {
                        t,
                        theta: s.theta,
                        phi: s.phi,
                        psi: s.psi,
                    }
                    .write_json(b)
                    .unwrap()
                }),
                (Channel::Quaternion, &|b| {
                    QuaternionMessage {
                        t,
                        x: q.x,
                        y: q.y,
                        z: q.z,
                        w: q.w,
                    }
                    .write_json(b)
                    .unwrap()
                }),
                (Channel::Position, &|b| {
                    Position {
                        t,
                        x: g.x,
                        y: g.y,
                        z: g.z,
                    }
                    .write_json(b)
                    .unwrap()
                }),
                (Channel::Contact, &|b| {
                    Position {
                        t,
                        x: p.x,
                        y: p.y,
                        z: p.z,
                    }
                    .write_json(b)
                    .unwrap()
                }),
                (Channel::Reaction, &|b| {
                    ReactionMessage {
                        t,
                        x: r.force.x,
                        y: r.force.y,
                        z: r.force.z,
                        friction: r.friction,
                        normal: r.normal,
                    }
                    .write_json(b)
                    .unwrap()
                }),
                (Channel::Energy, &|b| {
                    EnergyMessage {
                        t,
                        total: e.total,
                        kinetic: e.kinetic,
                        potential: e.potential,
                    }
                    .write_json(b)
                    .unwrap()
                }),
            ];
            for (c, f) in msgs {
                buf.clear();
                f(&mut buf);
                if c == Channel::Energy
                    && damage == Damage::EnergyWithExtraField
                    && t > 0.5
                    && !damaged
                {
                    buf.pop();
                    buf.extend_from_slice(b",\"power\":0}");
                    damaged = true;
                }
                write(c, &buf);
            }
            batch.clear();
            let last = (t - duration).abs() < 1e-9;
            fox.sample(t, lt, &s, last, &mut batch).unwrap();
            for (c, data) in batch.iter() {
                if c == Channel::Scene
                    && damage == Damage::SceneEntityWithoutMetadata
                    && t > 0.5
                    && !damaged
                {
                    let text = String::from_utf8(data.to_vec()).unwrap();
                    write(c, text.replacen("\"metadata\":[],", "", 1).as_bytes());
                    damaged = true;
                } else {
                    write(c, data);
                }
            }
            Flow::Continue
        },
    );
    w.finish().unwrap();
}

/// Writes one message into a buffer.
type Writer<'a> = dyn Fn(&mut Vec<u8>) + 'a;

fn datasets() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo().join("datasets"))
        .map(|d| {
            d.filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    files
}

#[test]
fn both_independent_readers_accept_every_dataset_and_a_fresh_recording() {
    let dir = tempfile::tempdir().unwrap();
    let fresh = dir.path().join("fresh-circle.mcap");
    record_circle(&fresh, 3.0, Damage::None);
    let mut files = datasets();
    files.push(fresh);
    let [(node_ok, node_out), (py_ok, py_out)] = run_readers(&files);
    println!("--- @mcap/core (check.mjs)\n{node_out}--- python mcap (check.py)\n{py_out}");
    assert!(node_ok, "@mcap/core reader refused a file:\n{node_out}");
    assert!(py_ok, "python mcap reader refused a file:\n{py_out}");
    for out in [&node_out, &py_out] {
        assert!(
            out.contains(&format!("{} passed, 0 failed", files.len())),
            "every file checked: {out}"
        );
    }
}

#[test]
fn both_readers_refuse_a_scene_entity_without_a_required_field() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad-scene.mcap");
    record_circle(&bad, 1.0, Damage::SceneEntityWithoutMetadata);
    let [(node_ok, node_out), (py_ok, py_out)] = run_readers(&[bad]);
    println!("--- check.mjs\n{node_out}--- check.py\n{py_out}");
    assert!(!node_ok && node_out.contains("metadata"), "{node_out}");
    assert!(!py_ok && py_out.contains("metadata"), "{py_out}");
}

#[test]
fn both_readers_refuse_a_coin_log_message_with_an_undeclared_field() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad-energy.mcap");
    record_circle(&bad, 1.0, Damage::EnergyWithExtraField);
    let [(node_ok, node_out), (py_ok, py_out)] = run_readers(&[bad]);
    println!("--- check.mjs\n{node_out}--- check.py\n{py_out}");
    assert!(!node_ok && node_out.contains("power"), "{node_out}");
    assert!(!py_ok && py_out.contains("power"), "{py_out}");
}
