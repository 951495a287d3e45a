#!/usr/bin/env python3
"""Opens a coin-log Protobuf recording with Rerun's own tooling and prints what Rerun made of it.

usage: .venv/bin/python scripts/readers/rerun_check.py FILE.mcap OUT.rrd

1. `rerun mcap check --full FILE.mcap` (Rerun's structure and timeline check, payloads decoded);
   `rerun mcap convert FILE.mcap --timeline-type duration -o OUT.rrd` (the CLI of the `rerun-sdk` package,
   from this venv): Rerun's MCAP importer with all its decoders, as the viewer runs it when it opens the
   .mcap; `--timeline-type duration` because coin-log's log times are simulation time from t = 0, not Unix
   time; then `rerun rrd verify OUT.rrd` (every column deserializes as its Rerun type).
2. Reads OUT.rrd back with the SDK (`rerun.chunk.RrdReader`) and prints one JSON document on stdout:
   - "rerun": the rerun-sdk version; "command": the conversion command;
   - "entities": {entity path: [component, ...]} for every entity with time-indexed data, and
     "timelines": {entity path: [timeline, ...]};
   - "transforms": {entity path: [{"log_time", "parent", "child", "translation", "quaternion"}, ...]}: every
     row of a `Transform3D` (Rerun stores them as 32-bit floats: printed as the exact decimal of that f32);
   - "messages": {entity path: [{"log_time", "fields": {name: 16 hex digits of the f64}}, ...]}: every row of
     a `<schema>:message` component whose fields are all numbers (the coin_log.* channels, decoded by
     Rerun's Protobuf reflection).
A summary goes to stderr. Exits 1 if the conversion or the reading fails, 2 on a usage error.
"""

from __future__ import annotations

import json
import struct
import subprocess
import sys
from pathlib import Path

import pyarrow as pa
import rerun as rr


def bits(value: float) -> str:
    return struct.pack(">d", value).hex()


def log_time_ns(batch: pa.RecordBatch) -> list[int]:
    return batch.column("message_log_time").cast(pa.int64()).to_pylist()


def main(argv):
    if len(argv) != 3:
        print("usage: rerun_check.py FILE.mcap OUT.rrd", file=sys.stderr)
        return 2
    mcap, rrd = argv[1], argv[2]
    cli = str(Path(sys.executable).parent / "rerun")
    command = [cli, "mcap", "convert", mcap, "--timeline-type", "duration", "-o", rrd]
    for step in ([cli, "mcap", "check", "--full", mcap], command, [cli, "rrd", "verify", rrd]):
        done = subprocess.run(step, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            shown = " ".join(["rerun", *step[1:]])
            print(f"rerun_check.py: `{shown}` failed ({done.returncode}):\n{done.stdout}{done.stderr}", file=sys.stderr)
            return 1

    entities, timelines, transforms, messages = {}, {}, {}, {}
    for chunk in rr.chunk.RrdReader(rrd).stream():
        if chunk.is_static:
            continue
        path = chunk.entity_path
        batch = chunk.to_record_batch()
        names = [n for n in batch.schema.names if ":" in n]
        entities.setdefault(path, set()).update(names)
        timelines.setdefault(path, set()).update(chunk.timeline_names)
        if "Transform3D:translation" in names or "Transform3D:quaternion" in names:
            rows = transforms.setdefault(path, [])
            columns = {n: batch.column(n).to_pylist() for n in names if n.startswith("Transform3D:")}
            for i, t in enumerate(log_time_ns(batch)):

                def first(name, i=i, columns=columns):
                    cell = columns.get(name, [None] * (i + 1))[i]
                    return cell[0] if cell else None

                rows.append(
                    {
                        "log_time": str(t),
                        "parent": first("Transform3D:parent_frame"),
                        "child": first("Transform3D:child_frame"),
                        "translation": first("Transform3D:translation"),
                        "quaternion": first("Transform3D:quaternion"),
                    }
                )
        for name in names:
            if not name.endswith(":message"):
                continue
            column = batch.column(name)
            item = column.type.value_type if pa.types.is_list(column.type) else None
            if item is None or not pa.types.is_struct(item):
                continue
            if not all(pa.types.is_floating(item.field(k).type) for k in range(item.num_fields)):
                continue  # not a flat message of numbers (e.g. a foxglove.SceneUpdate)
            rows = messages.setdefault(path, [])
            for t, cell in zip(log_time_ns(batch), column.to_pylist()):
                for value in cell or []:
                    rows.append({"log_time": str(t), "fields": {k: bits(v) for k, v in value.items()}})

    for rows in list(transforms.values()) + list(messages.values()):
        rows.sort(key=lambda r: int(r["log_time"]))
    document = {
        "rerun": rr.__version__,
        "command": ["rerun", *command[1:]],
        "entities": {p: sorted(c) for p, c in sorted(entities.items())},
        "timelines": {p: sorted(t) for p, t in sorted(timelines.items())},
        "transforms": transforms,
        "messages": messages,
    }
    json.dump(document, sys.stdout, separators=(",", ":"))
    print()
    for path, components in document["entities"].items():
        extra = ""
        if path in transforms:
            extra = f" ({len(transforms[path])} transforms)"
        elif path in messages:
            extra = f" ({len(messages[path])} rows of numbers)"
        print(f"{path}: {', '.join(components)}{extra}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
