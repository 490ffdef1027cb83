// Foxglove's own client library (@foxglove/ws-protocol, over the `ws`
// WebSocket) against `iplan view`: the advertised channels are the cell's
// catalogue topics plus the scene and cell-status channels, each with a JSON
// schema; a skeleton and a joint state published with `iplan topic pub`
// arrive and decode to what was published; the scene channel carries the
// robot drawn at that joint state, and an obstacle cloud as cubes.
import wsProtocol from "@foxglove/ws-protocol";
import { join } from "node:path";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
import { Proc, check, env, fail, sleep, startViewer, uniqueDomain, waitFor } from "./support.mjs";

const bin = env("IPLAN_BIN_DIR"), source = env("IPLAN_SOURCE_DIR");
const domain = String(uniqueDomain(11));
const dds = ["--dds", "cyclonedds", "--domain", domain];
const viewer = await startViewer(bin, [...dds, "--config-dir", join(source, "config")]);

const skeleton = { header: { frame_id: "world" }, body_id: 4, confidence: 0.9,
  joints: ["head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l", "shoulder_r", "elbow_r", "hand_r"].map((name, i) => (
    { name, position: { x: 1.3, y: -0.3 + 0.07 * i, z: 0.2 + 0.05 * i }, covariance: Array(9).fill(0), confidence: 1 })) };
const joints = { header: { frame_id: "world" }, name: [1, 2, 3, 4, 5, 6, 7].map((i) => `panda_joint${i}`),
  position: [0.1, -0.3, 0, -2.0, 0, 1.6, 0.7], velocity: Array(7).fill(0), effort: [] };
const pub = (topic, m) => new Proc([join(bin, "iplan"), "topic", "pub", topic, JSON.stringify(m), ...dds, "-r", "20",
  "-n", "0", "--stamp-now", "--wait-readers", "0"], `iplan topic pub ${topic}`);
// An obstacle cloud: 40 points on a line, FLOAT32 x y z.
const xyz = new Float32Array(40 * 3).map((_, i) => (i % 3 === 0 ? 0.5 + 0.01 * Math.floor(i / 3) : i % 3 === 1 ? -0.4 : 0.05));
const cloud = { header: { frame_id: "world" }, height: 1, width: 40, is_bigendian: false, point_step: 12, row_step: 480,
  is_dense: true, data: Array.from(new Uint8Array(xyz.buffer)),
  fields: ["x", "y", "z"].map((name, i) => ({ name, offset: 4 * i, datatype: 7, count: 1 })) };
const pubs = [pub("/iplan/human/skeleton", skeleton), pub("/joint_states", joints), pub("/iplan/depth/points", cloud)];

const ws = new WebSocket(`ws://127.0.0.1:${viewer.port}/`, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
ws.binaryType = "arraybuffer";
const client = new FoxgloveClient({ ws });
const channels = [], got = new Map(), subs = new Map();
let serverInfo = null;
client.on("serverInfo", (i) => { serverInfo = i; });
client.on("advertise", (cs) => channels.push(...cs));
client.on("message", ({ subscriptionId, data }) => {
  const topic = subs.get(subscriptionId);
  if (!got.has(topic)) got.set(topic, []);
  got.get(topic).push(JSON.parse(new TextDecoder().decode(data)));
});
client.on("error", (e) => fail(`client error: ${e}`));

await waitFor("the advertisement", () => channels.length > 0, 10000);
check(serverInfo?.name === "iplan", `serverInfo names the server (${serverInfo?.name})`);
const topics = channels.map((c) => c.topic).sort();
console.log("advertised:", topics.join(" "));
for (const t of ["/iplan/human/skeleton", "/joint_states", "/iplan/human/prediction", "/iplan/collision_risk",
  "/iplan/safety/permit/supervisor", "/iplan/safety/permit/collision_risk", "/diagnostics", "/iplan/viewer/scene",
  "/iplan/viewer/cell"]) {
  check(topics.includes(t), `channel ${t} is advertised`);
}
for (const c of channels) {
  if (c.encoding !== "json" || c.schemaEncoding !== "jsonschema") fail(`${c.topic}: encoding ${c.encoding}/${c.schemaEncoding}`);
  JSON.parse(c.schema);
}
check(true, `all ${channels.length} channels are JSON with a JSON schema`);
const byTopic = Object.fromEntries(channels.map((c) => [c.topic, c]));
check(byTopic["/joint_states"].schemaName === "sensor_msgs/msg/JointState", "joint states carry the ROS 2 type name");
check(byTopic["/iplan/viewer/scene"].schemaName === "foxglove.SceneUpdate", "the scene is a foxglove.SceneUpdate");

for (const t of ["/iplan/human/skeleton", "/joint_states", "/iplan/viewer/scene"]) subs.set(client.subscribe(byTopic[t].id), t);
const sceneHas = (id) => got.get("/iplan/viewer/scene")?.some((u) => u.entities[0]?.id === id);
await waitFor("a skeleton, a joint state, robot and obstacle scene entities", () => got.get("/iplan/human/skeleton")?.length
  && got.get("/joint_states")?.length && sceneHas("robot") && sceneHas("obstacles"), 20000);

const s = got.get("/iplan/human/skeleton")[0];
check(s.body_id === 4 && s.joints.length === 9, `skeleton decodes: body ${s.body_id}, ${s.joints.length} joints`);
check(s.joints[5].name === "hand_l" && Math.abs(s.joints[5].position.y - (-0.3 + 0.35)) < 1e-12,
  `skeleton joint hand_l at y = ${s.joints[5].position.y}`);
check(s.header.stamp.sec > 1.7e9, "skeleton stamp is wall-clock time");
const j = got.get("/joint_states")[0];
check(j.name.join() === joints.name.join() && j.position.every((v, i) => v === joints.position[i]),
  `joint state decodes: ${j.position.join(", ")}`);
const schema = JSON.parse(byTopic["/joint_states"].schema);
check(schema.required.join() === "header,name,position,velocity,effort" && schema.properties.position.type === "array",
  "joint state schema lists its fields in IDL order");
for (const k of schema.required) if (!(k in j)) fail(`joint state lacks required ${k}`);
const robot = got.get("/iplan/viewer/scene").find((u) => u.entities[0]?.id === "robot").entities[0];
check(robot.spheres.length > 20, `robot entity has ${robot.spheres.length} collision spheres`);
const person = got.get("/iplan/viewer/scene").find((u) => u.entities[0]?.id === "person")?.entities[0];
check(person && person.spheres.length === 16, `person entity has ${person?.spheres.length} body spheres`);

const obstacles = got.get("/iplan/viewer/scene").find((u) => u.entities[0]?.id === "obstacles")?.entities[0];
check(obstacles?.cubes.length === 40 && Math.abs(obstacles.cubes[39].pose.position.x - 0.89) < 1e-6,
  `obstacle cloud drawn as ${obstacles?.cubes.length} cubes`);

client.close();
for (const p of pubs) await p.stop("SIGINT");
const code = await viewer.proc.stop("SIGINT");
check(code === 0, `iplan view exits 0 (${code})`);
await sleep(100);
process.exit(0);
