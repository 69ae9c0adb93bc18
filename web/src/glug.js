// The engine in WebAssembly, loaded once per JavaScript realm (the page, an AudioWorklet's scope,
// Node.js), and `Glug`: one live glug, what the C library's handle is, with JavaScript names.

import "./text-coding.js";
import {
  initSync,
  Glug as WasmGlug,
  maxBlockFrames,
  maxUnits,
  unitFields,
  version as wasmVersion,
  tiltFromGravity as wasmTiltFromGravity,
  clip as wasmClip,
  clipFormats as wasmClipFormats,
  clipUnitFields,
} from "../dist/sake_glug_web.js";
import { CONTROLS, PRESETS, CONSTANTS, VERSION } from "../dist/tables.js";

export { CONTROLS, PRESETS, CONSTANTS, VERSION };

/** The WebAssembly instance's exports (its memory) once loaded in this realm. */
let loaded = null;
/** The compiled module, once compiled in this realm. */
let compiled = null;
/** The numbers of a unit's row, once loaded. */
let fields = null;

/** Whether this realm is Node.js. */
const isNode = typeof process !== "undefined" && process.versions != null && process.versions.node != null;

/** The .wasm beside the glue, as the package holds it (made on use: a worklet has no URL). */
export function wasmUrl() {
  return new URL("../dist/sake_glug_web_bg.wasm", import.meta.url);
}

/**
 * Instantiates the engine in this realm from a compiled `WebAssembly.Module` (synchronously: an
 * AudioWorklet's scope can fetch nothing, so the page hands it the module). Done once a realm.
 */
export function initFromModule(module) {
  if (loaded === null) {
    loaded = initSync({ module });
    compiled = module;
    fields = unitFields();
  }
  return compiled;
}

/**
 * Loads the engine in this realm and returns its compiled module (to hand to a worklet).
 * `source`: the .wasm as a URL or path, its bytes, or a compiled module; by default the
 * package's own .wasm (read from disk in Node.js, fetched in a browser).
 */
export async function loadSakeGlug(source) {
  if (compiled !== null) return compiled;
  let module;
  if (source instanceof WebAssembly.Module) {
    module = source;
  } else if (source instanceof ArrayBuffer || ArrayBuffer.isView(source)) {
    module = await WebAssembly.compile(source);
  } else {
    const url = source === undefined ? wasmUrl() : new URL(source, isNode ? `file://${process.cwd()}/` : globalThis.location?.href);
    let bytes;
    if (isNode && url.protocol === "file:") {
      const { readFile } = await import("node:fs/promises");
      bytes = await readFile(url);
    } else {
      const response = await fetch(url);
      if (!response.ok) {
        throw new Error(`sake-glug: the engine's .wasm could not be fetched from ${url} (${response.status})`);
      }
      bytes = await response.arrayBuffer();
    }
    module = await WebAssembly.compile(bytes);
  }
  return initFromModule(module);
}

function requireLoaded() {
  if (loaded === null) {
    throw new Error("sake-glug: the engine is not loaded yet: `await loadSakeGlug()` first");
  }
}

/** The version of the engine inside (the release's); the package's is the same. */
export function version() {
  requireLoaded();
  return wasmVersion();
}

/** The control of `name` (its id, such as "tilt" or "visc", or its scene key, "viscosity_c"). */
export function controlNumber(name) {
  const index = CONTROLS.findIndex((control) => control.id === name || control.key === name);
  if (index < 0) {
    throw new TypeError(
      `sake-glug: no control ${JSON.stringify(name)}: the controls are ${CONTROLS.map((c) => c.id).join(", ")}`,
    );
  }
  return index;
}

/**
 * A model file's text (MODEL.md §12.1) from `values` keyed by scene key ("viscosity_c",
 * "bottle.capacity_ml", "glug.f1_hz", …): how the page turns a preset and its sliders into a
 * bottle the engine reads, through its one parser.
 */
export function modelText(values) {
  const top = [];
  const tables = new Map();
  for (const [key, value] of Object.entries(values)) {
    if (typeof value !== "number") {
      throw new TypeError(`sake-glug: ${key} = ${JSON.stringify(value)} is not a number`);
    }
    const number = Number.isInteger(value) ? value.toFixed(1) : String(value);
    const dot = key.indexOf(".");
    if (dot < 0) {
      top.push(`${key} = ${number}`);
    } else {
      const table = key.slice(0, dot);
      if (!tables.has(table)) tables.set(table, []);
      tables.get(table).push(`${key.slice(dot + 1)} = ${number}`);
    }
  }
  let text = top.map((line) => `${line}\n`).join("");
  for (const [table, lines] of tables) {
    text += `\n[${table}]\n${lines.map((line) => `${line}\n`).join("")}`;
  }
  return text;
}

/** One live glug: the C library's handle, its blocks and units read from the engine's memory. */
export class Glug {
  #inner;
  #outputPtr;
  #unitsPtr;
  #buffer = null;
  #view = null;
  #viewFrames = -1;

  /**
   * A glug at `sampleRate` (Hz) playing `model` (a model file's text) or the shipped `preset`
   * (its id), or the paper's bottle; seeded with `seed` (a whole number; the products' default
   * if left out). Throws an Error saying what is wrong with any of them.
   */
  static create({ sampleRate = 48000, model, preset, seed } = {}) {
    requireLoaded();
    if (model != null && preset != null) {
      throw new TypeError("sake-glug: give a model or a preset, not both");
    }
    if (model != null && typeof model !== "string") {
      throw new TypeError("sake-glug: a model is the text of a model file (a string)");
    }
    if (preset != null && typeof preset !== "string") {
      throw new TypeError("sake-glug: a preset is named by its id (a string)");
    }
    const inner =
      preset != null ? WasmGlug.fromPreset(sampleRate, preset, seed) : new WasmGlug(sampleRate, model ?? undefined, seed);
    return new Glug(inner, sampleRate);
  }

  constructor(inner, sampleRate) {
    this.#inner = inner;
    this.sampleRate = sampleRate;
    this.#outputPtr = inner.outputPtr();
    this.#unitsPtr = inner.unitsPtr();
  }

  /** Sets `control` to `value` from the first sample of the next block on. */
  set(control, value) {
    this.#inner.set(controlNumber(control), value);
  }

  /** Ramps `control` to `target`, reached `samples` samples after the next block's first. */
  ramp(control, target, samples) {
    this.#inner.ramp(controlNumber(control), target, samples);
  }

  /** Refills the bottle to the fill level at the next block's first sample. */
  refill() {
    this.#inner.refill();
  }

  /** Refill, silence, re-seed and count from 0 at the next block's first sample. */
  reset() {
    this.#inner.reset();
  }

  /**
   * Compensates the units that start from the next block on for the actuator whose profile
   * file's text is `profileText` (MODEL.md §18); null plays the model's drive as it is.
   */
  setActuator(profileText) {
    this.#inner.setActuator(profileText ?? undefined);
  }

  /** The value `control` had when the glug was made (the model's or preset's, else its default). */
  startingValue(control) {
    return this.#inner.startingValue(controlNumber(control));
  }

  /**
   * Renders `frames` samples and returns them as a Float32Array view of the engine's own buffer:
   * valid until the next call (copy it to keep it). Allocates nothing in the engine.
   */
  process(frames) {
    this.#inner.process(frames);
    return this.#output(frames);
  }

  /** Renders `out.length` samples into `out` (a Float32Array). */
  processInto(out) {
    out.set(this.process(out.length));
  }

  #output(frames) {
    const buffer = loaded.memory.buffer;
    if (buffer !== this.#buffer || frames !== this.#viewFrames) {
      this.#buffer = buffer;
      this.#viewFrames = frames;
      this.#view = new Float32Array(buffer, this.#outputPtr, frames);
    }
    return this.#view;
  }

  /** Units first heard in the last block. */
  get unitCount() {
    return this.#inner.unitCount();
  }

  /** The last block's units as a Float64Array view, `UNIT_FIELDS.length` numbers a unit. */
  unitTable() {
    return new Float64Array(loaded.memory.buffer, this.#unitsPtr, this.#inner.unitCount() * fields.length);
  }

  /**
   * The last block's units as objects: `frame` (of the block, where the unit is first heard),
   * `audible`, `sample` (counted since the last reset), `fraction`, `tiltDeg`, `volumeMl`,
   * `pocketMl`, `amplitude`, `viscosityC`, `f1Hz`, `f2Hz`, `b1PerS`, `b2PerS`.
   */
  units() {
    return unitsOf(this.unitTable());
  }

  /** The bottle after the last block. */
  get state() {
    const inner = this.#inner;
    return {
      position: inner.position(),
      activeUntil: inner.activeUntil(),
      volumeMl: inner.volumeMl(),
      outflowMlPerS: inner.outflowMlPerS(),
      tiltDeg: inner.tiltDeg(),
      outputGain: inner.outputGain(),
      submerged: inner.submerged(),
      settled: inner.settled(),
      unitsLost: inner.unitsLost(),
    };
  }

  /** Samples rendered since the glug was made or last reset. */
  get position() {
    return this.#inner.position();
  }

  /** The sample after the last one in which liquid flowed or a unit sounded. */
  get activeUntil() {
    return this.#inner.activeUntil();
  }

  /** Nothing sounds and nothing will start under the controls now. */
  get settled() {
    return this.#inner.settled();
  }

  /** Frees the engine's memory of this glug; it may not be used after. */
  free() {
    this.#inner.free();
  }
}

/**
 * The bottle's tilt (°) from a gravity reading `[x, y, z]` that points up, along the sensor axis
 * `axis` from the bottle's base to its mouth (`+y` by default: a phone's top), as the plugin
 * reads a phone's gravity over OSC; null if the reading has no direction.
 */
export function tiltFromGravity([x, y, z], axis = "+y") {
  requireLoaded();
  return wasmTiltFromGravity(x, y, z, axis) ?? null;
}

/**
 * The bottle's tilt (°) from a DeviceOrientationEvent's `beta` and `gamma` (°), the phone held as
 * the bottle, its top the mouth: upright is 0°, flat on its back 90°. Null if they give none.
 */
export function tiltFromOrientation(beta, gamma) {
  const b = (beta * Math.PI) / 180;
  const g = (gamma * Math.PI) / 180;
  // "Up" in the phone's frame, after its rotations about x by beta and about y by gamma.
  return tiltFromGravity([-Math.sin(g) * Math.cos(b), Math.sin(b), Math.cos(g) * Math.cos(b)]);
}

/**
 * A haptic clip's text, written by the renderer's own writer (the file `sake-glug render -o
 * FORMAT:FILE` writes for the same units): `format` one of `clipFormats()` ("ahap", "haptic",
 * "rumble", "android-waveform", "android-xml", "haps"), from a render's `units` (each with its
 * `timeS`), `durationS` long; `name` and `seed` go into its description.
 */
export function clip(format, units, { durationS, name = "web", seed = 1 }) {
  requireLoaded();
  const width = clipUnitFields().length;
  const table = new Float64Array(units.length * width);
  units.forEach((unit, i) => {
    table.set(
      [unit.timeS, unit.amplitude, unit.viscosityC, unit.f1Hz, unit.f2Hz, unit.b1PerS, unit.b2PerS],
      i * width,
    );
  });
  return wasmClip(format, table, durationS, name, seed);
}

/** The clip formats `clip` writes. */
export function clipFormats() {
  requireLoaded();
  return wasmClipFormats();
}

/** The names of a unit's numbers, in the order of a unit table's rows. */
export function unitFieldNames() {
  requireLoaded();
  return fields;
}

/** The most frames one block renders, and the most units it keeps. */
export function limits() {
  requireLoaded();
  return { maxBlockFrames: maxBlockFrames(), maxUnits: maxUnits() };
}

/** Unit objects from a table of rows (a unit table, or a copy of one posted from a worklet). */
export function unitsOf(table) {
  const width = fields.length;
  const units = [];
  for (let row = 0; row + width <= table.length; row += width) {
    const unit = {};
    for (let k = 0; k < width; k += 1) unit[fields[k]] = table[row + k];
    unit.audible = unit.audible !== 0;
    units.push(unit);
  }
  return units;
}
