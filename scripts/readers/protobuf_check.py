#!/usr/bin/env python3
"""Independent reader of coin-log Protobuf recordings (`record --encoding protobuf`) with the Python `mcap`
package and `mcap-protobuf-support` (its DecoderFactory builds message classes from the FileDescriptorSet a
file stores, with Google's `protobuf` runtime).

usage: .venv/bin/python scripts/readers/protobuf_check.py [--dump DIR] FILE.mcap...

For each file: every schema has encoding `protobuf` and every channel message encoding `protobuf`; every
`coin_log.*` descriptor declares exactly the fields of schemas/<name>.json, in that order, numbered 1, 2, ...,
all `double`; every message is decoded by the DecoderFactory (a message it cannot parse fails the file), with
no field the descriptor does not declare (unknown fields fail too); counts equal the statistics (total and per
channel); Foxglove timestamps and coin_log `t` equal the log time. Prints per topic the message count and, for
the `coin_log.*` topics, the first and last value of each field.

With --dump DIR, writes DIR/<file name>.jsonl: one line per message, in log-time order,
{"topic", "schema", "log_time", "message"}, where "message" has every field of the descriptor (defaults
included): double and float as the 16 hex digits of the IEEE-754 f64 bit pattern (exact, keeps -0.0),
integers and enums as decimal strings, bytes as base64, an unset message field as null. The Node reader
(protobuf_check.mjs) writes the same form, so the two can be compared byte for byte, and the Rust test
compares them with the JSON recording of the same scene.

Exits 1 on any failure, 2 on a usage error.
"""

from __future__ import annotations

import base64
import json
import struct
import sys
from collections import Counter
from pathlib import Path

from google.protobuf import unknown_fields
from google.protobuf.descriptor import FieldDescriptor
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

SCHEMAS_DIR = Path(__file__).resolve().parent.parent.parent / "schemas"
MAX_REPORTED = 20
FLOATS = (FieldDescriptor.TYPE_DOUBLE, FieldDescriptor.TYPE_FLOAT)


class Failures(list):
    def add(self, msg):
        if len(self) < MAX_REPORTED:
            self.append(msg)
        elif len(self) == MAX_REPORTED:
            self.append("(more failures not shown)")


def bits(value: float) -> str:
    """The IEEE-754 binary64 bit pattern of `value`, 16 hex digits."""
    return struct.pack(">d", value).hex()


def scalar(field, value):
    if field.type in FLOATS:
        return bits(value)
    if field.type == FieldDescriptor.TYPE_BOOL:
        return bool(value)
    if field.type == FieldDescriptor.TYPE_STRING:
        return value
    if field.type == FieldDescriptor.TYPE_BYTES:
        return base64.b64encode(value).decode("ascii")
    return str(int(value))  # every integer type and enums


def is_repeated(field) -> bool:
    # protobuf >= 5 has `is_repeated`; `label` is deprecated there.
    flag = getattr(field, "is_repeated", None)
    return flag if isinstance(flag, bool) else field.label == FieldDescriptor.LABEL_REPEATED


def canonical(message, where, failures):
    """Every field of `message` in the dump's form; unknown fields (at any depth) are failures."""
    unknown = unknown_fields.UnknownFieldSet(message)
    if len(unknown):
        numbers = sorted({u.field_number for u in unknown})
        failures.add(f"{where}: {message.DESCRIPTOR.full_name} has fields its descriptor does not declare: {numbers}")
    out = {}
    for field in message.DESCRIPTOR.fields:
        value = getattr(message, field.name)
        if field.type == FieldDescriptor.TYPE_MESSAGE:
            if is_repeated(field):
                out[field.name] = [canonical(v, where, failures) for v in value]
            else:
                out[field.name] = canonical(value, where, failures) if message.HasField(field.name) else None
        elif is_repeated(field):
            out[field.name] = [scalar(field, v) for v in value]
        else:
            out[field.name] = scalar(field, value)
    return out


def check_coin_descriptor(schema, message_class, failures):
    """The descriptor of a coin_log.* type against schemas/<name>.json: same fields, same order, 1..n, double."""
    file = SCHEMAS_DIR / f"{schema.name}.json"
    if not file.exists():
        failures.add(f"schema {schema.name} has no file schemas/{schema.name}.json")
        return
    expected = list(json.loads(file.read_bytes())["properties"])
    declared = [(f.name, f.number, f.type) for f in message_class.DESCRIPTOR.fields]
    wanted = [(name, i + 1, FieldDescriptor.TYPE_DOUBLE) for i, name in enumerate(expected)]
    if declared != wanted:
        failures.add(
            f"schema {schema.name}: descriptor declares (name, number, type) {declared}, "
            f"schemas/{schema.name}.json implies {wanted}"
        )


def stamp_ns(stamp) -> int:
    return stamp.seconds * 1_000_000_000 + stamp.nanos


def timestamps(schema_name, message):
    if schema_name == "foxglove.FrameTransform":
        return [message.timestamp]
    if schema_name == "foxglove.SceneUpdate":
        return [e.timestamp for e in message.entities]
    return []


def check_file(path, dump_dir):
    failures = Failures()
    factory = DecoderFactory()
    dump = None
    if dump_dir is not None:
        dump = open(Path(dump_dir) / f"{Path(path).name}.jsonl", "w", encoding="utf-8")
    try:
        with open(path, "rb") as stream:
            reader = make_reader(stream, validate_crcs=True, decoder_factories=[factory])
            summary = reader.get_summary()
            if summary is None or summary.statistics is None:
                failures.add("no summary with a Statistics record")
                return failures, ""
            stats = summary.statistics
            decoders = {}
            for schema in summary.schemas.values():
                if schema.encoding != "protobuf":
                    failures.add(f"schema {schema.name}: encoding {schema.encoding!r}, expected 'protobuf'")
            for channel in summary.channels.values():
                if channel.message_encoding != "protobuf":
                    failures.add(
                        f"channel {channel.topic}: message encoding {channel.message_encoding!r}, expected 'protobuf'"
                    )
                    continue
                schema = summary.schemas.get(channel.schema_id)
                if schema is None:
                    failures.add(f"channel {channel.topic}: schema id {channel.schema_id} not in the file")
                    continue
                try:
                    decoder = factory.decoder_for(channel.message_encoding, schema)
                    if decoder is None:
                        raise ValueError("no decoder for it")
                    if schema.name.startswith("coin_log."):
                        check_coin_descriptor(schema, type(decoder(b"")), failures)
                except Exception as e:  # noqa: BLE001 - a descriptor the runtime refuses is a finding
                    failures.add(f"schema {schema.name}: the descriptor cannot be used: {type(e).__name__}: {e}")
                    continue
                decoders[channel.id] = (schema.name, decoder)

            counts = Counter()
            firsts, lasts = {}, {}
            total = 0
            for schema, channel, message in reader.iter_messages(log_time_order=True):
                total += 1
                counts[channel.id] += 1
                where = f"{channel.topic} at log time {message.log_time}"
                if message.publish_time != message.log_time:
                    failures.add(f"{where}: publish time {message.publish_time} != log time")
                if channel.id not in decoders:
                    continue
                name, decoder = decoders[channel.id]
                try:
                    decoded = decoder(message.data)
                except Exception as e:  # noqa: BLE001 - a message the runtime cannot parse is a finding
                    failures.add(f"{where}: {name} does not decode: {type(e).__name__}: {e}")
                    continue
                value = canonical(decoded, where, failures)
                if name.startswith("coin_log."):
                    expected = round(decoded.t * 1e9)
                    if expected != message.log_time:
                        failures.add(f"{where}: t = {decoded.t!r} gives {expected} ns")
                    numbers = {f.name: getattr(decoded, f.name) for f in decoded.DESCRIPTOR.fields}
                    firsts.setdefault(channel.id, numbers)
                    lasts[channel.id] = numbers
                for stamp in timestamps(name, decoded):
                    if stamp_ns(stamp) != message.log_time:
                        failures.add(f"{where}: timestamp {stamp.seconds}.{stamp.nanos:09d} != log time")
                if dump is not None:
                    line = {"topic": channel.topic, "schema": name, "log_time": str(message.log_time), "message": value}
                    dump.write(json.dumps(line, separators=(",", ":"), ensure_ascii=False) + "\n")

            if total != stats.message_count:
                failures.add(f"read {total} messages, statistics say {stats.message_count}")
            for channel_id, channel in summary.channels.items():
                expected = stats.channel_message_counts.get(channel_id, 0)
                if counts[channel_id] != expected:
                    failures.add(f"{channel.topic}: read {counts[channel_id]} messages, statistics say {expected}")
    finally:
        if dump is not None:
            dump.close()

    lines = [f"{total} messages decoded"]
    for channel_id, channel in sorted(summary.channels.items(), key=lambda kv: kv[1].topic):
        line = f"  {channel.topic} ({decoders.get(channel_id, ('?',))[0]}): {counts[channel_id]}"
        if channel_id in firsts:
            first, last = firsts[channel_id], lasts[channel_id]
            line += "; " + ", ".join(f"{k} {first[k]!r} .. {last[k]!r}" for k in first)
        lines.append(line)
    return failures, "\n".join(lines)


def main(argv):
    args = argv[1:]
    dump_dir = None
    if len(args) >= 2 and args[0] == "--dump":
        dump_dir, args = args[1], args[2:]
    if not args or any(a.startswith("--") for a in args):
        print("usage: protobuf_check.py [--dump DIR] FILE.mcap...", file=sys.stderr)
        return 2
    bad = 0
    for path in args:
        try:
            failures, text = check_file(path, dump_dir)
        except Exception as e:  # noqa: BLE001 - any failure to read is a finding for this file
            failures, text = [f"unreadable: {type(e).__name__}: {e}"], ""
        if failures:
            bad += 1
            print(f"FAIL {path}: {text}")
            for f in failures:
                print(f"     - {f}")
        else:
            print(f"ok   {path}: {text}")
    print(f"protobuf_check.py: {len(args) - bad} passed, {bad} failed")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
