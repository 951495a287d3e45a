//! Test helpers for `verify`: coin-log recordings written with the mcap crate straight from the model (files
//! the recorder cannot make: odd channel sets, small or uncompressed chunks), and rewriting a file with one
//! message or schema changed (negative controls). The message JSON and the MCAP registration come from
//! tests/support: a test crate using this module declares `mod support;` too.

// Every tests/*.rs is its own crate and uses only some of these helpers: the rest are dead code there.
// Test helpers panic on any setup failure by design.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use coin_log::integrate::{run_method, Flow, Method, MethodConfig, RunSettings, Termination};
use coin_log::model::invariants::Chaplygin;
use coin_log::model::{Coin, CoinParams, State, Steady};
use coin_log::record::{
    Channel, ResultMetadata, RunMetadata, FORMAT_VERSION, RESULT_METADATA_NAME, RUN_METADATA_NAME,
};
use coin_log::simulation::CoinEvents;
use coin_log::units::log_time;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::support::writers::{add_channel, message_json, tool_schema, write_message, COIN_CHANNELS};

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
    }
}

/// The note's steady circle: θ = 0.3, ω_Z = 1, + branch (R_G = 4.8979, R_C = 5.1934).
pub fn steady_circle() -> Spec {
    let coin = Coin::new(CoinParams::unit_disk());
    let steady = Steady::new(
        &coin,
        coin_log::model::SteadyKind::Circle {
            theta: 0.3,
            omega_z: 1.0,
            branch: coin_log::model::Branch::Plus,
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

/// Simulates `spec` with rk4 and writes it as a coin-log MCAP at `path`, following CONTRACT.
pub fn record(spec: &Spec, path: &Path) {
    let coin = Coin::new(CoinParams::unit_disk());
    let p = coin.params();
    let run = RunMetadata {
        format_version: FORMAT_VERSION.into(),
        tool_version: "test".into(),
        scene: spec.scene.clone(),
        mass: p.mass(),
        radius: p.radius(),
        gravity: p.gravity(),
        inertia_x: p.inertia_x(),
        inertia_z: p.inertia_z(),
        friction: None,
        time_unit: p.time_unit(),
        integrator: spec.method.name().into(),
        rtol: spec.rtol,
        atol: spec.atol,
        step: spec.step,
        rate: spec.rate,
        steady_kind: spec
            .steady
            .map_or("none".into(), |s| s.kind.name().to_string()),
        phi_dot: spec.steady.map(|s| s.phi_dot),
        psi_dot: spec.steady.map(|s| s.psi_dot),
        r_g: spec.steady.and_then(|s| s.r_g),
        r_c: spec.steady.and_then(|s| s.r_c),
    };
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
        .map(|c| (*c, add_channel(&mut w, &mut schemas, *c, &tool_schema)))
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
    let events = CoinEvents::new(coin, 1e-4, None);
    let y0 = spec.initial.to_array();
    let outcome = run_method(&config, &coin, &y0, &settings, &events, |t, y| {
        let s = State::from_array(y);
        let lt = log_time(t).unwrap();
        for (c, id) in &ids {
            let data = message_json(&coin, &chaplygin, *c, t, &s);
            write_message(&mut w, *id, sequence, lt, &data);
            sequence += 1;
        }
        Flow::Continue
    });
    let termination = match outcome.termination {
        Termination::Completed => "completed".to_string(),
        Termination::Event { index, .. } => CoinEvents::event(index).name().to_string(),
        other => panic!("test run failed: {other:?}"),
    };
    let result = ResultMetadata {
        steps: outcome.stats.steps,
        rhs_evaluations: outcome.stats.rhs_evaluations,
        rejected_steps: outcome.stats.rejected_steps,
        termination,
        termination_time: outcome.t_last,
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
    mut edit: impl FnMut(Edit<'_>),
) {
    let bytes = std::fs::read(src).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let metadata: Vec<mcap::records::Metadata> = summary
        .metadata_indexes
        .iter()
        .map(|i| mcap::read::metadata(&bytes, i).unwrap())
        .collect();
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
                Channel::from_topic(&topic).unwrap(),
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

/// Runs the `coin-log` binary with `args`; returns (exit code, stdout, stderr).
pub fn coin_log(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_coin-log"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Records built-in scene `scene` with the real recorder (`coin-log record`), plus `extra` flags.
pub fn record_scene(dir: &Path, scene: &str, extra: &[&str]) -> PathBuf {
    let path = dir.join(format!("{scene}.mcap"));
    let mut args = vec!["record", scene, "-o", path.to_str().unwrap(), "--overwrite"];
    args.extend_from_slice(extra);
    let (code, out, err) = coin_log(&args);
    assert_eq!(code, 0, "coin-log record {scene}: {out}{err}");
    path
}

/// The built-in scene names (`coin-log scenes`).
pub fn scene_names() -> Vec<String> {
    let (code, out, err) = coin_log(&["scenes"]);
    assert_eq!(code, 0, "{err}");
    out.lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_string)
        .collect()
}
