// Benchmark (not a test; docs/viewer.md quotes it): what the viewer costs a
// running cell, and the page's frame rate.
//   phase 1: the cell alone (iplan demo, every service a process);
//   phase 2: the same cell with `iplan view` and the page open in headless
//            Chromium (software WebGL: this machine has no GPU).
// CPU is read from /proc/<pid>/stat (utime + stime) in 5 s windows; the cell
// is the demo process and every service it started.
//   IPLAN_BIN_DIR=build/bin IPLAN_SOURCE_DIR=. node web/bench/viewer_load.mjs [--windows N] [--resolution fixed|auto]
import { readdirSync, readFileSync } from "node:fs";
import { loadavg } from "node:os";
import { join } from "node:path";
import { parseArgs } from "node:util";
import { Proc, env, launchBrowser, sleep, startViewer, tempDir, uniqueDomain, waitFor } from "../test/support.mjs";

const { values: args } = parseArgs({ options: { windows: { type: "string", default: "4" },
  resolution: { type: "string", default: "auto" } } });
const bin = env("IPLAN_BIN_DIR"), source = env("IPLAN_SOURCE_DIR");
const windows = Number(args.windows), WINDOW_MS = 5000;
const ticks = 100;  // USER_HZ on Linux

function cpuTicks(pid) {
  try {
    const f = readFileSync(`/proc/${pid}/stat`, "utf8").split(") ")[1].split(" ");
    return Number(f[11]) + Number(f[12]);  // utime, stime
  } catch {
    return 0;
  }
}
function children(pid) {
  const out = [];
  for (const d of readdirSync("/proc")) {
    if (!/^\d+$/.test(d)) continue;
    try {
      if (Number(readFileSync(`/proc/${d}/stat`, "utf8").split(") ")[1].split(" ")[1]) === pid) out.push(Number(d));
    } catch {}
  }
  return out;
}
const descendants = (pid) => children(pid).flatMap((c) => [c, ...descendants(c)]);
const total = (pids) => pids.reduce((s, p) => s + cpuTicks(p), 0);

async function measure(groups) {
  const rows = [];
  for (let w = 0; w < windows; w++) {
    const pids = Object.fromEntries(Object.entries(groups).map(([k, f]) => [k, f()]));
    const a = Object.fromEntries(Object.entries(pids).map(([k, p]) => [k, total(p)]));
    const t0 = Date.now();
    await sleep(WINDOW_MS);
    const dt = (Date.now() - t0) / 1000;
    rows.push(Object.fromEntries(Object.entries(pids).map(([k, p]) => [k, 100 * (total(p) - a[k]) / ticks / dt])));
  }
  return rows;
}
const median = (v) => [...v].sort((x, y) => x - y)[Math.floor(v.length / 2)];
const fmt = (v) => `${median(v).toFixed(1)} [${Math.min(...v).toFixed(1)}, ${Math.max(...v).toFixed(1)}]`;

const domain = String(uniqueDomain(51));
const config = join(source, "config");
const cell = new Proc([join(bin, "iplan"), "demo", "--episodes", "50", "--timeout", "900", "--domain", domain,
  "--config-dir", config, "--state-dir", tempDir("viewer-bench")], "iplan demo");
await cell.waitOutput(/episode 1\/50/, 120000);
await sleep(3000);
const cellPids = () => [cell.p.pid, ...descendants(cell.p.pid)];
console.log(`load average before: ${loadavg().map((l) => l.toFixed(2)).join(" ")}`);
const alone = await measure({ cell: cellPids });

const viewer = await startViewer(bin, ["--domain", domain, "--config-dir", config]);
const browser = await launchBrowser();
const page = await browser.newPage({ viewport: { width: 1280, height: 760 } });
await page.goto(`${viewer.url}${args.resolution === "fixed" ? "?resolution=fixed" : ""}`);
await waitFor("the page to connect", () => page.evaluate(() => window.iplanViewer.state.status === "connected"), 30000);
await sleep(3000);
const fps = [];
const sampler = setInterval(async () => fps.push(await page.evaluate(() => window.iplanViewer.state.fps)), 1000);
const withViewer = await measure({ cell: cellPids, viewer: () => [viewer.proc.p.pid],
  chromium: () => descendants(process.pid).filter((p) => {
    try { return /chrom/i.test(readFileSync(`/proc/${p}/comm`, "utf8")); } catch { return false; }
  }) });
clearInterval(sampler);
const res = await page.evaluate(() => window.iplanViewer.state.resolution);
const work = await page.evaluate(() => window.iplanViewer.state.frameWorkMs);
console.log(`load average after: ${loadavg().map((l) => l.toFixed(2)).join(" ")}`);
console.log(`windows: ${windows} x ${WINDOW_MS / 1000} s; CPU in % of one core, median [min, max]`);
console.log(`cell alone:             ${fmt(alone.map((r) => r.cell))} %`);
console.log(`cell with viewer open:  ${fmt(withViewer.map((r) => r.cell))} %`);
console.log(`iplan view process:     ${fmt(withViewer.map((r) => r.viewer))} %`);
console.log(`viewer / cell:          ${fmt(withViewer.map((r) => 100 * r.viewer / r.cell))} %`);
console.log(`headless Chromium:      ${fmt(withViewer.map((r) => r.chromium))} %`);
console.log(`page frame rate:        ${fmt(fps.slice(2))} fps (resolution ${args.resolution}, final ${Math.round(100 * res)} %)`);
console.log(`page work per frame:    ${work.toFixed(1)} ms (scene updates + render call, mean of the last second)`);
await browser.close();
await viewer.proc.stop("SIGINT");
await cell.stop("SIGINT", 60000);
process.exit(0);
