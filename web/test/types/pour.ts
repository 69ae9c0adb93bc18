// A web developer's code against the package's types (src/index.d.ts), checked by `tsc --noEmit`
// in types.test.mjs with the packed tarball installed: first the README's ten lines as they are,
// then more of the API, then calls the types must refuse (each `@ts-expect-error` fails the check
// if its line compiles).

import { createBottleNode } from "sake-glug";
import {
  clip,
  Glug,
  HapticsDriver,
  loadSakeGlug,
  PRESETS,
  render,
  renderInContext,
  renderToWav,
  type Call,
  type GlugState,
  type Rendered,
  type Scene,
  type Unit,
} from "sake-glug";

// What the README's example takes from its page.
declare const slider: HTMLInputElement;
declare const refillButton: HTMLButtonElement;

// The README's ten lines.
const context = new AudioContext();        // after a click: browsers start audio on a gesture
const bottle = await createBottleNode(context, { preset: "sake", controls: { tilt: 90 } });
bottle.connect(context.destination);
bottle.ramp("tilt", 135, 0.5);             // pour: 90° to 135° over half a second
bottle.addEventListener("units", (e) => console.log(e.detail.units.length, "glugs"));
slider.oninput = () => (bottle.tilt.value = slider.valueAsNumber);   // or drive the AudioParam
refillButton.onclick = () => bottle.refill();

// The events' details, the node's state and its calls at a context time.
bottle.addEventListener("state", (e) => {
  const volume: number = e.detail.volumeMl;
  const frame: number = e.detail.frame;
  console.log(volume, frame);
});
bottle.addEventListener("error", (e) => console.log(e.detail.message, e.detail.fatal));
const state: GlugState | null = bottle.state;
bottle.set("visc", 0.5, context.currentTime + 1);
bottle.param("output.gain_db").value = -6;
bottle.reset();

// Offline renders and the engine itself.
const score: Call[] = [
  { frame: 0, op: "set", control: "tilt_deg", value: 135 },
  { frame: 4800, op: "ramp", control: "gain", value: -12, frames: 4800 },
  { frame: 9600, op: "refill" },
];
const scene: Scene = { sampleRate: 44100, preset: PRESETS[0].id, score, seconds: 2 };
const rendered: Rendered = await render(scene, { blockFrames: 128 });
const wav: Uint8Array = await renderToWav({ sampleRate: 48000 });
const inContext = await renderInContext(scene);
const buffer: AudioBuffer | null = inContext.buffer;
await loadSakeGlug();
const glug = Glug.create({ sampleRate: 48000, seed: 7 });
const block: Float32Array = glug.process(128);
const units: Unit[] = glug.units();
glug.free();

// Haptics from the units.
const haptics = new HapticsDriver({ sampleRate: 48000, clock: () => context.currentTime });
haptics.add(rendered.units);
const tick = haptics.tick();
const ahap: string = clip("ahap", rendered.units, { durationS: rendered.samples.length / 48000 });

console.log(state, wav.length, buffer, block.length, units.length, tick.low, ahap.length);

// What the types refuse.
// @ts-expect-error: a control the engine does not have
bottle.set("tilt_degrees", 100);
// @ts-expect-error: a ramp's length is in seconds, a number
bottle.ramp("tilt", 135, "0.5");
// @ts-expect-error: a score's call names its op
const stray: Call = { frame: 0, control: "tilt", value: 1 };
// @ts-expect-error: a ramp has a length in frames
const rampless: Call = { frame: 0, op: "ramp", control: "tilt", value: 1 };
// @ts-expect-error: the units event's detail holds units, not samples
bottle.addEventListener("units", (e) => e.detail.samples);
// @ts-expect-error: the node is created on a context
await createBottleNode({ sampleRate: 48000 });
console.log(stray, rampless);
