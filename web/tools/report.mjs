#!/usr/bin/env node
// The HTML report behind `iplan report`: one self-contained file (uPlot and
// the data inlined; no network) with the plots of a demo run, from its
// summary JSON (iplan demo --summary) and its MCAP recording (iplan record):
//   learning curve, waiting time per episode           (summary)
//   separation and S_p over time with stops marked     (recording: /iplan/collision_risk, /iplan/safety/permit/*)
//   end-to-end latency histogram                       (recording: /iplan/robot/plan_status)
//   per-service cycle times and deadline misses        (recording: /diagnostics)
// A plot whose data the run lacks is listed under "Not in this run".
//   node report.mjs --summary S.json [--recording R.mcap] --out report.html
import { readFileSync, writeFileSync, renameSync } from "node:fs";
import { createRequire } from "node:module";
import { dirname, join } from "node:path";
import { parseArgs } from "node:util";
import { readMcap } from "./mcap_read.mjs";

const { values: args } = parseArgs({ options: { summary: { type: "string" }, recording: { type: "string" },
  out: { type: "string" } } });
if (!args.summary || !args.out) {
  console.error("usage: report.mjs --summary S.json [--recording R.mcap] --out report.html");
  process.exit(2);
}
const summary = JSON.parse(readFileSync(args.summary, "utf8"));
const plots = [], missing = [];

function learningPlots() {
  const curve = (summary.learning_curve ?? []).filter((e) => e.completion_time_s >= 0);
  if (!curve.length) {
    missing.push("learning curve and waiting time: the summary has no completed episode");
    return;
  }
  const ep = curve.map((e) => e.episode);
  plots.push({ id: "learning", title: "Learning curve: completion time per episode", x: "episode", integerX: true,
    series: [{ label: "completion time (s)", data: curve.map((e) => e.completion_time_s), points: true }], xs: ep });
  plots.push({ id: "waiting", title: "Robot waiting time per episode", x: "episode", bars: true, integerX: true,
    series: [{ label: "waiting (s)", data: curve.map((e) => e.waiting_time_s) }], xs: ep });
}

function separationPlot(msgs, t0) {
  const risk = msgs.filter((m) => m.topic === "/iplan/collision_risk" && typeof m.data.min_separation === "number"
    && m.data.min_separation < 1e6);
  if (!risk.length) {
    missing.push("separation over time: the recording has no /iplan/collision_risk with a person in view");
    return;
  }
  const stops = [], sources = {};
  let stopped = false;
  for (const m of msgs.filter((m) => m.topic.startsWith("/iplan/safety/permit/"))) {
    sources[m.data.source] = m.data.state === 0;
    const now = Object.values(sources).some((v) => v);
    if (now && !stopped) stops.push({ t: Number(m.logTime - t0) * 1e-9, reason: `${m.data.source}: ${m.data.reason}` });
    stopped = now;
  }
  const num = (v) => (typeof v === "number" ? v : null);
  plots.push({ id: "separation", title: "Separation and ISO/TS 15066 protective separation S_p (stops marked)",
    x: "time (s)", xs: risk.map((m) => Number(m.logTime - t0) * 1e-9),
    series: [{ label: "separation (m)", data: risk.map((m) => num(m.data.min_separation)) },
      { label: "S_p (m)", data: risk.map((m) => num(m.data.protective_separation)) },
      { label: "collision bound", data: risk.map((m) => num(m.data.max_bound)), scale: "p" }],
    marks: stops });
}

function latencyPlot(msgs) {
  const lat = msgs.filter((m) => m.topic === "/iplan/robot/plan_status" && m.data.latency > 0).map((m) => 1e3 * m.data.latency);
  if (!lat.length) {
    missing.push("latency histogram: the recording has no /iplan/robot/plan_status with a latency");
    return;
  }
  const max = Math.max(...lat), width = Math.max(1, Math.ceil(max / 30));
  const bins = Array.from({ length: Math.ceil(max / width) + 1 }, () => 0);
  for (const v of lat) bins[Math.floor(v / width)] += 1;
  const sorted = [...lat].sort((a, b) => a - b), q = (p) => sorted[Math.min(sorted.length - 1, Math.floor(p * sorted.length))];
  plots.push({ id: "latency", title: `End-to-end latency, skeleton to trajectory (${lat.length} trajectories; ` +
    `p50 ${q(0.5).toFixed(1)} ms, p99 ${q(0.99).toFixed(1)} ms)`, x: "latency (ms)", bars: true,
    xs: bins.map((_, i) => (i + 0.5) * width), series: [{ label: "trajectories", data: bins }] });
}

function servicePlots(msgs, t0) {
  const diag = msgs.filter((m) => m.topic === "/diagnostics");
  const cycle = {}, misses = {};
  for (const m of diag) {
    for (const st of m.data.status) {
      const kv = Object.fromEntries(st.values.map((v) => [v.key, v.value]));
      const t = Number(m.logTime - t0) * 1e-9;
      if (kv.cycle_time_p99_s !== undefined) (cycle[st.name] ??= []).push([t, 1e3 * Number(kv.cycle_time_p99_s)]);
      if (kv.deadline_misses !== undefined) misses[st.name] = Number(kv.deadline_misses);
    }
  }
  const names = Object.keys(cycle).sort();
  if (!names.length) {
    missing.push("per-service cycle times: the recording has no /diagnostics with cycle times");
  } else {
    // One time axis: every service's samples, others null (uPlot draws gaps).
    const times = [...new Set(names.flatMap((n) => cycle[n].map(([t]) => t)))].sort((a, b) => a - b);
    const series = names.map((n) => {
      const at = new Map(cycle[n]);
      return { label: `${n} p99 (ms)`, data: times.map((t) => at.get(t) ?? null), points: true, spanGaps: true };
    });
    plots.push({ id: "cycle", title: "Cycle time per service (p99 over its diagnostics window)", x: "time (s)",
      y: "cycle time p99 (ms)", xs: times, series });
  }
  const mnames = Object.keys(misses).sort();
  if (!mnames.length) {
    missing.push("deadline misses: the recording has no /diagnostics");
  } else {
    plots.push({ id: "deadlines", title: "Deadline misses per service (end of run; " + mnames.join(", ") + ")",
      x: "service", bars: true, xs: mnames.map((_, i) => i + 1), xlabels: mnames,
      series: [{ label: "deadline misses", data: mnames.map((n) => misses[n]) }] });
  }
}

learningPlots();
if (args.recording) {
  const { messages } = await readMcap(args.recording);
  const t0 = messages.length ? messages[0].logTime : 0n;
  separationPlot(messages, t0);
  latencyPlot(messages);
  servicePlots(messages, t0);
} else {
  missing.push("separation, latency histogram, cycle times, deadline misses: no recording (iplan demo --record FILE)");
}

const here = dirname(new URL(import.meta.url).pathname);
const req = createRequire(import.meta.url);
const uplotJs = readFileSync(req.resolve("uplot/dist/uPlot.iife.min.js"), "utf8");
const uplotCss = readFileSync(req.resolve("uplot/dist/uPlot.min.css"), "utf8");
const facts = [["episodes completed", `${summary.episodes_completed} / ${summary.episodes_requested}`],
  ["tasks completed", summary.tasks_completed], ["robot waiting time", `${(summary.robot_waiting_time_s ?? 0).toFixed(1)} s`],
  ["minimum separation (true body)", summary.min_separation_m >= 0 ? `${summary.min_separation_m.toFixed(3)} m` : "-"],
  ["maximum collision bound", Number(summary.max_collision_bound ?? 0).toFixed(4)], ["protective stops", summary.protective_stops],
  ["true contacts", summary.true_contacts],
  ["end-to-end latency", summary.latency_ms ? `p50 ${summary.latency_ms.p50.toFixed(1)} ms, p99 ${summary.latency_ms.p99.toFixed(1)} ms` : "-"],
  ["run time", `${(summary.duration_s ?? 0).toFixed(0)} s`], ["failure", summary.failure || "none"]];
const esc = (s) => String(s).replace(/[&<>]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;" })[c]);
const html = `<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>iplan run report</title>
<style>${uplotCss}
body { font: 14px system-ui, sans-serif; margin: 24px; color: #1d2430; max-width: 1000px; }
table { border-collapse: collapse; } td { padding: 2px 14px 2px 0; } .plot { margin: 8px 0 28px; }
h2 { font-size: 16px; margin: 18px 0 4px; } .missing { color: #8a4b00; }
</style></head><body>
<h1>iplan run report</h1>
<p>${esc(args.summary)}${args.recording ? " and " + esc(args.recording) : ""}</p>
<table>${facts.map(([k, v]) => `<tr><td>${esc(k)}</td><td>${esc(v)}</td></tr>`).join("")}</table>
${plots.map((p) => `<h2>${esc(p.title)}</h2><div class="plot" id="plot-${p.id}"></div>`).join("\n")}
${missing.length ? `<h2>Not in this run</h2><ul class="missing">${missing.map((m) => `<li>${esc(m)}</li>`).join("")}</ul>` : ""}
<script>${uplotJs}</script>
<script>const PLOTS = ${JSON.stringify(plots)};
${readFileSync(join(here, "report_page.js"), "utf8")}</script>
</body></html>
`;
writeFileSync(args.out + ".tmp", html);
renameSync(args.out + ".tmp", args.out);
console.log(`report written to ${args.out} (${plots.length} plots${missing.length ? `, ${missing.length} missing` : ""})`);
