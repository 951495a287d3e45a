//! Shared helpers of the integration tests that write MCAP files without the recorder: the message JSON of
//! a state computed from the model and the message types alone (what the recorder must write, so tests that
//! check the recorder do not compare it with itself), the schema and channel registration, and a small
//! recording written with the library's pieces. Used by tests/external_readers.rs, tests/foxglove.rs,
//! tests/record_roundtrip.rs and, through tests/common_verify, by the verify tests.

// Every tests/*.rs is its own crate and uses only some of these helpers: the rest are dead code there.
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
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

/// The eight per-sample `coin_log.*` channels, in the contract's order (no Foxglove channels).
pub const COIN_CHANNELS: [Channel; 8] = [
    Channel::Omega,
    Channel::Angles,
    Channel::Quaternion,
    Channel::Position,
    Channel::Contact,
    Channel::Reaction,
    Channel::Energy,
    Channel::Invariants,
];

/// The JSON of per-sample channel `c` (one of [`COIN_CHANNELS`]) at state `s`, time `t`, computed here from
/// the model's functions and the message types, independently of the recorder.
pub fn message_json(coin: &Coin, chaplygin: &Chaplygin, c: Channel, t: f64, s: &State) -> Vec<u8> {
    let mut buf = Vec::new();
    match c {
        Channel::Omega => AngularVelocity {
            t,
            x: s.omega_x,
            y: s.omega_y,
            z: s.omega_z,
        }
        .write_json(&mut buf),
        Channel::Angles => Angles {
            t,
            theta: s.theta,
            phi: s.phi,
            psi: s.psi,
        }
        .write_json(&mut buf),
        Channel::Quaternion => {
            let q = orientation(s);
            QuaternionMessage {
                t,
                x: q.x,
                y: q.y,
                z: q.z,
                w: q.w,
            }
            .write_json(&mut buf)
        }
        Channel::Position | Channel::Contact => {
            let p = if c == Channel::Position {
                centre(coin, s)
            } else {
                contact_point(coin, s)
            };
            Position {
                t,
                x: p.x,
                y: p.y,
                z: p.z,
            }
            .write_json(&mut buf)
        }
        Channel::Reaction => {
            let r = reaction(coin, s);
            ReactionMessage {
                t,
                x: r.force.x,
                y: r.force.y,
                z: r.force.z,
                friction: r.friction,
                normal: r.normal,
            }
            .write_json(&mut buf)
        }
        Channel::Energy => {
            let e = energy(coin, s);
            EnergyMessage {
                t,
                total: e.total,
                kinetic: e.kinetic,
                potential: e.potential,
            }
            .write_json(&mut buf)
        }
        Channel::Invariants => {
            let i = chaplygin.of_state(s);
            InvariantsMessage {
                t,
                c1: i.c1,
                c2: i.c2,
            }
            .write_json(&mut buf)
        }
        _ => panic!("channel {c} is not a per-sample coin_log channel"),
    }
    .unwrap();
    buf
}

/// This tool's bytes of schema `name`.
pub fn tool_schema(name: &str) -> Vec<u8> {
    schema_bytes(name).unwrap().to_vec()
}

/// Registers channel `c` in `w` (JSON messages, no metadata) with schema bytes `schema_of(name)`, each schema
/// once (`schemas` maps the names registered so far to their ids); returns the channel id.
pub fn add_channel<W: Write + Seek>(
    w: &mut mcap::Writer<W>,
    schemas: &mut BTreeMap<&'static str, u16>,
    c: Channel,
    schema_of: &dyn Fn(&str) -> Vec<u8>,
) -> u16 {
    let name = c.schema_name();
    let schema = match schemas.get(name) {
        Some(id) => *id,
        None => {
            let id = w
                .add_schema(name, SCHEMA_ENCODING, &schema_of(name))
                .unwrap();
            schemas.insert(name, id);
            id
        }
    };
    w.add_channel(schema, c.topic(), MESSAGE_ENCODING, &BTreeMap::new())
        .unwrap()
}

/// Writes one message on channel `channel_id`, its publish time equal to its log time `lt`.
pub fn write_message<W: Write + Seek>(
    w: &mut mcap::Writer<W>,
    channel_id: u16,
    sequence: u32,
    lt: u64,
    data: &[u8],
) {
    w.write_to_known_channel(
        &mcap::records::MessageHeader {
            channel_id,
            sequence,
            log_time: lt,
            publish_time: lt,
        },
        data,
    )
    .unwrap();
}

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
    let mut schemas = BTreeMap::new();
    let ids: BTreeMap<Channel, u16> = COIN_CHANNELS
        .into_iter()
        .chain([Channel::Tf, Channel::Scene])
        .map(|c| (c, add_channel(&mut w, &mut schemas, c, &tool_schema)))
        .collect();
    w.write_metadata(&mcap::records::Metadata {
        name: "coin-log".into(),
        metadata: BTreeMap::from([("format_version".to_string(), "1".to_string())]),
    })
    .unwrap();
    let mut fox = Foxglove3d::new(&coin, 0.05, true, true);
    let mut batch = FoxgloveBatch::default();
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
                write_message(&mut w, ids[&c], sequence, lt, data);
            };
            for c in COIN_CHANNELS {
                let mut buf = message_json(&coin, &chaplygin, c, t, &s);
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
