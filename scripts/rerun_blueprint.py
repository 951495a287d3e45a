#!/usr/bin/env python3
"""Writes a Rerun blueprint (.rbl) for coin-log's Protobuf recordings with the `rerun` channel
(`coin-log record --encoding protobuf --rerun`): a 3D view with the coin (the URDF `coin_shape`, solid),
the table (/rerun/table) and the whole contact track (/rerun/track from t = 0 to the time cursor), seen
from `world` with the camera following the coin, beside time-series plots of ω, θ, E and N taken from the
`coin_log.*` messages.

usage: .venv/bin/python scripts/rerun_blueprint.py OUT.rbl [--play=following|playing|paused]

Rerun decodes a `coin_log.*` message by Protobuf reflection into one struct component per topic
(`coin_log.Energy:message` on /coin/energy, ...), which a time-series view does not plot by itself; this
blueprint maps each plotted field onto a `SeriesLines` visualizer with a component mapping (source component
and a `.field` selector; Rerun marks component mappings experimental). Rerun shows a point cloud only at its
own time, so the track's entity gets a visible time range from -inf to the cursor. A blueprint applies to the
recordings of its application id, `coin-log`:

    rerun mcap convert wobble.mcap -d foxglove -d protobuf -d urdf --timeline-type duration \
        --application-id coin-log -n '^/tf_static$' -o wobble.rrd
    rerun wobble.rrd coin-log.rbl

`--play=following` opens at the latest time (the screenshot in docs/ is taken so). Every plotted field is
checked against schemas/<name>.json first (exit 1 if one is missing there). Needs rerun-sdk (pinned in
scripts/requirements.txt; written with 0.41.0).
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


def scene_view():
    """The coin, table and track in `world`, in display units (lengths / a), as Rerun draws the `rerun` channel."""
    timelines = ("message_log_time", "message_publish_time", "timestamp")
    since_start = rrb.VisibleTimeRanges(
        [
            rrb.VisibleTimeRange(t, start=rrb.TimeRangeBoundary.infinite(), end=rrb.TimeRangeBoundary.cursor_relative())
            for t in timelines
        ]
    )
    coin = "/coin_shape/visual_geometries/coin_body"
    # The URDF's shapes come without a fill mode, which Rerun draws as wireframes: make them solid.
    solid = {f"{coin}/disc": [rr.Cylinders3D.from_fields(fill_mode="solid").visualizer()]}
    for mark in ("mark_top", "mark_bottom"):
        solid[f"{coin}/{mark}"] = [rr.Boxes3D.from_fields(fill_mode="solid").visualizer()]
    return rrb.Spatial3DView(
        origin="/",
        name="coin, table and track (/rerun)",
        contents=["+ /coin_shape/**", "+ /rerun/table", "+ /rerun/track"],
        overrides={"/rerun/track": [since_start, rr.Points3D.from_fields(radii=-2.5).visualizer()], **solid},
        spatial_information=rrb.archetypes.SpatialInformation(target_frame="world", show_axes=False),
        eye_controls=rrb.archetypes.EyeControls3D(
            position=(-3.0, -5.5, 3.0), look_target=(0.0, 0.0, 0.3), eye_up=(0.0, 0.0, 1.0), tracking_entity=f"{coin}/disc"
        ),
        line_grid=rrb.archetypes.LineGrid3D(visible=False),
    )


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--play=")]
    play = next((a.split("=", 1)[1] for a in argv[1:] if a.startswith("--play=")), None)
    if len(args) != 1 or play not in (None, "following", "playing", "paused"):
        print("usage: rerun_blueprint.py OUT.rbl [--play=following|playing|paused]", file=sys.stderr)
        return 2
    panel = rrb.TimePanel(state="collapsed", timeline="message_log_time", play_state=play) if play else None
    blueprint = rrb.Blueprint(
        rrb.Horizontal(scene_view(), rrb.Vertical(*(plot(*p) for p in PLOTS)), column_shares=[2, 1]),
        *([panel] if panel else []),
        collapse_panels=True,
    )
    blueprint.save(APPLICATION_ID, args[0])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
