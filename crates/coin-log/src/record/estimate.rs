//! How many messages and bytes a scene will record, without recording it (`record --dry-run`, and the
//! warning before a recording larger than 1 GiB). Messages follow from the sampling rules (format.md:
//! Samples), for the full duration. Bytes follow from the format: each `coin_log.*` message is its keys and
//! punctuation plus [`TIME_CHARS`] for `t` and [`NUMBER_CHARS`] for every other number, plus the record's
//! overhead and index entry; the chunks shrink by the compression's typical ratio. The constants were
//! calibrated on real recordings of `wobble`, `circle-plus`, `high-spin`, `topple`, `five-hundred-yen` and
//! `long-horizon` with each compression, where the estimate falls within [`ACCURACY`] of the file's size
//! (a test keeps it so).

use super::foxglove::SCENE_RATE;
use crate::format::{schema_data, Channel, Encoding};
use crate::scene::Scene;
use coin_log_mcap::Compression;

/// Characters of a typical `t` value (`12.34`).
pub const TIME_CHARS: u64 = 5;
/// Characters of a typical number other than `t` (measured: 18.6–19.3 on generic motions).
pub const NUMBER_CHARS: u64 = 19;
/// Bytes of a `/tf` message (measured: 283–289; 236 on `topple`, whose numbers are shorter).
pub const TF_BYTES: u64 = 285;
/// Bytes of a Protobuf `/tf` message (keys, two frame names, 7 doubles, a timestamp).
pub const TF_PROTOBUF_BYTES: u64 = 100;
/// Bytes of a Protobuf `/scene` update without its track points.
pub const SCENE_PROTOBUF_BYTES: u64 = 900;
/// Bytes of one track point in a Protobuf `/scene` update.
pub const TRACK_POINT_PROTOBUF_BYTES: u64 = 20;
/// Bytes of a display update on the `rerun` channel without its track points (`/rerun/coin_body` and the
/// point cloud's header).
pub const RERUN_UPDATE_BYTES: u64 = 220;
/// Bytes of one track point in `/rerun/track` (at most one per sample: points are spaced by distance).
pub const TRACK_POINT_RERUN_BYTES: u64 = 16;
/// Messages per display update on the `scene` channel's topics (follow frame, coin, ~2 track levels).
pub const SCENE_MESSAGES_PER_UPDATE: u64 = 4;
/// Bytes of a `/scene` update without its track points (measured: 1700–1760).
pub const SCENE_BYTES: u64 = 1700;
/// Bytes of one track point in a `/scene` update (`{"x":...,"y":0.0,"z":...},`).
pub const TRACK_POINT_BYTES: u64 = 57;
/// Opcode, length, channel id, sequence, log time and publish time of a message record.
pub const RECORD_OVERHEAD: u64 = 1 + 8 + 2 + 4 + 8 + 8;
/// Bytes per message in the message indexes (log time and offset).
pub const INDEX_ENTRY: u64 = 16;
/// Bytes of the file that do not grow with its length besides schemas and the scene (magic, header,
/// the metadata records' other keys, statistics, summary offsets, footer).
pub const FIXED_BYTES: u64 = 2048;
/// Bytes of summary per chunk (its chunk index) and of chunks per MiB of records.
pub const CHUNK_INDEX_BYTES: u64 = 200;
/// The estimate is within this factor of the real file size on the calibration recordings.
pub const ACCURACY: f64 = 2.0;

/// Compressed size over uncompressed size of the chunks (measured on the calibration recordings: JSON zstd
/// 0.15–0.30, lz4 0.23–0.39; Protobuf zstd 0.26–0.44, lz4 0.33–0.53: binary doubles compress less).
#[must_use]
pub fn compression_ratio(compression: Compression, encoding: Encoding) -> f64 {
    match (compression, encoding) {
        (Compression::Zstd, Encoding::Json) => 0.25,
        (Compression::Lz4, Encoding::Json) => 0.35,
        (Compression::Zstd, Encoding::Protobuf) => 0.35,
        (Compression::Lz4, Encoding::Protobuf) => 0.45,
        (Compression::None, _) => 1.0,
    }
}

/// What a scene will write: the fields of `record --dry-run --json` (format.md: Dry run and the size
/// estimate); `per_channel` in the channel table's order.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    pub samples: u64,
    pub messages: u64,
    pub per_channel: Vec<(Channel, u64)>,
    pub bytes: u64,
}

/// Samples of a completed run: t = 0, the grid points t = k / rate before the end, and t = duration, by
/// the driver's own rule (a grid point within 2 ns of the end gives way to it).
#[must_use]
pub fn samples(duration: f64, rate: f64) -> u64 {
    coin_log_ode::samples_to_end(0.0, duration, 1.0 / rate)
}

/// Bytes of one message of a flat `coin_log.*` channel with `fields` (`t` first).
fn flat_bytes(fields: &[&str]) -> u64 {
    let keys: u64 = fields.iter().map(|f| f.len() as u64 + 3).sum();
    let n = fields.len() as u64;
    2 + keys + n.saturating_sub(1) + TIME_CHARS + n.saturating_sub(1) * NUMBER_CHARS
}

/// Bytes of one Protobuf message of a flat `coin_log.*` channel with `fields`: a one-byte key and 8 bytes per
/// field.
fn flat_protobuf_bytes(fields: &[&str]) -> u64 {
    9 * fields.len() as u64
}

/// The estimate for `scene` written with `compression` in `encoding`.
#[must_use]
#[allow(
    clippy::cast_possible_truncation,
    clippy::cast_sign_loss,
    clippy::cast_precision_loss
)]
pub fn estimate(scene: &Scene, compression: Compression, encoding: Encoding) -> Estimate {
    let n = samples(scene.run.duration, scene.run.rate);
    let updates = n.min((scene.run.duration * SCENE_RATE).ceil() as u64 + 2);
    let mut per_channel = Vec::new();
    let (mut payload, mut schemas) = (0u64, 0u64);
    let mut seen_schemas = std::collections::BTreeSet::new();
    // Bytes of a /tf message, of a /scene update and of one of its track points, of a flat message.
    let (tf, update, point, flat): (_, _, _, fn(&[&str]) -> u64) = match encoding {
        Encoding::Json => (TF_BYTES, SCENE_BYTES, TRACK_POINT_BYTES, flat_bytes),
        Encoding::Protobuf => (
            TF_PROTOBUF_BYTES,
            SCENE_PROTOBUF_BYTES,
            TRACK_POINT_PROTOBUF_BYTES,
            flat_protobuf_bytes,
        ),
    };
    for &c in &scene.channels {
        let (count, bytes) = match c {
            // /tf: world → table once, then table → coin per sample; /tf_static: world → table once.
            Channel::Tf => (n + 2, tf),
            // Per display update: the follow frame and the coin, and on average about two track levels
            // (level k changes every 2^k updates: a binary counter); the table once, then when it moves.
            // The bytes per message are averaged over these.
            Channel::Scene => (
                SCENE_MESSAGES_PER_UPDATE * updates + 1,
                (update + point * n.div_ceil(updates.max(1))) / SCENE_MESSAGES_PER_UPDATE,
            ),
            // Per display update: /rerun/coin_body and a point cloud of the track; the URDF once and the
            // table (a 60 × 60 voxel grid, 14.5 kB, compressing to little) once, then when it moves.
            Channel::Rerun => (
                2 * updates + 2,
                RERUN_UPDATE_BYTES + TRACK_POINT_RERUN_BYTES * n.div_ceil(updates.max(1)) / 2,
            ),
            _ => (n, c.message_type().map_or(100, |t| flat(t.fields))),
        };
        per_channel.push((c, count));
        payload += count * (bytes + RECORD_OVERHEAD);
        if seen_schemas.insert(c.schema_name()) {
            schemas += schema_data(c.schema_name(), encoding).map_or(0, |s| s.len() as u64);
        }
    }
    let messages: u64 = per_channel.iter().map(|(_, m)| m).sum();
    let chunks = payload.div_ceil(1 << 20);
    let compressed = (payload as f64 * compression_ratio(compression, encoding)).ceil() as u64;
    let bytes = FIXED_BYTES
        + 2 * schemas
        + 2 * scene.to_toml().len() as u64
        + compressed
        + messages * INDEX_ENTRY
        + chunks * CHUNK_INDEX_BYTES;
    Estimate {
        samples: n,
        messages,
        per_channel,
        bytes,
    }
}

#[cfg(test)]
mod tests {
    use super::{flat_bytes, samples};

    #[test]
    fn samples_follow_the_grid_and_the_end() {
        assert_eq!(samples(30.0, 100.0), 3001);
        assert_eq!(samples(0.3, 10.0), 4, "0.3·10 is 3 up to rounding");
        assert_eq!(samples(0.25, 10.0), 4, "t = 0, 0.1, 0.2 and the end 0.25");
        assert_eq!(samples(3.0, 200.0), 601);
        assert_eq!(
            samples(1.0, 1e-10),
            2,
            "t = 0 and the end, with no grid point between"
        );
        assert_eq!(
            samples(1.000_000_001_5, 1.0),
            2,
            "t = 1 is 1.5 ns before the end: it gives way"
        );
        assert_eq!(
            samples(100.000_000_1, 100.0),
            10_002,
            "t = 100 is 100 ns before the end"
        );
    }

    #[test]
    fn a_flat_message_is_its_keys_punctuation_and_numbers() {
        // {"t":12.34,"x":<19>,"y":<19>,"z":<19>}: 2 braces, 4 keys of 4 bytes, 3 commas, 5 + 3 × 19.
        assert_eq!(flat_bytes(&["t", "x", "y", "z"]), 2 + 16 + 3 + 5 + 57);
    }
}
