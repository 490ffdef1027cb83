#!/usr/bin/env node
// The MCAP writer behind `iplan record`: reads lines from stdin and writes
// them to an MCAP file with Foxglove's @mcap/core (chunked, indexed, with
// statistics, so Foxglove and `iplan view --replay` seek in it).
//   c {"id": n, "topic": "/x", "schemaName": "pkg/msg/T", "schema": "<JSON Schema>"}   a channel
//   m <channel id> <log time ns> <JSON message>                                          a message
// Chunks are zstd-compressed (@foxglove/wasm-zstd; MCAP's own compression,
// which Foxglove reads). Ends (and completes the file) at the end of stdin; SIGINT is ignored so
// that Ctrl-C in a terminal lets `iplan record` close the pipe in order.
import { McapWriter } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import { open } from "node:fs/promises";
import { createInterface } from "node:readline";

const out = process.argv[2];
if (!out) {
  console.error("usage: mcap_writer.mjs OUT.mcap < lines");
  process.exit(2);
}
process.on("SIGINT", () => {});
process.on("SIGTERM", () => {});

let file;
try {
  file = await open(out, "w");
} catch (e) {
  console.error(`mcap_writer: cannot write ${out}: ${e.message}`);
  process.exit(1);
}
let position = 0n;
const writable = {
  async write(buffer) {
    await file.write(buffer);
    position += BigInt(buffer.byteLength);
  },
  position: () => position,
};
await zstd.isLoaded;
const writer = new McapWriter({ writable, useChunks: true, useStatistics: true, useSummaryOffsets: true,
  useMessageIndex: true, useChunkIndex: true, chunkSize: 1 << 20,
  compressChunk: (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) }) });
await writer.start({ profile: "", library: "iplan record (@mcap/core)" });

const encoder = new TextEncoder();
const channels = new Map();  // iplan channel id -> { id, sequence }
let bad = 0;
for await (const line of createInterface({ input: process.stdin, crlfDelay: Infinity })) {
  if (line.startsWith("c ")) {
    const c = JSON.parse(line.slice(2));
    const schemaId = await writer.registerSchema({ name: c.schemaName, encoding: "jsonschema", data: encoder.encode(c.schema) });
    const id = await writer.registerChannel({ topic: c.topic, messageEncoding: "json", schemaId, metadata: new Map() });
    channels.set(c.id, { id, sequence: 0 });
  } else if (line.startsWith("m ")) {
    const a = line.indexOf(" ", 2), b = line.indexOf(" ", a + 1);
    const ch = channels.get(Number(line.slice(2, a)));
    if (!ch || b < 0) {
      ++bad;
      continue;
    }
    const t = BigInt(line.slice(a + 1, b));
    await writer.addMessage({ channelId: ch.id, sequence: ch.sequence++, logTime: t, publishTime: t,
      data: encoder.encode(line.slice(b + 1)) });
  } else if (line.length) {
    ++bad;
  }
}
await writer.end();
await file.close();
if (bad) console.error(`mcap_writer: ${bad} malformed lines skipped`);
