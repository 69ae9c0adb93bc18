// Bad input gets a clear JavaScript error, and never aborts the WebAssembly instance: after every
// refusal the same glug, and new ones, still play the CLI's samples.

import { test } from "node:test";
import assert from "node:assert/strict";
import { loadSakeGlug, Glug, render, renderLoaded, ScorePlayer, limits, modelText } from "../src/index.js";
import { cliRender, firstDifference } from "./support/cli.mjs";

await loadSakeGlug();

test("a broken model text, an unknown preset and bad numbers are refused with what is wrong", () => {
  const refusals = [
    [() => Glug.create({ model: "[bottle]\ncapacity_ml = [" }), Error, /^model text: .*line 2/],
    [() => Glug.create({ model: "[bottle]\nwidth_mm = 70.0\n" }), Error, /width_mm/],
    [() => Glug.create({ model: "tilt_deg = [[0.0, 90.0], [1.0, 135.0]]\n" }), Error, /tilt_deg/],
    [() => Glug.create({ model: 42 }), TypeError, /text of a model file/],
    [() => Glug.create({ preset: "beer" }), Error, /no preset `beer`.*syrup/],
    [() => Glug.create({ model: "", preset: "water" }), TypeError, /not both/],
    [() => Glug.create({ sampleRate: NaN }), Error, /sample_rate/],
    [() => Glug.create({ sampleRate: 44100.5 }), Error, /whole number/],
    [() => Glug.create({ sampleRate: 10 }), Error, /sample_rate/],
    [() => Glug.create({ seed: -1 }), Error, /seed/],
    [() => Glug.create({ seed: 0.5 }), Error, /seed/],
  ];
  for (const [call, kind, message] of refusals) {
    assert.throws(call, (error) => error instanceof kind && message.test(error.message), String(call));
  }
});

test("a NaN or out-of-range control, a huge block and a bad ramp are refused, and the glug plays on", () => {
  const glug = Glug.create({ sampleRate: 48000 });
  const { maxBlockFrames } = limits();
  assert.throws(() => glug.set("tilt", NaN), /Tilt \(tilt\): the value NaN is not a finite number; it takes 0 to 180/);
  assert.throws(() => glug.set("visc", Infinity), /Viscosity \(visc\).*not a finite number/);
  assert.throws(() => glug.set("fill", 101), /Fill level \(fill\).*outside its range, 0 to 100/);
  assert.throws(() => glug.set("tilt", "steep"), /not a finite number/);
  assert.throws(() => glug.set("angle", 90), (error) => error instanceof TypeError && /no control "angle": the controls are tilt, visc, fill, pour, gain/.test(error.message));
  assert.throws(() => glug.ramp("tilt", 135, -1), /ramp's length/);
  assert.throws(() => glug.ramp("tilt", 135, 2 ** 60), /ramp's length/);
  for (const frames of [maxBlockFrames + 1, 1e12, -1, 12.5, NaN, Infinity]) {
    assert.throws(() => glug.process(frames), /a block is a whole number of frames from 0 to 16384/, String(frames));
  }
  assert.throws(() => glug.setActuator("[response]\nfrequencies_hz = 3\n"), /Error: actuator profile: invalid actuator profile/);
  // Still the built-in pour, bit for bit.
  glug.set("tilt", 90);
  glug.ramp("tilt", 135, 24000);
  const out = [];
  while (!(glug.settled && glug.position > 0)) out.push(...glug.process(maxBlockFrames));
  const samples = Float32Array.from(out).subarray(0, glug.activeUntil);
  glug.free();
  assert.equal(firstDifference(samples, cliRender().samples), -1);
});

test("a score with a bad call is refused before anything plays", () => {
  const bad = [
    [{ frame: 0, op: "set", control: "tilt", value: NaN }, /Tilt \(tilt\): NaN is not a finite number/],
    [{ frame: 0, op: "set", control: "tilt", value: 200 }, /outside its range, 0 to 180/],
    [{ frame: -1, op: "refill" }, /frame is a whole number/],
    [{ frame: 0, op: "ramp", control: "tilt", value: 135, frames: 0.5 }, /ramp's length/],
    [{ frame: 0, op: "pour" }, /no call "pour"/],
    [{ frame: 0, op: "set", control: "angle", value: 1 }, /no control "angle"/],
    [null, /a score's call is an object/],
  ];
  for (const [call, message] of bad) {
    assert.throws(() => renderLoaded({ score: [call] }), message, JSON.stringify(call));
  }
  assert.throws(() => renderLoaded({ score: "pour" }), /array of calls/);
  assert.throws(() => renderLoaded({ seconds: -1 }), /finite number from 0/);
  assert.throws(() => renderLoaded({}, { blockFrames: 1e9 }), /blocks of 1 to 16384 frames/);
  assert.throws(() => modelText({ viscosity_c: "thick" }), /not a number/);
  const glug = Glug.create({});
  assert.throws(() => new ScorePlayer(glug, [{ op: "set", control: "tilt", value: -5 }]), /outside its range/);
  glug.free();
});

test("after every refusal a new glug still renders the CLI's samples", async () => {
  const { samples } = await render({ sampleRate: 48000 });
  assert.equal(firstDifference(samples, cliRender().samples), -1);
});
