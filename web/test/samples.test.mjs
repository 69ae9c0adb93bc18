// The engine in WebAssembly gives the CLI's f32 samples, bit for bit: the three scenes of
// support/scenes.mjs in an AudioWorklet's 128-frame blocks and in blocks of 4096, at 44.1 and
// 48 kHz, calls inside blocks acting at their very samples; and its units are the renderer's.

import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { render, builtInPour } from "../src/index.js";
import { cli, cliRender, workFolder, firstDifference } from "./support/cli.mjs";
import { SCENES } from "./support/scenes.mjs";

for (const scene of SCENES) {
  test(`${scene.name}: the CLI's samples in blocks of 128 and 4096 frames`, async () => {
    const expected = cliRender(scene.cli);
    assert.equal(expected.sampleRate, scene.web.sampleRate);
    for (const blockFrames of [128, 4096]) {
      const { samples } = await render(scene.web, { blockFrames });
      assert.equal(samples.length, expected.samples.length, `blocks of ${blockFrames}: length`);
      assert.equal(firstDifference(samples, expected.samples), -1, `blocks of ${blockFrames}: the first sample that differs`);
    }
    assert.ok(expected.samples.some((y) => y !== 0), "it glugs");
  });
}

for (const sampleRate of [44100, 48000]) {
  test(`the built-in pour at ${sampleRate} Hz in 128-frame blocks: the CLI's samples and units`, async () => {
    const folder = workFolder("units");
    cli(["render", "--sample-rate", String(sampleRate), "-o", "out.wav", "--units", "units.csv"], folder);
    const expected = cliRender({ args: ["--sample-rate", String(sampleRate)] });
    const { samples, units } = await render({ sampleRate, score: builtInPour(sampleRate) }, { blockFrames: 128 });
    assert.equal(firstDifference(samples, expected.samples), -1, "the first sample that differs");
    const [header, ...rows] = readFileSync(join(folder, "units.csv"), "utf8").trim().split("\n");
    const column = header.split(",");
    assert.equal(units.length, rows.length, "units");
    rows.forEach((row, i) => {
      const cells = row.split(",");
      const cell = (name) => Number(cells[column.indexOf(name)]);
      const unit = units[i];
      // Where and when a unit starts is exact arithmetic: the same bits.
      assert.equal(unit.timeS, cell("onset_s"), `unit ${i}: its onset`);
      assert.equal(unit.volumeMl, cell("volume_ml"), `unit ${i}: V`);
      assert.equal(unit.audible, cell("audible") === 1, `unit ${i}: audible`);
      // Its draws go through exp, ln and powf: glibc's natively, Rust's libm in WebAssembly,
      // which differ in an f64's last bit now and then (B1 of the default pour's second unit,
      // by one ulp); the samples are still the same bits (the tests above).
      const near = (a, b) => Math.abs(a - b) <= 1e-12 * Math.abs(b);
      for (const [field, key] of [
        ["f1Hz", "f1_hz"],
        ["f2Hz", "f2_hz"],
        ["b1PerS", "b1_per_s"],
        ["b2PerS", "b2_per_s"],
        ["viscosityC", "viscosity_c"],
      ]) {
        assert.ok(near(unit[field], cell(key)), `unit ${i}: ${field} ${unit[field]}, the CLI's ${cell(key)}`);
      }
      assert.ok(near(unit.viscosityC * unit.amplitude, cell("a1")), `unit ${i}: a1`);
      assert.ok(near((1 - unit.viscosityC) * unit.amplitude, cell("a2")), `unit ${i}: a2`);
    });
  });
}
