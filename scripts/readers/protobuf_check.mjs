#!/usr/bin/env node
// Independent reader of coin-log Protobuf recordings (`record --encoding protobuf`), the way Foxglove's app
// reads them: @mcap/core's McapIndexedReader, and protobufjs building the message types from the
// FileDescriptorSet a file stores (`Root.fromDescriptor` of protobufjs/ext/descriptor).
//
// usage: node scripts/readers/protobuf_check.mjs [--dump DIR] FILE.mcap...
//
// For each file: every schema has encoding `protobuf` and every channel message encoding `protobuf`; every
// coin_log.* descriptor declares exactly the fields of schemas/<name>.json, in that order, numbered 1, 2, ...,
// all `double`; every foxglove.* message type in a stored descriptor is the one Foxglove publishes (fields,
// numbers, types, labels and enum values equal to the .proto that @foxglove/schemas generates); every message
// is decoded through the indexes with CRCs validated (a message protobufjs cannot parse fails the file);
// counts equal the statistics (total and per channel); Foxglove timestamps and coin_log `t` equal the log time.
// Prints per topic the message count and, for the coin_log.* topics, the first and last value of each field.
//
// With --dump DIR, writes DIR/<file name>.node.jsonl in the form protobuf_check.py writes (see there): one
// line per message, every field of the descriptor, doubles as 16 hex digits of their bit pattern.
// Exits 1 on any failure, 2 on a usage error.

import { McapIndexedReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import protobuf from "protobufjs";
import descriptor from "protobufjs/ext/descriptor/index.js";
import { open, readFile, writeFile } from "node:fs/promises";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { createRequire } from "node:module";

const foxgloveInternal = createRequire(import.meta.url)("@foxglove/schemas/internal");
const here = path.dirname(fileURLToPath(import.meta.url));
const schemasDir = path.resolve(here, "..", "..", "schemas");
const MAX_REPORTED = 20;
const INTEGERS = new Set(["int32", "uint32", "sint32", "fixed32", "sfixed32", "int64", "uint64", "sint64", "fixed64", "sfixed64"]);

class FileReadable {
  constructor(handle, size) {
    this.handle = handle;
    this.fileSize = size;
  }
  async size() {
    return BigInt(this.fileSize);
  }
  async read(offset, size) {
    const buffer = new Uint8Array(Number(size));
    const { bytesRead } = await this.handle.read(buffer, 0, Number(size), Number(offset));
    if (bytesRead !== Number(size)) throw new Error(`short read at ${offset}: ${bytesRead} of ${size} bytes`);
    return buffer;
  }
}

/** The IEEE-754 binary64 bit pattern of `value`, 16 hex digits. */
const view = new DataView(new ArrayBuffer(8));
function bits(value) {
  view.setFloat64(0, value);
  return (view.getUint32(0).toString(16).padStart(8, "0") + view.getUint32(4).toString(16).padStart(8, "0"));
}

function scalar(field, value) {
  if (field.resolvedType instanceof protobuf.Enum) return String(value);
  if (field.type === "double" || field.type === "float") return bits(value);
  if (field.type === "bool") return Boolean(value);
  if (field.type === "string") return value;
  if (field.type === "bytes") return Buffer.from(value).toString("base64");
  if (INTEGERS.has(field.type)) return value.toString(); // number or Long
  throw new Error(`field ${field.fullName}: type ${field.type} not handled`);
}

/** Every field of `message` (of type `type`) in the dump's form. */
function canonical(type, message) {
  const out = {};
  for (const field of type.fieldsArray) {
    if (field.map) throw new Error(`field ${field.fullName}: map fields not handled`);
    const value = message[field.name];
    if (field.resolvedType instanceof protobuf.Type) {
      if (field.repeated) out[field.name] = value.map((v) => canonical(field.resolvedType, v));
      else out[field.name] = value == null ? null : canonical(field.resolvedType, value);
    } else if (field.repeated) {
      out[field.name] = value.map((v) => scalar(field, v));
    } else {
      out[field.name] = scalar(field, value);
    }
  }
  return out;
}

/** A field as (name, number, label, type), the type by its full name once resolved. */
function fieldShape(field) {
  const type = field.resolvedType ? field.resolvedType.fullName.replace(/^\./, "") : field.type;
  return `${field.name}=${field.id} ${field.repeated ? "repeated " : ""}${type}`;
}

function typeShape(type) {
  const fields = type.fieldsArray.map(fieldShape);
  const enums = type.nestedArray
    .filter((n) => n instanceof protobuf.Enum)
    .map((e) => `enum ${e.name} {${Object.entries(e.values).map(([k, v]) => `${k}=${v}`).join(", ")}}`);
  return [...fields, ...enums].join("; ");
}

/** The foxglove.* message types as Foxglove publishes them: the .proto text @foxglove/schemas generates. */
function publishedFoxglove() {
  const { foxgloveMessageSchemas, foxgloveEnumSchemas, generateProto } = foxgloveInternal;
  const root = new protobuf.Root();
  for (const file of ["google/protobuf/timestamp.proto", "google/protobuf/duration.proto"]) {
    root.addJSON(protobuf.common.get(file).nested);
  }
  for (const schema of Object.values(foxgloveMessageSchemas)) {
    const enums = Object.values(foxgloveEnumSchemas).filter((e) => e.parentSchemaName === schema.name);
    protobuf.parse(generateProto(schema, enums), root, { keepCase: true });
  }
  return root.resolveAll();
}

/** Every message type declared in a namespace, recursively. */
function* messageTypes(namespace) {
  for (const nested of namespace.nestedArray) {
    if (nested instanceof protobuf.Type) yield nested;
    if (nested.nestedArray) yield* messageTypes(nested);
  }
}

function timeNs(stamp) {
  return BigInt(stamp.seconds.toString()) * 1_000_000_000n + BigInt(stamp.nanos);
}

function foxgloveTimestamps(schemaName, message) {
  const zero = { seconds: 0, nanos: 0 };
  if (schemaName === "foxglove.FrameTransform") return [message.timestamp ?? zero];
  if (schemaName === "foxglove.SceneUpdate") return message.entities.map((e) => e.timestamp ?? zero);
  return [];
}

async function checkFile(file, published, roots, dumpDir) {
  const failures = [];
  const fail = (msg) => {
    if (failures.length < MAX_REPORTED) failures.push(msg);
    else if (failures.length === MAX_REPORTED) failures.push("(more failures not shown)");
  };
  const dump = [];
  const handle = await open(file, "r");
  try {
    const { size } = await handle.stat();
    const reader = await McapIndexedReader.Initialize({
      readable: new FileReadable(handle, size),
      decompressHandlers: {
        zstd: (buffer, decompressedSize) => zstd.decompress(buffer, Number(decompressedSize)),
        lz4: (buffer, decompressedSize) => lz4(buffer, Number(decompressedSize)),
      },
    });
    const stats = reader.statistics;
    if (!stats) {
      fail("no Statistics record in the summary");
      return { failures, summary: "" };
    }

    // A message type per channel, built from the stored FileDescriptorSet.
    const channelInfo = new Map();
    for (const [id, channel] of reader.channelsById) {
      const schema = reader.schemasById.get(channel.schemaId);
      if (!schema) {
        fail(`channel ${channel.topic}: schema id ${channel.schemaId} not in the file`);
        continue;
      }
      if (schema.encoding !== "protobuf") fail(`schema ${schema.name}: encoding '${schema.encoding}', expected 'protobuf'`);
      if (channel.messageEncoding !== "protobuf") {
        fail(`channel ${channel.topic}: message encoding '${channel.messageEncoding}', expected 'protobuf'`);
        continue;
      }
      let type;
      try {
        // One root per distinct descriptor (protobufjs generates code for every type of a root).
        const key = `${schema.name}\n${Buffer.from(schema.data).toString("base64")}`;
        let root = roots.get(key);
        if (root === undefined) {
          root = protobuf.Root.fromDescriptor(descriptor.FileDescriptorSet.decode(schema.data), { keepCase: true });
          roots.set(key, root);
        }
        type = root.lookupType(schema.name);
        for (const t of messageTypes(root)) {
          const name = t.fullName.replace(/^\./, "");
          if (!name.startsWith("foxglove.")) continue;
          const want = published.lookup(name);
          if (!(want instanceof protobuf.Type)) fail(`schema ${schema.name}: ${name} is not a type Foxglove publishes`);
          else if (typeShape(t) !== typeShape(want)) {
            fail(`schema ${schema.name}: ${name} is {${typeShape(t)}}, Foxglove publishes {${typeShape(want)}}`);
          }
        }
      } catch (e) {
        fail(`schema ${schema.name}: the descriptor cannot be used: ${e.message}`);
        continue;
      }
      if (schema.name.startsWith("coin_log.")) {
        let properties;
        try {
          properties = Object.keys(JSON.parse(await readFile(path.join(schemasDir, `${schema.name}.json`), "utf8")).properties);
        } catch {
          fail(`schema ${schema.name} has no file schemas/${schema.name}.json`);
          continue;
        }
        const declared = type.fieldsArray.map(fieldShape).join("; ");
        const wanted = properties.map((p, i) => `${p}=${i + 1} double`).join("; ");
        if (declared !== wanted) fail(`schema ${schema.name}: descriptor declares {${declared}}, schemas/${schema.name}.json implies {${wanted}}`);
      }
      channelInfo.set(id, { topic: channel.topic, schemaName: schema.name, type, count: 0n, first: null, last: null });
    }

    let total = 0n;
    const counted = new Map();
    for await (const record of reader.readMessages({ validateCrcs: true })) {
      total++;
      counted.set(record.channelId, (counted.get(record.channelId) ?? 0n) + 1n);
      const info = channelInfo.get(record.channelId);
      if (!info) continue;
      info.count++;
      const where = `${info.topic} at log time ${record.logTime}`;
      if (record.publishTime !== record.logTime) fail(`${where}: publish time ${record.publishTime} != log time`);
      let message;
      try {
        message = info.type.decode(record.data);
      } catch (e) {
        fail(`${where}: ${info.schemaName} does not decode: ${e.message}`);
        continue;
      }
      const value = canonical(info.type, message);
      if (info.schemaName.startsWith("coin_log.")) {
        const expected = BigInt(Math.round(message.t * 1e9));
        if (expected !== record.logTime) fail(`${where}: t = ${message.t} gives ${expected} ns`);
        const numbers = Object.fromEntries(info.type.fieldsArray.map((f) => [f.name, message[f.name]]));
        info.first ??= numbers;
        info.last = numbers;
      }
      for (const stamp of foxgloveTimestamps(info.schemaName, message)) {
        if (timeNs(stamp) !== record.logTime) fail(`${where}: timestamp ${stamp.seconds}.${stamp.nanos} != log time`);
      }
      if (dumpDir !== null) {
        dump.push(JSON.stringify({ topic: info.topic, schema: info.schemaName, log_time: record.logTime.toString(), message: value }));
      }
    }

    if (total !== stats.messageCount) fail(`read ${total} messages, statistics say ${stats.messageCount}`);
    for (const [id, channel] of reader.channelsById) {
      const expected = stats.channelMessageCounts.get(id) ?? 0n;
      const got = counted.get(id) ?? 0n;
      if (got !== expected) fail(`${channel.topic}: read ${got} messages, statistics say ${expected}`);
    }
    if (dumpDir !== null) {
      await writeFile(path.join(dumpDir, `${path.basename(file)}.node.jsonl`), dump.map((l) => `${l}\n`).join(""));
    }
    const lines = [`${total} messages decoded`];
    for (const info of [...channelInfo.values()].sort((a, b) => (a.topic < b.topic ? -1 : 1))) {
      let line = `  ${info.topic} (${info.schemaName}): ${info.count}`;
      if (info.first) line += "; " + Object.keys(info.first).map((k) => `${k} ${info.first[k]} .. ${info.last[k]}`).join(", ");
      lines.push(line);
    }
    return { failures, summary: lines.join("\n") };
  } finally {
    await handle.close();
  }
}

async function main() {
  let args = process.argv.slice(2);
  let dumpDir = null;
  if (args.length >= 2 && args[0] === "--dump") {
    dumpDir = args[1];
    args = args.slice(2);
  }
  if (args.length === 0 || args.some((a) => a.startsWith("--"))) {
    console.error("usage: node scripts/readers/protobuf_check.mjs [--dump DIR] FILE.mcap...");
    process.exit(2);
  }
  await zstd.isLoaded;
  await lz4.isLoaded;
  const published = publishedFoxglove();
  const roots = new Map();
  let bad = 0;
  for (const file of args) {
    let result;
    try {
      result = await checkFile(file, published, roots, dumpDir);
    } catch (e) {
      result = { failures: [`unreadable: ${e.message}`], summary: "" };
    }
    if (result.failures.length === 0) {
      console.log(`ok   ${file}: ${result.summary}`);
    } else {
      bad++;
      console.log(`FAIL ${file}: ${result.summary}`);
      for (const f of result.failures) console.log(`     - ${f}`);
    }
  }
  console.log(`protobuf_check.mjs: ${args.length - bad} passed, ${bad} failed`);
  process.exit(bad === 0 ? 0 : 1);
}

main().catch((e) => {
  console.error(`protobuf_check.mjs: ${e.stack ?? e}`);
  process.exit(1);
});
