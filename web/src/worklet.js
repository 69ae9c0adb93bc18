// The AudioWorklet processor "sake-glug": a Glug on the audio thread, rendered block by block
// (128 frames) as a host renders a plugin. Its AudioParams (k-rate: one value a block) are the
// engine's controls; a change takes effect at the first sample of the block, as a set. A score
// (from the node's options, or posted later) acts at its calls' very samples. The units first
// heard in a block are posted to the main thread for haptics. It never throws from process():
// whatever fails is posted as an error, and the node then plays silence.

import "./text-coding.js";
import { initFromModule, Glug, CONTROLS } from "./glug.js";
import { ScorePlayer } from "./score.js";

/** How often the bottle's state is posted (frames), about every 50 ms at 48 kHz. */
const STATE_EVERY_FRAMES = 2048;

class SakeGlugProcessor extends AudioWorkletProcessor {
  static get parameterDescriptors() {
    return CONTROLS.map((control) => ({
      name: control.id,
      defaultValue: control.default,
      minValue: control.min,
      maxValue: control.max,
      automationRate: "k-rate",
    }));
  }

  constructor(options) {
    super();
    const { module, model, preset, seed, score = [], params } = options.processorOptions;
    this.failed = false;
    this.nextState = 0;
    // The context's frame of the glug's frame 0: the score's frames count from it.
    this.origin = currentFrame;
    try {
      initFromModule(module);
      this.glug = Glug.create({ sampleRate, model, preset, seed });
      this.player = new ScorePlayer(this.glug, score);
      // The AudioParams' values the glug plays, as an AudioParam holds them (float32): a change
      // from these is a set.
      this.params = CONTROLS.map((control) =>
        Math.fround(params?.[control.id] ?? this.glug.startingValue(control.id)),
      );
    } catch (error) {
      this.fail(error);
    }
    this.port.onmessage = (event) => this.receive(event.data);
  }

  /** A call from the node, at a context frame, or without one at the next block. */
  receive({ contextFrame, ...call }) {
    if (this.failed) return;
    try {
      const frame = Math.max(0, (contextFrame ?? currentFrame) - this.origin);
      this.player.add({ ...call, frame });
    } catch (error) {
      this.port.postMessage({ type: "error", message: String(error?.message ?? error) });
    }
  }

  fail(error) {
    this.failed = true;
    this.port.postMessage({ type: "error", message: String(error?.message ?? error), fatal: true });
  }

  process(_inputs, outputs, parameters) {
    const out = outputs[0];
    if (this.failed) {
      for (const channel of out) channel.fill(0);
      return true;
    }
    try {
      for (let index = 0; index < CONTROLS.length; index += 1) {
        const control = CONTROLS[index];
        const value = parameters[control.id][0];
        if (value !== this.params[index]) {
          this.params[index] = value;
          // An AudioParam's float32 bounds may lie a hair outside the control's range.
          this.glug.set(control.id, Math.min(Math.max(value, control.min), control.max));
        }
      }
      const start = currentFrame - this.origin;
      let units = null;
      this.player.render(start, out[0], (table, offset) => {
        // Copied: the engine's table is reused by the next block.
        const rows = Float64Array.from(table);
        units = units === null ? [{ rows, offset }] : [...units, { rows, offset }];
      });
      for (let channel = 1; channel < out.length; channel += 1) out[channel].set(out[0]);
      if (units !== null) this.port.postMessage({ type: "units", pieces: units });
      if (start >= this.nextState) {
        this.nextState = start + STATE_EVERY_FRAMES;
        this.port.postMessage({ type: "state", frame: start, origin: this.origin, state: this.glug.state });
      }
    } catch (error) {
      for (const channel of out) channel.fill(0);
      this.fail(error);
    }
    return true;
  }
}

registerProcessor("sake-glug", SakeGlugProcessor);
