// The bottle as an AudioNode (browsers): an AudioWorkletNode running the "sake-glug" processor,
// its controls as AudioParams, its units as events; and a clip rendered through it in an
// OfflineAudioContext.

import { loadSakeGlug, Glug, CONTROLS, controlNumber, unitsOf } from "./glug.js";
import { checkedCall } from "./score.js";
import { checkedScene, renderLoaded } from "./render.js";

/** The processor's module, beside this one. */
export const WORKLET_URL = new URL("./worklet.js", import.meta.url);

/** The worklet module added to each context, once. */
const added = new WeakMap();

function addWorklet(context, url) {
  if (!added.has(context)) {
    added.set(context, context.audioWorklet.addModule(url));
  }
  return added.get(context);
}

/** The AudioParam names of the node's getters. */
const PARAM_NAMES = { tilt: "tilt", viscosity: "visc", fill: "fill", pourTime: "pour", gain: "gain" };

let NodeClass = null;

/** The node's class, made on first use (Node.js has no AudioWorkletNode to extend). */
function bottleNodeClass() {
  if (NodeClass !== null) return NodeClass;
  NodeClass = class SakeGlugNode extends AudioWorkletNode {
    #sampleRate;

    constructor(context, processorOptions, channels) {
      super(context, "sake-glug", {
        numberOfInputs: 0,
        numberOfOutputs: 1,
        outputChannelCount: [channels],
        parameterData: processorOptions.params,
        processorOptions,
      });
      this.#sampleRate = context.sampleRate;
      /** The context time of the glug's frame 0 (known once the processor has run). */
      this.originTime = null;
      /** The bottle's last state posted by the processor. */
      this.state = null;
      this.port.onmessage = (event) => this.#receive(event.data);
    }

    #receive(message) {
      switch (message.type) {
        case "units": {
          const units = [];
          for (const { rows, offset } of message.pieces) {
            for (const unit of unitsOf(rows)) {
              unit.timeS = (unit.sample + offset + unit.fraction) / this.#sampleRate;
              unit.contextTime = (this.originTime ?? 0) + unit.timeS;
              units.push(unit);
            }
          }
          this.dispatchEvent(new CustomEvent("units", { detail: { units } }));
          break;
        }
        case "state":
          this.originTime = message.origin / this.#sampleRate;
          this.state = message.state;
          this.dispatchEvent(new CustomEvent("state", { detail: { ...message.state, frame: message.frame } }));
          break;
        case "error":
          this.dispatchEvent(new CustomEvent("error", { detail: { message: message.message, fatal: !!message.fatal } }));
          break;
      }
    }

    /** The frame of context time `when` (s), or none: the next block. */
    #at(when) {
      if (when === undefined) return undefined;
      if (typeof when !== "number" || !Number.isFinite(when) || when < 0) {
        throw new RangeError(`sake-glug: a call's time is a context time in seconds, not ${when}`);
      }
      return Math.round(when * this.#sampleRate);
    }

    #post(call, when) {
      // Checked here, where the error reaches the caller (the processor would only post it).
      const checked = checkedCall({ ...call, frame: 0 });
      this.port.postMessage({ ...checked, frame: undefined, contextFrame: this.#at(when) });
    }

    /** Sets `control` to `value` at context time `when` (s), or at the next block. */
    set(control, value, when) {
      this.#post({ op: "set", control, value }, when);
    }

    /** Ramps `control` to `target` over `seconds`, from context time `when` or the next block. */
    ramp(control, target, seconds, when) {
      if (typeof seconds !== "number" || !Number.isFinite(seconds) || seconds < 0) {
        throw new RangeError(`sake-glug: a ramp lasts a finite number of seconds from 0, not ${seconds}`);
      }
      this.#post({ op: "ramp", control, value: target, frames: Math.round(seconds * this.#sampleRate) }, when);
    }

    /** Refills the bottle to the fill level, at context time `when` or the next block. */
    refill(when) {
      this.#post({ op: "refill" }, when);
    }

    /** Refill, silence and re-seed, at context time `when` or the next block. */
    reset(when) {
      this.#post({ op: "reset" }, when);
    }

    /** The AudioParam of `control` (its id, such as "tilt", or its scene key). */
    param(control) {
      return this.parameters.get(CONTROLS[controlNumber(control)].id);
    }
  };
  for (const [name, id] of Object.entries(PARAM_NAMES)) {
    Object.defineProperty(NodeClass.prototype, name, {
      get() {
        return this.parameters.get(id);
      },
    });
  }
  return NodeClass;
}

/**
 * The bottle as an AudioNode of `context`: a glug playing `model` (a model file's text) or
 * `preset` (an id), seeded with `seed`; `controls` its controls' values at the start (by id or
 * scene key); `score` calls at sample frames from its start (see ScorePlayer). Its AudioParams
 * `tilt`, `viscosity`, `fill`, `pourTime` and `gain` (k-rate, float32) set their control at the
 * start of each block they change in; `set`, `ramp`, `refill` and `reset` act at a context time's
 * very sample. It dispatches `units` (the units first heard, for haptics), `state` and `error`
 * events. Every argument is checked here, and a bad one throws.
 */
export async function createBottleNode(context, options = {}) {
  const { model, preset, seed, score = [], controls = {}, channels = 1, wasm, workletUrl = WORKLET_URL } = options;
  if (!Number.isSafeInteger(channels) || channels < 1 || channels > 32) {
    throw new RangeError(`sake-glug: a node has 1 to 32 output channels, not ${channels}`);
  }
  const module = await loadSakeGlug(wasm);
  // Made once here, where a broken model or an unknown preset throws to the caller.
  const probe = Glug.create({ sampleRate: context.sampleRate, model, preset, seed });
  const params = {};
  try {
    for (const control of CONTROLS) params[control.id] = probe.startingValue(control.id);
  } finally {
    probe.free();
  }
  const calls = [];
  for (const [name, value] of Object.entries(controls)) {
    const call = checkedCall({ frame: 0, op: "set", control: name, value });
    params[call.control] = value;
    calls.push(call);
  }
  if (!Array.isArray(score)) throw new TypeError("sake-glug: a score is an array of calls");
  for (const call of score) calls.push(checkedCall(call));
  await addWorklet(context, workletUrl);
  const Node = bottleNodeClass();
  return new Node(context, { module, model, preset, seed, score: calls, params }, channels);
}

/**
 * Renders `scene` (as `render` takes it) through the AudioWorklet in an OfflineAudioContext at the
 * scene's rate: `seconds` of it, or as long as a render on this thread says it lasts until it
 * settles. Returns `{ samples, units, sampleRate, buffer }` (the units of that render on this
 * thread: the worklet's come as events, which an offline context does not wait for).
 */
export async function renderInContext(scene = {}, { wasm, workletUrl = WORKLET_URL } = {}) {
  await loadSakeGlug(wasm);
  const checked = checkedScene(scene);
  const { sampleRate } = checked;
  const measured = renderLoaded(checked);
  const length = measured.samples.length;
  if (length === 0) return { ...measured, buffer: null };
  const context = new OfflineAudioContext({ numberOfChannels: 1, length, sampleRate });
  const node = await createBottleNode(context, { ...checked, wasm, workletUrl });
  node.connect(context.destination);
  const buffer = await context.startRendering();
  return { samples: buffer.getChannelData(0), units: measured.units, sampleRate, buffer };
}
