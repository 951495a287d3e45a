//! The `rerun` channel (docs/format.md: Rerun geometry): the coin (a URDF moved by `/rerun/coin_body`),
//! the table (a voxel grid) and the track (point clouds) again, in the types Rerun's MCAP importer turns
//! into geometry, since it draws no `foxglove.SceneUpdate`. Display units and frames as in [`super`].

use super::proto::{identity, pose, timestamp, transform};
use super::{
    coin_marks, Rgba, COIN_RGBA, FOLLOW_FRAME, TABLE_HALF_SIDE, TABLE_RGBA, TABLE_THICKNESS,
    TABLE_TOP, TRACK_RGBA, WORLD_FRAME,
};
use super::{FoxgloveBatch, Topic};
use crate::format::Channel;
use foxglove::messages::packed_element_field::NumericType;
use foxglove::messages::{PackedElementField, PointCloud, Vector3, VoxelGrid};
use nalgebra::UnitQuaternion;
use prost::Message;

/// The URDF's robot and link (the frame `/rerun/coin_body` moves).
pub const ROBOT: &str = "coin_shape";
/// The frame of the coin's URDF link, child of `coin_level`.
pub const BODY_FRAME: &str = "coin_body";
/// Largest distance between successive track points, display units (the Foxglove track's tolerance).
pub const TRACK_SPACING: f64 = 0.01;
/// Bytes per track point: x, y, z as f32, then red, green, blue, alpha as u8.
const POINT_STRIDE: u32 = 16;
/// Cells per side of the table's grid (one per display unit, as the Foxglove grid's lines).
const TABLE_CELLS: u32 = 60;
/// The two cell colours of the table, RGBA: the slab's and a darker one.
const TABLE_CHECKS: [[u8; 4]; 2] = [rgba8(TABLE_RGBA), [190, 188, 180, 255]];

/// A colour in 0..1 as 8-bit channels (the values here are in 0..1, so the cast cannot wrap).
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
const fn rgba8(c: Rgba) -> [u8; 4] {
    [
        (c[0] * 255.0 + 0.5) as u8,
        (c[1] * 255.0 + 0.5) as u8,
        (c[2] * 255.0 + 0.5) as u8,
        (c[3] * 255.0 + 0.5) as u8,
    ]
}

/// State of the `rerun` channel across drawing updates.
#[derive(Debug, Clone, Default)]
pub struct Rerun3d {
    thickness: f64,
    /// Whether the URDF has been written.
    started: bool,
    /// Track points not yet published, packed as the point cloud stores them.
    pending: Vec<u8>,
    /// The latest track point kept, and the latest contact point (display units).
    kept: Option<[f64; 2]>,
    latest: Option<[f64; 2]>,
}

impl Rerun3d {
    pub fn new(thickness: f64) -> Self {
        Self {
            thickness,
            ..Self::default()
        }
    }

    /// One sample's contact point `p` (display units, `world`): kept for the track when it is
    /// [`TRACK_SPACING`] or more from the last one kept.
    pub fn contact(&mut self, p: [f64; 2]) {
        self.latest = Some(p);
        if self
            .kept
            .is_none_or(|k| (p[0] - k[0]).hypot(p[1] - k[1]) >= TRACK_SPACING)
        {
            self.keep(p);
        }
    }

    fn keep(&mut self, p: [f64; 2]) {
        self.kept = Some(p);
        // Rerun stores positions as f32: the rounding the CI test allows.
        #[allow(clippy::cast_possible_truncation)]
        for v in [p[0] as f32, p[1] as f32, 0.0] {
            self.pending.extend_from_slice(&v.to_le_bytes());
        }
        self.pending.extend_from_slice(&rgba8(TRACK_RGBA));
    }

    /// A drawing update's coin: the URDF at the first, then `coin_level` → `coin_body` with rotation `r`.
    pub fn coin(&mut self, log_time: u64, r: &UnitQuaternion<f64>, out: &mut FoxgloveBatch) {
        if !self.started {
            let urdf = urdf(self.thickness);
            out.push(Topic::RerunRobot, |buf| cdr_string(buf, &urdf));
            self.started = true;
        }
        out.push(Topic::Main(Channel::Rerun), |buf| {
            transform(buf, log_time, FOLLOW_FRAME, BODY_FRAME, None, Some(r));
        });
    }

    /// A drawing update's track: the points kept since the previous update and the latest contact point,
    /// if the coin moved at all.
    pub fn track(&mut self, log_time: u64, out: &mut FoxgloveBatch) {
        if let Some(p) = self.latest.filter(|&p| Some(p) != self.kept) {
            self.keep(p);
        }
        if self.pending.is_empty() {
            return;
        }
        let data = std::mem::take(&mut self.pending);
        out.push(Topic::RerunTrack, |buf| {
            PointCloud {
                timestamp: Some(timestamp(log_time)),
                frame_id: WORLD_FRAME.to_string(),
                // Rerun's importer needs the pose and its position present, even when zero.
                pose: Some(identity()),
                point_stride: POINT_STRIDE,
                fields: ["x", "y", "z", "red", "green", "blue", "alpha"]
                    .iter()
                    .zip([0, 4, 8, 12, 13, 14, 15])
                    .map(|(name, offset)| field(name, offset, offset < 12))
                    .collect(),
                data: data.into(),
            }
            .encode_raw(buf);
        });
    }
}

fn field(name: &str, offset: u32, float: bool) -> PackedElementField {
    let numeric = if float {
        NumericType::Float32
    } else {
        NumericType::Uint8
    };
    PackedElementField {
        name: name.to_string(),
        offset,
        r#type: numeric as i32,
    }
}

/// `/rerun/table`: the table centred on `centre` (display units, finite: `/scene/table` checked it), as
/// one layer of [`TABLE_CELLS`]² checkered cells just under the plane, like the slab of `/scene/table`.
pub(super) fn table(buf: &mut Vec<u8>, log_time: u64, centre: [f64; 2]) {
    let n = TABLE_CELLS;
    let mut data = Vec::with_capacity(4 * (n * n) as usize);
    for row in 0..n {
        for column in 0..n {
            data.extend_from_slice(&TABLE_CHECKS[((row + column) % 2) as usize]);
        }
    }
    VoxelGrid {
        timestamp: Some(timestamp(log_time)),
        frame_id: WORLD_FRAME.to_string(),
        pose: Some(pose(
            [
                centre[0] - TABLE_HALF_SIDE,
                centre[1] - TABLE_HALF_SIDE,
                TABLE_TOP - TABLE_THICKNESS,
            ],
            &UnitQuaternion::identity(),
        )),
        row_count: n,
        column_count: n,
        cell_size: Some(Vector3 {
            x: 2.0 * TABLE_HALF_SIDE / f64::from(n),
            y: 2.0 * TABLE_HALF_SIDE / f64::from(n),
            z: TABLE_THICKNESS,
        }),
        slice_stride: 4 * n * n,
        row_stride: 4 * n,
        cell_stride: 4,
        fields: ["red", "green", "blue", "alpha"]
            .iter()
            .zip(0..)
            .map(|(name, offset)| field(name, offset, false))
            .collect(),
        data: data.into(),
    }
    .encode_raw(buf);
}

/// The coin's URDF: the disc and its two face marks (those of `/scene`, `coin_marks`) in the body frame.
#[must_use]
pub fn urdf(thickness: f64) -> String {
    let colour = |c: Rgba| format!("{:?} {:?} {:?} {:?}", c[0], c[1], c[2], c[3]);
    let mut visuals = format!(
        "    <visual name=\"disc\"><origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\
         <geometry><cylinder radius=\"1\" length=\"{thickness:?}\"/></geometry>\
         <material name=\"gold\"><color rgba=\"{}\"/></material></visual>\n",
        colour(COIN_RGBA)
    );
    let marks = coin_marks(&UnitQuaternion::identity(), thickness);
    for ((p, size, rgba), name) in marks.iter().zip(["mark_top", "mark_bottom"]) {
        visuals += &format!(
            "    <visual name=\"{name}\"><origin xyz=\"{:?} {:?} {:?}\" rpy=\"0 0 0\"/>\
             <geometry><box size=\"{:?} {:?} {:?}\"/></geometry>\
             <material name=\"{name}\"><color rgba=\"{}\"/></material></visual>\n",
            p.x,
            p.y,
            p.z,
            size[0],
            size[1],
            size[2],
            colour(*rgba)
        );
    }
    format!(
        "<?xml version=\"1.0\"?>\n<robot name=\"{ROBOT}\">\n  <link name=\"{BODY_FRAME}\">\n{visuals}  </link>\n</robot>\n"
    )
}

/// `text` as a CDR `std_msgs/msg/String`: the little-endian encapsulation header, the length with the NUL,
/// the bytes, the NUL, padding to 4.
fn cdr_string(buf: &mut Vec<u8>, text: &str) {
    let start = buf.len();
    buf.extend_from_slice(&[0, 1, 0, 0]);
    // A URDF of a few hundred bytes: its length fits in a u32.
    let len = u32::try_from(text.len() + 1).unwrap_or(u32::MAX);
    buf.extend_from_slice(&len.to_le_bytes());
    buf.extend_from_slice(text.as_bytes());
    buf.push(0);
    while !(buf.len() - start).is_multiple_of(4) {
        buf.push(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_urdf_is_a_cdr_string_with_the_disc_and_its_marks() {
        let mut buf = vec![7];
        cdr_string(&mut buf, "ab");
        assert_eq!(buf, [7, 0, 1, 0, 0, 3, 0, 0, 0, b'a', b'b', 0, 0]);
        let u = urdf(0.05);
        println!("{u}");
        assert!(u.contains("<cylinder radius=\"1\" length=\"0.05\"/>"));
        assert!(u.contains("<robot name=\"coin_shape\">"));
        // The marks of /scene, 0.2 · thickness thick (0.010000000000000002), just outside each face.
        assert_eq!(u.matches("<box size=\"0.85 0.12 0.01").count(), 2);
        assert!(
            u.contains("xyz=\"0.45 0.0 0.03"),
            "top mark outside the face"
        );
        assert!(
            u.contains("xyz=\"0.45 0.0 -0.03"),
            "bottom mark outside the face"
        );
    }

    #[test]
    fn track_points_are_spaced_and_end_at_the_latest_contact() {
        let mut r = Rerun3d::new(0.05);
        let mut out = FoxgloveBatch::default();
        for k in 0..=100 {
            r.contact([f64::from(k) * 1e-3, 0.0]);
        }
        r.track(0, &mut out);
        let (topic, bytes) = out.iter().next().unwrap();
        assert_eq!(topic, Topic::RerunTrack);
        let cloud = PointCloud::decode(bytes).unwrap();
        let xs: Vec<f32> = cloud
            .data
            .chunks(16)
            .map(|p| f32::from_le_bytes([p[0], p[1], p[2], p[3]]))
            .collect();
        println!("{xs:?}");
        // 0, 0.01, …, 0.1: one in ten samples, and the last sample (0.1) itself.
        assert_eq!(xs.len(), 11);
        #[allow(clippy::cast_possible_truncation)]
        let last = 0.1_f64 as f32;
        assert_eq!(xs[10], last);
        // No motion, no message.
        out.clear();
        r.contact([0.1, 0.0]);
        r.track(1, &mut out);
        assert!(out.iter().next().is_none());
    }
}
