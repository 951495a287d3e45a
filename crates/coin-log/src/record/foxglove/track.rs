//! The contact track as levels of a binary counter, so that the latest message of each track topic alone
//! draws the whole path up to the latest display update (format.md: Frames and Foxglove output, The track's
//! levels): at update n only level (trailing zero bits of n) changes, taking the levels below it.
//!
//! Each level is simplified by Douglas–Peucker with a tolerance that grows with the level ([`tolerance`]).
//! Re-simplifying a simplified polyline would add up the errors, so every segment carries a bound on the
//! distance of the original points it stands for: when points P_a..P_b are replaced by the segment
//! [P_a, P_b], the original points of the old segment (P_{k−1}, P_k) lie within E_k of it, and the old
//! segment lies within max(d(P_{k−1}), d(P_k)) of the new one (the distance to a segment is convex), so the
//! new bound is max_k E_k + max(d(P_{k−1}), d(P_k)). A segment is accepted when its bound is within the
//! level's tolerance; every original point therefore stays within [`MAX_TOLERANCE`] of the published
//! track, whatever the number of merges. Points are rounded to [`QUANTUM`]; a repeated point is skipped.

use super::round_to;
use crate::format::TRACK_LEVELS;

/// The highest level; it is never emptied.
pub const TOP: usize = TRACK_LEVELS - 1;

/// Grid the track's points are rounded to, in units of a.
pub const QUANTUM: f64 = 1e-4;

/// Tolerance of the simplification of level 0, in units of a.
pub const MIN_TOLERANCE: f64 = 1e-3;

/// The largest tolerance (any level), in units of a: no original point is farther than this from the
/// published track (plus half a [`QUANTUM`] diagonal for the rounding). 0.01 a is about one pixel with the
/// shipped layout's camera.
pub const MAX_TOLERANCE: f64 = 1e-2;

/// Tolerance of level `level`: [`MIN_TOLERANCE`] doubled every three levels, at most [`MAX_TOLERANCE`].
#[must_use]
pub fn tolerance(level: usize) -> f64 {
    let steps = i32::try_from(level).unwrap_or(i32::MAX).min(64);
    (MIN_TOLERANCE * 2f64.powf(f64::from(steps) / 3.0)).min(MAX_TOLERANCE)
}

/// A point of a level's polyline (display units) and the error bound of the segment that ends at it (0 for
/// the first).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TrackPoint {
    pub x: f64,
    pub y: f64,
    /// Bound on the distance of the original points of the segment ending here, display units.
    pub err: f64,
}

/// The track's levels and the points not yet in any level.
#[derive(Debug, Clone, Default)]
pub(crate) struct Track {
    levels: [Vec<TrackPoint>; TRACK_LEVELS],
    /// Points since the previous update.
    pending: Vec<TrackPoint>,
    /// The last point given (the chain's end once an update has taken it).
    last: Option<TrackPoint>,
    /// The end of the published chain (the last point of the newest content), once the first update is
    /// done.
    end: Option<TrackPoint>,
    /// Updates so far.
    updates: u64,
    // Scratch space of the merges, kept between updates.
    merged: Vec<TrackPoint>,
    keep: Vec<bool>,
    errors: Vec<f64>,
    stack: Vec<(usize, usize)>,
}

impl Track {
    /// Adds the contact point (x, y) in display units, unless it rounds to the previous one.
    pub fn add(&mut self, x: f64, y: f64) {
        let p = TrackPoint {
            x: round_to(x, QUANTUM),
            y: round_to(y, QUANTUM),
            err: 0.0,
        };
        if self.last.is_some_and(|q| q.x == p.x && q.y == p.y) {
            return;
        }
        self.last = Some(p);
        self.pending.push(p);
    }

    /// The content of `level` (empty, or at least two points).
    #[must_use]
    pub fn level(&self, level: usize) -> &[TrackPoint] {
        &self.levels[level]
    }

    /// Closes a display update: moves the points since the previous one into the level the update's number
    /// selects (module docs) and empties the levels below it. Returns that level (it has new content, or is
    /// empty), or `None` at the first update (which only fixes the start of the path).
    pub fn update(&mut self) -> Option<usize> {
        let n = self.updates;
        self.updates += 1;
        if n == 0 {
            self.end = self.pending.last().copied();
            self.pending.clear();
            return None;
        }
        // n ≥ 1 has at most 63 trailing zeros.
        let j = (n.trailing_zeros() as usize).min(TOP);
        let mut merged = std::mem::take(&mut self.merged);
        merged.clear();
        for i in (0..=j).rev() {
            let level = &self.levels[i];
            let skip = usize::from(!merged.is_empty() && !level.is_empty());
            merged.extend_from_slice(&level[skip.min(level.len())..]);
        }
        if merged.is_empty() {
            merged.extend(self.end.or(self.pending.first().copied()));
        }
        let skip = usize::from(
            merged
                .last()
                .zip(self.pending.first())
                .is_some_and(|(a, b)| a.x == b.x && a.y == b.y),
        );
        merged.extend_from_slice(&self.pending[skip.min(self.pending.len())..]);
        self.pending.clear();
        for level in &mut self.levels[..=j] {
            level.clear();
        }
        if merged.len() >= 2 {
            self.end = merged.last().copied();
            let mut out = std::mem::take(&mut self.levels[j]);
            self.simplify(&merged, tolerance(j), &mut out);
            self.levels[j] = out;
        } else if let Some(p) = merged.first() {
            self.end = Some(*p);
        }
        self.merged = merged;
        Some(j)
    }

    /// Douglas–Peucker of `points` with carried error bounds (module docs), into `out`.
    fn simplify(&mut self, points: &[TrackPoint], eps: f64, out: &mut Vec<TrackPoint>) {
        let m = points.len();
        self.keep.clear();
        self.keep.resize(m, false);
        self.errors.clear();
        self.errors.resize(m, 0.0);
        self.keep[0] = true;
        self.keep[m - 1] = true;
        self.stack.clear();
        self.stack.push((0, m - 1));
        while let Some((a, b)) = self.stack.pop() {
            let (bound, split) = segment_bound(points, a, b);
            match split {
                Some(k) if bound > eps => {
                    self.keep[k] = true;
                    self.stack.push((k, b));
                    self.stack.push((a, k));
                }
                _ => self.errors[b] = bound,
            }
        }
        out.clear();
        out.extend(
            points
                .iter()
                .zip(&self.keep)
                .zip(&self.errors)
                .filter(|((_, keep), _)| **keep)
                .map(|((p, _), &err)| TrackPoint { err, ..*p }),
        );
        out[0].err = 0.0;
    }
}

/// The error bound of replacing points a..=b by the segment [P_a, P_b], and the inner point farthest from
/// that segment (to split at), if there is an inner point off the segment.
fn segment_bound(points: &[TrackPoint], a: usize, b: usize) -> (f64, Option<usize>) {
    let (pa, pb) = ([points[a].x, points[a].y], [points[b].x, points[b].y]);
    let mut bound: f64 = 0.0;
    let mut farthest: Option<(usize, f64)> = None;
    let mut previous: f64 = 0.0;
    for (k, p) in points.iter().enumerate().take(b + 1).skip(a + 1) {
        let d = if k == b {
            0.0
        } else {
            segment_distance([p.x, p.y], pa, pb)
        };
        bound = bound.max(p.err + previous.max(d));
        if d > 0.0 && farthest.is_none_or(|(_, f)| d > f) {
            farthest = Some((k, d));
        }
        previous = d;
    }
    (bound, farthest.map(|(k, _)| k))
}

/// Distance from the point `p` to the segment [`a`, `b`] of the plane.
#[must_use]
pub fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let s = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - (a[0] + s * dx)).hypot(p[1] - (a[1] + s * dy))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance from p to the polyline `line`.
    fn to_polyline(p: (f64, f64), line: &[TrackPoint]) -> f64 {
        match line {
            [only] => (only.x - p.0).hypot(only.y - p.1),
            _ => line
                .windows(2)
                .map(|w| segment_distance([p.0, p.1], [w[0].x, w[0].y], [w[1].x, w[1].y]))
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// The levels' contents, highest level first: the chain from the start to the latest update.
    fn chain(track: &Track) -> Vec<TrackPoint> {
        let mut out: Vec<TrackPoint> = Vec::new();
        for level in (0..TRACK_LEVELS).rev() {
            let c = track.level(level);
            if c.is_empty() {
                continue;
            }
            if let Some(last) = out.last() {
                assert_eq!(
                    (last.x, last.y),
                    (c[0].x, c[0].y),
                    "level {level} starts where the level above ends"
                );
                out.extend_from_slice(&c[1..]);
            } else {
                out.extend_from_slice(c);
            }
        }
        out
    }

    /// A wiggly path: a circle of radius 3 with a fast wobble of amplitude 0.05.
    fn path(t: f64) -> (f64, f64) {
        let r = 3.0 + 0.05 * (17.0 * t).sin();
        (r * (0.4 * t).cos(), r * (0.4 * t).sin())
    }

    #[test]
    fn the_levels_cover_the_whole_path_at_every_update_within_the_tolerance() {
        let mut track = Track::default();
        let (per_update, updates) = (5, 700);
        let mut points = Vec::new();
        let mut worst: f64 = 0.0;
        let mut changed = Vec::new();
        let mut i = 0;
        for n in 0..updates {
            // One point at the first update, then `per_update` points before each.
            for _ in 0..if n == 0 { 1 } else { per_update } {
                let p = path(f64::from(i) * 0.01);
                track.add(p.0, p.1);
                points.push(p);
                i += 1;
            }
            changed.extend(track.update());
            let line = chain(&track);
            if n == 0 {
                assert!(line.is_empty());
                continue;
            }
            // The chain at every update; the distance of every point at every 13th (and the last).
            if n % 13 != 0 && n != updates - 1 {
                continue;
            }
            let (first, last) = (line[0], line[line.len() - 1]);
            let (p0, pn) = (points[0], points[points.len() - 1]);
            assert!((first.x - p0.0).abs() <= QUANTUM && (first.y - p0.1).abs() <= QUANTUM);
            assert!((last.x - pn.0).abs() <= QUANTUM && (last.y - pn.1).abs() <= QUANTUM);
            for p in &points {
                worst = worst.max(to_polyline(*p, &line));
            }
        }
        let bound = MAX_TOLERANCE + QUANTUM;
        println!(
            "worst distance of a path point from the track: {worst:e} (bound {bound:e}); levels changed: {:?}",
            &changed[..16]
        );
        assert!(worst <= bound);
        assert_eq!(&changed[..8], &[0, 1, 0, 2, 0, 1, 0, 3]);
    }

    #[test]
    fn simplification_keeps_few_points_on_a_straight_line_and_many_on_a_tight_curve() {
        let mut straight = Track::default();
        for n in 0..=64 {
            straight.add(f64::from(n) * 0.1, 0.5 * f64::from(n) * 0.1);
            straight.update();
        }
        // Update 64 = 2^6: level 6 holds everything, two points for a straight line.
        assert_eq!(straight.level(6).len(), 2, "{:?}", straight.level(6));
        let mut curve = Track::default();
        for n in 0..=64 {
            let a = f64::from(n) * 0.2;
            curve.add(a.cos(), a.sin());
            curve.update();
        }
        let kept = curve.level(6).len();
        println!("unit circle, 65 points over 2 turns: {kept} kept at level 6");
        assert!(kept > 40);
    }

    #[test]
    fn a_coin_that_does_not_move_has_no_track_and_repeated_points_are_dropped() {
        let mut track = Track::default();
        for _ in 0..40 {
            track.add(1.0, 2.0);
            track.add(1.00001, 2.0);
            track.update();
        }
        assert!((0..TRACK_LEVELS).all(|l| track.level(l).is_empty()));
    }

    #[test]
    fn the_top_level_keeps_everything_before_it() {
        let mut track = Track::default();
        let n_updates = (1u64 << TOP) * 2 + 3;
        for n in 0..n_updates {
            #[allow(clippy::cast_precision_loss)]
            let x = n as f64 * 0.01;
            track.add(x, (x * 0.3).sin());
            track.update();
        }
        let top = track.level(TOP);
        assert!((top[0].x, top[0].y) == (0.0, 0.0));
        #[allow(clippy::cast_precision_loss)]
        let boundary = ((1u64 << TOP) * 2) as f64 * 0.01;
        let end = top[top.len() - 1].x;
        println!("top level ends at x = {end}, expected {boundary}");
        assert!((end - boundary).abs() < QUANTUM);
        assert!(chain(&track).len() > top.len());
    }

    #[test]
    fn tolerances_grow_with_the_level_up_to_the_maximum() {
        assert_eq!(tolerance(0), MIN_TOLERANCE);
        for l in 1..TRACK_LEVELS {
            assert!(tolerance(l) >= tolerance(l - 1));
        }
        assert_eq!(tolerance(TOP), MAX_TOLERANCE);
    }
}
