#!/usr/bin/env python3
"""Independent check of `coin-log export`: every CSV value against the MCAP's messages, bit for bit.

usage: .venv/bin/python scripts/readers/check_export.py FILE.mcap DIR

Reads FILE.mcap with the Python `mcap` package and each `coin_log.*` message with `json` (Python's float
parsing rounds correctly), then DIR/<channel>.csv with `csv` and `float`: the header must be the message's
keys in order, one row per message, and every value must have the same bits (struct.pack('<d')). Prints
`N values equal bit for bit` and exits 0, or prints the first differences and exits 1.
"""

from __future__ import annotations

import csv
import json
import struct
import sys
from collections import defaultdict
from pathlib import Path

from mcap.reader import make_reader


def bits(x: float) -> bytes:
    return struct.pack("<d", x)


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    mcap_path, out = Path(sys.argv[1]), Path(sys.argv[2])
    messages = defaultdict(list)
    with mcap_path.open("rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if schema.name.startswith("coin_log."):
                messages[channel.topic].append(json.loads(message.data))
    compared, problems = 0, []
    for topic, rows in messages.items():
        table = out / (topic.rsplit("/", 1)[1] + ".csv")
        with table.open(newline="") as f:
            reader = csv.reader(f)
            header = next(reader)
            lines = list(reader)
        if header != list(rows[0].keys()):
            problems.append(f"{table}: header {header} is not the message's keys {list(rows[0])}")
        if len(lines) != len(rows):
            problems.append(f"{table}: {len(lines)} rows for {len(rows)} messages")
        for n, (line, row) in enumerate(zip(lines, rows)):
            for name, cell in zip(header, line):
                if bits(float(cell)) != bits(float(row[name])):
                    problems.append(f"{table} row {n + 1} `{name}`: {cell} != {row[name]!r}")
                compared += 1
    if not messages:
        problems.append(f"{mcap_path}: no coin_log channel")
    for p in problems[:20]:
        print(p)
    if problems:
        print(f"{len(problems)} differences")
        return 1
    print(f"{compared} values equal bit for bit")
    return 0


if __name__ == "__main__":
    sys.exit(main())
