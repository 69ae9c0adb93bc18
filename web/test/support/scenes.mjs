// The scenes the tests render both ways: as the CLI takes them (a scene file, a model file,
// options) and as the package takes them (a sample rate, a model or a preset, a score of calls).

import { builtInPour } from "../../src/index.js";

/** A model file: another liquid and glug, and the headspace law at work. */
export const MODEL = `viscosity_c = 0.45
pour_time_s = 4.0

[bottle]
headspace_ml = 40.0

[glug]
f1_hz = 95.0
f1_headspace_exponent = 0.5
`;

export const SCENES = [
  {
    name: "the default scene at 48 kHz",
    cli: {},
    web: { sampleRate: 48000 },
  },
  {
    name: "the syrup preset at 44.1 kHz",
    cli: { args: ["--preset", "syrup", "--sample-rate", "44100"] },
    web: { sampleRate: 44100, preset: "syrup", score: builtInPour(44100) },
  },
  {
    // Steps and ramps whose frames fall inside 128-frame blocks (12 000 = 93.75 blocks).
    name: "a model file with steps and ramps at 48 kHz",
    cli: {
      model: MODEL,
      scene: `tilt_deg = [[0.0, 100.0], [0.25, 100.0], [0.45, 150.0], [0.75, 150.0], [1.75, 40.0]]
viscosity_c = [[0.0, 0.5], [0.75, 0.5], [0.75, 0.8]]
output.gain_db = [[0.0, -6.0], [0.25, -6.0], [0.35, -12.0]]
pour_time_s = 3.0
`,
    },
    web: {
      sampleRate: 48000,
      model: MODEL,
      score: [
        { frame: 0, op: "set", control: "tilt", value: 100 },
        { frame: 0, op: "set", control: "visc", value: 0.5 },
        { frame: 0, op: "set", control: "pour", value: 3 },
        { frame: 12000, op: "ramp", control: "tilt", value: 150, frames: 9600 },
        { frame: 12000, op: "ramp", control: "gain", value: -12, frames: 4800 },
        { frame: 36000, op: "set", control: "visc", value: 0.8 },
        { frame: 36000, op: "ramp", control: "tilt", value: 40, frames: 48000 },
      ],
    },
  },
];
