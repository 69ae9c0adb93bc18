// The packed tarball, installed into an empty folder as a web developer installs it, renders the
// default scene to the CLI's samples, bit for bit, and writes the CLI's WAV file, byte for byte;
// it carries its .wasm, types, README, licence and third-party notices.

import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { cliRender, workFolder, readWav, firstDifference } from "./support/cli.mjs";

const TARBALL = process.env.SAKE_GLUG_TARBALL;

test("the packed tarball installs into an empty folder and renders the CLI's default scene", (t) => {
  if (!TARBALL) {
    t.skip("SAKE_GLUG_TARBALL names no tarball: run these tests with `cargo xtask web test`");
    return;
  }
  const folder = workFolder("npm-install");
  writeFileSync(join(folder, "package.json"), JSON.stringify({ name: "a-game", private: true, type: "module" }));
  execFileSync("npm", ["install", "--no-audit", "--no-fund", "--offline", TARBALL], { cwd: folder, stdio: "pipe" });
  const installed = join(folder, "node_modules", "sake-glug");
  for (const file of [
    "README.md",
    "dist/LICENSE",
    "dist/THIRD-PARTY.md",
    "dist/sake_glug_web_bg.wasm",
    "src/index.d.ts",
    "src/worklet.js",
    "demo/index.html",
  ]) {
    assert.ok(existsSync(join(installed, file)), `the package holds ${file}`);
  }
  assert.match(readFileSync(join(installed, "dist/LICENSE"), "utf8"), /^ISC License/);
  // The README's example, as a user would run it, from the folder that installed the package.
  writeFileSync(
    join(folder, "render.mjs"),
    `import { writeFileSync } from "node:fs";
import { renderToWav, loadSakeGlug, version } from "sake-glug";
writeFileSync("pour.wav", await renderToWav({ sampleRate: 48000 }));
console.log(version());
`,
  );
  const printed = execFileSync("node", ["render.mjs"], { cwd: folder, encoding: "utf8" }).trim();
  const manifest = JSON.parse(readFileSync(join(installed, "package.json"), "utf8"));
  assert.equal(printed, manifest.version, "the engine's version is the package's");
  const bytes = readFileSync(join(folder, "pour.wav"));
  const cli = cliRender();
  const { samples } = readWav(bytes);
  assert.equal(firstDifference(samples, cli.samples), -1, "the first sample that differs from the CLI's");
  assert.ok(samples.some((y) => y !== 0), "it glugs");
  assert.ok(bytes.equals(cli.bytes), "the WAV file is the CLI's, byte for byte");
});
