"""A sweep's catalogue from Python (README.md, Sweeps): open it with pandas, pick the runs that toppled,
and read one channel of one of them with the `mcap` package.

    coin-log sweep examples/sweep.toml -o lean-sweep
    python examples/sweep_catalogue.py lean-sweep

Needs pandas and mcap (pip install pandas mcap zstandard).
"""

import json
import sys
from pathlib import Path

import pandas as pd
from mcap.reader import make_reader

folder = Path(sys.argv[1] if len(sys.argv) > 1 else "lean-sweep")
# pandas 3 reads the shortest round-trip numbers back exactly (pandas 2: add float_precision="round_trip").
runs = pd.read_csv(folder / "catalogue.csv")
toppled = runs[runs["termination"] == "flat-landing"].sort_values("initial.theta")
print(f"{len(toppled)} of {len(runs)} runs toppled")
print(toppled[["index", "initial.theta", "t_end"]].to_string(index=False))

if toppled.empty:
    sys.exit(0)  # nothing toppled: no channel to read (a sweep of spinning coins, or too short a duration)

# The lean θ(t) of the run that toppled first, from its /coin/angles channel.
first = toppled.loc[toppled["t_end"].idxmin()]
with open(folder / first["file"], "rb") as f:
    angles = [json.loads(message.data) for _, _, message in make_reader(f).iter_messages(topics=["/coin/angles"])]
print(
    f"run {first['index']} ({first['file']}): {len(angles)} samples of /coin/angles, "
    f"theta from {angles[0]['theta']!r} to {angles[-1]['theta']!r} at t = {angles[-1]['t']!r}"
)
