// The page that pours, in headless Chromium, after a Render, as a PNG for the guide:
// `node test/support/screenshot.mjs OUT.png` in web/ (`cargo xtask web screenshot` runs it).

import { writeFileSync } from "node:fs";
import { fileURLToPath } from "node:url";
import { serve } from "./server.mjs";
import { startBrowser } from "./webdriver.mjs";

const out = process.argv[2];
if (!out) throw new Error("usage: node test/support/screenshot.mjs OUT.png");
const server = await serve(fileURLToPath(new URL("../..", import.meta.url)));
const browser = await startBrowser();
try {
  await browser.timeouts(120_000);
  await browser.size(1100, 1350);
  await browser.open(`${server.url}/demo/`);
  await browser.run(`
    await window.sakeGlugDemo;
    const $ = (id) => document.getElementById(id);
    $("preset").value = "sake";
    $("preset").dispatchEvent(new Event("change"));
    $("render").click();
    await window.sakeGlugPage.rendering;`);
  writeFileSync(out, await browser.screenshot());
  console.log(`${out} written`);
} finally {
  await browser.quit();
  await server.close();
}
