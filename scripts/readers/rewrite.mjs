#!/usr/bin/env node
// Lossless rewrite of an MCAP file by @mcap/core's McapWriter (the TypeScript writer of the MCAP project),
// in a chosen layout.
//
// usage: node scripts/readers/rewrite.mjs IN.mcap OUT.mcap [--compression zstd|none]
//            [--chunk-size BYTES | --unchunked] [--metadata original|first|last]
//
// Every schema (name, encoding, bytes), channel (topic, message encoding, metadata), message (log time,
// publish time, sequence, bytes, in file order) and metadata record (name, entries) of IN is written to OUT
// unchanged; only the layout changes. Ids are the writer's own (channels from 0, schemas from 1).
//
//   --compression  chunk compression (default zstd, through @foxglove/wasm-zstd; lz4 is read but not
//                  written: @foxglove/wasm-lz4 only decompresses)
//   --chunk-size   the writer's chunk size in bytes (default 1 MiB, the writer's own default)
//   --unchunked    messages as top-level records, no chunks
//   --metadata     where the metadata records go: `original` (default: at their place among the messages),
//                  `first` (all before the first message) or `last` (all after the last message)
//
// IN is read with McapStreamReader in file order, chunk CRCs validated. Exits 1 on a read error, 2 on a
// usage error.

import { McapStreamReader, McapWriter } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import { open } from "node:fs/promises";
import { createReadStream } from "node:fs";

const USAGE =
  "usage: rewrite.mjs IN.mcap OUT.mcap [--compression zstd|none] [--chunk-size BYTES | --unchunked] " +
  "[--metadata original|first|last]";

function usage(message) {
  console.error(`rewrite.mjs: ${message}\n${USAGE}`);
  process.exit(2);
}

function parseArgs(argv) {
  const options = { compression: "zstd", chunkSize: 1024 * 1024, chunked: true, metadata: "original" };
  const files = [];
  for (let i = 0; i < argv.length; i++) {
    const arg = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) usage(`${arg} needs a value`);
      return argv[++i];
    };
    if (arg === "--compression") {
      options.compression = value();
      if (!["zstd", "none"].includes(options.compression)) usage(`unknown compression ${options.compression}`);
    } else if (arg === "--chunk-size") {
      options.chunkSize = Number(value());
      if (!Number.isInteger(options.chunkSize) || options.chunkSize <= 0) usage("--chunk-size must be > 0");
    } else if (arg === "--unchunked") {
      options.chunked = false;
    } else if (arg === "--metadata") {
      options.metadata = value();
      if (!["original", "first", "last"].includes(options.metadata)) usage(`unknown --metadata ${options.metadata}`);
    } else if (arg.startsWith("--")) {
      usage(`unknown option ${arg}`);
    } else {
      files.push(arg);
    }
  }
  if (files.length !== 2) usage("give IN and OUT");
  return { source: files[0], target: files[1], ...options };
}

/** The records of the data section of `path`, chunks opened, in file order. */
async function* dataRecords(path) {
  const reader = new McapStreamReader({
    validateCrcs: true,
    decompressHandlers: {
      zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
      lz4: (buffer, size) => lz4(buffer, Number(size)),
    },
  });
  for await (const data of createReadStream(path)) {
    reader.append(data);
    for (let record; (record = reader.nextRecord()); ) {
      if (record.type === "DataEnd") return;
      yield record;
    }
  }
  if (!reader.done()) throw new Error("the file ends before its DataEnd record");
}

class FileWritable {
  constructor(handle) {
    this.handle = handle;
    this.offset = 0n;
  }
  async write(buffer) {
    await this.handle.write(buffer);
    this.offset += BigInt(buffer.byteLength);
  }
  position() {
    return this.offset;
  }
}

async function rewrite({ source, target, compression, chunkSize, chunked, metadata }) {
  await Promise.all([zstd.isLoaded, lz4.isLoaded]);
  const held = [];
  if (metadata === "first") {
    for await (const r of dataRecords(source)) if (r.type === "Metadata") held.push(r);
  }
  const handle = await open(target, "w");
  try {
    const writer = new McapWriter({
      writable: new FileWritable(handle),
      useChunks: chunked,
      chunkSize,
      compressChunk:
        compression === "zstd"
          ? (data) => ({ compression: "zstd", compressedData: zstd.compress(data) })
          : undefined,
    });
    await writer.start({ profile: "", library: "mcap-typescript rewrite.mjs" });
    const add = (r) => writer.addMetadata({ name: r.name, metadata: r.metadata });
    for (const r of held.splice(0)) await add(r);
    const schemas = new Map();
    const channels = new Map();
    for await (const r of dataRecords(source)) {
      if (r.type === "Schema" && !schemas.has(r.id)) {
        schemas.set(r.id, await writer.registerSchema({ name: r.name, encoding: r.encoding, data: r.data }));
      } else if (r.type === "Channel" && !channels.has(r.id)) {
        const channel = {
          topic: r.topic,
          messageEncoding: r.messageEncoding,
          schemaId: r.schemaId === 0 ? 0 : schemas.get(r.schemaId),
          metadata: r.metadata,
        };
        channels.set(r.id, await writer.registerChannel(channel));
      } else if (r.type === "Message") {
        await writer.addMessage({
          channelId: channels.get(r.channelId),
          sequence: r.sequence,
          logTime: r.logTime,
          publishTime: r.publishTime,
          data: r.data,
        });
      } else if (r.type === "Metadata") {
        if (metadata === "original") await add(r);
        else if (metadata === "last") held.push(r);
      }
    }
    for (const r of held) await add(r);
    await writer.end();
  } finally {
    await handle.close();
  }
}

const options = parseArgs(process.argv.slice(2));
try {
  await rewrite(options);
} catch (e) {
  console.error(`rewrite.mjs: ${options.source}: ${e.message ?? e}`);
  process.exit(1);
}
