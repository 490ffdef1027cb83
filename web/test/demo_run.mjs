// Fixture of the replay and report tests: one demo episode of the real cell,
// recorded (iplan demo --record) with its summary and report, into
// $IPLAN_VIEWER_RUN_DIR.
import { existsSync, mkdirSync, rmSync } from "node:fs";
import { join } from "node:path";
import { Proc, cellKeystore, check, env, tempDir, uniqueDomain } from "./support.mjs";

const bin = env("IPLAN_BIN_DIR"), source = env("IPLAN_SOURCE_DIR"), dir = env("IPLAN_VIEWER_RUN_DIR");
rmSync(dir, { recursive: true, force: true });
mkdirSync(dir, { recursive: true });
// Secured (the demo's default), with a keystore of the test's own.
const demo = new Proc([join(bin, "iplan"), "demo", "--episodes", "1", "--domain", String(uniqueDomain(37)),
  "--config-dir", join(source, "config"), "--state-dir", tempDir("viewer-run"),
  "--security", await cellKeystore(bin, "viewer-run-keys"),
  "--record", join(dir, "recording.mcap"), "--summary", join(dir, "summary.json")], "iplan demo");
const code = await demo.exited;
console.log(demo.out);
check(code === 0, `iplan demo --record exits 0 (${code})`);
for (const f of ["recording.mcap", "recording.mcap.stats.json", "summary.json", "summary.html"]) {
  check(existsSync(join(dir, f)), `${f} written`);
}
check(/report written to .*summary\.html/.test(demo.out), "iplan demo prints where its report is");
process.exit(0);
