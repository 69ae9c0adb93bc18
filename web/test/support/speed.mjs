// How fast the package renders, beside the CLI, for docs/guide/web.md: a minute of continuous
// glugs rendered by `sake-glug render` (the CLI of SAKE_GLUG_CLI), by the package's `render` in
// Node.js and on a page's thread in headless Chromium, and through the AudioWorklet in an
// OfflineAudioContext there; each the best of a few runs, all in this one run. Printed as JSON
// for `cargo xtask docs web`, which writes the guide's table; nothing here is a test (speed
// depends on the machine and its load).
//
// `node test/support/speed.mjs` in web/, after `cargo xtask web` (the package's dist/).

import { execFileSync } from "node:child_process";
import { fileURLToPath } from "node:url";
import { cliRender, firstDifference, workFolder } from "./cli.mjs";
import { serve } from "./server.mjs";
import { missingBrowser, startBrowser } from "./webdriver.mjs";
import { loadSakeGlug, render } from "../../src/index.js";

/** Runs of each render; the best is kept, the one least slowed by whatever else the machine runs. */
const RUNS = 5;
const SECONDS = 60;
const SAMPLE_RATE = 48000;
const TILT_DEG = 135;
const CAPACITY_ML = 3000;
/** A full bottle at 135° empties in this time: a minute of glugs without a pause. */
const POUR_TIME_S = 60;

/** The scene as the CLI takes it (a scene file) and as the package takes it. */
const SCENE = {
  cli: `sample_rate = ${SAMPLE_RATE}
duration_s = ${SECONDS}
tilt_deg = ${TILT_DEG}.0
pour_time_s = ${POUR_TIME_S}.0

[bottle]
capacity_ml = ${CAPACITY_ML}.0
`,
  web: {
    sampleRate: SAMPLE_RATE,
    seconds: SECONDS,
    model: `pour_time_s = ${POUR_TIME_S}.0\n\n[bottle]\ncapacity_ml = ${CAPACITY_ML}.0\n`,
    score: [{ frame: 0, op: "set", control: "tilt", value: TILT_DEG }],
  },
};

/** The least of `RUNS` timings (ms) of `run`, which resolves to its own timing. */
async function best(run) {
  let least = Infinity;
  for (let k = 0; k < RUNS; k += 1) least = Math.min(least, await run());
  return least;
}

// Without Chromium, no figures at all: the guide keeps its table rather than half of it.
const missing = missingBrowser();
if (missing !== null) {
  console.log(JSON.stringify({ missing }));
  process.exit(0);
}

// The CLI, timed as a user runs it: the process, the render and its WAV file.
const folder = workFolder("speed");
const expected = cliRender({ scene: SCENE.cli }, folder);
const cliMs = await best(async () => {
  const started = performance.now();
  execFileSync(process.env.SAKE_GLUG_CLI, ["render", "scene.toml", "-o", "out.wav"], { cwd: folder, stdio: "ignore" });
  return performance.now() - started;
});

// The package in Node.js, the engine loaded first (once, as an app loads it).
await loadSakeGlug();
let rendered;
const nodeMs = await best(async () => {
  const started = performance.now();
  rendered = await render(SCENE.web, { blockFrames: 4096 });
  return performance.now() - started;
});
// The figures are of one render: the same samples everywhere, or no figures.
if (firstDifference(rendered.samples, expected.samples) !== -1) {
  throw new Error("the package's render of the timed scene is not the CLI's");
}

// The package in headless Chromium, on the page's thread and through the AudioWorklet.
const server = await serve(fileURLToPath(new URL("../..", import.meta.url)));
const browser = await startBrowser();
let page;
try {
  await browser.timeouts(300_000);
  await browser.open(`${server.url}/demo/`);
  page = await browser.run(
    `const [scene, runs] = arguments;
    const { loadSakeGlug, render, renderInContext } = await import("/src/index.js");
    await loadSakeGlug();
    const timed = async (run) => {
      let least = Infinity;
      for (let k = 0; k < runs; k += 1) {
        const started = performance.now();
        const clip = await run();
        least = Math.min(least, performance.now() - started);
        if (clip.samples.length !== scene.seconds * scene.sampleRate) throw new Error("a short render");
      }
      return least;
    };
    return {
      renderMs: await timed(() => render(scene, { blockFrames: 4096 })),
      workletMs: await timed(() => renderInContext(scene)),
    };`,
    SCENE.web,
    RUNS,
  );
} finally {
  await browser.quit();
  await server.close();
}

console.log(
  JSON.stringify({
    seconds: SECONDS,
    sampleRate: SAMPLE_RATE,
    tiltDeg: TILT_DEG,
    capacityMl: CAPACITY_ML,
    pourTimeS: POUR_TIME_S,
    units: rendered.units.length,
    runs: RUNS,
    node: process.version,
    chromium: browser.browserVersion,
    ms: { cli: cliMs, node: nodeMs, page: page.renderMs, worklet: page.workletMs },
  }),
);
