#!/usr/bin/env python3
"""Writes a Rerun blueprint (.rbl) for coin-log's Protobuf recordings: a 3D view with the transform axes of
the frames on /tf, and time-series plots of ω, θ, E and N taken from the `coin_log.*` messages.

usage: .venv/bin/python scripts/rerun_blueprint.py OUT.rbl

Rerun decodes a `coin_log.*` message by Protobuf reflection into one struct component per topic
(`coin_log.Energy:message` on /coin/energy, ...), which a time-series view does not plot by itself; this
blueprint maps each plotted field onto a `SeriesLines` visualizer with a component mapping (source component
and a `.field` selector; Rerun marks component mappings experimental). A blueprint applies to the recordings
of its application id, `coin-log`:

    rerun mcap convert wobble.mcap --timeline-type duration --application-id coin-log -n '^/tf_static$' -o wobble.rrd
    rerun wobble.rrd coin-log.rbl

Every plotted field is checked against schemas/<name>.json first (exit 1 if one is missing there).
Needs rerun-sdk (pinned in scripts/requirements.txt; written with 0.41.0).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import rerun as rr
import rerun.blueprint as rrb
from rerun.blueprint.encodings import ComponentSourceKind, VisualizerComponentMapping

SCHEMAS_DIR = Path(__file__).resolve().parent.parent / "schemas"
APPLICATION_ID = "coin-log"

# (title, topic, schema, fields): the plots of datasets/foxglove-layout.json.
PLOTS = [
    ("ω (lean frame)", "/coin/omega", "coin_log.AngularVelocity", ["x", "y", "z"]),
    ("θ", "/coin/angles", "coin_log.Angles", ["theta"]),
    ("E", "/coin/energy", "coin_log.Energy", ["total", "kinetic", "potential"]),
    ("N", "/coin/reaction", "coin_log.Reaction", ["normal"]),
]


def plot(title, topic, schema, fields):
    declared = json.loads((SCHEMAS_DIR / f"{schema}.json").read_text(encoding="utf-8"))["properties"]
    missing = [f for f in fields if f not in declared]
    if missing:
        raise SystemExit(f"rerun_blueprint.py: {schema} has no field {missing} (schemas/{schema}.json)")
    lines = [
        rr.SeriesLines(names=[field]).visualizer(
            mappings=[
                VisualizerComponentMapping(
                    target="Scalars:scalars",
                    source_kind=ComponentSourceKind.SourceComponent,
                    source_component=f"{schema}:message",
                    selector=f".{field}",
                )
            ]
        )
        for field in fields
    ]
    return rrb.TimeSeriesView(origin=topic, name=title, overrides={topic: lines})


def main(argv):
    if len(argv) != 2:
        print("usage: rerun_blueprint.py OUT.rbl", file=sys.stderr)
        return 2
    frames = rrb.Spatial3DView(
        origin="/",
        name="frames (/tf)",
        overrides={"/tf": [rr.TransformAxes3D(axis_length=1.0, show_frame=True).visualizer()]},
        spatial_information=rrb.archetypes.SpatialInformation(target_frame="world", show_axes=True),
        eye_controls=rrb.archetypes.EyeControls3D(position=(6.0, -8.0, 5.0), look_target=(0.0, 0.0, 0.5)),
    )
    blueprint = rrb.Blueprint(
        rrb.Horizontal(frames, rrb.Vertical(*(plot(*p) for p in PLOTS))),
        collapse_panels=True,
    )
    blueprint.save(APPLICATION_ID, argv[1])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
