// The page that pours: the plugin's controls on a live AudioWorklet node, its waveform and units,
// gamepad and phone haptics where there are any, a phone's tilt where the browser gives it, and
// the built-in pour rendered offline for download. Everything it loads is in the package.

import {
  loadSakeGlug,
  version,
  CONTROLS,
  CONSTANTS,
  PRESETS,
  modelText,
  createBottleNode,
  renderInContext,
  builtInPour,
  encodeWav,
  clip,
  HapticsDriver,
  tiltFromOrientation,
} from "../src/index.js";

/** The constants of the headspace law (MODEL.md §5.1), as the engine's table names them. */
const HEADSPACE_KEYS = ["bottle.headspace_ml", "glug.f1_headspace_exponent", "glug.f2_headspace_exponent"];
/** The rate of the offline clip. */
const CLIP_RATE = 48000;

const $ = (id) => document.getElementById(id);
const controlKeys = new Set(CONTROLS.map((control) => control.key));

const page = {
  preset: PRESETS[0],
  controls: Object.fromEntries(CONTROLS.map((control) => [control.id, control.default])),
  headspace: {},
  sliders: {},
  context: null,
  node: null,
  analyser: null,
  haptics: null,
  units: 0,
  orientation: null,
};

/** A slider for a quantity of the engine's tables; `onChange(value)`. */
function slider(quantity, value, onChange) {
  const label = document.createElement("label");
  const shown = document.createElement("span");
  shown.className = "value";
  const input = document.createElement("input");
  input.type = "range";
  input.min = quantity.knobMin;
  input.max = quantity.knobMax;
  input.step = 10 ** -Math.max(quantity.decimals, 0);
  input.value = value;
  input.id = `slider-${quantity.id}`;
  input.title = quantity.note;
  const show = () => {
    shown.textContent = `${Number(input.value).toFixed(Math.max(quantity.decimals, 0))} ${quantity.unit}`;
  };
  input.addEventListener("input", () => {
    show();
    onChange(Number(input.value));
  });
  show();
  label.append(`${quantity.name} `, shown, input);
  return { label, input, show };
}

/** The bottle as a model file: the preset's constants and the headspace law's sliders. */
function model() {
  const values = {};
  for (const [key, value] of Object.entries(page.preset.values)) {
    if (!controlKeys.has(key)) values[key] = value;
  }
  return modelText({ ...values, ...page.headspace });
}

function setControl(id, value) {
  page.controls[id] = value;
  const slider = page.sliders[id];
  if (slider && Number(slider.input.value) !== value) {
    slider.input.value = value;
    slider.show();
  }
  if (page.node) page.node.param(id).setValueAtTime(value, page.context.currentTime);
}

function applyPreset(preset) {
  page.preset = preset;
  $("preset-description").textContent = preset.description;
  for (const control of CONTROLS) {
    if (preset.values[control.key] !== undefined) setControl(control.id, preset.values[control.key]);
  }
  for (const key of HEADSPACE_KEYS) {
    const constant = CONSTANTS.find((c) => c.key === key);
    const value = preset.values[key] ?? constant.default;
    page.headspace[key] = value;
    page.sliders[key].input.value = value;
    page.sliders[key].show();
  }
}

function buildControls() {
  for (const control of CONTROLS) {
    const made = slider(control, control.default, (value) => setControl(control.id, value));
    page.sliders[control.id] = made;
    $("controls").append(made.label);
  }
  for (const key of HEADSPACE_KEYS) {
    const constant = CONSTANTS.find((c) => c.key === key);
    const made = slider(constant, constant.default, (value) => {
      page.headspace[key] = value;
    });
    page.sliders[key] = made;
    $("headspace").append(made.label);
  }
  const note = document.createElement("p");
  note.className = "note";
  note.textContent = "The bottle's constants take effect at the next Play or Render.";
  $("headspace").append(note);
  for (const preset of PRESETS) {
    const option = document.createElement("option");
    option.value = preset.id;
    option.textContent = preset.name;
    $("preset").append(option);
  }
  $("preset").addEventListener("change", () => applyPreset(PRESETS.find((p) => p.id === $("preset").value)));
  applyPreset(PRESETS[0]);
}

function showUnits(units) {
  page.units += units.length;
  $("unit-count").textContent = page.units;
  const list = $("units");
  for (const unit of units) {
    const item = document.createElement("li");
    item.textContent = `${unit.timeS.toFixed(3)} s: f1 ${unit.f1Hz.toFixed(1)} Hz, f2 ${unit.f2Hz.toFixed(1)} Hz, a ${unit.amplitude.toFixed(3)}, V ${unit.volumeMl.toFixed(1)} ml${unit.audible ? "" : " (silent)"}`;
    list.prepend(item);
  }
  while (list.children.length > 40) list.lastChild.remove();
  list.start = page.units;
}

async function start() {
  $("start").disabled = true;
  const context = new AudioContext();
  const node = await createBottleNode(context, { model: model(), controls: { ...page.controls } });
  const analyser = new AnalyserNode(context, { fftSize: 2048 });
  node.connect(analyser).connect(context.destination);
  Object.assign(page, { context, node, analyser, units: 0 });
  $("units").replaceChildren();
  const latency = () => context.outputLatency || context.baseLatency || 0;
  page.haptics = new HapticsDriver({
    sampleRate: context.sampleRate,
    clock: () => context.currentTime - latency() - (node.originTime ?? context.currentTime),
  });
  node.addEventListener("units", (event) => {
    showUnits(event.detail.units);
    page.haptics.add(event.detail.units);
  });
  node.addEventListener("state", (event) => {
    const s = event.detail;
    $("status").textContent = `${s.volumeMl.toFixed(1)} ml in the bottle at ${s.tiltDeg.toFixed(1)}°${s.submerged ? ", glugging" : ""}`;
  });
  node.addEventListener("error", (event) => {
    $("status").textContent = event.detail.message;
  });
  const { gamepad, vibrate } = page.haptics.available;
  $("haptics").textContent = `Haptics: ${gamepad ? "a gamepad rumbles" : "no gamepad that rumbles (press a button on one)"}; ${vibrate ? "this device vibrates" : "no navigator.vibrate"}.`;
  page.haptics.start();
  await context.resume();
  $("stop").disabled = false;
  $("refill").disabled = false;
  draw();
}

function stop() {
  page.haptics?.stop();
  page.node?.disconnect();
  page.context?.close();
  Object.assign(page, { context: null, node: null, analyser: null, haptics: null });
  $("start").disabled = false;
  $("stop").disabled = true;
  $("refill").disabled = true;
}

/** A whole clip on the waveform's canvas: each column's lowest and highest sample. */
function drawClip(samples) {
  const canvas = $("waveform");
  const context2d = canvas.getContext("2d");
  const { width, height } = canvas;
  context2d.fillStyle = "#1d1b16";
  context2d.fillRect(0, 0, width, height);
  context2d.strokeStyle = "#e8c46a";
  context2d.beginPath();
  const perColumn = Math.max(1, Math.ceil(samples.length / width));
  for (let x = 0; x < width; x += 1) {
    let low = 0;
    let high = 0;
    for (let i = x * perColumn; i < Math.min((x + 1) * perColumn, samples.length); i += 1) {
      low = Math.min(low, samples[i]);
      high = Math.max(high, samples[i]);
    }
    context2d.moveTo(x + 0.5, height / 2 - high * (height / 2));
    context2d.lineTo(x + 0.5, height / 2 - low * (height / 2) + 1);
  }
  context2d.stroke();
}

function draw() {
  const canvas = $("waveform");
  const context2d = canvas.getContext("2d");
  const samples = new Float32Array(page.analyser?.fftSize ?? 2048);
  const frame = () => {
    if (!page.analyser) return;
    page.analyser.getFloatTimeDomainData(samples);
    const { width, height } = canvas;
    context2d.fillStyle = "#1d1b16";
    context2d.fillRect(0, 0, width, height);
    context2d.strokeStyle = "#e8c46a";
    context2d.beginPath();
    for (let i = 0; i < samples.length; i += 1) {
      const x = (i / (samples.length - 1)) * width;
      const y = height / 2 - samples[i] * (height / 2);
      if (i === 0) context2d.moveTo(x, y);
      else context2d.lineTo(x, y);
    }
    context2d.stroke();
    requestAnimationFrame(frame);
  };
  requestAnimationFrame(frame);
}

/** A phone's tilt as the bottle's, where the browser gives the device's orientation. */
async function phoneTilt() {
  if (typeof DeviceOrientationEvent === "undefined") return;
  if (typeof DeviceOrientationEvent.requestPermission === "function") {
    // iOS asks the user, once, on a tap.
    if ((await DeviceOrientationEvent.requestPermission()) !== "granted") {
      $("tilt-source").textContent = "The phone's tilt was not allowed.";
      return;
    }
  }
  $("tilt-source").textContent = "Waiting for the phone's orientation (none comes on a computer)…";
  window.addEventListener("deviceorientation", (event) => {
    if (event.beta === null || event.gamma === null) return;
    const tilt = tiltFromOrientation(event.beta, event.gamma);
    if (tilt === null) return;
    $("tilt-source").textContent = "Tilt follows the phone: hold it upright, then pour it over its top edge.";
    setControl("tilt", Math.round(tilt * 100) / 100);
  });
}

/** A file of `bytes` offered as a download by link `id`. */
function offer(id, bytes, type) {
  const link = $(id);
  if (link.href) URL.revokeObjectURL(link.href);
  link.href = URL.createObjectURL(new Blob([bytes], { type }));
  link.hidden = false;
}

async function renderClip() {
  $("render").disabled = true;
  $("render-status").textContent = "Rendering…";
  const started = performance.now();
  const settings = CONTROLS.filter((control) => control.id !== "tilt").map((control) => ({
    frame: 0,
    op: "set",
    control: control.id,
    value: page.controls[control.id],
  }));
  const rendered = await renderInContext({
    sampleRate: CLIP_RATE,
    model: model(),
    score: [...settings, ...builtInPour(CLIP_RATE)],
  });
  const seconds = rendered.samples.length / CLIP_RATE;
  const took = (performance.now() - started) / 1000;
  offer("download-wav", encodeWav(rendered.samples, CLIP_RATE), "audio/wav");
  // The clips by the renderer's own writers, in the engine.
  const clipOf = (format) => clip(format, rendered.units, { durationS: seconds, name: "web", seed: 1 });
  offer("download-ahap", clipOf("ahap"), "application/json");
  offer("download-haptic", clipOf("haptic"), "application/json");
  offer("download-rumble", clipOf("rumble"), "application/json");
  offer("download-android", clipOf("android-waveform"), "application/json");
  page.clip = { units: rendered.units, seconds };
  if (!page.node) {
    // Not pouring live: the page shows the clip.
    drawClip(rendered.samples);
    page.units = 0;
    $("units").replaceChildren();
    showUnits(rendered.units);
    $("status").textContent = `The clip: ${seconds.toFixed(2)} s.`;
  }
  $("feel").hidden = !(navigator.getGamepads || navigator.vibrate);
  $("render-status").textContent = `${seconds.toFixed(2)} s, ${rendered.units.length} units, rendered in ${took.toFixed(2)} s (${(seconds / took).toFixed(0)}× real time).`;
  $("render").disabled = false;
}

/** The rendered clip on the gamepad and the vibrator, from now. */
function feel() {
  const { units, seconds } = page.clip;
  const started = performance.now();
  const driver = new HapticsDriver({ sampleRate: CLIP_RATE, clock: () => (performance.now() - started) / 1000 });
  driver.add(units);
  driver.start();
  setTimeout(() => driver.stop(), seconds * 1000);
}

async function main() {
  await loadSakeGlug();
  $("version").textContent = `engine ${version()}`;
  buildControls();
  $("start").addEventListener("click", () => start().catch((error) => ($("status").textContent = error.message)));
  $("stop").addEventListener("click", stop);
  $("refill").addEventListener("click", () => page.node?.refill());
  $("render").addEventListener("click", () => {
    page.rendering = renderClip().catch((error) => {
      $("render-status").textContent = error.message;
      $("render").disabled = false;
    });
  });
  $("feel").addEventListener("click", feel);
  if (typeof DeviceOrientationEvent === "undefined") {
    $("phone-tilt").hidden = true;
  } else {
    $("phone-tilt").addEventListener("click", () => phoneTilt());
  }
}

/** Resolves once the page is built; the page's state (the browser test reads both). */
window.sakeGlugDemo = main();
window.sakeGlugPage = page;
