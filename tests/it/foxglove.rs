//! What a Foxglove-lineage viewer needs from a recording (docs/format.md: Frames and Foxglove output), checked
//! on every committed dataset and on a fresh recording of every built-in scene, and the shipped layouts.
//!
//! After a seek such a viewer restores only the latest message of each topic (and on a backward seek forgets
//! every transform and drawn object first). So at any cut time, the latest message of each topic alone must
//! give: the whole frame tree world → table → coin plus the level follow frame `coin_level` (at the coin's
//! centre, in units of a); the coin; the table under it; and the contact track from t = 0 to the latest
//! display update, within the simplification tolerance of every recorded contact point. The layouts must use
//! numbers where the viewer expects numbers (a `""` y-limit locks a plot to [0, 0]), plot only numeric fields
//! that exist, follow the level frame and show every drawing topic.

// Helpers outside #[test] functions panic on any failure by design.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::read_back;
use crate::support::{dataset_files, repo};
use coin_log::format::{
    log_time, schema_bytes, Channel, Encoding, Topic, FRAME_TRANSFORM, SCENE_UPDATE,
};
use coin_log::model::{centre, contact_point, Coin, CoinParams, Inertia, State};
use coin_log::record::foxglove::track::{segment_distance, MAX_TOLERANCE, QUANTUM};
use coin_log::record::foxglove::{
    FOLLOW_FRAME, SCENE_RATE, TABLE_HALF_SIDE, TABLE_ROTATION, TABLE_SNAP, WORLD_FRAME,
};
use coin_log::record::{self, Foxglove3d, FoxgloveBatch, RecordOptions};
use coin_log::scene::{self, presets, FlagOverrides};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::atomic::AtomicBool;
use std::sync::OnceLock;

/// One message: topic, log time, JSON (only for the topics these tests read; `Null` otherwise).
struct Message {
    topic: String,
    lt: u64,
    v: Value,
}

/// A recording read back: its name, the radius a, the data rate, its messages in file order.
struct Recording {
    name: String,
    a: f64,
    rate: f64,
    messages: Vec<Message>,
}

impl Recording {
    fn load(name: String, bytes: &[u8]) -> Self {
        let back = read_back(bytes);
        let run = &back.metadata["coin-log"].1;
        let number = |k: &str| run[k].parse::<f64>().unwrap();
        let messages = back
            .messages
            .into_iter()
            .map(|m| {
                let wanted = !m.topic.starts_with("/coin/")
                    || m.topic == "/coin/position"
                    || m.topic == "/coin/contact";
                let v = if wanted {
                    serde_json::from_slice(&m.data).unwrap()
                } else {
                    Value::Null
                };
                assert_eq!(m.publish_time, m.log_time, "{name}: {}", m.topic);
                Message {
                    topic: m.topic,
                    lt: m.log_time,
                    v,
                }
            })
            .collect();
        Self {
            name,
            a: number("radius"),
            rate: number("rate"),
            messages,
        }
    }

    /// The latest message of each topic at or before `cut` (what a seek to `cut` restores).
    fn latest(&self, cut: u64) -> BTreeMap<&str, &Message> {
        let mut out = BTreeMap::new();
        for m in self.messages.iter().take_while(|m| m.lt <= cut) {
            out.insert(m.topic.as_str(), m);
        }
        out
    }

    fn on(&self, topic: &str) -> impl Iterator<Item = &Message> + '_ {
        let topic = topic.to_string();
        self.messages.iter().filter(move |m| m.topic == topic)
    }

    /// Cut times: inside the run at uneven offsets, the first and the last log time.
    fn cuts(&self) -> Vec<u64> {
        let first = self.messages.first().unwrap().lt;
        let last = self.messages.iter().map(|m| m.lt).max().unwrap();
        let mut cuts: Vec<u64> = (1..=17)
            .map(|k| (first + (last - first) / 17 * k).saturating_sub((k * 7_919_993) % 40_000_000))
            .filter(|c| *c >= first)
            .collect();
        cuts.extend([first, last]);
        cuts
    }
}

/// Longest fresh recording, in time units, except `long-horizon`, recorded whole (1000 time units at 10
/// samples per unit: 10⁴ display updates, which exercise the track's high levels).
const FRESH_DURATION: f64 = 12.0;

/// Every committed dataset and a fresh recording of every built-in scene (loaded once).
fn recordings() -> &'static [Recording] {
    static ALL: OnceLock<Vec<Recording>> = OnceLock::new();
    ALL.get_or_init(|| {
        let mut all: Vec<Recording> = dataset_files()
            .into_iter()
            .map(|p| Recording::load(p.display().to_string(), &std::fs::read(&p).unwrap()))
            .collect();
        for name in presets::NAMES {
            let file = presets::preset(name).unwrap();
            let duration = file.run.as_ref().and_then(|r| r.duration).unwrap();
            let flags = FlagOverrides {
                duration: (name != "long-horizon").then_some(duration.min(FRESH_DURATION)),
                ..FlagOverrides::default()
            };
            let scene = scene::resolve(&file, &flags).unwrap();
            let mut out = std::io::Cursor::new(Vec::new());
            let stop = AtomicBool::new(false);
            record::record(&scene, &RecordOptions::default(), &mut out, &stop, |_| {}).unwrap();
            all.push(Recording::load(format!("fresh {name}"), &out.into_inner()));
        }
        all
    })
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

fn time_ns(stamp: &Value) -> u64 {
    stamp["sec"].as_u64().unwrap() * 1_000_000_000 + stamp["nsec"].as_u64().unwrap()
}

/// The frame tree the latest messages give at `cut`: child → parent. Err if a frame has two parents, a
/// transform is its own parent, or the tree is not world → table → coin and world → coin_level.
fn frame_tree(latest: &BTreeMap<&str, &Message>) -> Result<BTreeMap<String, String>, String> {
    let mut parents: BTreeMap<String, String> = BTreeMap::new();
    for m in latest.values() {
        if Topic::from_name(&m.topic).map(Topic::schema_name) != Some("foxglove.FrameTransform") {
            continue;
        }
        let child = m.v["child_frame_id"].as_str().unwrap().to_string();
        let parent = m.v["parent_frame_id"].as_str().unwrap().to_string();
        if child == parent {
            return Err(format!("{}: {child} is its own parent", m.topic));
        }
        if let Some(p) = parents.insert(child.clone(), parent.clone()) {
            if p != parent {
                return Err(format!("{child} has two parents, {p} and {parent}"));
            }
        }
    }
    let expected: BTreeMap<String, String> = [
        ("table", "world"),
        ("coin", "table"),
        (FOLLOW_FRAME, WORLD_FRAME),
    ]
    .into_iter()
    .map(|(c, p)| (c.to_string(), p.to_string()))
    .collect();
    if parents == expected {
        Ok(parents)
    } else {
        Err(format!("frame tree {parents:?}, expected {expected:?}"))
    }
}

#[test]
fn after_any_seek_the_latest_message_of_each_topic_gives_the_whole_frame_tree() {
    let mut checked = 0;
    for r in recordings() {
        for cut in r.cuts() {
            if let Err(e) = frame_tree(&r.latest(cut)) {
                panic!("{}: seek to {cut} ns: {e}", r.name);
            }
            checked += 1;
        }
    }
    println!(
        "{checked} seeks over {} recordings: full frame tree each time",
        recordings().len()
    );
    // Negative control: without /tf_static, a seek past t = 0 loses world → table.
    let r = &recordings()[0];
    let cut = r.cuts()[5];
    let mut latest = r.latest(cut);
    latest.remove("/tf_static");
    let e = frame_tree(&latest).unwrap_err();
    println!("without /tf_static: {e}");
}

#[test]
fn every_transform_and_drawing_timestamp_equals_its_log_time() {
    let mut checked = 0;
    for r in recordings() {
        for m in &r.messages {
            let stamps: Vec<&Value> = match Topic::from_name(&m.topic).map(Topic::schema_name) {
                Some("foxglove.FrameTransform") => vec![&m.v["timestamp"]],
                Some("foxglove.SceneUpdate") => m.v["entities"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .chain(m.v["deletions"].as_array().unwrap())
                    .map(|e| &e["timestamp"])
                    .collect(),
                _ => vec![],
            };
            for s in stamps {
                assert_eq!(time_ns(s), m.lt, "{}: {}: {s} vs log time", r.name, m.topic);
                assert!(s["nsec"].as_u64().unwrap() < 1_000_000_000);
                checked += 1;
            }
        }
    }
    println!("{checked} timestamps equal to their log time");
    assert!(checked > 100_000);
}

#[test]
fn the_static_transform_is_first_on_tf_and_alone_on_tf_static() {
    for r in recordings() {
        let tf: Vec<&Message> = r.on("/tf").collect();
        assert_eq!(tf[0].v["child_frame_id"], "table", "{}", r.name);
        assert_eq!(tf[0].v["parent_frame_id"], WORLD_FRAME);
        assert_eq!((tf[0].lt, r.messages[0].lt), (0, 0));
        let coin = tf
            .iter()
            .filter(|m| m.v["child_frame_id"] == "coin")
            .count();
        let samples = r.on("/coin/position").count();
        assert_eq!(coin, samples, "{}: table → coin at every sample", r.name);
        assert_eq!(tf.len(), coin + 1, "{}: world → table once on /tf", r.name);
        let statics: Vec<&Message> = r.on("/tf_static").collect();
        assert_eq!(statics.len(), 1, "{}", r.name);
        assert_eq!(statics[0].v, tf[0].v, "{}: the same transform", r.name);
        // At the first sample: /tf world → table, /tf table → coin, /tf_static, then the drawing.
        let at = |topic: &str| r.messages.iter().position(|m| m.topic == topic).unwrap();
        assert_eq!(at("/tf_static"), at("/tf") + 2, "{}", r.name);
        assert!(at("/scene/follow") > at("/tf_static"), "{}", r.name);
    }
}

#[test]
fn the_camera_follows_a_level_frame_at_the_coins_centre_in_units_of_a() {
    let mut checked = 0;
    for r in recordings() {
        let centres: BTreeMap<u64, &Value> = r.on("/coin/position").map(|m| (m.lt, &m.v)).collect();
        for m in r.on("/scene/follow") {
            assert_eq!(m.v["parent_frame_id"], WORLD_FRAME);
            assert_eq!(m.v["child_frame_id"], FOLLOW_FRAME);
            assert_eq!(
                m.v["rotation"],
                serde_json::json!({"x": 0, "y": 0, "z": 0, "w": 1}),
                "{}: the follow frame stays level",
                r.name
            );
            // World (z up) from the physics frame (y up): (x, −z, y), divided by a.
            let c = centres[&m.lt];
            let expected = [num(&c["x"]) / r.a, -num(&c["z"]) / r.a, num(&c["y"]) / r.a];
            let t = &m.v["translation"];
            for (got, want) in [num(&t["x"]), num(&t["y"]), num(&t["z"])]
                .iter()
                .zip(expected)
            {
                // Round-off of a division and of cos θ: 1e-12 of the coordinate or of a.
                assert!(
                    (got - want).abs() <= 1e-12 * want.abs().max(1.0),
                    "{}: follow {got} vs centre/a {want}",
                    r.name
                );
            }
            checked += 1;
        }
    }
    println!("{checked} follow transforms at the coin's centre, level");
}

#[test]
fn after_any_seek_the_coin_and_the_table_under_it_are_drawn() {
    for r in recordings() {
        for cut in r.cuts() {
            let latest = r.latest(cut);
            let coin = &latest["/scene"].v["entities"][0];
            assert_eq!(coin["id"], "coin", "{}", r.name);
            assert_eq!(coin["frame_id"], FOLLOW_FRAME);
            let table = &latest["/scene/table"].v["entities"][0]["cubes"][0]["pose"]["position"];
            let follow = &latest["/scene/follow"].v["translation"];
            let d = (num(&follow["x"]) - num(&table["x"]))
                .abs()
                .max((num(&follow["y"]) - num(&table["y"])).abs());
            assert!(
                d <= TABLE_SNAP + 1e-9,
                "{}: at {cut} ns the coin is {d} a from the table's centre (half side {TABLE_HALF_SIDE})",
                r.name
            );
        }
    }
}

/// The track the latest track messages draw at a cut, as one chain from the highest level down. Err if a
/// level does not start where the level above ends.
fn track_chain(latest: &BTreeMap<&str, &Message>) -> Result<Vec<[f64; 2]>, String> {
    let mut levels: Vec<(usize, Vec<[f64; 2]>)> = Vec::new();
    for (topic, m) in latest {
        let Some(Topic::SceneTrack(level)) = Topic::from_name(topic) else {
            continue;
        };
        let Some(e) = m.v["entities"].as_array().unwrap().first() else {
            continue; // a deletion: the level is empty
        };
        assert_eq!(e["id"], "track");
        assert_eq!(e["frame_id"], WORLD_FRAME);
        let points = e["lines"][0]["points"].as_array().unwrap();
        levels.push((
            usize::from(level),
            points
                .iter()
                .map(|p| [num(&p["x"]), num(&p["y"])])
                .collect(),
        ));
    }
    levels.sort_by_key(|l| std::cmp::Reverse(l.0));
    let mut chain: Vec<[f64; 2]> = Vec::new();
    for (level, points) in levels {
        match chain.last() {
            Some(end) if *end != points[0] => {
                return Err(format!(
                    "level {level} starts at {:?}, the levels above end at {end:?}",
                    points[0]
                ))
            }
            Some(_) => chain.extend_from_slice(&points[1..]),
            None => chain.extend_from_slice(&points),
        }
    }
    Ok(chain)
}

/// Checks that `chain` draws the contact points `path` (in time order, display units) from the first to the
/// last within `tolerance`: its ends are the path's ends, and every point lies within `tolerance` of it.
/// The chain's vertices are path points in order, so a pointer moves along it; a point not matched near the
/// pointer is searched in the whole chain.
fn covers(chain: &[[f64; 2]], path: &[[f64; 2]], tolerance: f64) -> Result<f64, String> {
    let (first, last) = (path[0], path[path.len() - 1]);
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) <= QUANTUM;
    if chain.len() < 2 || !near(chain[0], first) || !near(chain[chain.len() - 1], last) {
        return Err(format!(
            "the track runs {:?} → {:?}, the path {first:?} → {last:?}",
            chain.first(),
            chain.last()
        ));
    }
    let mut at = 0;
    let mut worst: f64 = 0.0;
    for p in path {
        let window = at..(at + 64).min(chain.len() - 1);
        let best = window
            .map(|i| (i, segment_distance(*p, chain[i], chain[i + 1])))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .filter(|(_, d)| *d <= tolerance)
            .or_else(|| {
                (0..chain.len() - 1)
                    .map(|i| (i, segment_distance(*p, chain[i], chain[i + 1])))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
            })
            .unwrap();
        if best.1 > tolerance {
            return Err(format!("contact point {p:?} is {} from the track", best.1));
        }
        at = best.0;
        worst = worst.max(best.1);
    }
    Ok(worst)
}

/// The contact points (display units) with log time ≤ `until`.
fn contact_path(r: &Recording, until: u64) -> Vec<[f64; 2]> {
    r.on("/coin/contact")
        .take_while(|m| m.lt <= until)
        .map(|m| [num(&m.v["x"]) / r.a, -num(&m.v["z"]) / r.a])
        .collect()
}

#[test]
fn after_any_seek_the_latest_track_messages_draw_the_whole_path_up_to_the_latest_update() {
    let tolerance = MAX_TOLERANCE + QUANTUM;
    let (mut checked, mut worst, mut deepest) = (0, 0.0_f64, 0);
    for r in recordings() {
        let updates: Vec<u64> = r.on("/scene").map(|m| m.lt).collect();
        for cut in r.cuts() {
            let latest = r.latest(cut);
            let last_update = *updates.iter().rev().find(|u| **u <= cut).unwrap();
            // Within one display interval: updates are ≤ 1/SCENE_RATE + 1/rate apart (docs/format.md).
            let gap = (cut - last_update) as f64 * 1e-9;
            assert!(
                gap <= 1.0 / SCENE_RATE + 1.0 / r.rate + 1e-9,
                "{}: {gap}",
                r.name
            );
            let path = contact_path(r, last_update);
            let moved = path
                .iter()
                .any(|p| (p[0] - path[0][0]).abs().max((p[1] - path[0][1]).abs()) > QUANTUM);
            let chain = track_chain(&latest).unwrap_or_else(|e| panic!("{}: {e}", r.name));
            if !moved {
                assert!(chain.is_empty(), "{}: no motion, no track", r.name);
                continue;
            }
            let d = covers(&chain, &path, tolerance)
                .unwrap_or_else(|e| panic!("{}: seek to {cut} ns: {e}", r.name));
            worst = worst.max(d);
            deepest = deepest.max(
                latest
                    .keys()
                    .filter(|t| t.starts_with("/scene/track/"))
                    .count(),
            );
            checked += 1;
        }
    }
    println!(
        "{checked} seeks: the track covers every contact point up to the latest update; worst distance \
         {worst:e} a (tolerance {tolerance:e}); up to {deepest} track levels in use"
    );
    assert!(deepest >= 12, "the long recordings use the high levels");
    // Negative control: dropping one level's latest message breaks the chain (or leaves points uncovered).
    let r = recordings()
        .iter()
        .find(|r| r.name.ends_with("wobble.mcap"))
        .unwrap();
    let cut = r.cuts()[9];
    let mut latest = r.latest(cut);
    let dropped = latest
        .keys()
        .find(|t| t.starts_with("/scene/track/") && latest[**t].v["entities"][0].is_object())
        .copied()
        .unwrap();
    latest.remove(dropped);
    let path = contact_path(r, cut);
    let broken = track_chain(&latest).and_then(|c| covers(&c, &path, tolerance));
    println!("without {dropped}: {broken:?}");
    assert!(broken.is_err());
}

#[test]
fn drawing_updates_come_at_about_thirty_per_time_unit_whatever_the_data_rate() {
    for r in recordings().iter().filter(|r| r.rate >= SCENE_RATE) {
        let times: Vec<u64> = r.on("/scene").map(|m| m.lt).collect();
        let span = (times[times.len() - 1] - times[0]) as f64 * 1e-9;
        let rate = (times.len() - 1) as f64 / span;
        println!("{}: {rate:.2} drawing updates per time unit", r.name);
        assert!((rate - SCENE_RATE).abs() <= 1.0, "{}: {rate}", r.name);
        assert_eq!(r.on("/scene/follow").count(), times.len());
        let last = r.messages.iter().map(|m| m.lt).max().unwrap();
        assert_eq!(
            times[times.len() - 1],
            last,
            "{}: the last sample is drawn",
            r.name
        );
    }
    // Whatever the data rate, on a synthetic motion.
    for rate in [30.0, 45.0, 100.0, 1000.0] {
        let messages = synthetic(rate, 4.0);
        let times: Vec<u64> = messages
            .iter()
            .filter(|(c, _, _)| *c == Topic::Main(Channel::Scene))
            .map(|(_, t, _)| *t)
            .collect();
        let n = times.len();
        println!("rate {rate}: {n} drawing updates over 4 time units, expected 121 ± 1");
        assert!((120..=122).contains(&n), "rate {rate}: {n}");
        assert_eq!(times[0], 0);
        assert_eq!(*times.last().unwrap(), 4_000_000_000);
        let max_gap = times.windows(2).map(|w| w[1] - w[0]).max().unwrap();
        assert!(max_gap <= 50_000_000, "rate {rate}: gap {max_gap} ns");
        let follows = messages
            .iter()
            .filter(|m| m.0 == Topic::SceneFollow)
            .count();
        assert_eq!(follows, n, "one follow transform per drawing update");
    }
}

// ---------------------------------------------------------------------------------------------------------
// The writer alone, on synthetic motions: schemas, frames, the drawing's geometry against the model, the
// table, scale invariance, non-finite values.

fn unit_coin() -> Coin {
    Coin::new(CoinParams::unit_disk())
}

/// A coin leaning at θ = 0.3, heading turning at 0.5 rad per time unit, centre on a circle of radius 4
/// (lengths in units of `a`): enough motion for a track; not a solution of the equations (the output does
/// not need one).
fn state_scaled(t: f64, a: f64) -> State {
    State {
        theta: 0.3,
        phi: 0.5 * t,
        psi: 2.0 * t,
        omega_x: 0.0,
        omega_y: 0.4,
        omega_z: 1.0,
        x: 4.0 * a * (0.5 * t).cos(),
        z: 4.0 * a * (0.5 * t).sin(),
    }
}

fn state_at(t: f64) -> State {
    state_scaled(t, 1.0)
}

/// (topic, log time, JSON) of each message.
type Messages = Vec<(Topic, u64, Value)>;

/// Writes `channels` (of `tf`, `scene`) of `state(t)` for `coin` at `rate` for `duration`, as Foxglove3d
/// writes them, into (topic, log time, JSON) triples.
fn synthetic_with(
    coin: &Coin,
    rate: f64,
    duration: f64,
    channels: &[Channel],
    state: impl Fn(f64) -> State,
) -> Messages {
    let mut fox = Foxglove3d::new(coin, 0.05, channels, Encoding::Json);
    let mut batch = FoxgloveBatch::default();
    let mut out = Vec::new();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = (duration * rate).round() as u64;
    for k in 0..=n {
        #[allow(clippy::cast_precision_loss)]
        let t = k as f64 / rate;
        let lt = log_time(t).unwrap();
        batch.clear();
        fox.sample(t, lt, &state(t), k == n, &mut batch).unwrap();
        for (c, bytes) in batch.iter() {
            let v: Value = serde_json::from_slice(bytes).unwrap_or_else(|e| {
                panic!(
                    "{c} message is not JSON ({e}): {}",
                    String::from_utf8_lossy(bytes)
                )
            });
            out.push((c, lt, v));
        }
    }
    out
}

/// Both channels of the unit coin on the circle of [`state_at`].
fn synthetic(rate: f64, duration: f64) -> Messages {
    synthetic_with(&unit_coin(), rate, duration, BOTH, state_at)
}

const BOTH: &[Channel] = &[Channel::Tf, Channel::Scene];

/// A small JSON Schema checker for the subset the official Foxglove schemas use: type, properties,
/// required, items, minimum/maximum, oneOf of constants. Returns the first violation.
fn violation(schema: &Value, v: &Value, path: &str) -> Option<String> {
    if let Some(options) = schema.get("oneOf").and_then(Value::as_array) {
        if !options.iter().any(|o| o.get("const") == Some(v)) {
            return Some(format!("{path}: {v} is none of the allowed constants"));
        }
    }
    let ok = match schema.get("type").and_then(Value::as_str) {
        None => true,
        Some("object") => v.is_object(),
        Some("array") => v.is_array(),
        Some("string") => v.is_string(),
        Some("boolean") => v.is_boolean(),
        Some("number") => v.is_number(),
        Some("integer") => v.is_u64() || v.is_i64(),
        Some(other) => panic!("schema type {other} not handled"),
    };
    if !ok {
        return Some(format!("{path}: {v} is not of type {}", schema["type"]));
    }
    if let (Some(min), Some(x)) = (schema.get("minimum").and_then(Value::as_f64), v.as_f64()) {
        if x < min {
            return Some(format!("{path}: {x} < minimum {min}"));
        }
    }
    if let (Some(max), Some(x)) = (schema.get("maximum").and_then(Value::as_f64), v.as_f64()) {
        if x > max {
            return Some(format!("{path}: {x} > maximum {max}"));
        }
    }
    if let Some(required) = schema.get("required").and_then(Value::as_array) {
        for r in required {
            let r = r.as_str().unwrap();
            if v.get(r).is_none() {
                return Some(format!("{path}: required field `{r}` missing"));
            }
        }
    }
    if let Some(props) = schema.get("properties").and_then(Value::as_object) {
        for (k, sub) in props {
            if let Some(x) = v.get(k) {
                if let Some(e) = violation(sub, x, &format!("{path}.{k}")) {
                    return Some(e);
                }
            }
        }
        for k in v.as_object().unwrap().keys() {
            if !props.contains_key(k) {
                return Some(format!("{path}: field `{k}` is not in the schema"));
            }
        }
    }
    if let (Some(items), Some(arr)) = (schema.get("items"), v.as_array()) {
        for (i, x) in arr.iter().enumerate() {
            if let Some(e) = violation(items, x, &format!("{path}[{i}]")) {
                return Some(e);
            }
        }
    }
    None
}

fn entities(v: &Value) -> &Vec<Value> {
    v["entities"].as_array().unwrap()
}

fn quaternion(v: &Value) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(
        num(&v["w"]),
        num(&v["x"]),
        num(&v["y"]),
        num(&v["z"]),
    ))
}

#[test]
fn every_message_is_json_that_satisfies_the_official_schema() {
    let messages = synthetic(100.0, 3.0);
    for (topic, _, v) in &messages {
        let schema: Value =
            serde_json::from_slice(schema_bytes(topic.schema_name()).unwrap()).unwrap();
        if let Some(e) = violation(&schema, v, topic.schema_name()) {
            panic!("{topic}: {e}\nmessage: {v}");
        }
    }
    let topics: std::collections::BTreeSet<Topic> = messages.iter().map(|m| m.0).collect();
    println!(
        "{} messages on {} topics checked against foxglove.* schemas",
        messages.len(),
        topics.len()
    );
    assert!(messages.len() > 300);
}

#[test]
fn the_table_rotation_is_proper_and_takes_the_note_up_axis_to_foxglove_up() {
    let q = TABLE_ROTATION;
    let cases = [
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [0.0, -1.0, 0.0]),
    ];
    for (from, to) in cases {
        let r = q.transform_vector(&Vector3::from(from));
        for i in 0..3 {
            assert!(
                (r[i] - to[i]).abs() < 1e-15,
                "{from:?} → {r:?}, expected {to:?}"
            );
        }
    }
    println!("|q| = {} (expected 1, tolerance 1e-15)", q.norm());
    assert!((q.norm() - 1.0).abs() < 1e-15);
}

#[test]
fn the_coin_frame_puts_the_rim_point_minus_a_e_y_on_the_contact_point() {
    // Translation + rotation of /tf table → coin must carry the coin-frame point c = −a e_Y of the lean
    // frame (in the coin frame: the rim point (0, −a, 0) before spin ψ, i.e. rotated back by ψ) onto the
    // model's contact point (physics §3): checks the frame against an independent formula.
    let coin = unit_coin();
    let rate = 1.0 / 0.37;
    let messages = synthetic_with(&coin, rate, 49.0 / rate, &[Channel::Tf], state_at);
    let mut worst: f64 = 0.0;
    for (_, lt, v) in messages.iter().filter(|m| m.2["child_frame_id"] == "coin") {
        #[allow(clippy::cast_precision_loss)]
        let s = state_at(*lt as f64 * 1e-9);
        let tr = &v["translation"];
        let q = quaternion(&v["rotation"]);
        // q = q_lean · q(e_z, ψ), so the coin-frame vector that q takes to −a e_Y is the rotation of
        // (0, −1, 0) by −ψ about z: (−sin ψ, −cos ψ, 0).
        let (sp, cp) = s.psi.sin_cos();
        let rim = q.transform_vector(&Vector3::new(-sp, -cp, 0.0));
        let c = contact_point(&coin, &s);
        let g = centre(&coin, &s);
        let got = [
            num(&tr["x"]) + rim[0],
            num(&tr["y"]) + rim[1],
            num(&tr["z"]) + rim[2],
        ];
        assert!((num(&tr["y"]) - g.y).abs() <= 1e-15);
        for (a, b) in got.iter().zip([c.x, c.y, c.z]) {
            worst = worst.max((a - b).abs());
        }
    }
    println!("contact point from /tf vs model: max error {worst:e}, tolerance 1e-12");
    assert!(worst < 1e-12);
}

/// Per display update: (log time, follow translation, coin entity).
fn drawings(messages: &Messages) -> Vec<(u64, [f64; 3], Value)> {
    let mut out = Vec::new();
    let mut follow = None;
    for (topic, lt, v) in messages {
        match topic {
            Topic::SceneFollow => {
                assert_eq!(v["parent_frame_id"], "world");
                assert_eq!(v["child_frame_id"], FOLLOW_FRAME);
                assert_eq!(
                    v["rotation"],
                    serde_json::json!({"x": 0, "y": 0, "z": 0, "w": 1}),
                    "the follow frame stays level"
                );
                let tr = &v["translation"];
                follow = Some([num(&tr["x"]), num(&tr["y"]), num(&tr["z"])]);
            }
            Topic::Main(Channel::Scene) => {
                let coin = entities(v).iter().find(|e| e["id"] == "coin").unwrap();
                out.push((
                    *lt,
                    follow.take().expect("follow frame first"),
                    coin.clone(),
                ));
            }
            _ => {}
        }
    }
    out
}

#[test]
fn the_drawn_coin_sits_on_the_contact_point_in_units_of_a() {
    // The drawn coin: centre = the follow frame's translation, orientation = the entity's pose. Its rim
    // point −e_Y (the contact, physics §3) must be the model's contact point divided by a, carried into
    // `world` by the table rotation: (x_c/a, −z_c/a, 0). Checked at every display update, for a = 1 and
    // for the 500-yen coin's a = 0.01325 with the same motion in units of a.
    for a in [1.0, 0.013_25] {
        let params = CoinParams::new(7e-3, a, 9.81, Inertia::ThinDisk).unwrap();
        let coin = Coin::new(params);
        let messages = synthetic_with(&coin, 100.0, 3.0, BOTH, |t| state_scaled(t, a));
        let mut worst: f64 = 0.0;
        let updates = drawings(&messages);
        for (lt, follow, e) in &updates {
            assert_eq!(e["frame_id"], FOLLOW_FRAME);
            let r = quaternion(&e["cylinders"][0]["pose"]["orientation"]);
            #[allow(clippy::cast_precision_loss)]
            let t = *lt as f64 * 1e-9;
            let s = state_scaled(t, a);
            let (sp, cp) = s.psi.sin_cos();
            let rim = r.transform_vector(&Vector3::new(-sp, -cp, 0.0));
            let c = contact_point(&coin, &s);
            let expected = [c.x / a, -c.z / a, 0.0];
            for i in 0..3 {
                worst = worst.max((follow[i] + rim[i] - expected[i]).abs());
            }
        }
        println!(
            "a = {a}: {} updates, drawn contact vs model: max error {worst:e} (tolerance 1e-12)",
            updates.len()
        );
        assert!(worst < 1e-12);
    }
}

#[test]
fn the_coin_entity_is_a_cylinder_with_a_mark_outside_each_face() {
    let messages = synthetic(100.0, 0.5);
    let (lt, _, coin) = &drawings(&messages)[0];
    assert_eq!(coin["frame_locked"], true);
    assert_eq!(coin["lifetime"], serde_json::json!({"sec": 0, "nsec": 0}));
    assert_eq!(time_ns(&coin["timestamp"]), *lt);
    let cyl = &coin["cylinders"][0];
    assert_eq!(coin["cylinders"].as_array().unwrap().len(), 1);
    assert_eq!(
        cyl["size"],
        serde_json::json!({"x": 2.0, "y": 2.0, "z": 0.05})
    );
    assert_eq!(cyl["bottom_scale"], 1);
    assert_eq!(cyl["top_scale"], 1);
    for ch in ["r", "g", "b", "a"] {
        assert!((0.0..=1.0).contains(&num(&cyl["color"][ch])));
    }
    let r = quaternion(&cyl["pose"]["orientation"]);
    let normal = r.transform_vector(&Vector3::z());
    let cubes = coin["cubes"].as_array().unwrap();
    assert_eq!(cubes.len(), 2);
    // Each mark's centre, along the coin's normal: outside the top (+) and bottom (−) faces at ±0.025.
    let along: Vec<f64> = cubes
        .iter()
        .map(|c| {
            let p = &c["pose"]["position"];
            Vector3::new(num(&p["x"]), num(&p["y"]), num(&p["z"])).dot(&normal)
        })
        .collect();
    assert!(
        along[0] > 0.025 && along[1] < -0.025,
        "marks outside both faces: {along:?}"
    );
}

#[test]
fn the_table_stays_under_the_coin_and_its_grid_is_fixed_to_the_table() {
    // A coin running off fast along x: the table must follow in steps of TABLE_SNAP, keep the coin at
    // least TABLE_HALF_SIDE − TABLE_SNAP from its edge, and draw grid lines on whole display units only
    // (so they stay put on the table while the slab moves).
    let coin = unit_coin();
    let run = |t: f64| State {
        x: 37.0 * t,
        z: 3.0 * t,
        ..state_at(t)
    };
    let messages = synthetic_with(&coin, 100.0, 4.0, BOTH, run);
    // Tables drawn and follow-frame positions, by log time.
    let mut tables: Vec<(u64, [f64; 2])> = Vec::new();
    let mut follows: Vec<(u64, [f64; 2])> = Vec::new();
    for (topic, lt, v) in &messages {
        match topic {
            Topic::SceneTable => {
                let e = &entities(v)[0];
                assert_eq!(e["frame_id"], WORLD_FRAME);
                let p = &e["cubes"][0]["pose"]["position"];
                tables.push((*lt, [num(&p["x"]), num(&p["y"])]));
                for line in e["lines"].as_array().unwrap() {
                    assert_eq!(line["type"], 2, "a line list");
                    for q in line["points"].as_array().unwrap() {
                        for k in ["x", "y"] {
                            assert_eq!(num(&q[k]).fract(), 0.0, "grid on whole units: {q}");
                        }
                    }
                }
            }
            Topic::SceneFollow => {
                let tr = &v["translation"];
                follows.push((*lt, [num(&tr["x"]), num(&tr["y"])]));
            }
            _ => {}
        }
    }
    let mut closest_edge = f64::INFINITY;
    for (lt, p) in &follows {
        let (_, t) = tables
            .iter()
            .rev()
            .find(|(tl, _)| tl <= lt)
            .expect("the table is drawn at the first update");
        let d = (p[0] - t[0]).abs().max((p[1] - t[1]).abs());
        closest_edge = closest_edge.min(TABLE_HALF_SIDE - d);
    }
    let moves = tables.len();
    println!("table drawn {moves} times for 148 a of travel; closest the coin came to an edge: {closest_edge} a (≥ 20)");
    assert!((14..=17).contains(&moves), "{moves}");
    assert!(closest_edge >= TABLE_HALF_SIDE - TABLE_SNAP - 1e-9);
}

#[test]
fn the_drawing_is_the_same_for_any_radius_in_units_of_a() {
    // The same motion in units of a, for a = 1 and a = 0.01325: every drawing message carries the same
    // numbers (to round-off), so one layout suits both.
    let unit = synthetic(100.0, 2.0);
    let params = CoinParams::new(7e-3, 0.013_25, 9.81, Inertia::ThinDisk).unwrap();
    let yen = synthetic_with(&Coin::new(params), 100.0, 2.0, BOTH, |t| {
        state_scaled(t, 0.013_25)
    });
    let drawing = |m: &Messages| -> Vec<(Topic, String)> {
        m.iter()
            .filter(|(t, _, _)| t.channel() == Channel::Scene)
            .map(|(t, _, v)| (*t, v.to_string()))
            .collect()
    };
    let (u, y) = (drawing(&unit), drawing(&yen));
    assert_eq!(u.len(), y.len());
    let mut differing = 0;
    for ((tu, vu), (ty, vy)) in u.iter().zip(&y) {
        assert_eq!(tu, ty);
        if vu != vy {
            differing += 1;
            // Only the follow translation may differ, by round-off of x·a/a.
            assert_eq!(*tu, Topic::SceneFollow, "{vu}\n{vy}");
        }
    }
    println!(
        "{} drawing messages, {differing} differ in round-off only",
        u.len()
    );
}

#[test]
fn a_coin_spinning_in_place_draws_no_track() {
    let spin = |t: f64| State {
        phi: 2.0 * t,
        omega_y: 2.0,
        ..State::default()
    };
    for (topic, _, _) in synthetic_with(&unit_coin(), 100.0, 1.99, &[Channel::Scene], spin) {
        assert_eq!(topic.channel(), Channel::Scene, "tf is off");
        assert!(!matches!(topic, Topic::SceneTrack(_)), "no track");
    }
    let off = synthetic_with(&unit_coin(), 100.0, 0.1, &[], state_at);
    assert!(
        off.is_empty(),
        "nothing is written when both channels are off"
    );
}

#[test]
fn non_finite_values_are_refused_and_leave_the_batch_alone() {
    let coin = unit_coin();
    let mut fox = Foxglove3d::new(&coin, 0.05, &[Channel::Tf, Channel::Scene], Encoding::Json);
    let mut batch = FoxgloveBatch::default();
    fox.sample(0.0, 0, &state_at(0.0), false, &mut batch)
        .unwrap();
    let before = batch.iter().count();
    let bad = State {
        psi: f64::NAN,
        ..state_at(0.01)
    };
    let err = fox
        .sample(0.01, 10_000_000, &bad, false, &mut batch)
        .unwrap_err();
    println!("{err}");
    assert_eq!(err.schema, FRAME_TRANSFORM);
    assert_eq!(batch.iter().count(), before);
    let bad = State {
        x: f64::INFINITY,
        ..state_at(0.02)
    };
    assert!(fox
        .sample(0.02, 20_000_000, &bad, false, &mut batch)
        .is_err());
    let mut drawing = Foxglove3d::new(&coin, 0.05, &[Channel::Scene], Encoding::Json);
    let err = drawing
        .sample(
            0.0,
            0,
            &State {
                theta: f64::NAN,
                ..state_at(0.0)
            },
            false,
            &mut batch,
        )
        .unwrap_err();
    assert_eq!(err.schema, SCENE_UPDATE);
}

// ---------------------------------------------------------------------------------------------------------
// The shipped layouts.

const LAYOUTS: [&str; 2] = ["foxglove-layout.json", "foxglove-layout-physics.json"];

fn layout(name: &str) -> Value {
    let text = std::fs::read_to_string(repo().join("datasets").join(name)).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Keys whose values the viewers read as numbers (Lichtblick's and Foxglove's panel configs).
const NUMERIC_KEYS: [&str; 14] = [
    "distance",
    "phi",
    "thetaOffset",
    "fovy",
    "near",
    "far",
    "minYValue",
    "maxYValue",
    "minXValue",
    "maxXValue",
    "splitPercentage",
    "speed",
    "sidebarDimension",
    "followingViewWidth",
];

/// Every place in `v` where a numeric key holds something else than a number, or a string looks like a
/// number or is empty (a viewer converting it with `+` gets a number the author did not mean: `+"" = 0`).
fn non_numbers(v: &Value, path: &str, out: &mut Vec<String>) {
    match v {
        Value::Object(o) => {
            for (k, x) in o {
                let here = format!("{path}.{k}");
                if NUMERIC_KEYS.contains(&k.as_str()) && !x.is_number() {
                    out.push(format!("{here} = {x}: a number or absent"));
                }
                non_numbers(x, &here, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                non_numbers(x, &format!("{path}[{i}]"), out);
            }
        }
        Value::String(s) if s.trim().is_empty() || s.trim().parse::<f64>().is_ok() => {
            out.push(format!(
                "{path} = {s:?}: a string where a number or nothing is meant"
            ));
        }
        _ => {}
    }
}

#[test]
fn every_numeric_field_of_the_layouts_is_a_number_or_absent() {
    for name in LAYOUTS {
        let mut problems = Vec::new();
        non_numbers(&layout(name), "", &mut problems);
        assert!(problems.is_empty(), "{name}: {problems:#?}");
        println!("{name}: every numeric field is a number");
    }
    // Negative control: the y-limits that emptied every plot.
    let mut bad = layout(LAYOUTS[0]);
    bad["configById"]["Plot!omega"]["minYValue"] = Value::from("");
    let mut problems = Vec::new();
    non_numbers(&bad, "", &mut problems);
    println!("negative control: {problems:?}");
    assert!(!problems.is_empty() && problems.iter().all(|p| p.contains("Plot!omega.minYValue")));
}

/// Panel ids in a layout tree (a string, or {first, second, direction, ...}).
fn panel_ids(node: &Value, out: &mut Vec<String>) {
    match node {
        Value::String(id) => out.push(id.clone()),
        Value::Object(o) => {
            panel_ids(&o["first"], out);
            panel_ids(&o["second"], out);
        }
        _ => panic!("bad layout node {node}"),
    }
}

/// The plotted paths of a layout.
fn plotted(layout: &Value) -> BTreeSet<String> {
    let mut paths = BTreeSet::new();
    for (id, c) in layout["configById"].as_object().unwrap() {
        if id.starts_with("Plot!") {
            for p in c["paths"].as_array().unwrap() {
                assert_eq!(p["enabled"], true);
                paths.insert(p["value"].as_str().unwrap().to_string());
            }
        }
    }
    paths
}

#[test]
fn every_plotted_path_is_a_numeric_field_of_a_recorded_topic() {
    let recorded: BTreeSet<&str> = recordings()[0]
        .messages
        .iter()
        .map(|m| m.topic.as_str())
        .collect();
    for name in LAYOUTS {
        for p in plotted(&layout(name)) {
            let (topic, field) = p.split_once('.').unwrap();
            let t = Topic::from_name(topic).unwrap_or_else(|| panic!("{name}: {p}: unknown topic"));
            assert!(recorded.contains(topic), "{name}: {p}: not in the datasets");
            let schema: Value =
                serde_json::from_slice(schema_bytes(t.schema_name()).unwrap()).unwrap();
            assert_eq!(
                schema["properties"][field]["type"],
                "number",
                "{name}: {p}: not a number field of {}",
                t.schema_name()
            );
        }
    }
    let main = plotted(&layout(LAYOUTS[0]));
    for w in [
        "/coin/omega.x",
        "/coin/omega.y",
        "/coin/omega.z",
        "/coin/angles.theta",
        "/coin/energy.total",
        "/coin/reaction.normal",
    ] {
        assert!(main.contains(w), "{}: no plot of {w}", LAYOUTS[0]);
    }
    let physics = plotted(&layout(LAYOUTS[1]));
    for w in [
        "/coin/omega.x",
        "/coin/omega.y",
        "/coin/omega.z",
        "/coin/angles.theta",
        "/coin/angles.phi_dot",
        "/coin/energy.drift_eps",
        "/coin/reaction.normal",
        "/coin/reaction.friction_ratio",
        "/coin/invariants.c1",
        "/coin/invariants.c2",
    ] {
        assert!(physics.contains(w), "{}: no plot of {w}", LAYOUTS[1]);
    }
}

#[test]
fn the_layouts_follow_the_level_frame_show_every_drawing_topic_and_name_every_panel() {
    for name in LAYOUTS {
        let layout = layout(name);
        let configs = layout["configById"].as_object().unwrap();
        let mut ids = Vec::new();
        panel_ids(&layout["layout"], &mut ids);
        let in_tree: BTreeSet<&String> = ids.iter().collect();
        assert_eq!(
            in_tree,
            configs.keys().collect(),
            "{name}: panels in the tree = panels configured"
        );
        for (id, c) in configs {
            let title = c["lichtblickPanelTitle"].as_str().unwrap_or_default();
            assert!(
                !title.is_empty(),
                "{name}: {id} has no lichtblickPanelTitle"
            );
            assert_eq!(
                c["foxglovePanelTitle"], title,
                "{name}: {id}: both title keys, the same"
            );
            if id.starts_with("Plot!") {
                for k in ["minYValue", "maxYValue"] {
                    assert!(
                        c.get(k).is_none(),
                        "{name}: {id}: {k} set, the plot would not autoscale"
                    );
                }
            } else {
                assert!(id.starts_with("3D!"), "{name}: unexpected panel {id}");
                check_3d_panel(name, c);
            }
        }
    }
}

fn check_3d_panel(name: &str, c: &Value) {
    assert_eq!(
        c["followTf"], FOLLOW_FRAME,
        "{name}: the camera follows the level frame"
    );
    assert_eq!(c["followMode"], "follow-pose");
    for t in Topic::all().filter(|t| t.schema_name() == "foxglove.SceneUpdate") {
        assert_eq!(
            c["topics"][t.name()]["visible"],
            true,
            "{name}: {t} hidden (SceneUpdate topics are hidden by default)"
        );
    }
    for frame in [WORLD_FRAME, "table", "coin", FOLLOW_FRAME] {
        assert_eq!(
            c["transforms"][format!("frame:{frame}")]["visible"],
            false,
            "{name}: frame {frame} would draw axes and a connector line"
        );
    }
    let camera = &c["cameraState"];
    // Units of a: the coin (diameter 2) and ≥ 5 a of track around it in view.
    let distance = num(&camera["distance"]);
    assert!(
        (10.0..=30.0).contains(&distance),
        "{name}: camera distance {distance}"
    );
}
