//! Foxglove's 3D view of the coin (docs/format.md: Frames and Foxglove output): after a seek a viewer keeps
//! only the latest message of each topic, so each thing the view needs has a topic whose latest message
//! alone draws it. Frames (`tf`, physical units): `world` (z up) → `table` (the physics frame, y up,
//! [`TABLE_ROTATION`]) → `coin`. The drawing (`scene`, units of a, at [`SCENE_RATE`]): `/scene/follow`
//! ([`FOLLOW_FRAME`]), `/scene` (the coin), `/scene/table`, and the track's levels ([`track`]); the opt-in
//! `rerun` channel draws them again for Rerun.

mod json;
mod proto;
mod rerun;
pub mod track;

use crate::format::messages::NonFiniteField;
use crate::format::{Channel, Encoding, Topic, FRAME_TRANSFORM, SCENE_UPDATE, TRACK_LEVELS};
use crate::model::{contact_point, orientation, Coin, State};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::ops::Range;
use track::Track;

/// Display rate of the drawing, in updates per time unit of simulation time (≈ 30 Hz in Foxglove).
pub const SCENE_RATE: f64 = 30.0;

/// Rotation `world` ← `table`: +90° about x (note's y up → Foxglove's z up), q_T = (cos 45°; sin 45°, 0, 0).
/// Unit to round-off (2·(1/√2)² = 1 ± 1 ulp), so it is wrapped as it is.
pub const TABLE_ROTATION: UnitQuaternion<f64> = UnitQuaternion::new_unchecked(Quaternion::new(
    std::f64::consts::FRAC_1_SQRT_2,
    std::f64::consts::FRAC_1_SQRT_2,
    0.0,
    0.0,
));

/// Root frame (z up).
pub const WORLD_FRAME: &str = "world";
/// The table, the note's y-up world frame.
pub const TABLE_FRAME: &str = "table";
/// The coin's body frame (origin at the centre, z its normal).
pub const COIN_FRAME: &str = "coin";
/// The level frame at the coin's centre, in display units: the frame the camera follows.
pub const FOLLOW_FRAME: &str = "coin_level";

/// Grid lines on each side of the table's centre line (one per display unit).
const GRID_HALF_COUNT: i32 = 30;
/// Half the side of the table slab, display units.
#[allow(clippy::cast_lossless)]
pub const TABLE_HALF_SIDE: f64 = GRID_HALF_COUNT as f64;
/// The table's centre is a multiple of this, display units; it moves when the coin is farther than this.
pub const TABLE_SNAP: f64 = 10.0;
/// Slab thickness, and heights of its top and of the grid lines (below the track at 0), display units:
/// 3e-3 apart, resolved by a 24-bit depth buffer with the layout's near plane 0.1 at the camera distance.
const TABLE_THICKNESS: f64 = 0.02;
const TABLE_TOP: f64 = -0.006;
const GRID_HEIGHT: f64 = -0.003;
/// Widths of the grid lines (minor, major) and of the track, in pixels (`scale_invariant` lines: as thick
/// at any zoom).
const GRID_WIDTHS: [f64; 2] = [1.0, 2.0];
const TRACK_WIDTH: f64 = 3.0;
/// Every GRID_MAJOR-th grid line is a major one.
const GRID_MAJOR: i32 = 5;

/// A colour (r, g, b, a) in 0..1, as both encodings write it.
type Rgba = [f64; 4];
const COIN_RGBA: Rgba = [0.85, 0.65, 0.2, 1.0];
const MARK_RGBA: [Rgba; 2] = [[0.6, 0.05, 0.05, 1.0], [0.05, 0.1, 0.55, 1.0]];
const TABLE_RGBA: Rgba = [0.87, 0.86, 0.82, 1.0];
const GRID_RGBA: [Rgba; 2] = [[0.66, 0.66, 0.63, 1.0], [0.45, 0.45, 0.43, 1.0]];
const TRACK_RGBA: Rgba = [0.1, 0.35, 0.9, 1.0];

pub use proto::MAX_SECONDS as PROTOBUF_MAX_SECONDS;

/// Calls the writer `$f` of `$encoding`: [`json`] and [`proto`] have the same writers.
macro_rules! encode {
    ($encoding:expr, $f:ident($($arg:expr),*)) => {
        match $encoding {
            Encoding::Json => json::$f($($arg),*),
            Encoding::Protobuf => proto::$f($($arg),*),
        }
    };
}

/// `Err` naming `field` of `schema` unless every value is finite (neither encoding carries the others).
fn finite(schema: &'static str, field: &'static str, values: &[f64]) -> Result<(), NonFiniteField> {
    match values.iter().find(|v| !v.is_finite()) {
        None => Ok(()),
        Some(&value) => Err(NonFiniteField {
            schema,
            field,
            value,
        }),
    }
}

/// The coin's two face marks, posed with the coin's orientation `r`: (centre in `coin_level`, size, colour),
/// the top (+z) face's first. A bar 0.85 × 0.12 just outside each face, `0.2 · thickness` thick (at least
/// 1e-3), so that spin and the face that is up both show.
fn coin_marks(r: &UnitQuaternion<f64>, thickness: f64) -> [(Vector3<f64>, [f64; 3], Rgba); 2] {
    let mark = (0.2 * thickness).max(1e-3);
    [1.0, -1.0].map(|sign: f64| {
        let colour = MARK_RGBA[usize::from(sign < 0.0)];
        (
            r * Vector3::new(0.45, 0.0, sign * 0.5 * (thickness + mark)),
            [0.85, 0.12, mark],
            colour,
        )
    })
}

/// The segments of the table's grid centred on `centre`: the minor lines (every 1) or the major ones (every
/// [`GRID_MAJOR`]), across the slab in both directions, as (start, end) in display units.
fn grid_segments(centre: [f64; 2], major: bool) -> impl Iterator<Item = ([f64; 2], [f64; 2])> {
    (-GRID_HALF_COUNT..=GRID_HALF_COUNT)
        // The centre is a multiple of TABLE_SNAP (10), itself a multiple of GRID_MAJOR.
        .filter(move |k| (k % GRID_MAJOR == 0) == major)
        .flat_map(move |k| {
            let offset = f64::from(k);
            [
                (offset, -TABLE_HALF_SIDE, offset, TABLE_HALF_SIDE),
                (-TABLE_HALF_SIDE, offset, TABLE_HALF_SIDE, offset),
            ]
            .map(|(x0, y0, x1, y1)| {
                (
                    [centre[0] + x0, centre[1] + y0],
                    [centre[0] + x1, centre[1] + y1],
                )
            })
        })
}

/// The messages due at one sample, in one reused buffer.
#[derive(Debug, Default)]
pub struct FoxgloveBatch {
    bytes: Vec<u8>,
    messages: Vec<(Topic, Range<usize>)>,
}

impl FoxgloveBatch {
    /// Empties the batch, keeping its capacity.
    pub fn clear(&mut self) {
        self.bytes.clear();
        self.messages.clear();
    }

    /// Appends one message on `topic`, written by `write`.
    pub fn push(&mut self, topic: Topic, write: impl FnOnce(&mut Vec<u8>)) {
        let start = self.bytes.len();
        write(&mut self.bytes);
        self.messages.push((topic, start..self.bytes.len()));
    }

    /// The messages, in the order they were pushed.
    pub fn iter(&self) -> impl Iterator<Item = (Topic, &[u8])> + '_ {
        self.messages
            .iter()
            .map(|(c, r)| (*c, &self.bytes[r.clone()]))
    }
}

/// State of the 3D output across samples (display rate, table, track).
#[derive(Debug, Clone)]
pub struct Foxglove3d {
    coin: Coin,
    encoding: Encoding,
    /// 1/a: lengths → display units.
    inv_a: f64,
    thickness: f64,
    tf: bool,
    scene: bool,
    /// Whether the first sample (static transform, first scene) has been written.
    started: bool,
    /// round(t · SCENE_RATE) of the last scene update.
    last_scene_slot: u64,
    /// Table centre (display units), once drawn.
    table: Option<[f64; 2]>,
    track: Track,
    /// Whether the latest message of each track level drew a line (else it deleted it, or there was none).
    drawn: [bool; TRACK_LEVELS],
    /// The `rerun` channel's output, when recorded (drawn with the scene, so only when `scene` is).
    rerun: Option<rerun::Rerun3d>,
}

impl Foxglove3d {
    /// Output for `coin` drawn `thickness` (fraction of a) thick, of those of `channels` it writes (`tf`,
    /// `scene`, `rerun`), in `encoding` (`rerun` is Protobuf whatever the encoding: the recorder refuses it
    /// in JSON).
    #[must_use]
    pub fn new(coin: &Coin, thickness: f64, channels: &[Channel], encoding: Encoding) -> Self {
        let scene = channels.contains(&Channel::Scene);
        Self {
            coin: *coin,
            encoding,
            inv_a: 1.0 / coin.params().radius(),
            thickness,
            tf: channels.contains(&Channel::Tf),
            scene,
            started: false,
            last_scene_slot: 0,
            table: None,
            track: Track::default(),
            drawn: [false; TRACK_LEVELS],
            rerun: (scene && channels.contains(&Channel::Rerun))
                .then(|| rerun::Rerun3d::new(thickness)),
        }
    }

    /// Appends to `out` the messages due at the sample (t, s), whose log time is `log_time` ns; `last` marks
    /// the run's final sample (so the drawing shows the final state).
    ///
    /// At the first sample: `/tf` world → table, `/tf` table → coin, `/tf_static` world → table, then the
    /// drawing. Afterwards: `/tf` table → coin at every sample, the drawing when a display slot of
    /// [`SCENE_RATE`] has passed, and at `last`. Samples must come in increasing t.
    ///
    /// # Errors
    /// [`NonFiniteField`] if a value is not finite (the state, or a thickness that is not).
    pub fn sample(
        &mut self,
        t: f64,
        log_time: u64,
        s: &State,
        last: bool,
        out: &mut FoxgloveBatch,
    ) -> Result<(), NonFiniteField> {
        let first = !self.started;
        let encoding = self.encoding;
        if self.tf {
            let translation = [s.x, self.coin.params().radius() * s.theta.cos(), s.z];
            let q = orientation(s);
            finite(FRAME_TRANSFORM, "translation", &translation)?;
            finite(FRAME_TRANSFORM, "rotation", q.coords.as_slice())?;
            let tf = Topic::Main(Channel::Tf);
            if first {
                out.push(tf, |buf| encode!(encoding, table_transform(buf, log_time)));
            }
            out.push(tf, |buf| {
                encode!(encoding, coin_transform(buf, log_time, translation, &q));
            });
            if first {
                out.push(Topic::TfStatic, |buf| {
                    encode!(encoding, table_transform(buf, log_time));
                });
            }
        }
        if self.scene {
            let c = contact_point(&self.coin, s);
            finite(SCENE_UPDATE, "lines.points", &[c.x, c.z])?;
            self.track.add(c.x * self.inv_a, -c.z * self.inv_a);
            if let Some(r) = &mut self.rerun {
                r.contact([c.x * self.inv_a, -c.z * self.inv_a]);
            }
            let slot = scene_slot(t);
            if first || last || slot > self.last_scene_slot {
                self.last_scene_slot = slot;
                self.push_drawing(log_time, s, out)?;
            }
        }
        self.started = true;
        Ok(())
    }

    /// Appends one display update: the follow frame, the coin, the table if it moved, the track levels that
    /// changed.
    fn push_drawing(
        &mut self,
        log_time: u64,
        s: &State,
        out: &mut FoxgloveBatch,
    ) -> Result<(), NonFiniteField> {
        let centre = [s.x * self.inv_a, -s.z * self.inv_a, s.theta.cos()];
        let rotation = TABLE_ROTATION * orientation(s);
        let (encoding, thickness) = (self.encoding, self.thickness);
        finite(SCENE_UPDATE, "pose.position", &centre)?;
        finite(SCENE_UPDATE, "pose.orientation", rotation.coords.as_slice())?;
        finite(SCENE_UPDATE, "cylinders.size.z", &[thickness])?;
        out.push(Topic::SceneFollow, |buf| {
            encode!(encoding, follow_transform(buf, log_time, centre));
        });
        out.push(Topic::Main(Channel::Scene), |buf| {
            encode!(encoding, coin(buf, log_time, &rotation, thickness));
        });
        if let Some(r) = &mut self.rerun {
            r.coin(log_time, &rotation, out);
        }
        let moved = match self.table {
            Some(t) if (centre[0] - t[0]).abs().max((centre[1] - t[1]).abs()) <= TABLE_SNAP => None,
            _ => Some([snap(centre[0]), snap(centre[1])]),
        };
        if let Some(table) = moved {
            out.push(Topic::SceneTable, |buf| {
                encode!(encoding, table(buf, log_time, table));
            });
            if self.rerun.is_some() {
                out.push(Topic::RerunTable, |buf| rerun::table(buf, log_time, table));
            }
            self.table = Some(table);
        }
        if let Some(changed) = self.track.update() {
            for level in (0..=changed).rev() {
                self.push_track_level(level, log_time, out)?;
            }
        }
        if let Some(r) = &mut self.rerun {
            r.track(log_time, out);
        }
        Ok(())
    }

    /// Appends the message of one track level: its line, or the deletion of the line it drew last.
    fn push_track_level(
        &mut self,
        level: usize,
        log_time: u64,
        out: &mut FoxgloveBatch,
    ) -> Result<(), NonFiniteField> {
        // level < TRACK_LEVELS = 16 fits in a u8.
        let topic = Topic::SceneTrack(u8::try_from(level).unwrap_or(u8::MAX));
        let points = self.track.level(level);
        let encoding = self.encoding;
        if !points.is_empty() {
            for p in points {
                finite(SCENE_UPDATE, "lines.points", &[p.x, p.y])?;
            }
            out.push(topic, |buf| encode!(encoding, track(buf, log_time, points)));
        } else if self.drawn[level] {
            out.push(topic, |buf| {
                encode!(encoding, track_deletion(buf, log_time))
            });
        }
        self.drawn[level] = !points.is_empty();
        Ok(())
    }
}

/// The display slot of simulation time t: round(t · SCENE_RATE). Rounding (not flooring) makes a data rate
/// equal to the display rate publish at every sample despite t = k/rate being inexact.
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
fn scene_slot(t: f64) -> u64 {
    let slot = (t * SCENE_RATE).round();
    if slot.is_finite() && slot > 0.0 {
        slot as u64
    } else {
        0
    }
}

/// `v` rounded to the nearest multiple of [`TABLE_SNAP`] (−0 as 0).
fn snap(v: f64) -> f64 {
    (v / TABLE_SNAP).round() * TABLE_SNAP + 0.0
}

#[cfg(test)]
mod tests {
    // Unit tests of the Foxglove output: schemas, frames, the drawing's geometry against the model, rates,
    // the table, the track's levels, scale invariance, non-finite values.

    use super::track::{segment_distance, MAX_TOLERANCE, QUANTUM};
    use super::*;
    use crate::format::log_time;
    use crate::format::schema_bytes;
    use crate::model::{centre, CoinParams, Inertia};
    use nalgebra::Vector3;
    use serde_json::Value;

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

    /// Records `state(t)` for `coin` at `rate` for `duration` into (topic, log time, JSON) triples.
    fn record_with(
        coin: &Coin,
        rate: f64,
        duration: f64,
        state: impl Fn(f64) -> State,
    ) -> Messages {
        let mut fox = Foxglove3d::new(coin, 0.05, &[Channel::Tf, Channel::Scene], Encoding::Json);
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

    fn record(rate: f64, duration: f64) -> Messages {
        record_with(&unit_coin(), rate, duration, state_at)
    }

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

    fn number(v: &Value) -> f64 {
        v.as_f64().unwrap()
    }

    fn time_of(entity: &Value) -> u64 {
        entity["timestamp"]["sec"].as_u64().unwrap() * 1_000_000_000
            + entity["timestamp"]["nsec"].as_u64().unwrap()
    }

    fn quaternion(v: &Value) -> UnitQuaternion<f64> {
        UnitQuaternion::new_unchecked(Quaternion::new(
            number(&v["w"]),
            number(&v["x"]),
            number(&v["y"]),
            number(&v["z"]),
        ))
    }

    #[test]
    fn every_message_is_json_that_satisfies_the_official_schema() {
        let messages = record(100.0, 3.0);
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
    fn the_static_table_transform_comes_first_on_tf_and_once_on_its_own_topic() {
        let messages = record(100.0, 1.0);
        let tables: Vec<(usize, Topic)> = messages
            .iter()
            .enumerate()
            .filter(|(_, (_, _, v))| v.get("child_frame_id") == Some(&Value::from("table")))
            .map(|(i, (t, _, _))| (i, *t))
            .collect();
        assert_eq!(
            tables,
            vec![(0, Topic::Main(Channel::Tf)), (2, Topic::TfStatic)],
            "world → table first on /tf and once on /tf_static"
        );
        let first_drawing = messages
            .iter()
            .position(|(c, _, _)| c.channel() == Channel::Scene)
            .unwrap();
        assert!(first_drawing > 2);
        for i in [0, 2] {
            assert_eq!(messages[i].2["parent_frame_id"], "world");
            assert_eq!(messages[i].1, 0);
        }
        let coin_tfs = messages
            .iter()
            .filter(|(_, _, v)| v.get("child_frame_id") == Some(&Value::from("coin")))
            .count();
        println!("coin transforms: measured {coin_tfs}, expected 101 (one per sample)");
        assert_eq!(coin_tfs, 101);
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
        let mut fox = Foxglove3d::new(&coin, 0.05, &[Channel::Tf], Encoding::Json);
        let mut batch = FoxgloveBatch::default();
        let mut worst: f64 = 0.0;
        for k in 0..50 {
            let t = f64::from(k) * 0.37;
            let s = state_at(t);
            batch.clear();
            fox.sample(t, log_time(t).unwrap(), &s, false, &mut batch)
                .unwrap();
            let v: Value = batch
                .iter()
                .map(|(_, bytes)| serde_json::from_slice::<Value>(bytes).unwrap())
                .find(|v| v["child_frame_id"] == "coin")
                .unwrap();
            let tr = &v["translation"];
            let q = quaternion(&v["rotation"]);
            // q = q_lean · q(e_z, ψ), so the coin-frame vector that q takes to −a e_Y is the rotation of
            // (0, −1, 0) by −ψ about z: (−sin ψ, −cos ψ, 0).
            let (sp, cp) = s.psi.sin_cos();
            let rim = q.transform_vector(&Vector3::new(-sp, -cp, 0.0));
            let c = contact_point(&coin, &s);
            let g = centre(&coin, &s);
            let got = [
                number(&tr["x"]) + rim[0],
                number(&tr["y"]) + rim[1],
                number(&tr["z"]) + rim[2],
            ];
            assert!((number(&tr["y"]) - g.y).abs() <= 1e-15);
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
                    follow = Some([number(&tr["x"]), number(&tr["y"]), number(&tr["z"])]);
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
            let messages = record_with(&coin, 100.0, 3.0, |t| state_scaled(t, a));
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
            println!("a = {a}: {} updates, drawn contact vs model: max error {worst:e} (tolerance 1e-12)", updates.len());
            assert!(worst < 1e-12);
        }
    }

    #[test]
    fn the_coin_entity_is_a_cylinder_with_a_mark_outside_each_face() {
        let messages = record(100.0, 0.5);
        let (lt, _, coin) = &drawings(&messages)[0];
        assert_eq!(coin["frame_locked"], true);
        assert_eq!(coin["lifetime"], serde_json::json!({"sec": 0, "nsec": 0}));
        assert_eq!(time_of(coin), *lt);
        let cyl = &coin["cylinders"][0];
        assert_eq!(coin["cylinders"].as_array().unwrap().len(), 1);
        assert_eq!(
            cyl["size"],
            serde_json::json!({"x": 2.0, "y": 2.0, "z": 0.05})
        );
        assert_eq!(cyl["bottom_scale"], 1);
        assert_eq!(cyl["top_scale"], 1);
        for ch in ["r", "g", "b", "a"] {
            assert!((0.0..=1.0).contains(&number(&cyl["color"][ch])));
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
                Vector3::new(number(&p["x"]), number(&p["y"]), number(&p["z"])).dot(&normal)
            })
            .collect();
        assert!(
            along[0] > 0.025 && along[1] < -0.025,
            "marks outside both faces: {along:?}"
        );
    }

    #[test]
    fn drawing_updates_come_at_about_thirty_per_time_unit_whatever_the_data_rate() {
        for rate in [30.0, 45.0, 100.0, 1000.0] {
            let messages = record(rate, 4.0);
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
        let messages = record_with(&coin, 100.0, 4.0, run);
        // Tables drawn and follow-frame positions, by log time.
        let mut tables: Vec<(u64, [f64; 2])> = Vec::new();
        let mut follows: Vec<(u64, [f64; 2])> = Vec::new();
        for (topic, lt, v) in &messages {
            match topic {
                Topic::SceneTable => {
                    let e = &entities(v)[0];
                    assert_eq!(e["frame_id"], WORLD_FRAME);
                    let p = &e["cubes"][0]["pose"]["position"];
                    tables.push((*lt, [number(&p["x"]), number(&p["y"])]));
                    for line in e["lines"].as_array().unwrap() {
                        assert_eq!(line["type"], 2, "a line list");
                        for q in line["points"].as_array().unwrap() {
                            for k in ["x", "y"] {
                                assert_eq!(number(&q[k]).fract(), 0.0, "grid on whole units: {q}");
                            }
                        }
                    }
                }
                Topic::SceneFollow => {
                    let tr = &v["translation"];
                    follows.push((*lt, [number(&tr["x"]), number(&tr["y"])]));
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

    /// The latest message of every track topic up to log time `cut`: the line each one draws, if any.
    fn latest_track_lines(messages: &Messages, cut: u64) -> Vec<(usize, Vec<[f64; 2]>)> {
        let mut latest: std::collections::BTreeMap<usize, &Value> =
            std::collections::BTreeMap::new();
        for (topic, lt, v) in messages {
            if let Topic::SceneTrack(level) = topic {
                if *lt <= cut {
                    latest.insert(usize::from(*level), v);
                }
            }
        }
        latest
            .into_iter()
            .filter_map(|(level, v)| {
                let e = entities(v).first()?;
                assert_eq!(e["id"], "track");
                assert_eq!(e["frame_id"], WORLD_FRAME);
                let points = e["lines"][0]["points"].as_array().unwrap();
                Some((
                    level,
                    points
                        .iter()
                        .map(|p| [number(&p["x"]), number(&p["y"])])
                        .collect(),
                ))
            })
            .collect()
    }

    #[test]
    fn after_any_cut_the_latest_track_messages_draw_the_path_from_the_start() {
        let coin = unit_coin();
        let messages = record(100.0, 9.0);
        let mut checked = 0;
        for cut_k in (7..=900).step_by(13) {
            let cut = log_time(f64::from(cut_k) * 0.01).unwrap();
            let mut lines = latest_track_lines(&messages, cut);
            lines.sort_by_key(|l| std::cmp::Reverse(l.0));
            let chain: Vec<[f64; 2]> = lines.iter().fold(Vec::new(), |mut acc, (level, l)| {
                if let Some(last) = acc.last() {
                    assert_eq!(
                        last, &l[0],
                        "level {level} starts where the level above ends"
                    );
                    acc.extend_from_slice(&l[1..]);
                } else {
                    acc.extend_from_slice(l);
                }
                acc
            });
            // The latest drawing update at or before the cut.
            let last_update = messages
                .iter()
                .filter(|(t, lt, _)| *t == Topic::Main(Channel::Scene) && *lt <= cut)
                .map(|m| m.1)
                .max()
                .unwrap();
            let c0 = contact_point(&coin, &state_at(0.0));
            #[allow(clippy::cast_precision_loss)]
            let cn = contact_point(&coin, &state_at(last_update as f64 * 1e-9));
            let (first, last) = (chain[0], chain[chain.len() - 1]);
            assert!((first[0] - c0.x).abs() <= QUANTUM && (first[1] + c0.z).abs() <= QUANTUM);
            assert!((last[0] - cn.x).abs() <= QUANTUM && (last[1] + cn.z).abs() <= QUANTUM);
            // Every sample's contact point up to the last update lies on the drawn track.
            for k in 0..=cut_k {
                let t = f64::from(k) * 0.01;
                if log_time(t).unwrap() > last_update {
                    break;
                }
                let c = contact_point(&coin, &state_at(t));
                let d = chain
                    .windows(2)
                    .map(|w| segment_distance([c.x, -c.z], w[0], w[1]))
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= MAX_TOLERANCE + QUANTUM, "t = {t}: {d} from the track");
            }
            checked += 1;
        }
        println!(
            "{checked} cut times: the latest track messages cover the path to the latest update"
        );
    }

    #[test]
    fn the_drawing_is_the_same_for_any_radius_in_units_of_a() {
        // The same motion in units of a, for a = 1 and a = 0.01325: every drawing message carries the same
        // numbers (to round-off), so one layout suits both.
        let unit = record(100.0, 2.0);
        let params = CoinParams::new(7e-3, 0.013_25, 9.81, Inertia::ThinDisk).unwrap();
        let yen = record_with(&Coin::new(params), 100.0, 2.0, |t| {
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
        let coin = unit_coin();
        let mut fox = Foxglove3d::new(&coin, 0.05, &[Channel::Scene], Encoding::Json);
        let mut batch = FoxgloveBatch::default();
        for k in 0..200 {
            let t = f64::from(k) * 0.01;
            let s = State {
                phi: 2.0 * t,
                omega_y: 2.0,
                ..State::default()
            };
            batch.clear();
            fox.sample(t, log_time(t).unwrap(), &s, k == 199, &mut batch)
                .unwrap();
            for (topic, _) in batch.iter() {
                assert_eq!(topic.channel(), Channel::Scene, "tf is off");
                assert!(!matches!(topic, Topic::SceneTrack(_)), "no track");
            }
        }
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

    #[test]
    fn nothing_is_written_when_both_channels_are_off() {
        let mut fox = Foxglove3d::new(&unit_coin(), 0.05, &[], Encoding::Json);
        let mut batch = FoxgloveBatch::default();
        fox.sample(0.0, 0, &state_at(0.0), true, &mut batch)
            .unwrap();
        assert!(batch.iter().next().is_none());
    }
}
