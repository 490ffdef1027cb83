// Replay of an MCAP recording (iplan record) in the page: the whole file is
// fetched from the viewer, read with @mcap/core (zstd chunks: fzstd), and its messages delivered
// in log-time order through the same handler as live ones, with a time
// slider. Seeking back rebuilds the state from the latest scene update per
// entity and the strip topics up to the new time.
import { McapIndexedReader } from "@mcap/core";
import { decompress } from "fzstd";

export class Replay {
  constructor(url, deliver, reset) {
    this.url = url;
    this.deliver = deliver;  // (topic, json) => void
    this.reset = reset;
    this.messages = [];
    this.index = 0;
    this.playing = false;
    this.speed = 1;
    this.state = { loaded: false, error: null, counts: {}, delivered: {}, duration: 0, t: 0, finished: false };
  }

  async load() {
    const bytes = new Uint8Array(await (await fetch(this.url)).arrayBuffer());
    const readable = { size: async () => BigInt(bytes.byteLength),
      read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)) };
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers: { zstd: (data) => decompress(data) } });
    const topics = new Map([...reader.channelsById].map(([id, c]) => [id, c.topic]));
    const decoder = new TextDecoder();
    for await (const m of reader.readMessages()) {
      const topic = topics.get(m.channelId);
      let entity = null;
      if (topic === "/iplan/viewer/scene") {
        // The entity id is the first "id" of the text (keys are sorted;
        // no primitive has one); the static scene's comes after its cubes.
        const id = /"id":"([^"]*)"/;
        entity = id.exec(decoder.decode(m.data.subarray(0, 400)))?.[1] ?? id.exec(decoder.decode(m.data))?.[1] ?? null;
      }
      this.messages.push({ topic, t: m.logTime, data: m.data, entity });
      this.state.counts[topic] = (this.state.counts[topic] ?? 0) + 1;
    }
    this.decoder = decoder;
    this.t0 = this.messages.length ? this.messages[0].t : 0n;
    this.state.duration = this.messages.length ? Number(this.messages.at(-1).t - this.t0) * 1e-9 : 0;
    this.state.loaded = true;
  }

  parse(m) {
    return JSON.parse(this.decoder.decode(m.data));
  }

  /** Delivers every message up to `t` s (from the start) in order. */
  advanceTo(t) {
    const until = this.t0 + BigInt(Math.round(t * 1e9));
    while (this.index < this.messages.length && this.messages[this.index].t <= until) {
      const m = this.messages[this.index++];
      this.state.delivered[m.topic] = (this.state.delivered[m.topic] ?? 0) + 1;
      this.deliver(m.topic, this.parse(m));
    }
    this.state.t = Math.min(t, this.state.duration);
    this.state.finished = this.index >= this.messages.length;
  }

  /** Back to the start, nothing delivered yet (delivery counts restart). */
  restart() {
    this.reset();
    this.index = 0;
    this.state.delivered = {};
    this.state.t = 0;
    this.state.finished = this.messages.length === 0;
  }

  /** Jumps to `t` s: the state is rebuilt as it was then. */
  seek(t) {
    const until = this.t0 + BigInt(Math.round(t * 1e9));
    this.reset();
    let end = 0;
    while (end < this.messages.length && this.messages[end].t <= until) end++;
    const latestScene = new Map();
    for (let i = 0; i < end; i++) {
      const m = this.messages[i];
      if (m.entity !== null) latestScene.set(m.entity, m);
      else if (m.topic !== "/iplan/viewer/scene") this.deliver(m.topic, this.parse(m));
    }
    for (const m of latestScene.values()) this.deliver(m.topic, this.parse(m));
    this.index = end;
    this.state.delivered = {};  // counts restart: they count in-order playback only
    this.state.t = t;
    this.state.finished = end >= this.messages.length;
  }
}
