//! The Protobuf form of the Foxglove messages: the `foxglove` crate's message types (Foxglove's published
//! schemas) encoded by prost, with the geometry of [`super::json`] (a test compares the two field by field).
//! The values were checked finite by [`super::Foxglove3d`].

use super::track::TrackPoint;
use super::{
    coin_marks, grid_segments, Rgba, COIN_RGBA, FOLLOW_FRAME, GRID_HEIGHT, GRID_RGBA, GRID_WIDTHS,
    TABLE_HALF_SIDE, TABLE_RGBA, TABLE_THICKNESS, TABLE_TOP, TRACK_RGBA, TRACK_WIDTH, WORLD_FRAME,
};
use foxglove::messages::{
    line_primitive, scene_entity_deletion, Color, CubePrimitive, CylinderPrimitive, Duration,
    FrameTransform, LinePrimitive, Point3, Pose, Quaternion, SceneEntity, SceneEntityDeletion,
    SceneUpdate, Timestamp, Vector3,
};
use nalgebra::UnitQuaternion;
use prost::Message;

/// The timestamp of a log time (ns). Foxglove's `Timestamp` counts seconds in a u32: up to 4.29e9 time
/// units, beyond the longest run the recorder accepts in Protobuf ([`MAX_SECONDS`]).
pub(super) fn timestamp(log_time: u64) -> Timestamp {
    let sec = u32::try_from(log_time / 1_000_000_000).unwrap_or(u32::MAX);
    // log_time % 1e9 < 1e9 fits in a u32.
    let nsec = u32::try_from(log_time % 1_000_000_000).unwrap_or(0);
    Timestamp::new_checked(sec, nsec).unwrap_or(Timestamp::MAX)
}

/// The longest run, in time units (= seconds of log time), whose timestamps fit Foxglove's u32 seconds.
pub const MAX_SECONDS: f64 = 4_294_967_295.0;

fn vector3(x: f64, y: f64, z: f64) -> Option<Vector3> {
    Some(Vector3 { x, y, z })
}

fn quaternion(q: &UnitQuaternion<f64>) -> Option<Quaternion> {
    Some(Quaternion {
        x: q.i,
        y: q.j,
        z: q.k,
        w: q.w,
    })
}

fn color(c: Rgba) -> Option<Color> {
    Some(Color {
        r: c[0],
        g: c[1],
        b: c[2],
        a: c[3],
    })
}

/// The pose at `position` rotated by `q`.
pub(super) fn pose(position: [f64; 3], q: &UnitQuaternion<f64>) -> Pose {
    Pose {
        position: vector3(position[0], position[1], position[2]),
        orientation: quaternion(q),
    }
}

/// The pose of a frame's own origin, unrotated.
pub(super) fn identity() -> Pose {
    pose([0.0; 3], &UnitQuaternion::identity())
}

/// A point (x, y, 0) of a line.
fn point(x: f64, y: f64) -> Point3 {
    Point3 { x, y, z: 0.0 }
}

/// A `FrameTransform` `parent` → `child`: no translation (`None`) is the zero one, no rotation the identity
/// (signature as in [`super::json`]).
pub(super) fn transform(
    buf: &mut Vec<u8>,
    log_time: u64,
    parent: &str,
    child: &str,
    translation: Option<[f64; 3]>,
    rotation: Option<&UnitQuaternion<f64>>,
) {
    let [x, y, z] = translation.unwrap_or([0.0; 3]);
    FrameTransform {
        timestamp: Some(timestamp(log_time)),
        parent_frame_id: parent.to_string(),
        child_frame_id: child.to_string(),
        translation: vector3(x, y, z),
        rotation: quaternion(rotation.unwrap_or(&UnitQuaternion::identity())),
    }
    .encode_raw(buf);
}

/// An entity with the fields every drawn one shares (no lifetime: it stays until replaced).
fn entity(log_time: u64, frame: &str, id: &str) -> SceneEntity {
    SceneEntity {
        timestamp: Some(timestamp(log_time)),
        frame_id: frame.to_string(),
        id: id.to_string(),
        lifetime: Some(Duration::new(0, 0)),
        frame_locked: true,
        ..SceneEntity::default()
    }
}

fn update(entity: SceneEntity) -> SceneUpdate {
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![entity],
    }
}

/// `/scene`: the coin posed with `r`, `thickness` thick, and its two face marks.
pub(super) fn coin(buf: &mut Vec<u8>, log_time: u64, r: &UnitQuaternion<f64>, thickness: f64) {
    let mut e = entity(log_time, FOLLOW_FRAME, "coin");
    for (position, size, rgba) in coin_marks(r, thickness) {
        e.cubes.push(CubePrimitive {
            pose: Some(pose(position.into(), r)),
            size: vector3(size[0], size[1], size[2]),
            color: color(rgba),
        });
    }
    e.cylinders.push(CylinderPrimitive {
        pose: Some(pose([0.0; 3], r)),
        size: vector3(2.0, 2.0, thickness),
        bottom_scale: 1.0,
        top_scale: 1.0,
        color: color(COIN_RGBA),
    });
    update(e).encode_raw(buf);
}

/// `/scene/table`: the slab centred on `centre` and its grid.
pub(super) fn table(buf: &mut Vec<u8>, log_time: u64, centre: [f64; 2]) {
    let mut e = entity(log_time, WORLD_FRAME, "table");
    let side = 2.0 * TABLE_HALF_SIDE;
    e.cubes.push(CubePrimitive {
        pose: Some(pose(
            [centre[0], centre[1], TABLE_TOP - 0.5 * TABLE_THICKNESS],
            &UnitQuaternion::identity(),
        )),
        size: vector3(side, side, TABLE_THICKNESS),
        color: color(TABLE_RGBA),
    });
    for major in [false, true] {
        let points = grid_segments(centre, major)
            .flat_map(|(a, b)| [point(a[0], a[1]), point(b[0], b[1])])
            .collect();
        e.lines.push(LinePrimitive {
            r#type: line_primitive::Type::LineList as i32,
            pose: Some(pose([0.0, 0.0, GRID_HEIGHT], &UnitQuaternion::identity())),
            thickness: GRID_WIDTHS[usize::from(major)],
            scale_invariant: true,
            points,
            color: color(GRID_RGBA[usize::from(major)]),
            ..LinePrimitive::default()
        });
    }
    update(e).encode_raw(buf);
}

/// `/scene/track/<L>`: the level's points as one line strip.
pub(super) fn track(buf: &mut Vec<u8>, log_time: u64, points: &[TrackPoint]) {
    let line = points.iter().map(|p| point(p.x, p.y)).collect();
    let mut e = entity(log_time, WORLD_FRAME, "track");
    e.lines.push(LinePrimitive {
        r#type: line_primitive::Type::LineStrip as i32,
        pose: Some(identity()),
        thickness: TRACK_WIDTH,
        scale_invariant: true,
        points: line,
        color: color(TRACK_RGBA),
        ..LinePrimitive::default()
    });
    update(e).encode_raw(buf);
}

/// `/scene/track/<L>` when the level is empty: the deletion of its line.
pub(super) fn track_deletion(buf: &mut Vec<u8>, log_time: u64) {
    SceneUpdate {
        deletions: vec![SceneEntityDeletion {
            timestamp: Some(timestamp(log_time)),
            r#type: scene_entity_deletion::Type::MatchingId as i32,
            id: "track".to_string(),
        }],
        entities: Vec::new(),
    }
    .encode_raw(buf);
}
