// The report of a demo run (iplan demo --summary, written beside the
// summary; and `iplan report RUN` again here) renders in headless Chromium
// with every plot present: a uPlot canvas with drawn pixels and data points.
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { Proc, check, env, fail, launchBrowser, waitFor } from "./support.mjs";

const bin = env("IPLAN_BIN_DIR"), dir = env("IPLAN_VIEWER_RUN_DIR");
const out = join(dir, "report-again.html");
const rep = new Proc([join(bin, "iplan"), "report", dir, "--out", out], "iplan report");
check(await rep.exited === 0, `iplan report RUN exits 0: ${rep.out.trim()}`);
const html = readFileSync(out, "utf8");
check(!/(src|href)=["']?(https?:)?\/\//.test(html), "the report loads nothing from the network");

const browser = await launchBrowser();
const page = await browser.newPage({ viewport: { width: 1100, height: 900 } });
page.on("pageerror", (e) => fail(`report page error: ${e}`));
page.on("request", (r) => { if (!r.url().startsWith("file:")) fail(`report requested ${r.url()}`); });
await page.goto(`file://${out}`);
await waitFor("the report's plots", () => page.evaluate(() => window.iplanReport?.ready), 20000);
const plots = await page.evaluate(() => window.iplanReport.plots);
const ids = plots.map((p) => p.id);
for (const id of ["learning", "waiting", "separation", "latency", "cycle", "deadlines"]) {
  check(ids.includes(id), `plot '${id}' present`);
  const p = plots.find((q) => q.id === id);
  check(p.points > 0, `plot '${id}' has ${p.points} points`);
  const inked = await page.evaluate((id) => {
    const c = document.querySelector(`#plot-${id} canvas`);
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n++;
    return n;
  }, id);
  check(inked > 500, `plot '${id}' canvas has ${inked} drawn pixels`);
}
const summary = JSON.parse(readFileSync(join(dir, "summary.json"), "utf8"));
const learning = plots.find((p) => p.id === "learning");
check(learning.points === summary.learning_curve.filter((e) => e.completion_time_s >= 0).length,
  "the learning curve has one point per completed episode");
if (process.env.IPLAN_SCREENSHOT_DIR) {
  writeFileSync(join(process.env.IPLAN_SCREENSHOT_DIR, "report.png"), await page.screenshot({ fullPage: true }));
}
await browser.close();
process.exit(0);
