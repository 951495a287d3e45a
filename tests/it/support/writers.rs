//! Coin-log MCAP files written with the mcap crate straight from the model and the message types, not by
//! the recorder (so tests that check the recorder do not compare it with itself, and files the recorder
//! cannot make: odd channel sets, small or uncompressed chunks, Foxglove output with a defect), and a
//! recording rewritten with one message or schema changed (negative controls).
// Test helpers are not #[test] functions, so clippy.toml's allow-unwrap-in-tests does not reach them; a
// failed unwrap here is a failed test, which is what we want.
#![allow(clippy::unwrap_used)]

use coin_log::format::messages::{
    Angles, AngularVelocity, EnergyMessage, InvariantsMessage, Position, QuaternionMessage,
    ReactionMessage, WorkMessage,
};
use coin_log::format::{
    log_time, schema_bytes, Channel, Encoding, ResultMetadata, Topic, RESULT_METADATA_NAME,
    RUN_METADATA_NAME,
};
use coin_log::integrate::{run_method, Flow, Method, MethodConfig, NoEvents, RunEnd, RunSettings};
use coin_log::model::{
    centre, contact_point, energy, orientation, Branch, Chaplygin, Coin, CoinParams, Dynamics,
    State, Steady, SteadyKind, STATE_LEN,
};
use coin_log::scene::{file_from_table, set_value, Scene};
use coin_log::simulation::CoinEvents;
// `record_circle`'s (the independent readers' tests).
#[cfg(feature = "external-readers")]
use coin_log::record::{Foxglove3d, FoxgloveBatch};
use std::collections::BTreeMap;
use std::io::{BufWriter, Seek, Write};
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
/// the model's functions and the message types, independently of the recorder; `e0` is the energy at the
/// first sample (E₀ of the energy's `change`).
pub fn message_json(
    coin: &Coin,
    chaplygin: &Chaplygin,
    c: Channel,
    t: f64,
    s: &State,
    e0: f64,
) -> Vec<u8> {
    message_json_with(&Dynamics::Conservative(*coin), chaplygin, c, t, s, None, e0)
}

/// [`message_json`] for any dynamics: the reaction follows them (physics §11), and `/coin/work` carries W
/// (`work`, for a dissipative run) and E + W.
pub fn message_json_with(
    dynamics: &Dynamics,
    chaplygin: &Chaplygin,
    c: Channel,
    t: f64,
    s: &State,
    work: Option<f64>,
    e0: f64,
) -> Vec<u8> {
    let coin = dynamics.coin();
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
            // φ̇ = ω_Y / cos θ, physics eq (18).
            phi_dot: Some(s.omega_y / s.theta.cos()),
        }
        .write_json(&mut buf),
        Channel::Quaternion => {
            let q = orientation(s);
            QuaternionMessage {
                t,
                x: q.i,
                y: q.j,
                z: q.k,
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
            let r = dynamics.reaction(s);
            ReactionMessage {
                t,
                x: r.force.x,
                y: r.force.y,
                z: r.force.z,
                friction: r.friction,
                normal: r.normal,
                // F / max(N, 1e-12 Mg), docs/format.md.
                friction_ratio: Some(
                    r.friction
                        / r.normal
                            .max(1e-12 * coin.params().mass() * coin.params().gravity()),
                ),
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
                change: Some(e.total - e0),
                // (E − E₀)/(ε max(|E₀|, Mga)), written out here rather than taken from the library.
                drift_eps: Some(
                    (e.total - e0) / (f64::EPSILON * e0.abs().max(coin.params().energy_scale())),
                ),
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
        Channel::Work => {
            let Some(w) = work else {
                panic!("the work channel needs W")
            };
            WorkMessage {
                t,
                dissipated: w,
                balance: energy(coin, s).total + w,
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

/// Registers topic `c` (a channel's main topic, or a Foxglove extra) in `w` (JSON messages, no metadata) with
/// schema bytes `schema_of(name)`, each schema once (`schemas` maps the names registered so far to their ids);
/// returns the channel id.
pub fn add_channel<W: Write + Seek>(
    w: &mut mcap::Writer<W>,
    schemas: &mut BTreeMap<&'static str, u16>,
    c: Topic,
    schema_of: &dyn Fn(&str) -> Vec<u8>,
) -> u16 {
    let name = c.schema_name();
    let schema = match schemas.get(name) {
        Some(id) => *id,
        None => {
            let id = w
                .add_schema(name, Encoding::Json.schema_encoding(), &schema_of(name))
                .unwrap();
            schemas.insert(name, id);
            id
        }
    };
    w.add_channel(
        schema,
        c.name(),
        Encoding::Json.message_encoding(),
        &BTreeMap::new(),
    )
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

/// How the helper damages a file, for negative controls (the independent readers' tests).
#[cfg(feature = "external-readers")]
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
#[cfg(feature = "external-readers")]
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
    let mut ids: BTreeMap<Topic, u16> = COIN_CHANNELS
        .into_iter()
        .map(|c| {
            (
                Topic::Main(c),
                add_channel(&mut w, &mut schemas, Topic::Main(c), &tool_schema),
            )
        })
        .collect();
    w.write_metadata(&mcap::records::Metadata {
        name: "coin-log".into(),
        metadata: BTreeMap::from([("format_version".to_string(), "1".to_string())]),
    })
    .unwrap();
    let mut fox = Foxglove3d::new(&coin, 0.05, &[Channel::Tf, Channel::Scene], Encoding::Json);
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
    let e0 = energy(&coin, &steady.state).total;
    let rk4 = MethodConfig {
        method: Method::Rk4,
        rtol: 0.0,
        atol: 0.0,
        step: 1e-3,
    };
    run_method(
        &rk4,
        &coin,
        &steady.state.to_array(),
        &settings,
        &events,
        |t, y| {
            let s = State::from_array(y);
            let lt = log_time(t).unwrap();
            let mut write = |c: Topic, data: &[u8]| {
                sequence += 1;
                let id = *ids
                    .entry(c)
                    .or_insert_with(|| add_channel(&mut w, &mut schemas, c, &tool_schema));
                write_message(&mut w, id, sequence, lt, data);
            };
            for c in COIN_CHANNELS {
                let mut buf = message_json(&coin, &chaplygin, c, t, &s, e0);
                if c == Channel::Energy
                    && damage == Damage::EnergyWithExtraField
                    && t > 0.5
                    && !damaged
                {
                    buf.pop();
                    buf.extend_from_slice(b",\"power\":0}");
                    damaged = true;
                }
                write(Topic::Main(c), &buf);
            }
            batch.clear();
            let last = (t - duration).abs() < 1e-9;
            fox.sample(t, lt, &s, last, &mut batch).unwrap();
            for (c, data) in batch.iter() {
                if c == Topic::Main(Channel::Scene)
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

/// What to record.
#[derive(Debug, Clone)]
pub struct Spec {
    pub initial: State,
    pub scene: String,
    pub steady: Option<Steady>,
    pub duration: f64,
    pub rate: f64,
    pub step: f64,
    pub channels: Vec<Channel>,
    pub compression: Option<mcap::Compression>,
    pub method: Method,
    pub rtol: f64,
    pub atol: f64,
    pub chunk_size: Option<u64>,
    /// μ, written to the metadata (and, with `events`, ending the run at slip).
    pub friction: Option<f64>,
    /// Whether physical events end the run (flat landing, lift-off, slip); without, the model is
    /// integrated past them, as a recording the model does not hold for.
    pub events: bool,
}

/// The note's wobbling coin: θ = 0.3, ω = (0, 0.195, 1), unit thin disk.
pub fn wobble() -> Spec {
    Spec {
        initial: State {
            theta: 0.3,
            omega_y: 0.195,
            omega_z: 1.0,
            ..State::default()
        },
        scene: "description = \"wobble\"\n[body]\nmass = 1.0\nradius = 1.0\ngravity = 1.0\nshape = \"thin-disk\"\n[initial]\ntheta = 0.3\nomega = [0.0, 0.195, 1.0]\n[run]\nduration = 10.0\nintegrator = \"dop853\"\n".into(),
        steady: None,
        duration: 10.0,
        rate: 100.0,
        step: 1e-3,
        channels: COIN_CHANNELS.to_vec(),
        compression: Some(mcap::Compression::Zstd),
        chunk_size: None,
        method: Method::Dop853,
        rtol: 1e-10,
        atol: 1e-12,
        friction: None,
        events: true,
    }
}

/// The note's steady circle: θ = 0.3, ω_Z = 1, + branch (R_G = 4.8979, R_C = 5.1934).
pub fn steady_circle() -> Spec {
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
    Spec {
        initial: steady.state,
        scene: "description = \"steady circle\"\n[body]\nmass = 1.0\nradius = 1.0\ngravity = 1.0\nshape = \"thin-disk\"\n[initial]\nsteady = { kind = \"circle\", theta = 0.3, omega_z = 1.0, branch = \"+\" }\n[run]\nduration = 10.0\nintegrator = \"dop853\"\n".into(),
        steady: Some(steady),
        ..wobble()
    }
}

/// The scene of `spec` as `record` would store it: `spec.scene` with the spec's initial state (unless it
/// is a steady motion), run settings, μ and channels set on it, resolved.
fn stored_scene(spec: &Spec) -> Scene {
    let mut t: toml::Table = toml::from_str(&spec.scene).unwrap();
    let mut set = |key: &str, value: toml::Value| set_value(&mut t, key, value).unwrap();
    let s = &spec.initial;
    if spec.steady.is_none() {
        set("initial.theta", s.theta.into());
        set(
            "initial.omega",
            vec![s.omega_x, s.omega_y, s.omega_z].into(),
        );
        for (key, value) in [("phi", s.phi), ("psi", s.psi), ("x", s.x), ("z", s.z)] {
            set(&format!("initial.{key}"), value.into());
        }
    }
    set("run.duration", spec.duration.into());
    set("run.rate", spec.rate.into());
    set("run.integrator", spec.method.name().into());
    set("run.rtol", spec.rtol.into());
    set("run.atol", spec.atol.into());
    set("run.step", spec.step.into());
    if let Some(mu) = spec.friction {
        set("body.friction", mu.into());
    }
    let channels: Vec<&str> = spec.channels.iter().map(|c| c.name()).collect();
    set("record.channels", channels.into());
    Scene::from_file(&file_from_table(t).unwrap()).unwrap()
}

/// Simulates `spec` with rk4 and writes it as a coin-log MCAP at `path`, following format.md.
pub fn record(spec: &Spec, path: &Path) {
    let coin = Coin::new(CoinParams::unit_disk());
    let mut run = stored_scene(spec).run_metadata();
    run.tool_version = "test".into();
    let file = BufWriter::new(std::fs::File::create(path).unwrap());
    let mut options = mcap::WriteOptions::new()
        .compression(spec.compression)
        .library("coin-log/test");
    if spec.chunk_size.is_some() {
        options = options.chunk_size(spec.chunk_size);
    }
    let mut w = options.create(file).unwrap();
    w.write_metadata(&mcap::records::Metadata {
        name: RUN_METADATA_NAME.into(),
        metadata: run.to_map(),
    })
    .unwrap();
    let mut schemas = BTreeMap::new();
    let ids: Vec<(Channel, u16)> = spec
        .channels
        .iter()
        .map(|&c| {
            (
                c,
                add_channel(&mut w, &mut schemas, Topic::Main(c), &tool_schema),
            )
        })
        .collect();
    let chaplygin = Chaplygin::new(coin.params()).unwrap();
    let mut sequence = 0u32;
    let config = MethodConfig {
        method: spec.method,
        rtol: spec.rtol,
        atol: spec.atol,
        step: spec.step,
    };
    let settings = RunSettings {
        t0: 0.0,
        t_end: spec.duration,
        sample_interval: 1.0 / spec.rate,
    };
    let y0 = spec.initial.to_array();
    let e0 = energy(&coin, &spec.initial).total;
    let mut observe = |t: f64, y: &[f64; STATE_LEN]| {
        let s = State::from_array(y);
        let lt = log_time(t).unwrap();
        for (c, id) in &ids {
            let data = message_json(&coin, &chaplygin, *c, t, &s, e0);
            write_message(&mut w, *id, sequence, lt, &data);
            sequence += 1;
        }
        Flow::Continue
    };
    let outcome = if spec.events {
        let events = CoinEvents::new(coin, 1e-4, spec.friction);
        run_method(&config, &coin, &y0, &settings, &events, &mut observe)
    } else {
        run_method(&config, &coin, &y0, &settings, &NoEvents, &mut observe)
    };
    let termination = match outcome.termination {
        RunEnd::Completed | RunEnd::Event { .. } => {
            coin_log::format::Termination::of_run(&outcome.termination)
        }
        other => panic!("test run failed: {other:?}"),
    };
    let result = ResultMetadata {
        steps: outcome.stats.steps,
        rhs_evaluations: outcome.stats.rhs_evaluations,
        rejected_steps: outcome.stats.rejected_steps,
        termination,
        termination_time: outcome.t_last,
        termination_alpha: None,
        expected_to_fail: None,
    };
    w.write_metadata(&mcap::records::Metadata {
        name: RESULT_METADATA_NAME.into(),
        metadata: result.to_map(),
    })
    .unwrap();
    w.finish().unwrap();
}

/// One message as `rewrite` hands it to the edit function.
pub struct Edit<'a> {
    pub topic: &'a str,
    pub index: usize,
    pub log_time: &'a mut u64,
    pub data: &'a mut Vec<u8>,
}

/// Copies the coin-log MCAP `src` to `dst` (same metadata, channels, message order), letting `edit`
/// change each message (its index counts messages of the same topic from 0).
pub fn rewrite(src: &Path, dst: &Path, edit: impl FnMut(Edit<'_>)) {
    rewrite_with_schemas(src, dst, &tool_schema, edit);
}

/// [`rewrite`], embedding `schema_of(name)` as the bytes of each schema (e.g. another version's).
pub fn rewrite_with_schemas(
    src: &Path,
    dst: &Path,
    schema_of: &dyn Fn(&str) -> Vec<u8>,
    edit: impl FnMut(Edit<'_>),
) {
    copy(src, dst, schema_of, &|_, _| {}, edit);
}

/// [`rewrite`], with every metadata record's entries changed by `edit_metadata(name, entries)` too.
pub fn rewrite_with_metadata(
    src: &Path,
    dst: &Path,
    edit_metadata: &dyn Fn(&str, &mut BTreeMap<String, String>),
    edit: impl FnMut(Edit<'_>),
) {
    copy(src, dst, &tool_schema, edit_metadata, edit);
}

/// Copies the coin-log MCAP `src` to `dst` with its `coin-log` record's entries changed by `edit_run`.
pub fn rewrite_run_metadata(
    src: &Path,
    dst: &Path,
    edit_run: &dyn Fn(&mut BTreeMap<String, String>),
) {
    let edit_metadata = |name: &str, entries: &mut BTreeMap<String, String>| {
        if name == RUN_METADATA_NAME {
            edit_run(entries);
        }
    };
    copy(src, dst, &tool_schema, &edit_metadata, |_| {});
}

fn copy(
    src: &Path,
    dst: &Path,
    schema_of: &dyn Fn(&str) -> Vec<u8>,
    edit_metadata: &dyn Fn(&str, &mut BTreeMap<String, String>),
    mut edit: impl FnMut(Edit<'_>),
) {
    let bytes = std::fs::read(src).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut metadata: Vec<mcap::records::Metadata> = summary
        .metadata_indexes
        .iter()
        .map(|i| mcap::read::metadata(&bytes, i).unwrap())
        .collect();
    for m in &mut metadata {
        edit_metadata(&m.name, &mut m.metadata);
    }
    let file = BufWriter::new(std::fs::File::create(dst).unwrap());
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .library("coin-log/test")
        .create(file)
        .unwrap();
    for m in metadata.iter().filter(|m| m.name == RUN_METADATA_NAME) {
        w.write_metadata(m).unwrap();
    }
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let mut ids: BTreeMap<String, u16> = BTreeMap::new();
    let mut schemas: BTreeMap<&'static str, u16> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let topic = m.channel.topic.clone();
        let id = *ids.entry(topic.clone()).or_insert_with(|| {
            add_channel(
                &mut w,
                &mut schemas,
                Topic::from_name(&topic).unwrap(),
                schema_of,
            )
        });
        let index = counts.entry(topic.clone()).or_insert(0);
        let mut data = m.data.to_vec();
        let mut lt = m.log_time;
        edit(Edit {
            topic: &topic,
            index: *index,
            log_time: &mut lt,
            data: &mut data,
        });
        *index += 1;
        write_message(&mut w, id, m.sequence, lt, &data);
    }
    for m in metadata.iter().filter(|m| m.name != RUN_METADATA_NAME) {
        w.write_metadata(m).unwrap();
    }
    w.finish().unwrap();
}

/// Writes every message of the MCAP file `bytes` to `w`, those of `topic` twice: again on a second
/// channel of that topic with another publisher (legal MCAP; the writer would merge an identical channel
/// into the first), its data passed through `second`. Returns the channel ids by (topic, second copy).
pub fn copy_messages_twice<W: Write + Seek>(
    bytes: &[u8],
    w: &mut mcap::Writer<W>,
    topic: &str,
    mut second: impl FnMut(&mut Vec<u8>),
) -> BTreeMap<(String, bool), u16> {
    let mut ids = BTreeMap::new();
    for m in mcap::MessageStream::new(bytes).unwrap() {
        let m = m.unwrap();
        let copies: &[bool] = if m.channel.topic == topic {
            &[false, true]
        } else {
            &[false]
        };
        for &copy in copies {
            let id = *ids
                .entry((m.channel.topic.clone(), copy))
                .or_insert_with(|| {
                    let s = m.channel.schema.as_ref().unwrap();
                    let sid = w.add_schema(&s.name, &s.encoding, &s.data).unwrap();
                    let publisher = copy.then(|| ("publisher".to_string(), "2".to_string()));
                    w.add_channel(
                        sid,
                        &m.channel.topic,
                        &m.channel.message_encoding,
                        &publisher.into_iter().collect(),
                    )
                    .unwrap()
                });
            let mut data = m.data.to_vec();
            if copy {
                second(&mut data);
            }
            w.write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: m.sequence,
                    log_time: m.log_time,
                    publish_time: m.publish_time,
                },
                &data,
            )
            .unwrap();
        }
    }
    ids
}

/// Changes field `field` of a JSON message by `delta`, keeping every other byte.
pub fn nudge(data: &mut Vec<u8>, field: &str, delta: f64) {
    let mut v: serde_json::Map<String, serde_json::Value> = serde_json::from_slice(data).unwrap();
    let x = v[field].as_f64().unwrap() + delta;
    v.insert(field.into(), serde_json::json!(x));
    *data = serde_json::to_vec(&v).unwrap();
}

/// A temporary folder and a recording of `spec` in it.
pub fn recorded(spec: &Spec, name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    record(spec, &path);
    (dir, path)
}

/// Copies the Protobuf recording `src` to `dst` with the mcap crate, letting `schema` replace a schema's
/// bytes, `encoding` a channel's message encoding, and `edit` a message (`index` counts per topic).
pub fn rewrite_protobuf(
    src: &Path,
    dst: &Path,
    schema: impl Fn(&str, &[u8]) -> Vec<u8>,
    encoding: impl Fn(&str) -> &'static str,
    mut edit: impl FnMut(&str, usize, &mut Vec<u8>),
) {
    let bytes = std::fs::read(src).unwrap();
    let file = super::record::read_back(&bytes);
    let mut w = mcap::WriteOptions::new()
        .library("coin-log/test")
        .create(BufWriter::new(std::fs::File::create(dst).unwrap()))
        .unwrap();
    let (_, run) = &file.metadata["coin-log"];
    w.write_metadata(&mcap::records::Metadata {
        name: "coin-log".into(),
        metadata: run.clone(),
    })
    .unwrap();
    let mut ids: BTreeMap<String, u16> = BTreeMap::new();
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for m in &file.messages {
        let id = *ids.entry(m.topic.clone()).or_insert_with(|| {
            let data = schema(&m.schema_name, &file.schemas[&m.schema_name]);
            let s = w.add_schema(&m.schema_name, "protobuf", &data).unwrap();
            w.add_channel(s, &m.topic, encoding(&m.topic), &BTreeMap::new())
                .unwrap()
        });
        let index = counts.entry(m.topic.clone()).or_default();
        let mut data = m.data.clone();
        edit(&m.topic, *index, &mut data);
        *index += 1;
        write_message(&mut w, id, m.sequence, m.log_time, &data);
    }
    let (_, result) = &file.metadata["coin-log.result"];
    w.write_metadata(&mcap::records::Metadata {
        name: "coin-log.result".into(),
        metadata: result.clone(),
    })
    .unwrap();
    w.finish().unwrap();
}
