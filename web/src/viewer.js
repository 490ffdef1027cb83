// The iplan viewer page: a Foxglove WebSocket client of `iplan view` (the
// same protocol a Foxglove app speaks), drawing the scene channel in 3D and
// the strip from the cell's topics; or, with ?replay=FILE, a player of an
// MCAP recording. Orbit (drag), zoom (wheel), pause (button or space).
// The page's state is window.iplanViewer.state (for tests and debugging).
import { FoxgloveClient } from "@foxglove/ws-protocol";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { Replay } from "./replay.js";
import { SceneView } from "./scene.js";
import { STRIP_TOPICS, applyStrip, emptyStrip, renderStrip } from "./strip.js";

const SCENE = "/iplan/viewer/scene";
const CELL = "/iplan/viewer/cell";
const params = new URLSearchParams(location.search);

const view = new SceneView(document.getElementById("view"));
const controls = new OrbitControls(view.camera, view.renderer.domElement);
controls.target.set(0.55, 0, 0.3);
controls.update();

const state = {
  mode: params.has("replay") ? "replay" : "live",
  status: "connecting",  // connected | disconnected | connecting | replay
  connected: false,      // WebSocket open
  cellAlive: false,      // the viewer hears the cell (as of now, see cellAgeS)
  cellAgeS: null,        // s since the cell's last message, as the page knows now
  lagS: 0,               // how late the page got the viewer's last message (s)
  maxLagS: 0,            // the most it was behind on this page
  skippedFrames: 0,      // frames not drawn to catch up with the stream
  channels: [],
  received: {},          // messages per topic
  entities: {},
  strip: emptyStrip(),
  paused: false,
  frames: 0,
  fps: 0,
  replay: null,
};
// Scene updates wait here, the latest per entity, until the next animation
// frame (or the end of a pause) applies them: the page does at most one
// update per entity per frame however fast they come, and parses only those
// (an update is a JSON text until then).
const pending = new Map();  // entity id -> SceneUpdate (object or JSON text)
// The latest /iplan/viewer/cell status, when it came, and how late.
let cellStatus = null;
// Clock offset page - viewer (ms): the smallest (receipt - stamp) seen on
// this connection, i.e. the transit of the promptest message. A message
// received later than that was queued (the page or the network is behind).
let minOffsetMs = Infinity;

// The entity id is the first "id" of the text (keys are sorted; no
// primitive has one); the static scene's comes after its cubes.
function entityId(text) {
  const id = /"id":"([^"]*)"/;
  return id.exec(text.slice(0, 400))?.[1] ?? id.exec(text)?.[1] ?? "";
}

function applyPending() {
  for (const u of pending.values()) view.apply(typeof u === "string" ? JSON.parse(u) : u);
  pending.clear();
}

// `m`: the message, parsed or as JSON text; `lagMs`: how late it came. The viewer sends one entity per
// scene update and no deletions; any other update is applied at once.
function deliver(topic, m, lagMs = 0) {
  state.received[topic] = (state.received[topic] ?? 0) + 1;
  if (topic === SCENE && typeof m === "string") {
    pending.set(entityId(m), m);
    return;
  }
  if (typeof m === "string") m = JSON.parse(m);
  if (topic === SCENE) {
    if ((m.entities ?? []).length === 1 && !(m.deletions ?? []).length) pending.set(m.entities[0].id, m);
    else { applyPending(); view.apply(m); }
  } else if (topic === CELL) {
    cellStatus = { ...m, receivedMs: performance.now(), lagMs };
    updateStatus();
  } else {
    applyStrip(state.strip, topic, m);
  }
}

function setStatus(s) {
  if (state.status !== s) state.statusSinceMs = Date.now();  // wall clock, for tests
  state.status = s;
  const el = document.getElementById("status");
  el.textContent = s;
  el.className = `badge ${s === "connected" || s === "replay" ? "ok" : "bad"}`;
}

// The cell is alive while its last message, as of now, is at most
// `alive_after_s` old: the age the viewer stated, plus how late the status
// reached the page, plus the time since. So a page that is behind, or a
// viewer that went quiet, turns "disconnected" alive_after_s after the
// cell's last message, however slow the machine.
function updateStatus() {
  if (state.mode === "replay") return;
  let age = null;
  if (state.connected && cellStatus && cellStatus.last_message_age_s >= 0) {
    age = cellStatus.last_message_age_s + (cellStatus.lagMs + performance.now() - cellStatus.receivedMs) / 1000;
  }
  state.cellAgeS = age;
  state.cellAlive = age !== null && !!cellStatus.alive && age <= (cellStatus.alive_after_s ?? 1);
  state.aliveAfterS = cellStatus?.alive_after_s ?? null;
  state.statusPeriodS = cellStatus?.status_period_s ?? null;
  setStatus(state.cellAlive ? "connected" : "disconnected");
}

function connect() {
  const ws = new WebSocket(`ws://${location.host}/`, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const byChannel = new Map(), bySubscription = new Map();
  const decoder = new TextDecoder();
  client.on("open", () => {
    state.connected = true;
    minOffsetMs = Infinity;  // a new connection, maybe to another viewer
    cellStatus = null;
  });
  client.on("advertise", (channels) => {
    for (const c of channels) {
      byChannel.set(c.id, c);
      state.channels.push({ id: c.id, topic: c.topic, schemaName: c.schemaName });
      if (c.topic === SCENE || c.topic === CELL || STRIP_TOPICS.includes(c.topic)) {
        bySubscription.set(client.subscribe(c.id), c.topic);
      }
    }
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const topic = bySubscription.get(subscriptionId);
    if (!topic) return;
    const offset = Date.now() - Number(timestamp / 1000000n);
    minOffsetMs = Math.min(minOffsetMs, offset);
    const lagMs = offset - minOffsetMs;
    state.lagS = lagMs / 1000;
    state.maxLagS = Math.max(state.maxLagS, state.lagS);
    deliver(topic, decoder.decode(data), lagMs);
  });
  client.on("close", () => {
    state.connected = false;
    cellStatus = null;
    state.channels = [];
    updateStatus();
    setTimeout(connect, 1000);  // the viewer may come back
  });
  client.on("error", () => {});
}

function togglePause() {
  state.paused = !state.paused;
  document.getElementById("pause").textContent = state.paused ? "resume" : "pause";
  if (!state.paused) applyPending();
}
document.getElementById("pause").addEventListener("click", togglePause);
window.addEventListener("keydown", (e) => { if (e.code === "Space") togglePause(); });

let replay = null, lastFrame = performance.now(), lastRender = 0;
const LAG_SKIP_S = 0.25, MIN_FRAME_MS = 500;
async function startReplay() {
  setStatus("replay");
  replay = new Replay(params.get("replay"), deliver, () => { view.clear(); state.strip = emptyStrip(); });
  state.replay = replay.state;
  try {
    await replay.load();
  } catch (e) {
    replay.state.error = String(e);
    setStatus("replay failed");
    return;
  }
  const panel = document.getElementById("replay"), slider = document.getElementById("slider");
  const play = document.getElementById("play");
  panel.hidden = false;
  play.addEventListener("click", () => { replay.playing = !replay.playing; play.textContent = replay.playing ? "pause" : "play"; });
  slider.addEventListener("input", () => replay.seek(slider.value / 1000 * replay.state.duration));
  replay.advanceTo(0);
  if (params.has("autoplay")) play.click();
}

function showReplayTime() {
  const s = replay.state;
  document.getElementById("time").textContent = `${s.t.toFixed(1)} / ${s.duration.toFixed(1)} s`;
  document.getElementById("slider").value = s.duration > 0 ? Math.round(s.t / s.duration * 1000) : 0;
}

// Dynamic resolution: below 30 fps (software rendering, a busy machine) the
// canvas renders fewer pixels, down to 40 % of the full resolution in each
// direction; above 50 fps it goes back up. ?resolution=fixed turns it off.
state.resolution = 1;
function adaptResolution() {
  if (params.get("resolution") === "fixed") return;
  const r = state.fps < 30 ? Math.max(0.4, state.resolution * 0.8) : state.fps > 50 ? Math.min(1, state.resolution * 1.25) : state.resolution;
  if (Math.abs(r - state.resolution) > 1e-3) {
    state.resolution = r;
    view.setResolution(r);
  }
}

let fpsFrames = 0, fpsSince = performance.now(), workMs = 0;
function frame(now) {
  requestAnimationFrame(frame);
  if (replay?.state.loaded && replay.playing && !state.paused) {
    replay.advanceTo(replay.state.t + (now - lastFrame) / 1000 * replay.speed);
    if (replay.state.finished) replay.playing = false;
  }
  if (replay?.state.loaded) showReplayTime();
  lastFrame = now;
  // Behind the live stream (messages wait in the socket while the machine
  // renders): skip drawing (but draw at least 2 frames a second), so the page catches up
  // instead of falling further behind.
  if (state.mode === "live" && state.lagS > LAG_SKIP_S && now - lastRender < MIN_FRAME_MS) {
    state.skippedFrames += 1;
    return;
  }
  lastRender = now;
  const t0 = performance.now();
  if (!state.paused) applyPending();
  controls.update();
  view.render();
  workMs += performance.now() - t0;
  state.frames += 1;
  if (++fpsFrames && now - fpsSince >= 1000) {
    state.fps = fpsFrames * 1000 / (now - fpsSince);
    state.frameWorkMs = workMs / fpsFrames;
    workMs = 0;
    fpsFrames = 0;
    fpsSince = now;
    adaptResolution();
    document.getElementById("fps").textContent = `${state.fps.toFixed(0)} fps` +
      (state.resolution < 0.99 ? ` (${Math.round(100 * state.resolution)} % res.)` : "") +
      (state.mode === "live" && state.lagS > LAG_SKIP_S ? `, ${state.lagS.toFixed(1)} s behind` : "");
  }
  state.entities = view.summaries();
  renderStrip(state.strip);
}

window.iplanViewer = {
  state,
  project: (p) => view.project(p),
  view,  // the SceneView (for debugging)
  togglePause,
  /** Replay controls for tests: speed factor, play from the start. */
  replayPlay: (speed = 1) => { replay.speed = speed; replay.restart(); replay.playing = true; },
};

if (state.mode === "replay") {
  startReplay();
} else {
  setStatus("connecting");
  connect();
  setInterval(updateStatus, 100);
}
requestAnimationFrame(frame);
