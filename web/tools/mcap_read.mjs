// Reads a whole MCAP file (as iplan record writes it) with @mcap/core:
// messages in log-time order, each { topic, logTime (ns, bigint), data (parsed JSON) }.
import { McapIndexedReader } from "@mcap/core";
import { decompress } from "fzstd";
import { readFile } from "node:fs/promises";

export async function readMcap(path, { topics } = {}) {
  const bytes = await readFile(path);
  const readable = {
    size: async () => BigInt(bytes.byteLength),
    read: async (offset, size) => new Uint8Array(bytes.buffer, bytes.byteOffset + Number(offset), Number(size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers: { zstd: (data) => decompress(data) } });
  const decoder = new TextDecoder();
  const byId = new Map([...reader.channelsById].map(([id, c]) => [id, c.topic]));
  const messages = [];
  for await (const m of reader.readMessages({ topics })) {
    messages.push({ topic: byId.get(m.channelId), logTime: m.logTime, data: JSON.parse(decoder.decode(m.data)) });
  }
  return { messages, channels: [...reader.channelsById.values()], statistics: reader.statistics };
}

/** Messages per topic. */
export function countByTopic(messages) {
  const counts = {};
  for (const m of messages) counts[m.topic] = (counts[m.topic] ?? 0) + 1;
  return counts;
}
