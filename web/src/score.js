// A score: control calls at sample frames, played on a Glug block by block. A block is cut at
// each call's frame, so a call acts at its very sample whatever the block size (the engine gives
// the same samples however time is cut): a set is a step of a scene's lane, a ramp a two-point
// segment of it (MODEL.md §10, §17). The AudioWorklet and the offline renders play scores
// through this one class.

import { controlNumber, CONTROLS } from "./glug.js";

/**
 * A score's call, checked and made plain (structured-cloneable, for a worklet):
 * `{ frame, op: "set" | "ramp" | "refill" | "reset", control, value, frames }`.
 * `frame`: when (a whole number of samples from the start); `control`: a control's id or scene
 * key; `value`: the value set or the ramp's target; `frames`: the ramp's length in samples.
 */
export function checkedCall(call) {
  if (call === null || typeof call !== "object") {
    throw new TypeError("sake-glug: a score's call is an object such as { frame: 0, op: \"set\", control: \"tilt\", value: 90 }");
  }
  const { frame = 0, op } = call;
  if (!Number.isSafeInteger(frame) || frame < 0) {
    throw new RangeError(`sake-glug: a call's frame is a whole number of samples from 0, not ${frame}`);
  }
  switch (op) {
    case "set":
      return { frame, op, control: checkedControl(call), value: call.value };
    case "ramp":
      if (!Number.isSafeInteger(call.frames) || call.frames < 0) {
        throw new RangeError(`sake-glug: a ramp's length is a whole number of samples from 0, not ${call.frames}`);
      }
      return { frame, op, control: checkedControl(call), value: call.value, frames: call.frames };
    case "refill":
    case "reset":
      return { frame, op };
    default:
      throw new TypeError(`sake-glug: no call ${JSON.stringify(op)}: the calls are set, ramp, refill and reset`);
  }
}

/** The id of a call's control, if its value is a finite number within the control's range. */
function checkedControl({ control, value }) {
  const spec = CONTROLS[controlNumber(control)];
  if (typeof value !== "number" || !Number.isFinite(value)) {
    throw new TypeError(`sake-glug: ${spec.name} (${spec.id}): ${value} is not a finite number`);
  }
  if (value < spec.min || value > spec.max) {
    throw new RangeError(`sake-glug: ${spec.name} (${spec.id}): ${value} is outside its range, ${spec.min} to ${spec.max} ${spec.unit}`);
  }
  return spec.id;
}

/** The default scene of `sake-glug render` (the built-in pour): 90° to 135° over half a second. */
export function builtInPour(sampleRate) {
  return [
    { frame: 0, op: "set", control: "tilt", value: 90 },
    { frame: 0, op: "ramp", control: "tilt", value: 135, frames: Math.floor(sampleRate / 2) },
  ];
}

export class ScorePlayer {
  /** Calls still to come, in order of frame (calls at one frame in the order given). */
  #pending = [];

  /** Plays `calls` (see checkedCall) on `glug`. */
  constructor(glug, calls = []) {
    this.glug = glug;
    for (const call of calls) this.add(call);
  }

  /** Adds a call; one whose frame has passed acts at the next block's first sample. */
  add(call) {
    const checked = checkedCall(call);
    let at = this.#pending.length;
    while (at > 0 && this.#pending[at - 1].frame > checked.frame) at -= 1;
    this.#pending.splice(at, 0, checked);
  }

  /** Whether calls are still to come. */
  get pending() {
    return this.#pending.length;
  }

  #apply(call) {
    const glug = this.glug;
    switch (call.op) {
      case "set":
        glug.set(call.control, call.value);
        break;
      case "ramp":
        glug.ramp(call.control, call.value, call.frames);
        break;
      case "refill":
        glug.refill();
        break;
      case "reset":
        glug.reset();
        break;
    }
  }

  /**
   * Renders `out.length` samples into `out`, the first at frame `start`, taking each call at its
   * frame; `onUnits(table, offset)` is told of the units first heard in each piece (a view of the
   * engine's table, valid during the call) and what to add to a unit's `sample` (counted since
   * the glug's last reset) to count it from frame 0 of the score.
   */
  render(start, out, onUnits) {
    const glug = this.glug;
    const pending = this.#pending;
    const frames = out.length;
    let done = 0;
    while (done < frames) {
      while (pending.length > 0 && pending[0].frame <= start + done) {
        this.#apply(pending.shift());
      }
      const end = pending.length > 0 ? Math.min(frames, pending[0].frame - start) : frames;
      const piece = glug.process(end - done);
      out.set(piece, done);
      if (onUnits && glug.unitCount > 0) {
        onUnits(glug.unitTable(), start + end - glug.position);
      }
      done = end;
    }
  }
}
