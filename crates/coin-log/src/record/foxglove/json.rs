//! The JSON form of the Foxglove messages, written piece by piece (by hand rather than through serde: each
//! call site decides whether a number is a literal, and the transform of every sample is on the hot path).
//! The values were checked finite by [`super::Foxglove3d`]. Signatures as in [`super::proto`].

use super::track::TrackPoint;
use super::{
    coin_marks, grid_segments, Rgba, COIN_RGBA, FOLLOW_FRAME, GRID_HEIGHT, GRID_RGBA, GRID_WIDTHS,
    TABLE_HALF_SIDE, TABLE_RGBA, TABLE_THICKNESS, TABLE_TOP, TRACK_RGBA, TRACK_WIDTH, WORLD_FRAME,
};
use crate::format::messages::push_number;
use nalgebra::{UnitQuaternion, Vector3};
use std::io::Write as _;

const IDENTITY_POSE: &[u8] =
    br#"{"position":{"x":0,"y":0,"z":0},"orientation":{"x":0,"y":0,"z":0,"w":1}}"#;

/// Appends JSON pieces to a buffer: raw literals, numbers, times.
struct Writer<'a> {
    buf: &'a mut Vec<u8>,
    ryu: ryu::Buffer,
}

impl<'a> Writer<'a> {
    fn new(buf: &'a mut Vec<u8>) -> Self {
        Self {
            buf,
            ryu: ryu::Buffer::new(),
        }
    }

    fn raw(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    fn num(&mut self, value: f64) {
        push_number(self.buf, value, &mut self.ryu);
    }

    /// A `Color` {r, g, b, a}, each component's shortest decimal, whole ones without `.0` (`"a":1`).
    fn color(&mut self, rgba: Rgba) {
        let keys: [&[u8]; 4] = [b"{\"r\":", b",\"g\":", b",\"b\":", b",\"a\":"];
        for (key, v) in keys.into_iter().zip(rgba) {
            self.buf.extend_from_slice(key);
            let text = self.ryu.format(v);
            self.buf
                .extend_from_slice(text.strip_suffix(".0").unwrap_or(text).as_bytes());
        }
        self.buf.push(b'}');
    }

    fn uint(&mut self, n: u64) {
        // Writing into a Vec cannot fail.
        let _ = write!(self.buf, "{n}");
    }

    /// Each of `items` as `write` writes it, separated by commas.
    fn list<T>(&mut self, items: impl IntoIterator<Item = T>, mut write: impl FnMut(&mut Self, T)) {
        for (i, item) in items.into_iter().enumerate() {
            if i > 0 {
                self.raw(b",");
            }
            write(self, item);
        }
    }

    /// `{"sec":S,"nsec":N}` of a log time in ns.
    fn time(&mut self, log_time: u64) {
        self.raw(b"{\"sec\":");
        self.uint(log_time / 1_000_000_000);
        self.raw(b",\"nsec\":");
        self.uint(log_time % 1_000_000_000);
        self.raw(b"}");
    }

    /// `{"x":..,"y":..,"z":..}` of a vector's `[x, y, z]`, or with `"w":..` of a quaternion's `[i, j, k, w]`
    /// (Foxglove's `{x, y, z, w}`).
    fn xyzw(&mut self, values: &[f64]) {
        let keys: [&[u8]; 4] = [b"{\"x\":", b",\"y\":", b",\"z\":", b",\"w\":"];
        for (key, v) in keys.into_iter().zip(values) {
            self.raw(key);
            self.num(*v);
        }
        self.raw(b"}");
    }

    /// A `Pose`: `position` and the rotation `q` as `orientation`.
    fn pose(&mut self, position: &Vector3<f64>, q: &UnitQuaternion<f64>) {
        self.raw(b"{\"position\":");
        self.xyzw(position.as_slice());
        self.raw(b",\"orientation\":");
        self.xyzw(&[q.i, q.j, q.k, q.w]);
        self.raw(b"}");
    }

    /// A `Point3` (x, y, 0) of a line.
    fn point(&mut self, x: f64, y: f64) {
        self.raw(b"{\"x\":");
        self.num(x);
        self.raw(b",\"y\":");
        self.num(y);
        self.raw(b",\"z\":0}");
    }

    /// A `SceneUpdate` of one entity up to its `"arrows":[],`; the caller writes cubes, spheres, cylinders
    /// and lines (each followed by a comma), then [`Self::entity_tail`].
    fn entity_head(&mut self, log_time: u64, frame: &str, id: &[u8]) {
        self.raw(b"{\"deletions\":[],\"entities\":[{\"timestamp\":");
        self.time(log_time);
        self.raw(b",\"frame_id\":\"");
        self.raw(frame.as_bytes());
        self.raw(b"\",\"id\":\"");
        self.raw(id);
        self.raw(b"\",\"lifetime\":{\"sec\":0,\"nsec\":0},\"frame_locked\":true");
        self.raw(b",\"metadata\":[],\"arrows\":[],");
    }

    fn entity_tail(&mut self) {
        self.raw(b"\"triangles\":[],\"texts\":[],\"models\":[]}]}");
    }
}

/// A `FrameTransform` `parent` → `child`: the zero translation (`None`) and the identity rotation (`None`)
/// are written as literals.
pub(super) fn transform(
    buf: &mut Vec<u8>,
    log_time: u64,
    parent: &str,
    child: &str,
    translation: Option<[f64; 3]>,
    rotation: Option<&UnitQuaternion<f64>>,
) {
    let mut w = Writer::new(buf);
    w.raw(b"{\"timestamp\":");
    w.time(log_time);
    w.raw(b",\"parent_frame_id\":\"");
    w.raw(parent.as_bytes());
    w.raw(b"\",\"child_frame_id\":\"");
    w.raw(child.as_bytes());
    w.raw(b"\",\"translation\":");
    match translation {
        Some(t) => w.xyzw(&t),
        None => w.raw(b"{\"x\":0,\"y\":0,\"z\":0}"),
    }
    w.raw(b",\"rotation\":");
    match rotation {
        Some(q) => w.xyzw(&[q.i, q.j, q.k, q.w]),
        None => w.raw(b"{\"x\":0,\"y\":0,\"z\":0,\"w\":1}"),
    }
    w.raw(b"}");
}

/// `/scene`: the coin in `coin_level`, posed with its orientation `r` in `world`: a cylinder with its axis
/// along the body's z, `thickness` thick, and a stripe on each face.
pub(super) fn coin(buf: &mut Vec<u8>, log_time: u64, r: &UnitQuaternion<f64>, thickness: f64) {
    let mut w = Writer::new(buf);
    w.entity_head(log_time, FOLLOW_FRAME, b"coin");
    w.raw(b"\"cubes\":[");
    w.list(coin_marks(r, thickness), |w, (position, size, colour)| {
        w.raw(b"{\"pose\":");
        w.pose(&position, r);
        w.raw(b",\"size\":");
        w.xyzw(&size);
        w.raw(b",\"color\":");
        w.color(colour);
        w.raw(b"}");
    });
    w.raw(b"],\"spheres\":[],\"cylinders\":[{\"pose\":");
    w.pose(&Vector3::zeros(), r);
    w.raw(b",\"size\":");
    w.xyzw(&[2.0, 2.0, thickness]);
    w.raw(b",\"bottom_scale\":1,\"top_scale\":1,\"color\":");
    w.color(COIN_RGBA);
    w.raw(b"}],\"lines\":[],");
    w.entity_tail();
}

/// `/scene/table`: the slab centred on `centre` (display units) and its grid, in `world`.
pub(super) fn table(buf: &mut Vec<u8>, log_time: u64, centre: [f64; 2]) {
    let mut w = Writer::new(buf);
    w.entity_head(log_time, WORLD_FRAME, b"table");
    w.raw(b"\"cubes\":[{\"pose\":{\"position\":");
    w.xyzw(&[centre[0], centre[1], TABLE_TOP - 0.5 * TABLE_THICKNESS]);
    w.raw(b",\"orientation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1}},\"size\":");
    let side = 2.0 * TABLE_HALF_SIDE;
    w.xyzw(&[side, side, TABLE_THICKNESS]);
    w.raw(b",\"color\":");
    w.color(TABLE_RGBA);
    w.raw(b"}],\"spheres\":[],\"cylinders\":[],\"lines\":[");
    w.list([false, true], |w, major| grid(w, centre, major));
    w.raw(b"],");
    w.entity_tail();
}

/// One `LinePrimitive` (a line list) of the table's grid: the minor or the major lines, at the grid height.
fn grid(w: &mut Writer, centre: [f64; 2], major: bool) {
    w.raw(b"{\"type\":2,\"pose\":{\"position\":{\"x\":0,\"y\":0,\"z\":");
    w.num(GRID_HEIGHT);
    w.raw(b"},\"orientation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1}},\"thickness\":");
    w.num(GRID_WIDTHS[usize::from(major)]);
    w.raw(b",\"scale_invariant\":true,\"points\":[");
    w.list(grid_segments(centre, major), |w, (a, b)| {
        w.point(a[0], a[1]);
        w.raw(b",");
        w.point(b[0], b[1]);
    });
    w.raw(b"],\"color\":");
    w.color(GRID_RGBA[usize::from(major)]);
    w.raw(b",\"colors\":[],\"indices\":[]}");
}

/// `/scene/track/<L>`: the level's points as one line strip, entity `track` in `world`.
pub(super) fn track(buf: &mut Vec<u8>, log_time: u64, points: &[TrackPoint]) {
    let mut w = Writer::new(buf);
    w.entity_head(log_time, WORLD_FRAME, b"track");
    w.raw(b"\"cubes\":[],\"spheres\":[],\"cylinders\":[],\"lines\":[{\"type\":0,\"pose\":");
    w.raw(IDENTITY_POSE);
    w.raw(b",\"thickness\":");
    w.num(TRACK_WIDTH);
    w.raw(b",\"scale_invariant\":true,\"points\":[");
    w.list(points, |w, p| w.point(p.x, p.y));
    w.raw(b"],\"color\":");
    w.color(TRACK_RGBA);
    w.raw(b",\"colors\":[],\"indices\":[]}],");
    w.entity_tail();
}

/// `/scene/track/<L>` when the level is empty: the deletion of its line.
pub(super) fn track_deletion(buf: &mut Vec<u8>, log_time: u64) {
    let mut w = Writer::new(buf);
    w.raw(b"{\"deletions\":[{\"timestamp\":");
    w.time(log_time);
    w.raw(b",\"type\":0,\"id\":\"track\"}],\"entities\":[]}");
}
