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
            let rotation = Some(&TABLE_ROTATION);
            let table = |buf: &mut _| {
                encode!(
                    encoding,
                    transform(buf, log_time, WORLD_FRAME, TABLE_FRAME, None, rotation)
                );
            };
            if first {
                out.push(tf, table);
            }
            out.push(tf, |buf| {
                let (parent, child) = (TABLE_FRAME, COIN_FRAME);
                encode!(
                    encoding,
                    transform(buf, log_time, parent, child, Some(translation), Some(&q))
                );
            });
            if first {
                out.push(Topic::TfStatic, table);
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
            let (parent, child) = (WORLD_FRAME, FOLLOW_FRAME);
            encode!(
                encoding,
                transform(buf, log_time, parent, child, Some(centre), None)
            );
        });
        out.push(Topic::Main(Channel::Scene), |buf| {
            encode!(encoding, coin(buf, log_time, &rotation, thickness));
        });
        if let Some(r) = &mut self.rerun {
            r.coin(log_time, &rotation, out);
        }
        let moved = match self.table {
            Some(t) if (centre[0] - t[0]).abs().max((centre[1] - t[1]).abs()) <= TABLE_SNAP => None,
            _ => Some([
                round_to(centre[0], TABLE_SNAP),
                round_to(centre[1], TABLE_SNAP),
            ]),
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

/// `v` rounded to the nearest multiple of `step` (−0 as 0).
fn round_to(v: f64, step: f64) -> f64 {
    (v / step).round() * step + 0.0
}
