// Offline renders without an AudioContext (Node.js, or a page's own thread): a scene played on a
// Glug through the score player, to its end or for a fixed time, and written as a WAV file.

import { Glug, loadSakeGlug, unitsOf, limits } from "./glug.js";
import { ScorePlayer, builtInPour } from "./score.js";

/** The longest render to "until it settles" (10 minutes of samples), against a scene that never does. */
const MAX_UNSETTLED_S = 600;

/**
 * A scene, checked and made plain: `{ sampleRate, model?, preset?, seed?, score, seconds? }`.
 * Without a score it is the built-in pour (`sake-glug render` without a scene).
 */
export function checkedScene(scene = {}) {
  const { sampleRate = 48000, model, preset, seed, seconds } = scene;
  const score = scene.score ?? builtInPour(sampleRate);
  if (!Array.isArray(score)) {
    throw new TypeError("sake-glug: a scene's score is an array of calls");
  }
  if (seconds !== undefined && !(typeof seconds === "number" && seconds >= 0 && Number.isFinite(seconds))) {
    throw new RangeError(`sake-glug: a render's length in seconds is a finite number from 0, not ${seconds}`);
  }
  return { sampleRate, model, preset, seed, score, seconds };
}

/**
 * Renders `scene` offline: `seconds` of it, or until the pour has settled and every unit has
 * decayed (cut where the last one fell silent, as `sake-glug render` cuts a scene without a
 * duration). Returns `{ samples: Float32Array, units, sampleRate }`, each unit with `timeS`, its
 * onset in seconds from the start.
 */
export async function render(scene = {}, { blockFrames = 4096 } = {}) {
  await loadSakeGlug();
  return renderLoaded(scene, { blockFrames });
}

/** `render` once the engine is loaded (synchronous). */
export function renderLoaded(scene = {}, { blockFrames = 4096 } = {}) {
  const { sampleRate, model, preset, seed, score, seconds } = checkedScene(scene);
  const { maxBlockFrames } = limits();
  if (!Number.isSafeInteger(blockFrames) || blockFrames < 1 || blockFrames > maxBlockFrames) {
    throw new RangeError(`sake-glug: blocks of 1 to ${maxBlockFrames} frames, not ${blockFrames}`);
  }
  const glug = Glug.create({ sampleRate, model, preset, seed });
  try {
    const player = new ScorePlayer(glug, score);
    const fixed = seconds === undefined ? null : Math.round(seconds * sampleRate);
    const limit = fixed ?? MAX_UNSETTLED_S * sampleRate;
    const chunks = [];
    const units = [];
    let rendered = 0;
    let ended = null;
    const block = new Float32Array(blockFrames);
    while (rendered < limit) {
      const frames = Math.min(blockFrames, limit - rendered);
      const out = frames === blockFrames ? block : block.subarray(0, frames);
      player.render(rendered, out, (table, offset) => {
        for (const unit of unitsOf(table)) {
          unit.timeS = (unit.sample + offset + unit.fraction) / sampleRate;
          units.push(unit);
        }
      });
      chunks.push(out.slice());
      rendered += frames;
      if (fixed === null && player.pending === 0 && glug.settled) {
        ended = rendered - (glug.position - glug.activeUntil);
        break;
      }
    }
    if (fixed === null && ended === null) {
      throw new Error(`sake-glug: the scene had not settled after ${MAX_UNSETTLED_S} s: give it a length in seconds`);
    }
    const samples = new Float32Array(ended ?? rendered);
    let at = 0;
    for (const chunk of chunks) {
      const take = Math.min(chunk.length, samples.length - at);
      samples.set(chunk.subarray(0, take), at);
      at += take;
      if (at === samples.length) break;
    }
    return { samples, units, sampleRate };
  } finally {
    glug.free();
  }
}

/** The GUID of WAVE_FORMAT_IEEE_FLOAT in an extensible format chunk. */
const IEEE_FLOAT_GUID = [0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x80, 0x00, 0x00, 0xaa, 0x00, 0x38, 0x9b, 0x71];

/**
 * A mono WAV file of 32-bit float samples: the bytes `sake-glug render -o FILE.wav` writes for
 * the same samples (an extensible format chunk, as its WAV writer has it, then the data).
 */
export function encodeWav(samples, sampleRate) {
  const header = 12 + 8 + 40 + 8;
  const dataBytes = samples.length * 4;
  const bytes = new Uint8Array(header + dataBytes);
  const view = new DataView(bytes.buffer);
  const ascii = (at, text) => {
    for (let i = 0; i < text.length; i += 1) bytes[at + i] = text.charCodeAt(i);
  };
  ascii(0, "RIFF");
  view.setUint32(4, header - 8 + dataBytes, true);
  ascii(8, "WAVE");
  ascii(12, "fmt ");
  view.setUint32(16, 40, true);
  view.setUint16(20, 0xfffe, true); // WAVE_FORMAT_EXTENSIBLE
  view.setUint16(22, 1, true); // mono
  view.setUint32(24, sampleRate, true);
  view.setUint32(28, sampleRate * 4, true);
  view.setUint16(32, 4, true);
  view.setUint16(34, 32, true);
  view.setUint16(36, 22, true);
  view.setUint16(38, 32, true); // valid bits
  view.setUint32(40, 1, true); // the channel mask: front left
  bytes.set(IEEE_FLOAT_GUID, 44);
  ascii(60, "data");
  view.setUint32(64, dataBytes, true);
  for (let i = 0; i < samples.length; i += 1) view.setFloat32(header + 4 * i, samples[i], true);
  return bytes;
}

/** `render(scene)` as the bytes of a WAV file. */
export async function renderToWav(scene = {}, options = {}) {
  const { samples, sampleRate } = await render(scene, options);
  return encodeWav(samples, sampleRate);
}
