#!/usr/bin/env python3
"""Lossless rewrite of an MCAP file by the official Python `mcap` writer (foxglove/mcap), in a chosen layout.

usage: .venv/bin/python scripts/readers/rewrite.py IN.mcap OUT.mcap [--compression zstd|lz4|none]
           [--chunk-size BYTES | --unchunked] [--metadata original|first|last] [--no-summary]

Every schema (name, encoding, bytes), channel (topic, message encoding, metadata), message (log time,
publish time, sequence, bytes, in file order) and metadata record (name, entries) of IN is written to OUT
unchanged; only the layout changes, as a user who recompresses or re-chunks a recording with the standard
tools would change it. Ids are renumbered by the writer (1, 2, ... in order of first appearance).

  --compression     chunk compression (default zstd)
  --chunk-size      the writer's chunk size in bytes (default 1 MiB, the writer's own default)
  --unchunked       messages as top-level records, no chunks (and so no chunk or message indexes)
  --metadata        where the metadata records go: `original` (default: at their place among the messages),
                    `first` (all before the first message) or `last` (all after the last message; with small
                    chunks the `coin-log` record then follows the first chunk)
  --no-summary      no summary section at all (no statistics, indexes, repeated schemas or channels): the
                    footer's summary_start is 0, as in a file written by a streaming recorder

IN is read with the package's StreamReader, in file order, CRCs validated. Exits 1 on a read error, 2 on a
usage error.
"""

from __future__ import annotations

import argparse
import sys

from mcap.records import Channel, DataEnd, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, IndexType, Writer

COMPRESSION = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE}


def data_records(path):
    """The records of the data section of `path`, chunks opened, in file order."""
    with open(path, "rb") as stream:
        for record in StreamReader(stream, validate_crcs=True).records:
            if isinstance(record, DataEnd):
                return
            yield record


def rewrite(source, target, compression, chunk_size, chunked, metadata, summary):
    options = dict(chunk_size=chunk_size, compression=COMPRESSION[compression], use_chunking=chunked)
    if not summary:
        options.update(
            index_types=IndexType.NONE,
            repeat_channels=False,
            repeat_schemas=False,
            use_statistics=False,
            use_summary_offsets=False,
        )
    held = []
    if metadata == "first":
        held = [r for r in data_records(source) if isinstance(r, Metadata)]
    with open(target, "wb") as out:
        writer = Writer(out, **options)
        writer.start()
        for record in held:
            writer.add_metadata(record.name, record.metadata)
        held = []
        schemas, channels = {}, {}
        for record in data_records(source):
            if isinstance(record, Schema) and record.id not in schemas:
                schemas[record.id] = writer.register_schema(record.name, record.encoding, record.data)
            elif isinstance(record, Channel) and record.id not in channels:
                channels[record.id] = writer.register_channel(
                    record.topic, record.message_encoding, schemas.get(record.schema_id, 0), record.metadata
                )
            elif isinstance(record, Message):
                writer.add_message(
                    channels[record.channel_id],
                    record.log_time,
                    record.data,
                    record.publish_time,
                    record.sequence,
                )
            elif isinstance(record, Metadata):
                if metadata == "original":
                    writer.add_metadata(record.name, record.metadata)
                elif metadata == "last":
                    held.append(record)
        for record in held:
            writer.add_metadata(record.name, record.metadata)
        writer.finish()


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("source", metavar="IN")
    parser.add_argument("target", metavar="OUT")
    parser.add_argument("--compression", choices=sorted(COMPRESSION), default="zstd")
    layout = parser.add_mutually_exclusive_group()
    layout.add_argument("--chunk-size", type=int, default=1024 * 1024)
    layout.add_argument("--unchunked", action="store_true")
    parser.add_argument("--metadata", choices=["original", "first", "last"], default="original")
    parser.add_argument("--no-summary", action="store_true")
    args = parser.parse_args(argv)
    if args.chunk_size <= 0:
        parser.error("--chunk-size must be > 0")
    try:
        rewrite(
            args.source,
            args.target,
            args.compression,
            args.chunk_size,
            not args.unchunked,
            args.metadata,
            not args.no_summary,
        )
    except Exception as e:  # any reader error: say which file and why
        print(f"rewrite.py: {args.source}: {type(e).__name__}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
