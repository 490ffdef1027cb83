// A demo episode's recording replays with the same number of messages per
// topic: what `iplan record` took from DDS (its stats file) equals what the
// MCAP file holds (read here with @mcap/core) and what the page delivers when
// it plays the recording in headless Chromium (`iplan view --replay`). The
// scene entities of the recording appear, and the time slider seeks.
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { countByTopic, readMcap } from "../tools/mcap_read.mjs";
import { check, env, fail, launchBrowser, startViewer, waitFor } from "./support.mjs";

const bin = env("IPLAN_BIN_DIR"), dir = env("IPLAN_VIEWER_RUN_DIR");
const file = join(dir, "recording.mcap");
const recorded = JSON.parse(readFileSync(`${file}.stats.json`, "utf8")).messages;
const { messages } = await readMcap(file);
const inFile = countByTopic(messages);
const same = (a, b) => Object.keys({ ...a, ...b }).every((t) => (a[t] ?? 0) === (b[t] ?? 0));
const table = (c) => Object.entries(c).map(([t, n]) => `${t} ${n}`).join(", ");
console.log(`recorded: ${table(recorded)}`);
for (const t of ["/joint_states", "/iplan/human/skeleton", "/iplan/human/prediction", "/iplan/viewer/scene"]) {
  check(recorded[t] > 10, `${t}: ${recorded[t]} messages recorded`);
}
check(same(recorded, Object.fromEntries(Object.keys(recorded).map((t) => [t, inFile[t] ?? 0]))),
  "the MCAP file holds as many messages per topic as were recorded");

const browser = await launchBrowser();
const viewer = await startViewer(bin, ["--replay", file]);
const page = await browser.newPage({ viewport: { width: 1280, height: 760 } });
page.on("pageerror", (e) => fail(`page error: ${e}`));
await page.goto(`${viewer.url}&resolution=fixed`);  // sharp screenshots; no frame-rate judgement here
const state = () => page.evaluate(() => JSON.parse(JSON.stringify(window.iplanViewer.state)));
await waitFor("the recording to load", async () => (await state()).replay?.loaded, 60000);
let s = await state();
check(s.status === "replay" && !s.replay.error, `replay loaded: ${s.replay.duration.toFixed(1)} s`);
check(same(s.replay.counts, inFile), "the page reads every message of the file");

// Play the whole recording at 20x and count what the page delivered.
await page.evaluate(() => window.iplanViewer.replayPlay(20));
await waitFor("the replay to finish", async () => (await state()).replay.finished, s.replay.duration / 20 * 1000 + 60000, 500);
s = await state();
console.log(`delivered: ${table(s.replay.delivered)}`);
check(same(s.replay.delivered, recorded), "the replay delivers the same number of messages per topic as were recorded");
check(s.entities.robot?.spheres > 20 && s.entities.person?.spheres === 16, "the replayed scene has the robot and the person");
if (process.env.IPLAN_SCREENSHOT_DIR) {
  await page.evaluate(() => { document.getElementById("slider").value = 500; document.getElementById("slider").dispatchEvent(new Event("input")); });
  await page.waitForTimeout(500);
  writeFileSync(join(process.env.IPLAN_SCREENSHOT_DIR, "viewer-replay.png"), await page.screenshot());
}
// Seek to the middle with the slider.
await page.evaluate(() => { const el = document.getElementById("slider"); el.value = 500; el.dispatchEvent(new Event("input")); });
s = await state();
check(Math.abs(s.replay.t - s.replay.duration / 2) < 0.01 * s.replay.duration + 0.1 && !s.replay.finished,
  `the slider seeks to ${s.replay.t.toFixed(1)} s`);
check(s.entities.robot?.spheres > 20, "after the seek the robot is drawn as it was then");
check(s.entities.scene?.cubes >= 3, "after the seek the table and scene objects are drawn");
await browser.close();
await viewer.proc.stop("SIGINT");
process.exit(0);
