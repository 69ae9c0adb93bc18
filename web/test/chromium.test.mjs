// The package in headless Chromium, driven by chromedriver: the page loads with no console
// error and renders its clip; an OfflineAudioContext render through the AudioWorklet (128-frame
// blocks, at 48 and 44.1 kHz) of the three scenes gives the CLI's f32 samples bit for bit; the
// page's rumble and vibrate calls, with the browser's APIs stubbed, follow the CLI's rumble clip;
// bad input throws clear errors, and a processor given a bad score posts an error and plays
// silence rather than failing the audio thread. Skipped where Chromium is not installed, but
// under CI, which installs it.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { fileURLToPath } from "node:url";
import { serve } from "./support/server.mjs";
import { startBrowser, missingBrowser } from "./support/webdriver.mjs";
import { cli, cliRender, workFolder, firstDifference } from "./support/cli.mjs";
import { SCENES } from "./support/scenes.mjs";

const ROOT = fileURLToPath(new URL("..", import.meta.url));
const missing = missingBrowser();
if (missing !== null && process.env.CI) {
  throw new Error(`the browser tests must run under CI: ${missing}`);
}
const skip = missing ?? false;

let server;
let browser;

before(async () => {
  if (skip) return;
  server = await serve(ROOT);
  browser = await startBrowser();
  await browser.timeouts(300_000);
  await browser.open(`${server.url}/demo/`);
  await browser.run("await window.sakeGlugDemo;");
});

after(async () => {
  await browser?.quit();
  await server?.close();
});

/** A Float32Array's bytes as base64, in the page (a script's result is JSON). */
const BASE64 = `const base64 = (samples) => {
  const bytes = new Uint8Array(samples.buffer, samples.byteOffset, samples.byteLength);
  let text = "";
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(text);
};`;

function samplesOf(base64) {
  const bytes = Buffer.from(base64, "base64");
  return new Float32Array(bytes.buffer, bytes.byteOffset, bytes.byteLength / 4);
}

test("the page loads, builds its controls and renders its clip with no console error", { skip }, async () => {
  const shown = await browser.run(`
    const $ = (id) => document.getElementById(id);
    const sliders = document.querySelectorAll("input[type=range]").length;
    const presets = $("preset").options.length;
    $("render").click();
    await window.sakeGlugPage.rendering;
    const offered = ["wav", "ahap", "haptic", "rumble", "android"].filter((kind) => $("download-" + kind).href.startsWith("blob:"));
    const ahap = JSON.parse(await (await fetch($("download-ahap").href)).text());
    return { version: $("version").textContent, sliders, presets, offered, ahapVersion: ahap.Version, status: $("render-status").textContent };`);
  assert.match(shown.version, /^engine \d+\.\d+\.\d+$/);
  assert.equal(shown.sliders, 8, "the five controls and the headspace law's three");
  assert.equal(shown.presets, 8);
  assert.deepEqual(shown.offered, ["wav", "ahap", "haptic", "rumble", "android"], "the files to download");
  assert.equal(shown.ahapVersion, 1, "an .ahap pattern");
  assert.match(shown.status, /units, rendered in/);
  const errors = (await browser.console()).filter((entry) => entry.level === "SEVERE" || entry.level === "WARNING");
  assert.deepEqual(errors, [], "the console's errors and warnings");
});

for (const scene of SCENES) {
  test(`${scene.name}: an OfflineAudioContext render through the AudioWorklet gives the CLI's samples`, { skip }, async () => {
    const got = await browser.run(
      `${BASE64}
      const { renderInContext } = await import("/src/index.js");
      const clip = await renderInContext(arguments[0]);
      return { samples: base64(clip.samples), rate: clip.buffer.sampleRate };`,
      scene.web,
    );
    const expected = cliRender(scene.cli);
    const samples = samplesOf(got.samples);
    assert.equal(got.rate, expected.sampleRate);
    assert.equal(samples.length, expected.samples.length, "length");
    assert.equal(firstDifference(samples, expected.samples), -1, "the first sample that differs from the CLI's");
  });
}

test("the page's rumble and vibrate calls follow the CLI's rumble clip, the APIs stubbed", { skip }, async () => {
  const calls = await browser.run(`
    const { renderInContext, HapticsDriver } = await import("/src/index.js");
    const effects = [];
    const patterns = [];
    const pad = { connected: true, vibrationActuator: { effects: ["dual-rumble"],
      playEffect: (type, p) => { effects.push([type, p.strongMagnitude, p.weakMagnitude]); return Promise.resolve("complete"); },
      reset: () => Promise.resolve("complete") } };
    Object.defineProperty(navigator, "getGamepads", { value: () => [pad], configurable: true });
    Object.defineProperty(navigator, "vibrate", { value: (p) => { patterns.push(p); return true; }, configurable: true });
    const clip = await renderInContext({ sampleRate: 48000 });
    let now = 0;
    const driver = new HapticsDriver({ sampleRate: 48000, clock: () => now });
    driver.add(clip.units);
    const ticks = Math.ceil(clip.samples.length / 48000 * 100);
    for (let k = 0; k < ticks; k += 1) { now = k / 100; driver.tick(); }
    return { effects, patterns: patterns.filter((p) => Array.isArray(p) && p.length > 0).length };`);
  const folder = workFolder("page-rumble");
  cli(["render", "-o", "rumble:rumble.json"], folder);
  const rumble = JSON.parse(readFileSync(join(folder, "rumble.json"), "utf8"));
  assert.equal(calls.effects.length, rumble.frames.length, "one effect a frame");
  calls.effects.forEach(([type, strong, weak], k) => {
    assert.equal(type, "dual-rumble");
    assert.ok(Math.abs(strong - rumble.frames[k].low) <= 1.0001e-4, `frame ${k}: strong ${strong}, the clip's low ${rumble.frames[k].low}`);
    assert.ok(Math.abs(weak - rumble.frames[k].high) <= 1.0001e-4, `frame ${k}: weak ${weak}, the clip's high ${rumble.frames[k].high}`);
  });
  assert.ok(calls.patterns > 10, "navigator.vibrate played the glugs");
});

test("bad input throws clear errors in the page, and a bad score silences only its node", { skip }, async () => {
  const seen = await browser.run(`
    const { createBottleNode, loadSakeGlug } = await import("/src/index.js");
    const module = await loadSakeGlug();
    const context = new OfflineAudioContext({ numberOfChannels: 1, length: 48000, sampleRate: 48000 });
    const message = async (promise) => { try { await promise; return "no error"; } catch (error) { return error.name + ": " + error.message; } };
    const model = await message(createBottleNode(context, { model: "[glug]\\nf1_hz = [" }));
    const preset = await message(createBottleNode(context, { preset: "beer" }));
    const node = await createBottleNode(context, { controls: { tilt: 135 } });
    node.connect(context.destination);
    const nan = await message((async () => node.set("tilt", NaN))());
    const range = await message((async () => node.ramp("visc", 2, 0.1))());
    const param = await message((async () => { node.tilt.value = NaN; })());
    // A score the page did not check, straight to the processor: it posts why, and plays silence.
    const raw = new AudioWorkletNode(context, "sake-glug", { numberOfInputs: 0, numberOfOutputs: 1, outputChannelCount: [1],
      processorOptions: { module, score: [{ frame: 0, op: "set", control: "tilt", value: NaN }] } });
    const refused = new Promise((resolve) => { raw.port.onmessage = (event) => { if (event.data.type === "error") resolve(event.data); }; });
    // A processor that threw instead: the audio thread's error, at once.
    const threw = new Promise((resolve) => { raw.onprocessorerror = () => resolve({ message: "processorerror", fatal: false }); });
    raw.connect(context.destination);
    const buffer = await context.startRendering();
    const error = await Promise.race([refused, threw]);
    const samples = buffer.getChannelData(0);
    return { model, preset, nan, range, param, error, glugs: samples.some((y) => y !== 0) };`);
  assert.match(seen.model, /^Error: model text: .*line 2/);
  assert.match(seen.preset, /^Error: no preset `beer`/);
  assert.match(seen.nan, /^TypeError: sake-glug: Tilt \(tilt\): NaN is not a finite number/);
  assert.match(seen.range, /^RangeError: sake-glug: Viscosity \(visc\): 2 is outside its range/);
  assert.match(seen.param, /^TypeError: .*non-finite/);
  assert.match(seen.error.message, /Tilt \(tilt\): NaN is not a finite number/);
  assert.equal(seen.error.fatal, true);
  assert.ok(seen.glugs, "the good node still glugs beside the silenced one");
});
