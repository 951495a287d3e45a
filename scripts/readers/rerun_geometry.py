#!/usr/bin/env python3
"""Checks the geometry Rerun's MCAP importer makes of a coin-log recording's `rerun` channel against the
recorded centre and contact point, at three drawing times (docs/format.md: Rerun geometry).

usage: .venv/bin/python scripts/readers/rerun_geometry.py FILE.mcap OUT.rrd [--shift]

1. `rerun mcap convert FILE.mcap -d foxglove -d protobuf -d urdf --timeline-type duration -o OUT.rrd` (the
   README's conversion; `-d urdf` is what turns /rerun/robot_description into the coin), then
   `rerun rrd verify OUT.rrd`.
2. Reads OUT.rrd back with the SDK and resolves the transform tree from it alone (every Transform3D row,
   each entity's CoordinateFrame and InstancePoses3D, latest-at on `message_log_time`), then at three
   /rerun/coin_body times compares, in display units in `world`:
   - coin centre: the URDF disc's (Cylinders3D) centre with /coin/position (through q_T, divided by a);
   - coin contact: the lowest point of the disc's rim with /coin/contact;
   - track end: the newest /rerun/track point (Points3D) up to that time with /coin/contact;
   - table: the contact lies on the /rerun/table voxel grid (VoxelGridMap), 10 a or more from its edge.
   The tolerance is 64 f32 roundings of the largest coordinate (Rerun stores positions and transforms as
   f32; the chain has three transforms). --shift (negative control) compares with the samples one later:
   every position check must then fail.
Prints one JSON document on stdout: {"checks": [{"name", "t", "error", "tolerance", "ok"}, ...], "ok"};
a summary on stderr. Exits 1 if a check fails or the geometry is missing, 2 on a usage error.
"""

from __future__ import annotations

import json
import subprocess
import sys
from bisect import bisect_right
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr

F32_EPS = float(np.finfo(np.float32).eps)
DISC = "/coin_shape/visual_geometries/coin_body/disc"
TRACK, TABLE, BODY = "/rerun/track", "/rerun/table", "/rerun/coin_body"
Q_T = (np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5))  # world <- table, (x, y, z, w)


def rows(rrd):
    """{entity: [(log_time or None when static, {component: value})]}, static rows first then by time."""
    out = {}
    for chunk in rr.chunk.RrdReader(rrd).stream():
        batch = chunk.to_record_batch()
        names = [n for n in batch.schema.names if ":" in n and not n.startswith("Mcap")]
        if not names:
            continue
        cols = {n: batch.column(n).to_pylist() for n in names}
        if chunk.is_static:
            times = [None] * batch.num_rows
        else:
            times = batch.column("message_log_time").cast(pa.int64()).to_pylist()
        for i, t in enumerate(times):
            out.setdefault(chunk.entity_path, []).append((t, {n: cols[n][i] for n in names if cols[n][i] is not None}))
    for v in out.values():
        v.sort(key=lambda r: -1 if r[0] is None else r[0])
    return out


def qmat(q):
    x, y, z, w = (float(c) for c in q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def latest(rs, t):
    """The components of an entity's rows merged latest-at t (static rows first)."""
    merged = {}
    for rt, c in rs:
        if rt is None or rt <= t:
            merged.update(c)
    return merged


class Tree:
    """child frame -> time-sorted [(t, parent, R, T)], from every Transform3D row in the file."""

    def __init__(self, data):
        self.edges = {}
        for rs in data.values():
            for t, c in rs:
                if "Transform3D:child_frame" in c:
                    T = np.array(c.get("Transform3D:translation", [[0, 0, 0]])[0], dtype=np.float64)
                    R = qmat(c.get("Transform3D:quaternion", [[0, 0, 0, 1]])[0])
                    edge = (t or 0, c["Transform3D:parent_frame"][0], R, T)
                    self.edges.setdefault(c["Transform3D:child_frame"][0], []).append(edge)
        for v in self.edges.values():
            v.sort(key=lambda e: e[0])

    def to_root(self, frame, t):
        """(R, T) of `frame` in the root, latest-at t."""
        R, T = np.eye(3), np.zeros(3)
        while frame in self.edges:
            es = self.edges[frame]
            k = bisect_right([e[0] for e in es], t) - 1
            if k < 0:
                raise KeyError(f"no transform for frame {frame!r} at {t} ns")
            _, frame, Re, Te = es[k]
            R, T = Re @ R, Re @ T + Te
        return R, T


def convert(mcap, rrd):
    cli = str(Path(sys.executable).parent / "rerun")
    convert = [cli, "mcap", "convert", mcap, "-d", "foxglove", "-d", "protobuf", "-d", "urdf"]
    convert += ["--timeline-type", "duration", "-o", rrd]
    for step in (convert, [cli, "rrd", "verify", rrd]):
        done = subprocess.run(step, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            shown = " ".join(["rerun", *step[1:]])
            raise SystemExit(f"rerun_geometry.py: `{shown}` failed ({done.returncode}):\n{done.stdout}{done.stderr}")


def main(argv):
    args = [a for a in argv[1:] if a != "--shift"]
    if len(args) != 2:
        print("usage: rerun_geometry.py FILE.mcap OUT.rrd [--shift]", file=sys.stderr)
        return 2
    shift = "--shift" in argv
    convert(*args)
    data = rows(args[1])
    missing = [e for e in (DISC, TRACK, TABLE, BODY) if e not in data]
    if missing:
        print(f"rerun_geometry.py: no {', '.join(missing)} in the .rrd: record with --rerun (the `rerun` channel)", file=sys.stderr)
        return 1
    tree = Tree(data)

    def samples(entity):
        return {t: np.array([c["coin_log.Position:message"][0][k] for k in "xyz"]) for t, c in data[entity] if t is not None}

    centres, contacts = samples("/coin/position"), samples("/coin/contact")
    sample_times = sorted(centres)
    # The radius a: the follow frame's height (cos θ) against the recorded centre's (a cos θ).
    t0 = sample_times[0]
    a = centres[t0][1] / tree.to_root("coin_level", t0)[1][2]
    q_t = qmat(Q_T)
    body_times = [t for t, _ in data[BODY] if t is not None]
    picks = [body_times[len(body_times) // 7], body_times[len(body_times) // 2], body_times[-3]]
    checks = []

    def check(name, t, got, want, tol):
        error = float(np.max(np.abs(np.asarray(got, dtype=np.float64) - np.asarray(want, dtype=np.float64))))
        checks.append({"name": name, "t": t, "error": error, "tolerance": tol, "ok": error <= tol})
        mark = "ok " if error <= tol else "BAD"
        print(f"  {mark} {name}: got {np.round(got, 6)} want {np.round(want, 6)} |error| {error:.2e} (tolerance {tol:.1e})", file=sys.stderr)

    for t in picks:
        at = sample_times[sample_times.index(t) + 1] if shift else t
        centre, contact = q_t @ centres[at] / a, q_t @ contacts[at] / a
        tol = 64 * F32_EPS * (1.0 + float(np.max(np.abs(centre))))
        print(f"t = {t / 1e9:.3f}: centre {np.round(centre, 6)}, contact {np.round(contact, 6)} (display units, world)", file=sys.stderr)
        disc = latest(data[DISC], t)
        R, T = tree.to_root(disc["CoordinateFrame:frame"][0], t)
        middle = R @ np.array(disc["InstancePoses3D:translations"][0], dtype=np.float64) + T
        R = R @ qmat(disc["InstancePoses3D:quaternions"][0])
        radius = float(disc["Cylinders3D:radii"][0])
        check("coin centre", t, middle, centre, tol)
        n = R[:, 2]
        down = np.array([0.0, 0.0, -1.0]) + n * n[2]  # the rim's lowest direction: -z without its normal part
        check("coin contact", t, middle + radius * down / np.linalg.norm(down), contact, tol)
        points = [p for rt, c in data[TRACK] if rt is not None and rt <= t for p in c.get("Points3D:positions", [])]
        Rt, Tt = tree.to_root(latest(data[TRACK], t)["CoordinateFrame:frame"][0], t)
        check("track end", t, Rt @ np.array(points[-1], dtype=np.float64) + Tt, contact, tol)
        table = latest(data[TABLE], t)
        corner = np.array(table["VoxelGridMap:translation"][0], dtype=np.float64)
        cells = np.array(table["VoxelGridMap:voxel_indices"], dtype=np.float64)
        size = np.array(table["VoxelGridMap:voxel_size"][0], dtype=np.float64)
        lo, hi = corner[:2] + size[:2] * cells[:, :2].min(0), corner[:2] + size[:2] * (cells[:, :2].max(0) + 1)
        margin = float(min(contact[0] - lo[0], contact[1] - lo[1], hi[0] - contact[0], hi[1] - contact[1]))
        check("table under the contact (margin >= 10 a)", t, min(margin, 10.0), 10.0, 0.0)
    ok = all(c["ok"] for c in checks)
    print(f"{sum(c['ok'] for c in checks)} of {len(checks)} checks passed (a = {a!r})", file=sys.stderr)
    print(json.dumps({"checks": checks, "ok": ok}))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
