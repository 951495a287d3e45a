#!/usr/bin/env node
// Independent reader of coin-log MCAP files, with the libraries Foxglove itself uses:
// @mcap/core's McapIndexedReader (zstd and lz4 chunks through @foxglove/wasm-zstd / @foxglove/wasm-lz4)
// and the JSON Schemas published in @foxglove/schemas, validated with ajv.
//
// usage: node scripts/readers/check.mjs FILE.mcap...
//
// For each file: the summary (statistics, chunk indexes) must be present; every message is read through the
// indexes with CRC validation, decoded as UTF-8 JSON and validated (foxglove.* against @foxglove/schemas,
// coin_log.* against schemas/ of this repository, both also refusing fields the schema does not declare);
// message counts must equal the statistics (total and per channel); the stored schema bytes must equal
// schemas/<name>.json, and the foxglove.* ones must be the published schemas; Foxglove timestamps
// {sec, nsec} and coin_log `t` must equal the log time. Exits 1 on any failure, 2 on a usage error.

import { McapIndexedReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import Ajv from "ajv";
import { open, readFile } from "node:fs/promises";
import { isDeepStrictEqual } from "node:util";
import path from "node:path";
import { fileURLToPath } from "node:url";
import { createRequire } from "node:module";

// @foxglove/schemas is CommonJS; its JSON Schemas are the exports of @foxglove/schemas/jsonschema.
const foxgloveSchemas = createRequire(import.meta.url)("@foxglove/schemas/jsonschema");

const here = path.dirname(fileURLToPath(import.meta.url));
const schemasDir = path.resolve(here, "..", "..", "schemas");
const MAX_REPORTED = 20;

/** A copy of `schema` in which every object with declared properties refuses undeclared ones. */
function strict(schema) {
  if (Array.isArray(schema)) return schema.map(strict);
  if (schema === null || typeof schema !== "object") return schema;
  const out = {};
  for (const [k, v] of Object.entries(schema)) out[k] = k === "const" ? v : strict(v);
  if (out.type === "object" && out.properties && !("additionalProperties" in out)) {
    out.additionalProperties = false;
  }
  return out;
}

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

/** ajv errors as text, naming an undeclared property. */
function describe(errors) {
  return errors
    .map((e) => {
      const extra = e.params?.additionalProperty;
      return `${e.instancePath || "/"} ${e.message}${extra === undefined ? "" : ` ('${extra}')`}`;
    })
    .join("; ");
}

function timeNs(stamp) {
  return BigInt(stamp.sec) * 1_000_000_000n + BigInt(stamp.nsec);
}

/** Every `timestamp` that must equal the log time: the transform's, or each scene entity's. */
function foxgloveTimestamps(schemaName, message) {
  if (schemaName === "foxglove.FrameTransform") return [message.timestamp];
  if (schemaName === "foxglove.SceneUpdate") return message.entities.map((e) => e.timestamp);
  return [];
}

async function checkFile(file, ajv, validators) {
  const failures = [];
  const fail = (msg) => {
    if (failures.length < MAX_REPORTED) failures.push(msg);
    else if (failures.length === MAX_REPORTED) failures.push("(more failures not shown)");
  };
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
    if (reader.chunkIndexes.length === 0 && stats.messageCount > 0n) fail("no chunk indexes in the summary");

    // Schemas: encoding, stored bytes, a validator per channel.
    const channelInfo = new Map();
    for (const [id, channel] of reader.channelsById) {
      const schema = reader.schemasById.get(channel.schemaId);
      if (!schema) {
        fail(`channel ${channel.topic}: schema id ${channel.schemaId} not in the file`);
        continue;
      }
      if (schema.encoding !== "jsonschema") fail(`schema ${schema.name}: encoding ${schema.encoding}, expected jsonschema`);
      if (channel.messageEncoding !== "json") fail(`channel ${channel.topic}: message encoding ${channel.messageEncoding}, expected json`);
      let repoBytes;
      try {
        repoBytes = await readFile(path.join(schemasDir, `${schema.name}.json`));
      } catch {
        fail(`schema ${schema.name} has no file schemas/${schema.name}.json`);
        continue;
      }
      if (Buffer.compare(Buffer.from(schema.data), repoBytes) !== 0) {
        fail(`schema ${schema.name}: stored bytes differ from schemas/${schema.name}.json`);
      }
      let validate;
      if (schema.name.startsWith("foxglove.")) {
        const published = foxgloveSchemas[schema.name.slice("foxglove.".length)];
        if (!published) {
          fail(`schema ${schema.name} is not published in @foxglove/schemas`);
          continue;
        }
        if (!isDeepStrictEqual(JSON.parse(Buffer.from(schema.data).toString("utf8")), published)) {
          fail(`schema ${schema.name}: stored schema differs from @foxglove/schemas' ${schema.name}`);
        }
        validate = validators.get(schema.name) ?? ajv.compile(strict(published));
      } else {
        validate = validators.get(schema.name) ?? ajv.compile(JSON.parse(repoBytes.toString("utf8")));
      }
      validators.set(schema.name, validate);
      channelInfo.set(id, { topic: channel.topic, schemaName: schema.name, validate, count: 0n });
    }

    // Messages, through the indexes, CRCs validated.
    let total = 0n;
    const decoder = new TextDecoder("utf-8", { fatal: true });
    for await (const record of reader.readMessages({ validateCrcs: true })) {
      total++;
      const info = channelInfo.get(record.channelId);
      if (!info) {
        fail(`message on unknown channel id ${record.channelId}`);
        continue;
      }
      info.count++;
      const where = `${info.topic} at log time ${record.logTime}`;
      if (record.publishTime !== record.logTime) fail(`${where}: publish time ${record.publishTime} != log time`);
      let message;
      try {
        message = JSON.parse(decoder.decode(record.data));
      } catch (e) {
        fail(`${where}: not UTF-8 JSON (${e.message})`);
        continue;
      }
      if (!info.validate(message)) {
        fail(`${where}: invalid ${info.schemaName}: ${describe(info.validate.errors)}`);
        continue;
      }
      if (info.schemaName.startsWith("coin_log.")) {
        const expected = BigInt(Math.round(message.t * 1e9));
        if (expected !== record.logTime) fail(`${where}: t = ${message.t} gives ${expected} ns`);
      }
      for (const stamp of foxgloveTimestamps(info.schemaName, message)) {
        if (timeNs(stamp) !== record.logTime) fail(`${where}: timestamp ${stamp.sec}.${stamp.nsec} != log time`);
      }
    }

    // Counts against the statistics.
    if (total !== stats.messageCount) fail(`read ${total} messages, statistics say ${stats.messageCount}`);
    for (const [id, info] of channelInfo) {
      const expected = stats.channelMessageCounts.get(id) ?? 0n;
      if (info.count !== expected) fail(`${info.topic}: read ${info.count} messages, statistics say ${expected}`);
    }
    let metadata = 0;
    for await (const _ of reader.readMetadata()) metadata++;
    if (BigInt(metadata) !== BigInt(stats.metadataCount)) fail(`read ${metadata} metadata records, statistics say ${stats.metadataCount}`);

    const compressions = [...new Set(reader.chunkIndexes.map((c) => c.compression || "none"))].join("+") || "-";
    const perTopic = [...channelInfo.values()].map((i) => `${i.topic}=${i.count}`).join(" ");
    const summary = `${total} messages in ${reader.chunkIndexes.length} chunks (${compressions}), ${metadata} metadata; ${perTopic}`;
    return { failures, summary };
  } finally {
    await handle.close();
  }
}

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error("usage: node scripts/readers/check.mjs FILE.mcap...");
    process.exit(2);
  }
  await zstd.isLoaded;
  await lz4.isLoaded;
  const ajv = new Ajv({ allErrors: true, strict: true });
  const validators = new Map();
  let bad = 0;
  for (const file of files) {
    let result;
    try {
      result = await checkFile(file, ajv, validators);
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
  console.log(`check.mjs: ${files.length - bad} passed, ${bad} failed`);
  process.exit(bad === 0 ? 0 : 1);
}

main().catch((e) => {
  console.error(`check.mjs: ${e.stack ?? e}`);
  process.exit(1);
});
