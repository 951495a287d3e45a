//! Foxglove's 3D view of the coin: `/tf` (world → table → coin) and `/scene` (the coin as a cylinder with a
//! mark, the table, the contact track), as format.md (Channels) and FOXGLOVE.md describe.
//!
//! # Frames
//! - `world`: Foxglove's convention, z up. The root, so that the 3D panel has a fixed frame to follow.
//! - `table`: the note's world frame (physics §1: the table is the z–x plane, y up). Its transform from
//!   `world` is the static rotation R = rotation by +90° about x, q_T = (sin 45°, 0, 0, cos 45°)
//!   ([`TABLE_ROTATION`]): it takes the note's x to world x, y (up) to world z, z to world −y. It is a
//!   proper rotation (det +1), so handedness is kept and the note's quaternion needs no change. Published
//!   once, at the first sample (t = 0), before any scene update (Foxglove preloads `/tf`, so a transform
//!   published once is known at every time, seeks included).
//! - `coin`: translation = centre (x, a cos θ, z) in `table` (physics §1), rotation = q = q(e_y, φ) ·
//!   q(e_x, θ) · q(e_z, ψ) from [`orientation`]. q rotates the coin lying in the x–y plane with normal +z,
//!   so in the `coin` frame the coin is a cylinder whose axis is z (physics §8 item 5).
//!   Published at **every data sample**, not at the display rate: the 3D panel interpolates between
//!   transforms by slerp (the shortest arc), so a coin turning by more than π between two transforms
//!   would be drawn spinning backwards; at the data rate the transform is also exactly the recorded state
//!   at each sample time (no interpolation error against the plotted channels).
//!
//! # `/scene`
//! Published at the display rate [`SCENE_RATE`] (≈ 30 per time unit of simulation time, one time unit
//! being one second of log time), at the first sample and at the last sample; never more often than the
//! data rate (it is only ever written at a data sample). Each update carries:
//! - `coin` (frame `coin`, constant id, lifetime 0, frame_locked): a `CylinderPrimitive` of size
//!   {2a, 2a, thickness·a}, and two thin `CubePrimitive` stripes from the centre towards the rim, one on
//!   each face (dark red on +z, dark blue on −z), so that spin and which face is up both show.
//! - `table` (frame `table`, constant id): a large thin slab just below the table plane (its top at
//!   y = −0.005a, so that Foxglove's own grid at the plane and the track stay visible), centred on the
//!   contact point snapped to a 10a grid. Republished in every update rather than once: after a seek
//!   Foxglove shows only the last `/scene` message, and a table sent once at t = 0 would vanish. Cost: a
//!   few hundred bytes per update before compression (a constant factor, linear in duration).
//! - `track-N` (frame `table`): a `LinePrimitive` strip of the contact points (physics §3) since the previous
//!   update, starting with the last point of the previous strip so the track is continuous. Each update
//!   adds a fresh id and never repeats older points, so the bytes are linear in duration. Points closer
//!   than [`TRACK_MIN_SPACING`]·a to the previous kept point are skipped (a coin spinning in place adds
//!   none); an update with no new point carries no track entity.
//!
//! All timestamps `{sec, nsec}` are the log time of the sample ([`crate::format::log_time`]).

use crate::format::messages::{push_number, NonFiniteField};
use crate::format::Channel;
use crate::model::{contact_point, orientation, Coin, State};
use nalgebra::{Quaternion, UnitQuaternion};
use std::ops::Range;

/// Display rate of `/scene`, in updates per time unit of simulation time (≈ 30 Hz in Foxglove).
pub const SCENE_RATE: f64 = 30.0;

/// Skipped contact points: closer than this to the last kept one, in units of the radius a.
pub const TRACK_MIN_SPACING: f64 = 1e-3;

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

/// Size of the table slab, in units of a (its side) and of the snapping grid of its centre.
const TABLE_SIDE: f64 = 60.0;
const TABLE_SNAP: f64 = 10.0;
/// Table slab thickness and the gap between its top and the table plane, in units of a.
const TABLE_THICKNESS: f64 = 0.02;
const TABLE_GAP: f64 = 0.005;
/// Track line width, in units of a.
const TRACK_WIDTH: f64 = 0.02;

const FRAME_TRANSFORM: &str = "foxglove.FrameTransform";
const SCENE_UPDATE: &str = "foxglove.SceneUpdate";

const IDENTITY_POSE: &[u8] =
    br#"{"position":{"x":0,"y":0,"z":0},"orientation":{"x":0,"y":0,"z":0,"w":1}}"#;
const COIN_COLOR: &[u8] = br#"{"r":0.85,"g":0.65,"b":0.2,"a":1}"#;
const MARK_TOP_COLOR: &[u8] = br#"{"r":0.6,"g":0.05,"b":0.05,"a":1}"#;
const MARK_BOTTOM_COLOR: &[u8] = br#"{"r":0.05,"g":0.1,"b":0.55,"a":1}"#;
const TABLE_COLOR: &[u8] = br#"{"r":0.78,"g":0.78,"b":0.74,"a":1}"#;
const TRACK_COLOR: &[u8] = br#"{"r":0.1,"g":0.35,"b":0.9,"a":1}"#;

/// The Foxglove messages due at one sample, in one reused buffer.
#[derive(Debug, Default)]
pub struct FoxgloveBatch {
    bytes: Vec<u8>,
    messages: Vec<(Channel, Range<usize>)>,
}

impl FoxgloveBatch {
    /// Empties the batch, keeping its capacity.
    pub fn clear(&mut self) {
        self.bytes.clear();
        self.messages.clear();
    }

    /// Appends one message on `channel`, written by `write`.
    ///
    /// # Errors
    /// Whatever `write` returns; the batch is then left without the message.
    pub fn push(
        &mut self,
        channel: Channel,
        write: impl FnOnce(&mut Vec<u8>) -> Result<(), NonFiniteField>,
    ) -> Result<(), NonFiniteField> {
        let start = self.bytes.len();
        match write(&mut self.bytes) {
            Ok(()) => {
                self.messages.push((channel, start..self.bytes.len()));
                Ok(())
            }
            Err(e) => {
                self.bytes.truncate(start);
                Err(e)
            }
        }
    }

    /// The messages, in the order they were pushed.
    pub fn iter(&self) -> impl Iterator<Item = (Channel, &[u8])> + '_ {
        self.messages
            .iter()
            .map(|(c, r)| (*c, &self.bytes[r.clone()]))
    }

    /// Number of messages in the batch.
    #[must_use]
    pub fn len(&self) -> usize {
        self.messages.len()
    }

    /// True when the batch holds no message.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.messages.is_empty()
    }
}

/// State of the 3D output across samples (display rate, the contact track published so far).
#[derive(Debug, Clone)]
pub struct Foxglove3d {
    coin: Coin,
    thickness: f64,
    tf: bool,
    scene: bool,
    /// Whether the first sample (static transform, first scene) has been written.
    started: bool,
    /// round(t · SCENE_RATE) of the last scene update.
    last_scene_slot: u64,
    /// Contact points (x, z) of the track not yet published, led by the last published point.
    track: Vec<[f64; 2]>,
    /// Id number of the next track entity.
    next_track_id: u64,
    /// Table centre (x, z), snapped.
    table_centre: [f64; 2],
    /// Log time of the latest sample, and whether it had a scene update (for [`Self::finish`]).
    last_log_time: u64,
    last_had_scene: bool,
}

impl Foxglove3d {
    /// Output for `coin` drawn `thickness` (fraction of a) thick; `tf` and `scene` say which channels are on.
    #[must_use]
    pub fn new(coin: &Coin, thickness: f64, tf: bool, scene: bool) -> Self {
        Self {
            coin: *coin,
            thickness,
            tf,
            scene,
            started: false,
            last_scene_slot: 0,
            track: Vec::with_capacity(64),
            next_track_id: 0,
            table_centre: [0.0, 0.0],
            last_log_time: 0,
            last_had_scene: false,
        }
    }

    /// True when neither `/tf` nor `/scene` is recorded (nothing to compute).
    #[must_use]
    pub fn is_off(&self) -> bool {
        !self.tf && !self.scene
    }

    /// Appends to `out` the messages due at the sample (t, s), whose log time is `log_time` ns; `last` marks
    /// the run's final sample (so the scene shows the final state).
    ///
    /// At the first sample: `/tf` world → table, then `/tf` table → coin, then `/scene`. Afterwards: `/tf`
    /// table → coin at every sample, `/scene` when a display slot of [`SCENE_RATE`] has passed, and at
    /// `last`. Samples must come in increasing t.
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
        if self.is_off() {
            return Ok(());
        }
        let first = !self.started;
        if self.tf {
            if first {
                out.push(Channel::Tf, |buf| write_table_transform(buf, log_time))?;
            }
            out.push(Channel::Tf, |buf| {
                self.write_coin_transform(buf, log_time, s)
            })?;
        }
        self.last_had_scene = false;
        if self.scene {
            self.add_track_point(s)?;
            let slot = scene_slot(t);
            if first || last || slot > self.last_scene_slot {
                self.last_scene_slot = slot;
                self.push_scene(log_time, out)?;
            }
        }
        self.started = true;
        self.last_log_time = log_time;
        Ok(())
    }

    /// Ends the output: if the latest sample had no `/scene` update (a recorder that learns only after the
    /// fact that a sample was the last one), appends one at that sample's log time, so the scene shows the
    /// final state and the whole track. Does nothing otherwise, or if no sample was given.
    ///
    /// # Errors
    /// [`NonFiniteField`] if a value is not finite.
    pub fn finish(&mut self, out: &mut FoxgloveBatch) -> Result<(), NonFiniteField> {
        if self.scene && self.started && !self.last_had_scene {
            self.push_scene(self.last_log_time, out)?;
        }
        Ok(())
    }

    /// Appends a `/scene` update with the pending track, then starts the next piece of track.
    fn push_scene(&mut self, log_time: u64, out: &mut FoxgloveBatch) -> Result<(), NonFiniteField> {
        let track_id = self.next_track_id;
        let with_track = self.track.len() >= 2;
        out.push(Channel::Scene, |buf| {
            self.write_scene(buf, log_time, with_track.then_some(track_id))
        })?;
        self.last_had_scene = true;
        if with_track {
            self.next_track_id += 1;
            let tail = self.track[self.track.len() - 1];
            self.track.clear();
            self.track.push(tail);
        }
        Ok(())
    }

    /// Appends the contact point of `s` to the pending track unless it is within the minimum spacing.
    fn add_track_point(&mut self, s: &State) -> Result<(), NonFiniteField> {
        let c = contact_point(&self.coin, s);
        check(SCENE_UPDATE, "lines.points.x", c.x)?;
        check(SCENE_UPDATE, "lines.points.z", c.z)?;
        let a = self.coin.params().radius();
        let p = [c.x, c.z];
        match self.track.last() {
            Some(q) if (p[0] - q[0]).hypot(p[1] - q[1]) < TRACK_MIN_SPACING * a => {}
            _ => self.track.push(p),
        }
        // The table follows the coin in steps of TABLE_SNAP·a (uniform slab: the step does not show).
        self.table_centre = [snap(c.x, TABLE_SNAP * a), snap(c.z, TABLE_SNAP * a)];
        Ok(())
    }

    fn write_coin_transform(
        &self,
        buf: &mut Vec<u8>,
        log_time: u64,
        s: &State,
    ) -> Result<(), NonFiniteField> {
        let a = self.coin.params().radius();
        let q = orientation(s);
        let mut w = Writer::new(buf, FRAME_TRANSFORM);
        w.raw(b"{\"timestamp\":");
        w.time(log_time);
        w.raw(
            b",\"parent_frame_id\":\"table\",\"child_frame_id\":\"coin\",\"translation\":{\"x\":",
        );
        w.num("translation.x", s.x)?;
        w.raw(b",\"y\":");
        w.num("translation.y", a * s.theta.cos())?;
        w.raw(b",\"z\":");
        w.num("translation.z", s.z)?;
        w.raw(b"},\"rotation\":");
        w.quaternion(&q)?;
        w.raw(b"}");
        Ok(())
    }

    fn write_scene(
        &self,
        buf: &mut Vec<u8>,
        log_time: u64,
        track_id: Option<u64>,
    ) -> Result<(), NonFiniteField> {
        let h = self.thickness * self.coin.params().radius();
        check(SCENE_UPDATE, "cylinders.size.z", h)?;
        let mut w = Writer::new(buf, SCENE_UPDATE);
        w.raw(b"{\"deletions\":[],\"entities\":[");
        self.write_coin_entity(&mut w, log_time, h)?;
        w.raw(b",");
        self.write_table_entity(&mut w, log_time)?;
        if let Some(id) = track_id {
            w.raw(b",");
            self.write_track_entity(&mut w, log_time, id)?;
        }
        w.raw(b"]}");
        Ok(())
    }

    /// The coin: a cylinder of thickness `h` with its axis along the coin frame's z, stripes on both faces.
    fn write_coin_entity(
        &self,
        w: &mut Writer,
        log_time: u64,
        h: f64,
    ) -> Result<(), NonFiniteField> {
        let a = self.coin.params().radius();
        w.entity_head(log_time, COIN_FRAME, b"coin", None, true);
        let mark = (0.2 * h).max(1e-3 * a);
        w.raw(b"\"cubes\":[");
        for (sign, color) in [(1.0, MARK_TOP_COLOR), (-1.0, MARK_BOTTOM_COLOR)] {
            if sign < 0.0 {
                w.raw(b",");
            }
            w.raw(b"{\"pose\":{\"position\":{\"x\":");
            w.num("cubes.pose.position.x", 0.45 * a)?;
            w.raw(b",\"y\":0,\"z\":");
            w.num("cubes.pose.position.z", sign * 0.5 * (h + mark))?;
            w.raw(b"},\"orientation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1}},\"size\":");
            w.vector3("cubes.size", 0.85 * a, 0.12 * a, mark)?;
            w.raw(b",\"color\":");
            w.raw(color);
            w.raw(b"}");
        }
        w.raw(b"],\"spheres\":[],\"cylinders\":[{\"pose\":");
        w.raw(IDENTITY_POSE);
        w.raw(b",\"size\":");
        w.vector3("cylinders.size", 2.0 * a, 2.0 * a, h)?;
        w.raw(b",\"bottom_scale\":1,\"top_scale\":1,\"color\":");
        w.raw(COIN_COLOR);
        w.raw(b"}],\"lines\":[],");
        w.entity_tail();
        Ok(())
    }

    /// The table: a thin slab just below the plane y = 0 of the table frame.
    fn write_table_entity(&self, w: &mut Writer, log_time: u64) -> Result<(), NonFiniteField> {
        let a = self.coin.params().radius();
        w.entity_head(log_time, TABLE_FRAME, b"table", None, true);
        w.raw(b"\"cubes\":[{\"pose\":{\"position\":{\"x\":");
        w.num("cubes.pose.position.x", self.table_centre[0])?;
        w.raw(b",\"y\":");
        w.num(
            "cubes.pose.position.y",
            -(TABLE_GAP + 0.5 * TABLE_THICKNESS) * a,
        )?;
        w.raw(b",\"z\":");
        w.num("cubes.pose.position.z", self.table_centre[1])?;
        w.raw(b"},\"orientation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1}},\"size\":");
        w.vector3(
            "cubes.size",
            TABLE_SIDE * a,
            TABLE_THICKNESS * a,
            TABLE_SIDE * a,
        )?;
        w.raw(b",\"color\":");
        w.raw(TABLE_COLOR);
        w.raw(b"}],\"spheres\":[],\"cylinders\":[],\"lines\":[],");
        w.entity_tail();
        Ok(())
    }

    /// The new piece of the contact track, entity `track-<id>`.
    fn write_track_entity(
        &self,
        w: &mut Writer,
        log_time: u64,
        id: u64,
    ) -> Result<(), NonFiniteField> {
        let a = self.coin.params().radius();
        w.entity_head(log_time, TABLE_FRAME, b"track-", Some(id), false);
        w.raw(b"\"cubes\":[],\"spheres\":[],\"cylinders\":[],\"lines\":[{\"type\":0,\"pose\":");
        w.raw(IDENTITY_POSE);
        w.raw(b",\"thickness\":");
        w.num("lines.thickness", TRACK_WIDTH * a)?;
        w.raw(b",\"scale_invariant\":false,\"points\":[");
        for (i, p) in self.track.iter().enumerate() {
            if i > 0 {
                w.raw(b",");
            }
            w.raw(b"{\"x\":");
            w.num("lines.points.x", p[0])?;
            w.raw(b",\"y\":0,\"z\":");
            w.num("lines.points.z", p[1])?;
            w.raw(b"}");
        }
        w.raw(b"],\"color\":");
        w.raw(TRACK_COLOR);
        w.raw(b",\"colors\":[],\"indices\":[]}],");
        w.entity_tail();
        Ok(())
    }
}

/// `/tf` world → table (static, [`TABLE_ROTATION`]).
fn write_table_transform(buf: &mut Vec<u8>, log_time: u64) -> Result<(), NonFiniteField> {
    let mut w = Writer::new(buf, FRAME_TRANSFORM);
    w.raw(b"{\"timestamp\":");
    w.time(log_time);
    w.raw(b",\"parent_frame_id\":\"world\",\"child_frame_id\":\"table\",\"translation\":{\"x\":0,\"y\":0,\"z\":0},\"rotation\":");
    w.quaternion(&TABLE_ROTATION)?;
    w.raw(b"}");
    Ok(())
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

/// `v` rounded to the nearest multiple of `step`.
fn snap(v: f64, step: f64) -> f64 {
    (v / step).round() * step
}

fn check(schema: &'static str, field: &'static str, value: f64) -> Result<(), NonFiniteField> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(NonFiniteField {
            schema,
            field,
            value,
        })
    }
}

/// Appends JSON pieces to a buffer: raw literals, checked numbers, times.
struct Writer<'a> {
    buf: &'a mut Vec<u8>,
    ryu: ryu::Buffer,
    schema: &'static str,
}

impl<'a> Writer<'a> {
    fn new(buf: &'a mut Vec<u8>, schema: &'static str) -> Self {
        Self {
            buf,
            ryu: ryu::Buffer::new(),
            schema,
        }
    }

    fn raw(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    fn num(&mut self, field: &'static str, value: f64) -> Result<(), NonFiniteField> {
        check(self.schema, field, value)?;
        push_number(self.buf, value, &mut self.ryu);
        Ok(())
    }

    fn uint(&mut self, mut n: u64) {
        let mut digits = [0u8; 20];
        let mut i = digits.len();
        loop {
            i -= 1;
            // n % 10 < 10 always fits in a u8.
            digits[i] = b'0' + u8::try_from(n % 10).unwrap_or(0);
            n /= 10;
            if n == 0 {
                break;
            }
        }
        self.buf.extend_from_slice(&digits[i..]);
    }

    /// `{"sec":S,"nsec":N}` of a log time in ns.
    fn time(&mut self, log_time: u64) {
        self.raw(b"{\"sec\":");
        self.uint(log_time / 1_000_000_000);
        self.raw(b",\"nsec\":");
        self.uint(log_time % 1_000_000_000);
        self.raw(b"}");
    }

    fn vector3(
        &mut self,
        field: &'static str,
        x: f64,
        y: f64,
        z: f64,
    ) -> Result<(), NonFiniteField> {
        self.raw(b"{\"x\":");
        self.num(field, x)?;
        self.raw(b",\"y\":");
        self.num(field, y)?;
        self.raw(b",\"z\":");
        self.num(field, z)?;
        self.raw(b"}");
        Ok(())
    }

    /// Foxglove's `{x, y, z, w}` are the quaternion's (i, j, k, w).
    fn quaternion(&mut self, q: &UnitQuaternion<f64>) -> Result<(), NonFiniteField> {
        self.raw(b"{\"x\":");
        self.num("rotation.x", q.i)?;
        self.raw(b",\"y\":");
        self.num("rotation.y", q.j)?;
        self.raw(b",\"z\":");
        self.num("rotation.z", q.k)?;
        self.raw(b",\"w\":");
        self.num("rotation.w", q.w)?;
        self.raw(b"}");
        Ok(())
    }

    /// An entity up to its `"arrows":[],`; the caller writes cubes, spheres, cylinders and lines (each
    /// followed by a comma), then [`Self::entity_tail`].
    fn entity_head(
        &mut self,
        log_time: u64,
        frame: &str,
        id: &[u8],
        id_number: Option<u64>,
        frame_locked: bool,
    ) {
        self.raw(b"{\"timestamp\":");
        self.time(log_time);
        self.raw(b",\"frame_id\":\"");
        self.raw(frame.as_bytes());
        self.raw(b"\",\"id\":\"");
        self.raw(id);
        if let Some(n) = id_number {
            self.uint(n);
        }
        self.raw(b"\",\"lifetime\":{\"sec\":0,\"nsec\":0},\"frame_locked\":");
        self.raw(if frame_locked { b"true" } else { b"false" });
        self.raw(b",\"metadata\":[],\"arrows\":[],");
    }

    fn entity_tail(&mut self) {
        self.raw(b"\"triangles\":[],\"texts\":[],\"models\":[]}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::log_time;
    use crate::format::schema_bytes;
    use crate::model::{centre, CoinParams};
    use nalgebra::Vector3;
    use serde_json::Value;

    fn unit_coin() -> Coin {
        Coin::new(CoinParams::unit_disk())
    }

    /// A coin leaning at θ = 0.3, heading turning at 0.5 rad per time unit, centre on a circle of radius 4:
    /// enough motion for a track; not a solution of the equations (the output does not need one).
    fn state_at(t: f64) -> State {
        State {
            theta: 0.3,
            phi: 0.5 * t,
            psi: 2.0 * t,
            omega_x: 0.0,
            omega_y: 0.4,
            omega_z: 1.0,
            x: 4.0 * (0.5 * t).cos(),
            z: 4.0 * (0.5 * t).sin(),
        }
    }

    /// Records samples at `rate` for `duration` into (channel, log time, JSON) triples.
    fn record(rate: f64, duration: f64) -> Vec<(Channel, u64, Value)> {
        let coin = unit_coin();
        let mut fox = Foxglove3d::new(&coin, 0.05, true, true);
        let mut batch = FoxgloveBatch::default();
        let mut out = Vec::new();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let n = (duration * rate).round() as u64;
        for k in 0..=n {
            #[allow(clippy::cast_precision_loss)]
            let t = k as f64 / rate;
            let lt = log_time(t).unwrap();
            batch.clear();
            fox.sample(t, lt, &state_at(t), k == n, &mut batch).unwrap();
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

    #[test]
    fn every_message_is_json_that_satisfies_the_official_schema() {
        let messages = record(100.0, 3.0);
        for (c, _, v) in &messages {
            let schema: Value =
                serde_json::from_slice(schema_bytes(c.schema_name()).unwrap()).unwrap();
            if let Some(e) = violation(&schema, v, c.schema_name()) {
                panic!("{e}\nmessage: {v}");
            }
        }
        println!(
            "{} messages checked against foxglove.* schemas",
            messages.len()
        );
        assert!(messages.len() > 300);
    }

    #[test]
    fn the_static_table_transform_comes_first_and_only_once() {
        let messages = record(100.0, 1.0);
        let tables: Vec<usize> = messages
            .iter()
            .enumerate()
            .filter(|(_, (_, _, v))| v.get("child_frame_id") == Some(&Value::from("table")))
            .map(|(i, _)| i)
            .collect();
        assert_eq!(tables, vec![0], "world → table at index 0 only");
        let first_scene = messages
            .iter()
            .position(|(c, _, _)| *c == Channel::Scene)
            .unwrap();
        assert!(first_scene > 0);
        let v = &messages[0].2;
        assert_eq!(v["parent_frame_id"], "world");
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
        // Translation + rotation of /tf table → coin must carry the coin-frame point c = −a e_Y of the
        // lean frame (in the coin frame: the rim point (0, −a, 0) before spin ψ, i.e. rotated back by ψ)
        // onto the model's contact point (physics §3): checks the frame against an independent formula.
        let coin = unit_coin();
        let mut fox = Foxglove3d::new(&coin, 0.05, true, false);
        let mut batch = FoxgloveBatch::default();
        let mut worst: f64 = 0.0;
        for k in 0..50 {
            let t = f64::from(k) * 0.37;
            let s = state_at(t);
            batch.clear();
            fox.sample(t, log_time(t).unwrap(), &s, false, &mut batch)
                .unwrap();
            let (_, bytes) = batch.iter().last().unwrap();
            let v: Value = serde_json::from_slice(bytes).unwrap();
            let tr = &v["translation"];
            let r = &v["rotation"];
            let q = UnitQuaternion::new_unchecked(Quaternion::new(
                r["w"].as_f64().unwrap(),
                r["x"].as_f64().unwrap(),
                r["y"].as_f64().unwrap(),
                r["z"].as_f64().unwrap(),
            ));
            // q = q_lean · q(e_z, ψ), so the coin-frame vector that q takes to −a e_Y is the rotation of
            // (0, −1, 0) by −ψ about z: (−sin ψ, −cos ψ, 0).
            let (sp, cp) = s.psi.sin_cos();
            let rim = q.transform_vector(&Vector3::new(-sp, -cp, 0.0));
            let c = contact_point(&coin, &s);
            let g = centre(&coin, &s);
            let got = [
                tr["x"].as_f64().unwrap() + rim[0],
                tr["y"].as_f64().unwrap() + rim[1],
                tr["z"].as_f64().unwrap() + rim[2],
            ];
            assert!((tr["y"].as_f64().unwrap() - g.y).abs() <= 1e-15);
            for (a, b) in got.iter().zip([c.x, c.y, c.z]) {
                worst = worst.max((a - b).abs());
            }
        }
        println!("contact point from /tf vs model: max error {worst:e}, tolerance 1e-12");
        assert!(worst < 1e-12);
    }

    #[test]
    fn the_coin_entity_is_a_cylinder_in_the_coin_frame_with_a_mark_on_each_face() {
        let messages = record(100.0, 0.5);
        let (_, lt, scene) = messages
            .iter()
            .find(|(c, _, _)| *c == Channel::Scene)
            .unwrap();
        let coin = entities(scene).iter().find(|e| e["id"] == "coin").unwrap();
        assert_eq!(coin["frame_id"], "coin");
        assert_eq!(coin["frame_locked"], true);
        assert_eq!(coin["lifetime"], serde_json::json!({"sec": 0, "nsec": 0}));
        assert_eq!(
            coin["timestamp"]["sec"].as_u64().unwrap() * 1_000_000_000
                + coin["timestamp"]["nsec"].as_u64().unwrap(),
            *lt
        );
        let cyl = &coin["cylinders"][0];
        assert_eq!(coin["cylinders"].as_array().unwrap().len(), 1);
        assert_eq!(
            cyl["size"],
            serde_json::json!({"x": 2.0, "y": 2.0, "z": 0.05})
        );
        assert_eq!(cyl["bottom_scale"], 1);
        assert_eq!(cyl["top_scale"], 1);
        for ch in ["r", "g", "b", "a"] {
            let x = cyl["color"][ch].as_f64().unwrap();
            assert!((0.0..=1.0).contains(&x));
        }
        assert!(cyl["color"]["a"].as_f64().unwrap() > 0.0);
        let cubes = coin["cubes"].as_array().unwrap();
        assert_eq!(cubes.len(), 2);
        let zs: Vec<f64> = cubes
            .iter()
            .map(|c| c["pose"]["position"]["z"].as_f64().unwrap())
            .collect();
        assert!(
            zs[0] > 0.025 && zs[1] < -0.025,
            "marks outside both faces: {zs:?}"
        );
        // Every scene update carries the coin and the table (so a seek shows them).
        for (c, _, v) in &messages {
            if *c == Channel::Scene {
                let ids: Vec<&str> = entities(v)
                    .iter()
                    .map(|e| e["id"].as_str().unwrap())
                    .collect();
                assert_eq!(&ids[..2], &["coin", "table"]);
            }
        }
    }

    #[test]
    fn the_track_is_continuous_incremental_and_in_the_table_frame() {
        let messages = record(100.0, 4.0);
        let mut previous_last: Option<Value> = None;
        let mut ids = std::collections::BTreeSet::new();
        let mut points = 0;
        for (c, _, v) in &messages {
            if *c != Channel::Scene {
                continue;
            }
            for e in entities(v)
                .iter()
                .filter(|e| e["id"].as_str().unwrap().starts_with("track-"))
            {
                assert_eq!(e["frame_id"], "table");
                assert!(
                    ids.insert(e["id"].as_str().unwrap().to_string()),
                    "fresh id"
                );
                let line = &e["lines"][0];
                assert_eq!(line["type"], 0);
                assert!(line["thickness"].as_f64().unwrap() > 0.0);
                assert_eq!(line["colors"], serde_json::json!([]));
                assert_eq!(line["indices"], serde_json::json!([]));
                let pts = line["points"].as_array().unwrap();
                assert!(pts.len() >= 2);
                if let Some(last) = &previous_last {
                    assert_eq!(
                        &pts[0], last,
                        "each piece starts where the previous one ended"
                    );
                }
                previous_last = pts.last().cloned();
                points += pts.len() - 1;
            }
        }
        // Every sample's contact point appears once (the spacing here is far above the minimum).
        println!(
            "track: {} pieces, {points} new points, expected 400 (samples after the first)",
            ids.len()
        );
        assert_eq!(points, 400);
        // The last point is the contact point of the final sample.
        let c = contact_point(&unit_coin(), &state_at(4.0));
        let last = previous_last.unwrap();
        // serde_json's default float parsing may be 1 ulp off the shortest round-trip text.
        assert!((last["x"].as_f64().unwrap() - c.x).abs() <= 1e-15 * c.x.abs());
        assert!((last["z"].as_f64().unwrap() - c.z).abs() <= 1e-15 * c.z.abs());
    }

    #[test]
    fn scene_updates_come_at_about_thirty_per_time_unit_whatever_the_data_rate() {
        for rate in [30.0, 45.0, 100.0, 1000.0] {
            let messages = record(rate, 4.0);
            let times: Vec<u64> = messages
                .iter()
                .filter(|(c, _, _)| *c == Channel::Scene)
                .map(|(_, t, _)| *t)
                .collect();
            let n = times.len();
            println!("rate {rate}: {n} scene updates over 4 time units, expected 121 ± 1");
            assert!((120..=122).contains(&n), "rate {rate}: {n}");
            assert_eq!(times[0], 0);
            assert_eq!(*times.last().unwrap(), 4_000_000_000);
            let max_gap = times.windows(2).map(|w| w[1] - w[0]).max().unwrap();
            assert!(max_gap <= 50_000_000, "rate {rate}: gap {max_gap} ns");
        }
    }

    #[test]
    fn a_coin_spinning_in_place_publishes_no_degenerate_track() {
        let coin = unit_coin();
        let mut fox = Foxglove3d::new(&coin, 0.05, false, true);
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
            for (c, bytes) in batch.iter() {
                assert_eq!(c, Channel::Scene, "tf is off");
                let v: Value = serde_json::from_slice(bytes).unwrap();
                assert_eq!(entities(&v).len(), 2, "coin and table only");
            }
        }
    }

    #[test]
    fn non_finite_values_are_refused_and_leave_the_batch_alone() {
        let coin = unit_coin();
        let mut fox = Foxglove3d::new(&coin, 0.05, true, true);
        let mut batch = FoxgloveBatch::default();
        fox.sample(0.0, 0, &state_at(0.0), false, &mut batch)
            .unwrap();
        let before = batch.len();
        let bad = State {
            psi: f64::NAN,
            ..state_at(0.01)
        };
        let err = fox
            .sample(0.01, 10_000_000, &bad, false, &mut batch)
            .unwrap_err();
        println!("{err}");
        assert_eq!(err.schema, "foxglove.FrameTransform");
        assert_eq!(batch.len(), before);
        let bad = State {
            x: f64::INFINITY,
            ..state_at(0.02)
        };
        assert!(fox
            .sample(0.02, 20_000_000, &bad, false, &mut batch)
            .is_err());
    }

    #[test]
    fn finish_adds_the_final_scene_only_when_the_last_sample_had_none() {
        let coin = unit_coin();
        let mut batch = FoxgloveBatch::default();
        // Samples to t = 0.06, none flagged `last` (the recorder learns of the end afterwards).
        let mut fox = Foxglove3d::new(&coin, 0.05, false, true);
        let mut scenes = Vec::new();
        for k in 0..=6 {
            let t = f64::from(k) * 0.01;
            batch.clear();
            fox.sample(t, log_time(t).unwrap(), &state_at(t), false, &mut batch)
                .unwrap();
            scenes.push(batch.len());
        }
        batch.clear();
        fox.finish(&mut batch).unwrap();
        let finished = batch.len();
        println!("scene updates per sample {scenes:?}, finish added {finished}");
        // t = 0.06: round(1.8) = 2 = the slot of t = 0.05 (round(1.5) = 2), so no update at 0.06.
        assert_eq!(scenes[6], 0);
        assert_eq!(finished, 1);
        let (_, bytes) = batch.iter().next().unwrap();
        let v: Value = serde_json::from_slice(bytes).unwrap();
        let track = entities(&v)
            .iter()
            .find(|e| e["id"].as_str().unwrap().starts_with("track-"));
        assert!(track.is_some(), "the final piece of track is published");
        assert_eq!(time_of(&entities(&v)[0]), 60_000_000);
        // After a sample flagged `last`, finish adds nothing.
        batch.clear();
        fox.sample(0.07, 70_000_000, &state_at(0.07), true, &mut batch)
            .unwrap();
        batch.clear();
        fox.finish(&mut batch).unwrap();
        assert!(batch.is_empty());
    }

    fn time_of(entity: &Value) -> u64 {
        entity["timestamp"]["sec"].as_u64().unwrap() * 1_000_000_000
            + entity["timestamp"]["nsec"].as_u64().unwrap()
    }

    #[test]
    fn nothing_is_written_when_both_channels_are_off() {
        let mut fox = Foxglove3d::new(&unit_coin(), 0.05, false, false);
        assert!(fox.is_off());
        let mut batch = FoxgloveBatch::default();
        fox.sample(0.0, 0, &state_at(0.0), true, &mut batch)
            .unwrap();
        assert!(batch.is_empty());
    }
}
