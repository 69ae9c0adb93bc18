// Types of the sake-glug package (src/index.js).

/** A control's id (the plugin's parameter id) or its scene key. */
export type ControlName =
  | "tilt"
  | "visc"
  | "fill"
  | "pour"
  | "gain"
  | "tilt_deg"
  | "viscosity_c"
  | "fill_percent"
  | "pour_time_s"
  | "output.gain_db";

/** A quantity of the engine's tables: a control or a model constant. */
export interface Quantity {
  /** The parameter id ("tilt", "visc", …). */
  id: string;
  /** The scene key ("tilt_deg", "bottle.capacity_ml", …). */
  key: string;
  name: string;
  unit: string;
  note: string;
  min: number;
  max: number;
  default: number;
  /** The span a knob or slider shows, and its decimals. */
  knobMin: number;
  knobMax: number;
  decimals: number;
}

/** A shipped preset: the values it sets, keyed by scene key. */
export interface Preset {
  id: string;
  name: string;
  description: string;
  values: Record<string, number>;
}

/** The controls, in the engine's order (tilt, visc, fill, pour, gain). */
export const CONTROLS: readonly Quantity[];
/** The model's constants (what a model file may set besides the controls). */
export const CONSTANTS: readonly Quantity[];
/** The shipped presets. */
export const PRESETS: readonly Preset[];
/** The release's version (the engine's and the package's). */
export const VERSION: string;

/** Where the .wasm is, as a URL, a path, its bytes, or the module compiled already. */
export type WasmSource = string | URL | ArrayBuffer | ArrayBufferView | WebAssembly.Module;

/** Loads the engine in this realm (once); resolves to its compiled module. */
export function loadSakeGlug(source?: WasmSource): Promise<WebAssembly.Module>;
/** Instantiates the engine in this realm from a compiled module, synchronously (a worklet). */
export function initFromModule(module: WebAssembly.Module): WebAssembly.Module;
/** The URL of the package's own .wasm. */
export function wasmUrl(): URL;
/** The engine's version (after loadSakeGlug). */
export function version(): string;
/** The number of a control in the engine's table; throws a TypeError for an unknown name. */
export function controlNumber(name: ControlName | string): number;
/** A model file's text (MODEL.md §12.1) from values keyed by scene key. */
export function modelText(values: Record<string, number>): string;
/** The names of a unit's numbers, in the order of a unit table's rows. */
export function unitFieldNames(): readonly string[];
/** The most frames a block renders and the most units it keeps. */
export function limits(): { maxBlockFrames: number; maxUnits: number };
/** The clip formats `clip` writes. */
export function clipFormats(): string[];
/**
 * A haptic clip's text by the renderer's own writer ("ahap", "haptic", "rumble",
 * "android-waveform", "android-xml", "haps"), from a render's units (each with its timeS).
 */
export function clip(
  format: string,
  units: Unit[],
  options: { durationS: number; name?: string; seed?: number },
): string;
/** The bottle's tilt (°) from a gravity reading that points up, along `axis` ("+y" by default). */
export function tiltFromGravity(reading: [number, number, number], axis?: string): number | null;
/** The bottle's tilt (°) from a DeviceOrientationEvent's beta and gamma (°). */
export function tiltFromOrientation(beta: number, gamma: number): number | null;

/** One glug unit as it started (MODEL.md §5, §7). */
export interface Unit {
  /** The frame of its block at which it is first heard. */
  frame: number;
  /** Whether any of its components sounds. */
  audible: boolean;
  /** The sample, counted since the glug's last reset, during which it starts. */
  sample: number;
  /** Its onset lies at (sample + fraction) / sampleRate. */
  fraction: number;
  tiltDeg: number;
  volumeMl: number;
  pocketMl: number;
  /** G·a: its peak amplitude as heard, both components (a1 = c·amplitude, a2 = (1 − c)·amplitude). */
  amplitude: number;
  viscosityC: number;
  f1Hz: number;
  f2Hz: number;
  b1PerS: number;
  b2PerS: number;
  /** Its onset (s) from the start of a render or of a node. */
  timeS?: number;
  /** Its onset on the AudioContext's clock (a node's units). */
  contextTime?: number;
}

/** The bottle after the last block. */
export interface GlugState {
  position: number;
  activeUntil: number;
  volumeMl: number;
  outflowMlPerS: number;
  tiltDeg: number;
  outputGain: number;
  submerged: boolean;
  settled: boolean;
  unitsLost: number;
}

export interface GlugOptions {
  /** Hz, a whole number from 1000 to 768000 (default 48000). */
  sampleRate?: number;
  /** A model file's text. */
  model?: string;
  /** A shipped preset's id ("water", "syrup", …). */
  preset?: string;
  /** A whole number (default: the products' seed). */
  seed?: number;
}

/** One live glug: the C library's handle. Every method throws an Error on a bad argument. */
export class Glug {
  static create(options?: GlugOptions): Glug;
  readonly sampleRate: number;
  set(control: ControlName, value: number): void;
  ramp(control: ControlName, target: number, samples: number): void;
  refill(): void;
  reset(): void;
  setActuator(profileText: string | null): void;
  startingValue(control: ControlName): number;
  /** A view of the engine's buffer, valid until the next call. */
  process(frames: number): Float32Array;
  processInto(out: Float32Array): void;
  readonly unitCount: number;
  unitTable(): Float64Array;
  units(): Unit[];
  readonly state: GlugState;
  readonly position: number;
  readonly activeUntil: number;
  readonly settled: boolean;
  free(): void;
}

/** Unit objects from a unit table's rows. */
export function unitsOf(table: Float64Array): Unit[];

/** A call of a score, at a sample frame from its start. */
export type Call =
  | { frame?: number; op: "set"; control: ControlName; value: number }
  | { frame?: number; op: "ramp"; control: ControlName; value: number; frames: number }
  | { frame?: number; op: "refill" | "reset" };

/** The built-in pour's score: 90° to 135° over half a second. */
export function builtInPour(sampleRate: number): Call[];
/** A call checked (throws on a bad one) and made plain. */
export function checkedCall(call: Call): Call;

/** Plays a score on a glug, cutting blocks at the calls' frames. */
export class ScorePlayer {
  constructor(glug: Glug, calls?: Call[]);
  readonly glug: Glug;
  add(call: Call): void;
  readonly pending: number;
  render(start: number, out: Float32Array, onUnits?: (table: Float64Array, offset: number) => void): void;
}

export interface Scene extends GlugOptions {
  /** The calls; default: the built-in pour. */
  score?: Call[];
  /** Its length; default: until it settles and every unit has decayed. */
  seconds?: number;
}

export interface Rendered {
  samples: Float32Array;
  units: Unit[];
  sampleRate: number;
}

export function checkedScene(scene?: Scene): Required<Pick<Scene, "sampleRate" | "score">> & Scene;
export function render(scene?: Scene, options?: { blockFrames?: number }): Promise<Rendered>;
export function renderLoaded(scene?: Scene, options?: { blockFrames?: number }): Rendered;
export function renderToWav(scene?: Scene, options?: { blockFrames?: number }): Promise<Uint8Array>;
/** A mono 32-bit float WAV file's bytes (those `sake-glug render` writes). */
export function encodeWav(samples: Float32Array, sampleRate: number): Uint8Array;

export interface BottleNodeOptions extends GlugOptions {
  /** Controls' values at the start. */
  controls?: Partial<Record<ControlName, number>>;
  score?: Call[];
  /** Output channels, each the mono glug (default 1). */
  channels?: number;
  wasm?: WasmSource;
  workletUrl?: string | URL;
}

/** The bottle as an AudioNode. */
export interface SakeGlugNode extends AudioWorkletNode {
  readonly tilt: AudioParam;
  readonly viscosity: AudioParam;
  readonly fill: AudioParam;
  readonly pourTime: AudioParam;
  readonly gain: AudioParam;
  /** The AudioParam of a control. */
  param(control: ControlName): AudioParam;
  /** The context time of the glug's frame 0, once known. */
  readonly originTime: number | null;
  readonly state: GlugState | null;
  /** At context time `when` (s), or at the next block. */
  set(control: ControlName, value: number, when?: number): void;
  ramp(control: ControlName, target: number, seconds: number, when?: number): void;
  refill(when?: number): void;
  reset(when?: number): void;
  addEventListener(type: "units", listener: (event: CustomEvent<{ units: Unit[] }>) => void): void;
  addEventListener(type: "state", listener: (event: CustomEvent<GlugState & { frame: number }>) => void): void;
  addEventListener(type: "error", listener: (event: CustomEvent<{ message: string; fatal: boolean }>) => void): void;
  addEventListener(type: string, listener: EventListenerOrEventListenerObject): void;
}

export const WORKLET_URL: URL;
export function createBottleNode(context: BaseAudioContext, options?: BottleNodeOptions): Promise<SakeGlugNode>;
export function renderInContext(
  scene?: Scene,
  options?: { wasm?: WasmSource; workletUrl?: string | URL },
): Promise<Rendered & { buffer: AudioBuffer | null }>;

export const RUMBLE_RATE_HZ: number;
export const ANDROID_STEP_MS: number;
export const ANDROID_FULL_AMPLITUDE: number;
export const ENVELOPE_FLOOR: number;

export interface ClipOptions {
  sampleRate: number;
  durationS: number;
  /** The output's ceiling (default 1). */
  ceiling?: number;
}

export class ComponentEnvelopes {
  constructor(options: { sampleRate: number; ceiling?: number });
  add(units: Unit[]): void;
  forgetBefore(t: number): void;
  at(t: number): [number, number];
  mean(fromS: number, toS: number): [number, number];
}

export interface RumbleFrame {
  tMs: number;
  low: number;
  high: number;
}

export function rumbleFrames(units: Unit[], options: ClipOptions & { rateHz?: number }): RumbleFrame[];

export interface AndroidStep {
  startMs: number;
  durationMs: number;
  amplitude: number;
  onset: boolean;
}

export function androidSteps(units: Unit[], options: ClipOptions): AndroidStep[];
export function vibratePattern(steps: AndroidStep[]): number[];

export interface HapticsOptions {
  sampleRate: number;
  /** Seconds on the units' timeline (their timeS). */
  clock: () => number;
  ceiling?: number;
  navigator?: Navigator;
  rateHz?: number;
  vibrateWindowMs?: number;
  gamepad?: boolean;
  vibrate?: boolean;
}

export class HapticsDriver {
  constructor(options: HapticsOptions);
  readonly available: { gamepad: boolean; vibrate: boolean };
  add(units: Unit[]): void;
  tick(): { tS: number; low: number; high: number; pads: number; pattern: number[] | null };
  start(): void;
  stop(): void;
}
