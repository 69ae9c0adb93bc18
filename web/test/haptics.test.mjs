// Haptics from the units, checked against the CLI's clips of the same render (the renderer's
// mappings, crates/render/src/steps.rs): the dual-rumble frames (low = the f1 component's
// envelope, high = the f2 component's) and the Android waveform steps; and the live driver's
// calls to a gamepad's vibrationActuator and to navigator.vibrate, with both stubbed (there is no
// gamepad here), following those frames and steps.

import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import {
  render,
  rumbleFrames,
  androidSteps,
  vibratePattern,
  HapticsDriver,
  RUMBLE_RATE_HZ,
  clip,
  clipFormats,
} from "../src/index.js";
import { cli, workFolder } from "./support/cli.mjs";
import { SCENES } from "./support/scenes.mjs";

/** The CLI's rumble and Android waveform files of a scene, and the package's render of it. */
async function clips(scene) {
  const folder = workFolder("clips");
  const args = [...(scene.cli.args ?? [])];
  if (scene.cli.model !== undefined) throw new Error("a scene without a model file");
  cli(["render", ...args, "-o", "rumble:rumble.json", "-o", "android-waveform:android.json"], folder);
  const read = (name) => JSON.parse(readFileSync(join(folder, name), "utf8"));
  const rendered = await render(scene.web);
  return {
    rumble: read("rumble.json"),
    android: read("android.json"),
    units: rendered.units,
    sampleRate: rendered.sampleRate,
    durationS: rendered.samples.length / rendered.sampleRate,
  };
}

/** Rounded as the rumble file writes its numbers. */
const rounded = (x) => Math.round(x * 1e4) / 1e4;

/** A gamepad whose vibrationActuator records what it is asked to play. */
function stubGamepad() {
  const played = [];
  return {
    played,
    pad: {
      connected: true,
      vibrationActuator: {
        effects: ["dual-rumble", "trigger-rumble"],
        playEffect: (type, params) => {
          played.push({ type, ...params });
          return Promise.resolve("complete");
        },
        reset: () => Promise.resolve("complete"),
      },
    },
  };
}

for (const scene of SCENES.filter((s) => s.cli.model === undefined)) {
  test(`${scene.name}: the rumble frames and Android steps are the CLI's clips`, async () => {
    const { rumble, android, units, sampleRate, durationS } = await clips(scene);
    const frames = rumbleFrames(units, { sampleRate, durationS });
    assert.equal(rumble.rate_hz, RUMBLE_RATE_HZ);
    assert.equal(frames.length, rumble.frames.length, "frames");
    frames.forEach((frame, k) => {
      const theirs = rumble.frames[k];
      assert.equal(rounded(frame.tMs), theirs.t_ms, `frame ${k}: its time`);
      // The same numbers to the file's 4 decimals (a last-bit difference in exp may move one
      // rounding by a step).
      assert.ok(Math.abs(rounded(frame.low) - theirs.low) <= 1.0001e-4, `frame ${k}: low ${frame.low}, the CLI's ${theirs.low}`);
      assert.ok(Math.abs(rounded(frame.high) - theirs.high) <= 1.0001e-4, `frame ${k}: high ${frame.high}, the CLI's ${theirs.high}`);
    });
    assert.ok(frames.some((f) => f.low > 0.05) && frames.some((f) => f.high > 0.05), "both motors run");
    const steps = androidSteps(units, { sampleRate, durationS });
    assert.deepEqual(
      steps.map((s) => s.durationMs),
      android.timings,
      "the steps' timings",
    );
    steps.forEach((step, k) => {
      assert.ok(Math.abs(step.amplitude - android.amplitudes[k]) <= 1, `step ${k}: amplitude ${step.amplitude}, the CLI's ${android.amplitudes[k]}`);
    });
    const exact = steps.filter((s, k) => s.amplitude === android.amplitudes[k]).length;
    assert.ok(exact >= steps.length - 2, `${steps.length - exact} steps' amplitudes off by one`);
  });
}

test("a vibrate pattern plays each Android step as a pulse of its amplitude's share", () => {
  const steps = [
    { startMs: 0, durationMs: 183, amplitude: 0, onset: false },
    { startMs: 183, durationMs: 10, amplitude: 255, onset: true },
    { startMs: 193, durationMs: 10, amplitude: 128, onset: false },
    { startMs: 203, durationMs: 10, amplitude: 200, onset: false },
    { startMs: 213, durationMs: 40, amplitude: 0, onset: false },
  ];
  // 0 on, 183 off, 10 + 5 on (255, then 128 of 255 of 10 ms), 5 off, 8 on (200: 7.8 ms),
  // 2 + 40 off.
  assert.deepEqual(vibratePattern(steps), [0, 183, 15, 5, 8, 42]);
  assert.deepEqual(vibratePattern([{ startMs: 0, durationMs: 50, amplitude: 0, onset: false }]), []);
});

test("the live driver's rumble and vibrate calls follow the units, with the APIs stubbed", async () => {
  const { rumble, units, sampleRate, durationS } = await clips(SCENES[0]);
  const { pad, played } = stubGamepad();
  const vibrations = [];
  let now = 0;
  const known = [];
  const navigator = {
    getGamepads: () => [null, pad],
    vibrate: (pattern) => {
      vibrations.push({ pattern, t: now, known: [...known] });
      return true;
    },
  };
  const driver = new HapticsDriver({ sampleRate, clock: () => now, navigator, vibrateWindowMs: 200 });
  assert.deepEqual(driver.available, { gamepad: true, vibrate: true });
  // The units arrive as a node posts them: each block's before the block is heard.
  const pending = [...units];
  const ticks = Math.ceil(durationS * RUMBLE_RATE_HZ);
  for (let k = 0; k < ticks; k += 1) {
    now = k / RUMBLE_RATE_HZ;
    const ahead = pending.filter((u) => u.timeS < now + 0.01);
    pending.splice(0, ahead.length);
    known.push(...ahead);
    driver.add(ahead);
    driver.tick();
  }
  assert.equal(played.length, ticks, "one dual-rumble effect a frame");
  played.forEach((effect, k) => {
    assert.equal(effect.type, "dual-rumble");
    const theirs = rumble.frames[k];
    assert.ok(Math.abs(effect.strongMagnitude - theirs.low) <= 1.0001e-4, `frame ${k}: strong ${effect.strongMagnitude}, the file's low ${theirs.low}`);
    assert.ok(Math.abs(effect.weakMagnitude - theirs.high) <= 1.0001e-4, `frame ${k}: weak ${effect.weakMagnitude}, the file's high ${theirs.high}`);
    assert.ok(effect.duration > 0 && effect.startDelay === 0);
  });
  // A pattern whenever units come and at least every 200 ms: the next 200 ms of the steps of
  // the units known then, from then on.
  const onsets = new Set(units.map((u) => Math.floor(u.timeS * RUMBLE_RATE_HZ + 1)));
  assert.ok(vibrations.length >= onsets.size && vibrations.length <= onsets.size + ticks / 20 + 1, "a pattern when units come, else a window");
  vibrations.forEach(({ pattern, t, known }, w) => {
    const window = known.map((u) => ({ ...u, timeS: u.timeS - t }));
    const expected = vibratePattern(androidSteps(window, { sampleRate, durationS: 0.2 }));
    assert.deepEqual(pattern, expected.length > 0 ? expected : 0, `pattern ${w} at ${t} s`);
  });
  assert.ok(vibrations.some(({ pattern }) => Array.isArray(pattern) && pattern.length > 2), "it vibrates while it glugs");
  driver.stop();
  assert.equal(vibrations.at(-1).pattern, 0, "stop stops the vibrator");
});

test("without a gamepad or a vibrator the driver calls nothing and fails nothing", () => {
  for (const navigator of [undefined, {}, { getGamepads: () => [null, null] }, { getGamepads: () => [{ connected: true }] }]) {
    const driver = new HapticsDriver({ sampleRate: 48000, clock: () => 0, navigator });
    driver.add([{ timeS: 0, amplitude: 0.5, viscosityC: 0.33, b1PerS: 45, b2PerS: 40 }]);
    const played = driver.tick();
    assert.equal(played.pads, 0);
    assert.equal(played.pattern, null);
    assert.ok(played.low > 0 && played.high > 0, "the envelope is still there for a page to show");
    driver.stop();
  }
});

/** Two JSON values alike, their numbers within `tolerance` of each other (relative). */
function assertAlike(ours, theirs, tolerance, where) {
  if (typeof theirs === "number") {
    assert.ok(Math.abs(ours - theirs) <= tolerance * Math.abs(theirs), `${where}: ${ours}, the CLI's ${theirs}`);
  } else if (theirs !== null && typeof theirs === "object") {
    assert.deepEqual(Object.keys(ours), Object.keys(theirs), `${where}: keys`);
    for (const key of Object.keys(theirs)) assertAlike(ours[key], theirs[key], tolerance, `${where}.${key}`);
  } else {
    assert.equal(ours, theirs, where);
  }
}

test("the clips the package writes are the CLI's: rumble and Android's byte for byte, .ahap, .haptic and .haps to an f64's last bits", async () => {
  const folder = workFolder("clip-files");
  const files = {
    ahap: "c.ahap",
    haptic: "c.haptic",
    rumble: "c.rumble.json",
    "android-waveform": "c.android.json",
    "android-xml": "c.xml",
    haps: "c.haps",
  };
  assert.deepEqual(clipFormats(), Object.keys(files));
  cli(["render", ...Object.entries(files).flatMap(([format, file]) => ["-o", `${format}:${file}`])], folder);
  const { samples, units, sampleRate } = await render({ sampleRate: 48000 });
  const durationS = samples.length / sampleRate;
  for (const [format, file] of Object.entries(files)) {
    const ours = clip(format, units, { durationS, name: "default", seed: 1 });
    const theirs = readFileSync(join(folder, file), "utf8");
    if (["rumble", "android-waveform", "android-xml"].includes(format)) {
      assert.equal(ours, theirs, `${format}: the CLI's bytes`);
    } else {
      // A unit's heard amplitude is G·a here, the CLI multiplies c·a by G: the last bits differ.
      assertAlike(JSON.parse(ours), JSON.parse(theirs), 1e-14, format);
    }
  }
  assert.throws(() => clip("wav", units, { durationS }), /no clip format `wav`: the page writes ahap, haptic/);
  assert.throws(() => clip("ahap", units, { durationS: NaN }), /a clip lasts a finite number of seconds/);
});
