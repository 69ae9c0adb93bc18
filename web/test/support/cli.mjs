// The release CLI (`cargo xtask test` passes its path in SAKE_GLUG_CLI) and its WAV files, which
// the package's renders are compared with.

import { execFileSync } from "node:child_process";
import { mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

export const CLI = process.env.SAKE_GLUG_CLI;

/** A fresh folder under the xtask's work folder (or the system's). */
export function workFolder(name) {
  return mkdtempSync(join(process.env.SAKE_GLUG_WORK ?? tmpdir(), `${name}-`));
}

/** Runs the CLI with `args` in `folder`; returns its stdout. */
export function cli(args, folder) {
  if (!CLI) throw new Error("SAKE_GLUG_CLI names no CLI: run these tests with `cargo xtask web test`");
  return execFileSync(CLI, args, { cwd: folder, encoding: "utf8", stdio: ["ignore", "pipe", "pipe"] });
}

/**
 * The CLI's render of a scene: `{ bytes, samples, sampleRate }` of its f32 WAV. `scene` (a scene
 * file's text) and `model` (a model file's text) are written beside it; `args` are more options.
 */
export function cliRender({ scene, model, args = [] } = {}, folder = workFolder("cli")) {
  const options = [...args];
  if (model !== undefined) {
    writeFileSync(join(folder, "model.toml"), model);
    options.push("--model", "model.toml");
  }
  if (scene !== undefined) {
    writeFileSync(join(folder, "scene.toml"), scene);
    options.push("scene.toml");
  }
  cli(["render", ...options, "-o", "out.wav"], folder);
  const bytes = readFileSync(join(folder, "out.wav"));
  return { bytes, ...readWav(bytes) };
}

/** The samples and rate of a mono f32 WAV file. */
export function readWav(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const sampleRate = view.getUint32(24, true);
  let at = 12;
  while (at + 8 <= bytes.length) {
    const id = String.fromCharCode(...bytes.subarray(at, at + 4));
    const size = view.getUint32(at + 4, true);
    if (id === "data") {
      const samples = new Float32Array(size / 4);
      for (let i = 0; i < samples.length; i += 1) samples[i] = view.getFloat32(at + 8 + 4 * i, true);
      return { samples, sampleRate };
    }
    at += 8 + size + (size & 1);
  }
  throw new Error("no data chunk");
}

/** Where two sample arrays first differ in their bits (-1: nowhere), and their lengths. */
export function firstDifference(a, b) {
  const bitsA = new Uint32Array(a.buffer, a.byteOffset, a.length);
  const bitsB = new Uint32Array(b.buffer, b.byteOffset, b.length);
  const n = Math.min(a.length, b.length);
  for (let i = 0; i < n; i += 1) if (bitsA[i] !== bitsB[i]) return i;
  return a.length === b.length ? -1 : n;
}
