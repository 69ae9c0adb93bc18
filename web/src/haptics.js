// Haptics from the glug units, as the renderer's platform formats make them
// (crates/render/src/steps.rs, clips.rs; web/test/haptics.test.mjs holds these numbers to the
// CLI's `rumble` and `android-waveform` files):
//
// - a dual-rumble gamepad: the low (strong) motor follows the f1 component's envelope
//   Σ c·a·e^(−B1·τ), the high (weak) motor the f2 component's Σ (1 − c)·a·e^(−B2·τ), both scaled
//   down together where their sum passes the output ceiling, each the mean over its frame
//   (100 frames a second), as the `rumble` clip;
// - a phone's `navigator.vibrate`, which has no amplitude: the `android-waveform` clip's 10 ms
//   steps of the felt envelope (their amplitudes 0–255), each played as a pulse that lasts
//   amplitude/255 of its step.
//
// Both drivers are optional and feature-detected: without a gamepad that rumbles or a
// `navigator.vibrate`, they do nothing.

/** Frames a second of the `rumble` clip (DEFAULT_RUMBLE_RATE_HZ, sinks/rumble.rs). */
export const RUMBLE_RATE_HZ = 100;
/** The length of an Android waveform step (ms; ANDROID_STEP_MS, steps.rs). */
export const ANDROID_STEP_MS = 10;
/** Android's full amplitude (ANDROID_FULL_AMPLITUDE, steps.rs). */
export const ANDROID_FULL_AMPLITUDE = 255;
/** The envelope level below which a step is off (ENVELOPE_FLOOR, clips.rs). */
export const ENVELOPE_FLOOR = 1e-3;
/** Points at which a frame's or step's mean envelope is sampled (MEAN_POINTS, steps.rs). */
const MEAN_POINTS = 8;
/** The shortest clip (s; MIN_CLIP_S, clips.rs). */
const MIN_CLIP_S = 0.001;

/**
 * A unit as the clips see it: its onset (s), its components' amplitudes and decays. `sampleRate`
 * turns `sample + fraction` into seconds where the unit has no `timeS` of its own.
 */
function clipGlug(unit, sampleRate) {
  const onsetS = unit.timeS ?? (unit.sample + unit.fraction) / sampleRate;
  const c = unit.viscosityC;
  return {
    onsetS,
    amplitudes: [Math.abs(c * unit.amplitude), Math.abs((1 - c) * unit.amplitude)],
    decays: [unit.b1PerS, unit.b2PerS],
  };
}

/**
 * The envelopes of the two components of the units given so far, as they ring at any time:
 * what both drivers and the clips of this module are computed from.
 */
export class ComponentEnvelopes {
  #glugs = [];
  #largest = 0;
  #slowest = Infinity;

  /** `ceiling`: the output's ceiling (linear; 1 unless the model sets another). */
  constructor({ sampleRate, ceiling = 1 } = {}) {
    this.sampleRate = sampleRate;
    this.limit = Math.max(ceiling, 0);
  }

  /** Adds units (from a render or a node's `units` event), in any order. */
  add(units) {
    for (const unit of units) {
      const glug = clipGlug(unit, this.sampleRate);
      // A unit of no amplitude is not felt (clips.rs, is_audible).
      if (!(glug.amplitudes[0] + glug.amplitudes[1] > 0)) continue;
      let at = this.#glugs.length;
      while (at > 0 && this.#glugs[at - 1].onsetS > glug.onsetS) at -= 1;
      this.#glugs.splice(at, 0, glug);
      this.#largest = Math.max(this.#largest, glug.amplitudes[0] + glug.amplitudes[1]);
      this.#slowest = Math.min(this.#slowest, ...glug.decays);
    }
  }

  /** Forgets the units that have rung out by time `t` (a live driver's memory stays small). */
  forgetBefore(t) {
    let keep = 0;
    while (
      keep < this.#glugs.length &&
      this.#largest * Math.exp(-this.#slowest * (t - this.#glugs[keep].onsetS)) < 1e-15
    ) {
      keep += 1;
    }
    if (keep > 0) this.#glugs.splice(0, keep);
  }

  /** The units kept, sorted by onset. */
  get glugs() {
    return this.#glugs;
  }

  /** `[low, high]`: the f1 and the f2 component's envelope at `t` (s). */
  at(t) {
    const glugs = this.#glugs;
    let started = glugs.length;
    while (started > 0 && glugs[started - 1].onsetS > t) started -= 1;
    let low = 0;
    let high = 0;
    for (let i = started - 1; i >= 0; i -= 1) {
      const glug = glugs[i];
      const tau = t - glug.onsetS;
      if (this.#largest * Math.exp(-this.#slowest * tau) < 1e-15) break;
      low += glug.amplitudes[0] * Math.exp(-glug.decays[0] * tau);
      high += glug.amplitudes[1] * Math.exp(-glug.decays[1] * tau);
    }
    const scale = low + high > this.limit ? this.limit / (low + high) : 1;
    return [low * scale, high * scale];
  }

  /** The mean of `[low, high]` over `fromS..toS`. */
  mean(fromS, toS) {
    const width = (toS - fromS) / MEAN_POINTS;
    let low = 0;
    let high = 0;
    for (let point = 0; point < MEAN_POINTS; point += 1) {
      const [l, h] = this.at(fromS + (point + 0.5) * width);
      low += l;
      high += h;
    }
    return [low / MEAN_POINTS, high / MEAN_POINTS];
  }
}

const clamp01 = (x) => Math.min(Math.max(x, 0), 1);

/** The end of a clip of `durationS` (never less than 1 ms). */
function clipEndS(durationS) {
  return Number.isFinite(durationS) ? Math.max(durationS, MIN_CLIP_S) : MIN_CLIP_S;
}

/**
 * The dual-rumble frames of a clip of `durationS` seconds (the `rumble` clip's `frames`):
 * `[{ tMs, low, high }]`, each held for 1/rateHz.
 */
export function rumbleFrames(units, { sampleRate, durationS, ceiling = 1, rateHz = RUMBLE_RATE_HZ }) {
  const envelopes = new ComponentEnvelopes({ sampleRate, ceiling });
  envelopes.add(units);
  const period = 1 / rateHz;
  const count = Math.max(1, Math.ceil(clipEndS(durationS) * rateHz));
  const frames = [];
  for (let k = 0; k < count; k += 1) {
    const start = k * period;
    const [low, high] = envelopes.mean(start, start + period);
    frames.push({ tMs: start * 1000, low: clamp01(low), high: clamp01(high) });
  }
  return frames;
}

/** An envelope level (0..1) on Android's scale: 1..255 while felt, 0 below the floor. */
function androidAmplitude(level) {
  if (Number.isNaN(level) || level < ENVELOPE_FLOOR) return 0;
  return Math.min(Math.max(Math.round(level * ANDROID_FULL_AMPLITUDE), 1), ANDROID_FULL_AMPLITUDE);
}

/**
 * The felt envelope of a clip as Android waveform steps (the `android-waveform` clip):
 * `[{ startMs, durationMs, amplitude, onset }]`: a step at every audible unit's onset (to the
 * millisecond), then every 10 ms until the next; each holds the envelope's mean over it; silent
 * steps in a row are merged.
 */
export function androidSteps(units, { sampleRate, durationS, ceiling = 1 }) {
  const envelopes = new ComponentEnvelopes({ sampleRate, ceiling });
  envelopes.add(units);
  const endS = clipEndS(durationS);
  const endMs = Math.max(Math.ceil(endS * 1000), 1);
  const onsetsMs = [];
  for (const glug of envelopes.glugs) {
    if (glug.onsetS < 0 || glug.onsetS > endS) continue;
    const ms = Math.round(glug.onsetS * 1000);
    if (ms < endMs && onsetsMs[onsetsMs.length - 1] !== ms) onsetsMs.push(ms);
  }
  const anchors = [[0, false], ...onsetsMs.map((ms) => [ms, true])];
  const starts = [];
  anchors.forEach(([anchorMs, onset], index) => {
    const nextMs = index + 1 < anchors.length ? anchors[index + 1][0] : endMs;
    if (nextMs === anchorMs) return;
    starts.push([anchorMs, onset]);
    for (let ms = anchorMs + ANDROID_STEP_MS; ms < nextMs; ms += ANDROID_STEP_MS) starts.push([ms, false]);
  });
  const steps = [];
  starts.forEach(([startMs, onset], index) => {
    const stopMs = index + 1 < starts.length ? starts[index + 1][0] : endMs;
    const [low, high] = envelopes.mean(startMs / 1000, stopMs / 1000);
    const amplitude = androidAmplitude(low + high);
    const last = steps[steps.length - 1];
    if (last && !onset && amplitude === 0 && last.amplitude === 0) {
      last.durationMs += stopMs - startMs;
    } else {
      steps.push({ startMs, durationMs: stopMs - startMs, amplitude, onset });
    }
  });
  return steps;
}

/**
 * A `navigator.vibrate` pattern (ms: vibrate, pause, vibrate, …) playing Android steps on a
 * motor without amplitude: each step a pulse of round(duration × amplitude / 255) ms, then the
 * rest of the step off; runs of one kind merged.
 */
export function vibratePattern(steps) {
  const pattern = [0];
  let on = true;
  const push = (vibrating, ms) => {
    if (ms <= 0) return;
    if (vibrating !== on) {
      pattern.push(0);
      on = vibrating;
    }
    pattern[pattern.length - 1] += ms;
  };
  for (const step of steps) {
    const pulse = Math.round((step.durationMs * step.amplitude) / ANDROID_FULL_AMPLITUDE);
    push(true, pulse);
    push(false, step.durationMs - pulse);
  }
  // Nothing felt: no pattern at all.
  return pattern.some((ms, index) => index % 2 === 0 && ms > 0) ? pattern : [];
}

/** The gamepads that can play a dual-rumble effect, of `navigator`. */
function rumblingGamepads(navigator) {
  if (!navigator || typeof navigator.getGamepads !== "function") return [];
  return Array.from(navigator.getGamepads() ?? []).filter((pad) => {
    const actuator = pad?.vibrationActuator;
    if (!actuator || typeof actuator.playEffect !== "function") return false;
    // Chromium lists what an actuator plays; others may not say.
    return !Array.isArray(actuator.effects) || actuator.effects.includes("dual-rumble");
  });
}

/**
 * Live haptics from a glug's units: call `add(units)` as they come (a node's `units` events or a
 * render's units) and `tick()` every frame (`start()` runs it on a timer). `clock()` gives the
 * time on the units' timeline (s: the node's `timeS`, such as `context.currentTime −` the
 * node's start). Each tick plays the next frame's mean envelope on every gamepad that rumbles
 * (`dual-rumble`: strong = low, weak = high) and, when units have come or the last pattern has
 * run out (`vibrateWindowMs`), the next window's steps as a `navigator.vibrate` pattern. Returns
 * what it played.
 */
export class HapticsDriver {
  #timer = null;
  #vibratedUntilMs = -Infinity;
  /** Units came since the last pattern: the next tick plays a new one. */
  #fresh = false;

  constructor({
    sampleRate,
    clock,
    ceiling = 1,
    navigator = globalThis.navigator,
    rateHz = RUMBLE_RATE_HZ,
    vibrateWindowMs = 200,
    gamepad = true,
    vibrate = true,
  }) {
    if (typeof clock !== "function") throw new TypeError("sake-glug: haptics need a clock() in seconds");
    this.envelopes = new ComponentEnvelopes({ sampleRate, ceiling });
    this.sampleRate = sampleRate;
    this.ceiling = ceiling;
    this.clock = clock;
    this.navigator = navigator;
    this.periodS = 1 / rateHz;
    this.vibrateWindowMs = vibrateWindowMs;
    this.gamepad = gamepad;
    this.vibrate = vibrate && typeof navigator?.vibrate === "function";
  }

  /** Whether this platform has a gamepad that rumbles now, or a vibrator. */
  get available() {
    return { gamepad: rumblingGamepads(this.navigator).length > 0, vibrate: this.vibrate };
  }

  add(units) {
    if (units.length > 0) this.#fresh = true;
    this.envelopes.add(units);
  }

  /** Plays the frame that starts now; returns `{ tS, low, high, pads, pattern }`. */
  tick() {
    const t = this.clock();
    const envelopes = this.envelopes;
    envelopes.forgetBefore(t);
    const [low, high] = envelopes.mean(t, t + this.periodS);
    const played = { tS: t, low: clamp01(low), high: clamp01(high), pads: 0, pattern: null };
    if (this.gamepad) {
      for (const pad of rumblingGamepads(this.navigator)) {
        // Held for two frames, so that a late tick leaves no gap; the next frame replaces it.
        pad.vibrationActuator
          .playEffect("dual-rumble", {
            startDelay: 0,
            duration: Math.round(2000 * this.periodS),
            strongMagnitude: played.low,
            weakMagnitude: played.high,
          })
          .catch(() => {});
        played.pads += 1;
      }
    }
    const nowMs = t * 1000;
    // A pattern is played whole unless replaced: a new one when units have come (from now, with
    // them) or when the last one has run out.
    if (this.vibrate && (this.#fresh || nowMs >= this.#vibratedUntilMs)) {
      played.pattern = this.#vibrateWindow(t);
      this.#vibratedUntilMs = nowMs + this.vibrateWindowMs;
      this.#fresh = false;
    }
    return played;
  }

  /** The next window's steps on `navigator.vibrate`, from now (the steps' clock starts at `t`). */
  #vibrateWindow(t) {
    const window = this.vibrateWindowMs / 1000;
    const ahead = this.envelopes.glugs.filter((glug) => glug.onsetS <= t + window);
    // The window as a clip of its own: the units ringing into it, shifted to start at 0.
    const units = ahead.map((glug) => ({
      timeS: glug.onsetS - t,
      amplitude: glug.amplitudes[0] + glug.amplitudes[1],
      viscosityC: glug.amplitudes[0] / (glug.amplitudes[0] + glug.amplitudes[1]),
      b1PerS: glug.decays[0],
      b2PerS: glug.decays[1],
    }));
    const steps = androidSteps(units, { sampleRate: this.sampleRate, durationS: window, ceiling: this.ceiling });
    const pattern = vibratePattern(steps);
    this.navigator.vibrate(pattern.length > 0 ? pattern : 0);
    return pattern;
  }

  /** Ticks every frame on a timer (the page's; a test calls `tick()` itself). */
  start() {
    if (this.#timer === null) this.#timer = setInterval(() => this.tick(), this.periodS * 1000);
  }

  /** Stops the timer and both motors. */
  stop() {
    if (this.#timer !== null) clearInterval(this.#timer);
    this.#timer = null;
    for (const pad of rumblingGamepads(this.navigator)) pad.vibrationActuator.reset?.();
    if (this.vibrate) this.navigator.vibrate(0);
  }
}
