// Shared by the browser and Foxglove-client tests: real processes (the iplan
// tool and the cell's services from the build), a real headless Chromium
// (Debian's, driven by playwright-core), and small assertion helpers.
import { spawn } from "node:child_process";
import { existsSync, mkdirSync, mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

export const SKIP = 77;  // ctest SKIP_RETURN_CODE

export function env(name) {
  const v = process.env[name];
  if (!v) fail(`${name} is not set (the test is run by ctest)`);
  return v;
}

export function fail(message) {
  console.error(`FAIL: ${message}`);
  process.exit(1);
}

export function check(cond, message) {
  if (!cond) fail(message);
  console.log(`ok: ${message}`);
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

export async function waitFor(what, fn, timeoutMs, everyMs = 200) {
  const end = Date.now() + timeoutMs;
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (Date.now() > end) fail(`timed out after ${timeoutMs / 1000} s waiting for ${what}`);
    await sleep(everyMs);
  }
}

/** A child process whose output is kept (and shown when the test fails). */
export class Proc {
  constructor(argv, name) {
    this.name = name;
    this.out = "";
    this.p = spawn(argv[0], argv.slice(1), { stdio: ["ignore", "pipe", "pipe"] });
    this.p.stdout.on("data", (d) => { this.out += d; });
    this.p.stderr.on("data", (d) => { this.out += d; });
    this.exited = new Promise((r) => this.p.on("exit", (code, sig) => r(code ?? 128)));
    process.on("exit", () => { try { this.p.kill("SIGKILL"); } catch {} });
  }
  async waitOutput(re, timeoutMs) {
    return waitFor(`${this.name} to print ${re}`, () => re.exec(this.out), timeoutMs);
  }
  async stop(sig = "SIGTERM", timeoutMs = 30000) {
    this.p.kill(sig);
    const code = await Promise.race([this.exited, sleep(timeoutMs).then(() => "timeout")]);
    if (code === "timeout") fail(`${this.name} did not stop within ${timeoutMs / 1000} s:\n${this.out}`);
    return code;
  }
}

/** Starts `iplan view` on a free port; returns { proc, url, port }. */
export async function startViewer(bin, args) {
  const proc = new Proc([join(bin, "iplan"), "view", "--port", "0", ...args], "iplan view");
  const m = await proc.waitOutput(/open (http:\/\/[^:]+:(\d+)\/\S*)/, 30000);
  return { proc, url: m[1], port: Number(m[2]) };
}

export const CHROMIUM = process.env.IPLAN_CHROMIUM || "/usr/bin/chromium";

/** Exits with SKIP when there is no Chromium; else launches it headless. */
export async function launchBrowser() {
  if (!existsSync(CHROMIUM)) {
    console.log(`SKIP: no Chromium at ${CHROMIUM} (scripts/setup.sh installs Debian's chromium)`);
    process.exit(SKIP);
  }
  const { chromium } = await import("playwright-core");
  // As root on a closed network Chromium needs these, or it fails to
  // connect. playwright gives every launch a fresh profile of its own (it
  // refuses --user-data-dir in args).
  return chromium.launch({ executablePath: CHROMIUM, headless: true, args: ["--headless", "--no-sandbox",
    "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking", "--disable-component-update",
    "--disable-sync", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"] });
}

export function tempDir(tag) {
  const d = mkdtempSync(join(tmpdir(), `iplan-${tag}-`));
  mkdirSync(d, { recursive: true });
  return d;
}

/** A DDS Security keystore of this test's own (`iplan security create-keystore`): the
 * demo cell runs secured by default, and a viewer must hold the cell's observer enclave. */
export async function cellKeystore(bin, tag) {
  const dir = join(tempDir(tag), "keystore");
  const p = new Proc([join(bin, "iplan"), "security", "create-keystore", dir], "iplan security");
  if (await p.exited !== 0) fail(`cannot create a keystore:\n${p.out}`);
  return dir;
}

/** A DDS domain of this test's own (as tests/support/test_paths.h does). */
export function uniqueDomain(offset = 0) {
  return 1 + ((process.pid * 7 + offset) % 200);
}
