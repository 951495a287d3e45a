//! Shared helpers of the integration tests: a small recording written with the library's pieces.

// Test helpers panic on any setup failure by design.
#![allow(clippy::unwrap_used, dead_code)]

use coin_log::integrate::{Flow, Rk4, RunSettings};
use coin_log::model::{
    centre, contact_point, energy, orientation, reaction, Branch, Chaplygin, Coin, CoinParams,
    State, Steady, SteadyKind,
};
use coin_log::record::messages::{
    Angles, AngularVelocity, EnergyMessage, InvariantsMessage, Position, QuaternionMessage,
    ReactionMessage,
};
use coin_log::record::{
    schema_bytes, Channel, Foxglove3d, FoxgloveBatch, MESSAGE_ENCODING, SCHEMA_ENCODING,
};
use coin_log::simulation::{simulate, CoinEvents};
use coin_log::units::log_time;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The repository root.
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// How the helper damages a file, for negative controls.
#[derive(Clone, Copy, PartialEq)]
pub enum Damage {
    None,
    /// One SceneUpdate entity without its required `metadata`.
    SceneEntityWithoutMetadata,
    /// One energy message with a field the schema does not declare.
    EnergyWithExtraField,
}

/// Records a steady circle (θ₀ = 0.3, ω_Z = 1, + branch) for `duration` at 100 samples per time unit with
/// the library's pieces (model, rk4, messages, Foxglove output) straight into an MCAP file.
pub fn record_circle(path: &Path, duration: f64, damage: Damage) {
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
        Channel::Invariants,
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
    let chaplygin = Chaplygin::new(coin.params()).unwrap();
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
            let c = chaplygin.of_state(&s);
            let msgs: [(Channel, &Writer); 8] = [
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
                (Channel::Invariants, &|b| {
                    InvariantsMessage {
                        t,
                        c1: c.c1,
                        c2: c.c2,
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

/// Every message of an MCAP file as (topic, log time, JSON value), in file order.
pub fn read_messages(path: &Path) -> Vec<(String, u64, serde_json::Value)> {
    let bytes = std::fs::read(path).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            assert_eq!(m.log_time, m.publish_time);
            (
                m.channel.topic.clone(),
                m.log_time,
                serde_json::from_slice(&m.data).unwrap(),
            )
        })
        .collect()
}
