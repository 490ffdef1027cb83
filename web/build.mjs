// Builds web/dist from web/src and the npm packages (npm ci first): the
// viewer page bundled by esbuild (three.js, @foxglove/ws-protocol,
// @mcap/core; nothing is fetched at run time), and the Foxglove JSON schemas
// the C++ server advertises (from @foxglove/schemas).
import { build } from "esbuild";
import { mkdirSync, copyFileSync, writeFileSync } from "node:fs";
import { createRequire } from "node:module";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const dist = join(here, "dist");
mkdirSync(join(dist, "schemas"), { recursive: true });

await build({
  entryPoints: [join(here, "src/viewer.js")],
  bundle: true,
  format: "esm",
  target: "es2020",
  minify: true,
  sourcemap: false,
  outfile: join(dist, "viewer.js"),
  logLevel: "warning",
});
copyFileSync(join(here, "src/index.html"), join(dist, "index.html"));
copyFileSync(join(here, "src/viewer.css"), join(dist, "viewer.css"));

const schemas = createRequire(import.meta.url)("@foxglove/schemas/jsonschema");
for (const name of ["SceneUpdate"]) {
  writeFileSync(join(dist, "schemas", `foxglove.${name}.json`), JSON.stringify(schemas[name]));
}
console.log("web: built", dist);
