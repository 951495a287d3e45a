//! The JSON of the Foxglove messages, written piece by piece into a reused buffer: literals, checked numbers
//! (shortest round-trip decimals, never NaN), `{sec, nsec}` times, and the common parts of a `SceneEntity`.
//! By hand rather than through serde because the transform of every sample is on the recorder's hot path and
//! must refuse non-finite numbers instead of writing `null`.

use crate::format::messages::{push_number, NonFiniteField};
use nalgebra::{UnitQuaternion, Vector3};

/// `Err` naming `field` of `schema` unless `value` is finite.
pub(super) fn check(
    schema: &'static str,
    field: &'static str,
    value: f64,
) -> Result<(), NonFiniteField> {
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
pub(super) struct Writer<'a> {
    buf: &'a mut Vec<u8>,
    ryu: ryu::Buffer,
    schema: &'static str,
}

impl<'a> Writer<'a> {
    pub(super) fn new(buf: &'a mut Vec<u8>, schema: &'static str) -> Self {
        Self {
            buf,
            ryu: ryu::Buffer::new(),
            schema,
        }
    }

    pub(super) fn raw(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    pub(super) fn num(&mut self, field: &'static str, value: f64) -> Result<(), NonFiniteField> {
        check(self.schema, field, value)?;
        push_number(self.buf, value, &mut self.ryu);
        Ok(())
    }

    /// A `Color` {r, g, b, a}, each component's shortest decimal, whole ones without `.0` (`"a":1`).
    pub(super) fn color(&mut self, rgba: super::Rgba) {
        let keys: [&[u8]; 4] = [b"{\"r\":", b",\"g\":", b",\"b\":", b",\"a\":"];
        for (key, v) in keys.into_iter().zip(rgba) {
            self.buf.extend_from_slice(key);
            let text = self.ryu.format(v);
            self.buf
                .extend_from_slice(text.strip_suffix(".0").unwrap_or(text).as_bytes());
        }
        self.buf.push(b'}');
    }

    pub(super) fn uint(&mut self, mut n: u64) {
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
    pub(super) fn time(&mut self, log_time: u64) {
        self.raw(b"{\"sec\":");
        self.uint(log_time / 1_000_000_000);
        self.raw(b",\"nsec\":");
        self.uint(log_time % 1_000_000_000);
        self.raw(b"}");
    }

    pub(super) fn vector3(
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
    pub(super) fn quaternion(&mut self, q: &UnitQuaternion<f64>) -> Result<(), NonFiniteField> {
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

    /// A `Pose`: `position` and the rotation `q` as `orientation`.
    pub(super) fn pose(
        &mut self,
        position: &Vector3<f64>,
        q: &UnitQuaternion<f64>,
    ) -> Result<(), NonFiniteField> {
        self.raw(b"{\"position\":");
        self.vector3("pose.position", position.x, position.y, position.z)?;
        self.raw(b",\"orientation\":{\"x\":");
        self.num("pose.orientation.x", q.i)?;
        self.raw(b",\"y\":");
        self.num("pose.orientation.y", q.j)?;
        self.raw(b",\"z\":");
        self.num("pose.orientation.z", q.k)?;
        self.raw(b",\"w\":");
        self.num("pose.orientation.w", q.w)?;
        self.raw(b"}}");
        Ok(())
    }

    /// A `Point3` (x, y, 0) of a line.
    pub(super) fn point(&mut self, x: f64, y: f64) -> Result<(), NonFiniteField> {
        self.raw(b"{\"x\":");
        self.num("lines.points.x", x)?;
        self.raw(b",\"y\":");
        self.num("lines.points.y", y)?;
        self.raw(b",\"z\":0}");
        Ok(())
    }

    /// An entity up to its `"arrows":[],`; the caller writes cubes, spheres, cylinders and lines (each
    /// followed by a comma), then [`Self::entity_tail`].
    pub(super) fn entity_head(
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

    pub(super) fn entity_tail(&mut self) {
        self.raw(b"\"triangles\":[],\"texts\":[],\"models\":[]}");
    }
}
