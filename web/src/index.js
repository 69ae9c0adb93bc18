// sake-glug: the glug of liquid poured from a sake bottle, synthesized live by the engine of
// Sake Glug in WebAssembly, sample for sample the glug its plugin, CLI and C library play.
//
// - loadSakeGlug(), Glug: the engine itself, block by block (browsers, workers, Node.js);
// - render(), renderToWav(), encodeWav(): offline renders (browsers and Node.js);
// - createBottleNode(), renderInContext(): the bottle as an AudioNode on an AudioWorklet, and a
//   clip rendered through it in an OfflineAudioContext (browsers);
// - HapticsDriver, rumbleFrames(), androidSteps(), vibratePattern(): gamepad rumble and
//   navigator.vibrate from the glug units.

export {
  loadSakeGlug,
  initFromModule,
  version,
  Glug,
  controlNumber,
  modelText,
  unitFieldNames,
  unitsOf,
  limits,
  tiltFromGravity,
  tiltFromOrientation,
  clip,
  clipFormats,
  CONTROLS,
  CONSTANTS,
  PRESETS,
  VERSION,
  wasmUrl,
} from "./glug.js";
export { ScorePlayer, builtInPour, checkedCall } from "./score.js";
export { render, renderLoaded, renderToWav, encodeWav, checkedScene } from "./render.js";
export { createBottleNode, renderInContext, WORKLET_URL } from "./node.js";
export {
  ComponentEnvelopes,
  HapticsDriver,
  rumbleFrames,
  androidSteps,
  vibratePattern,
  RUMBLE_RATE_HZ,
  ANDROID_STEP_MS,
  ANDROID_FULL_AMPLITUDE,
  ENVELOPE_FLOOR,
} from "./haptics.js";
