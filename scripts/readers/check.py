#!/usr/bin/env python3
"""Independent reader of coin-log MCAP files with the Python `mcap` package (foxglove/mcap).

usage: .venv/bin/python scripts/readers/check.py FILE.mcap...

For each file: the summary (statistics, chunk indexes) must be present; every message is read twice, through
the chunk indexes (SeekingReader, chunk CRCs validated) and by a linear scan (NonSeekingReader, data-section
CRC validated); each is decoded as UTF-8 JSON and validated with `jsonschema` against schemas/<name>.json
(the foxglove.* files are the published @foxglove/schemas ones; check.mjs proves that), refusing fields a
schema does not declare; message counts must equal the statistics (total and per channel) in both passes;
the stored schema bytes must equal schemas/<name>.json; Foxglove timestamps and coin_log `t` must equal the
log time. Exits 1 on any failure, 2 on a usage error.
"""

from __future__ import annotations

import copy
import json
import sys
from collections import Counter
from pathlib import Path

import jsonschema
from mcap.reader import NonSeekingReader, SeekingReader

SCHEMAS_DIR = Path(__file__).resolve().parent.parent.parent / "schemas"
MAX_REPORTED = 20


def strict(schema):
    """A copy of `schema` in which every object with declared properties refuses undeclared ones."""
    schema = copy.deepcopy(schema)

    def walk(node):
        if isinstance(node, list):
            for item in node:
                walk(item)
        elif isinstance(node, dict):
            for key, value in node.items():
                if key != "const":
                    walk(value)
            if node.get("type") == "object" and "properties" in node:
                node.setdefault("additionalProperties", False)

    walk(schema)
    return schema


def timestamps(schema_name, message):
    if schema_name == "foxglove.FrameTransform":
        return [message["timestamp"]]
    if schema_name == "foxglove.SceneUpdate":
        return [e["timestamp"] for e in message["entities"]]
    return []


class Failures(list):
    def add(self, msg):
        if len(self) < MAX_REPORTED:
            self.append(msg)
        elif len(self) == MAX_REPORTED:
            self.append("(more failures not shown)")


def check_file(path, validators):
    failures = Failures()
    with open(path, "rb") as stream:
        reader = SeekingReader(stream, validate_crcs=True)
        summary = reader.get_summary()
        if summary is None or summary.statistics is None:
            failures.add("no summary with a Statistics record")
            return failures, ""
        stats = summary.statistics
        if not summary.chunk_indexes and stats.message_count > 0:
            failures.add("no chunk indexes in the summary")

        for schema in summary.schemas.values():
            if schema.encoding != "jsonschema":
                failures.add(f"schema {schema.name}: encoding {schema.encoding}, expected jsonschema")
            file = SCHEMAS_DIR / f"{schema.name}.json"
            if not file.exists():
                failures.add(f"schema {schema.name} has no file schemas/{schema.name}.json")
                continue
            repo_bytes = file.read_bytes()
            if schema.data != repo_bytes:
                failures.add(f"schema {schema.name}: stored bytes differ from schemas/{schema.name}.json")
            if schema.name not in validators:
                document = json.loads(repo_bytes)
                if schema.name.startswith("foxglove."):
                    document = strict(document)
                cls = jsonschema.validators.validator_for(document)
                cls.check_schema(document)
                validators[schema.name] = cls(document)
        for channel in summary.channels.values():
            if channel.message_encoding != "json":
                failures.add(f"channel {channel.topic}: message encoding {channel.message_encoding}, expected json")

        counts = Counter()
        total = 0
        for schema, channel, message in reader.iter_messages(log_time_order=True):
            total += 1
            counts[channel.id] += 1
            where = f"{channel.topic} at log time {message.log_time}"
            if message.publish_time != message.log_time:
                failures.add(f"{where}: publish time {message.publish_time} != log time")
            if schema is None or schema.name not in validators:
                failures.add(f"{where}: no usable schema")
                continue
            try:
                decoded = json.loads(message.data.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError) as e:
                failures.add(f"{where}: not UTF-8 JSON ({e})")
                continue
            error = jsonschema.exceptions.best_match(validators[schema.name].iter_errors(decoded))
            if error is not None:
                failures.add(f"{where}: invalid {schema.name}: {error.message} at {list(error.absolute_path)}")
                continue
            if schema.name.startswith("coin_log."):
                expected = round(decoded["t"] * 1e9)
                if expected != message.log_time:
                    failures.add(f"{where}: t = {decoded['t']!r} gives {expected} ns")
            for stamp in timestamps(schema.name, decoded):
                if stamp["sec"] * 1_000_000_000 + stamp["nsec"] != message.log_time:
                    failures.add(f"{where}: timestamp {stamp} != log time")

        if total != stats.message_count:
            failures.add(f"indexed read: {total} messages, statistics say {stats.message_count}")
        for channel_id, channel in summary.channels.items():
            expected = stats.channel_message_counts.get(channel_id, 0)
            if counts[channel_id] != expected:
                failures.add(f"{channel.topic}: indexed read {counts[channel_id]} messages, statistics say {expected}")

        metadata = sum(1 for _ in reader.iter_metadata())
        if metadata != stats.metadata_count:
            failures.add(f"{metadata} metadata records, statistics say {stats.metadata_count}")

    # Second pass: a linear scan of the whole file, validating the data-section CRC.
    with open(path, "rb") as stream:
        linear = Counter(ch.id for _, ch, _ in NonSeekingReader(stream, validate_crcs=True).iter_messages())
    if sum(linear.values()) != stats.message_count:
        failures.add(f"linear read: {sum(linear.values())} messages, statistics say {stats.message_count}")

    compressions = "+".join(sorted({c.compression or "none" for c in summary.chunk_indexes})) or "-"
    per_topic = " ".join(f"{summary.channels[i].topic}={n}" for i, n in sorted(counts.items()))
    text = (
        f"{total} messages in {len(summary.chunk_indexes)} chunks ({compressions}), "
        f"{metadata} metadata; {per_topic}"
    )
    return failures, text


def main(argv):
    files = argv[1:]
    if not files:
        print("usage: check.py FILE.mcap...", file=sys.stderr)
        return 2
    validators = {}
    bad = 0
    for path in files:
        try:
            failures, text = check_file(path, validators)
        except Exception as e:  # noqa: BLE001 - any failure to read is a finding for this file
            failures, text = [f"unreadable: {type(e).__name__}: {e}"], ""
        if failures:
            bad += 1
            print(f"FAIL {path}: {text}")
            for f in failures:
                print(f"     - {f}")
        else:
            print(f"ok   {path}: {text}")
    print(f"check.py: {len(files) - bad} passed, {bad} failed")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
