// Headless Chromium driven by chromedriver over WebDriver (HTTP and JSON, with Node.js's own
// fetch): a session, a page, scripts run in it, and its console.

import { spawn } from "node:child_process";
import { createServer } from "node:net";
import { existsSync } from "node:fs";

/** The Chromium and chromedriver of Debian's packages, or where CHROMIUM and CHROMEDRIVER say. */
export const CHROMIUM = process.env.CHROMIUM ?? "/usr/bin/chromium";
export const CHROMEDRIVER = process.env.CHROMEDRIVER ?? "/usr/bin/chromedriver";

/** Why the browser tests cannot run here, or null. */
export function missingBrowser() {
  const missing = [CHROMIUM, CHROMEDRIVER].filter((path) => !existsSync(path));
  return missing.length > 0 ? `${missing.join(" and ")} missing (Debian: apt-get install chromium chromium-driver)` : null;
}

async function freePort() {
  const server = createServer();
  await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
  const { port } = server.address();
  await new Promise((resolve) => server.close(resolve));
  return port;
}

/** Starts chromedriver and a headless Chromium session; resolves to a Session. */
export async function startBrowser() {
  const port = await freePort();
  const driver = spawn(CHROMEDRIVER, [`--port=${port}`], { stdio: ["ignore", "pipe", "pipe"] });
  const base = `http://127.0.0.1:${port}`;
  // chromedriver answers its status once it listens: asked until it does (no fixed wait).
  let ready = false;
  for (let attempt = 0; attempt < 200 && !ready; attempt += 1) {
    try {
      ready = (await (await fetch(`${base}/status`)).json()).value?.ready === true;
    } catch {
      await new Promise((resolve) => setTimeout(resolve, 50));
    }
  }
  if (!ready) {
    driver.kill();
    throw new Error("chromedriver did not start");
  }
  const created = await command(base, "POST", "/session", {
    capabilities: {
      alwaysMatch: {
        browserName: "chrome",
        "goog:chromeOptions": {
          binary: CHROMIUM,
          args: ["--headless=new", "--no-sandbox", "--disable-gpu", "--autoplay-policy=no-user-gesture-required"],
        },
        "goog:loggingPrefs": { browser: "ALL" },
      },
    },
  });
  return new Session(base, created.sessionId, driver, created.capabilities?.browserVersion);
}

async function command(base, method, path, body) {
  const response = await fetch(`${base}${path}`, {
    method,
    headers: { "content-type": "application/json" },
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  const reply = await response.json();
  if (!response.ok) {
    throw new Error(`WebDriver ${method} ${path}: ${reply.value?.error}: ${reply.value?.message}`);
  }
  return reply.value;
}

export class Session {
  constructor(base, id, driver, browserVersion) {
    this.base = base;
    this.id = id;
    this.driver = driver;
    /** Chromium's version, as the session reports it (for the figures it measures). */
    this.browserVersion = browserVersion;
  }

  #command(method, path, body) {
    return command(this.base, method, `/session/${this.id}${path}`, body);
  }

  /** Loads `url` and waits until the page has loaded. */
  open(url) {
    return this.#command("POST", "/url", { url });
  }

  /** Runs `script` (an async function's body, `arguments` its args) in the page; its result. */
  run(script, ...args) {
    return this.#command("POST", "/execute/async", {
      script: `const done = arguments[arguments.length - 1];
        (async (...args) => { ${script} })(...Array.from(arguments).slice(0, -1))
          .then((value) => done({ ok: value }), (error) => done({ error: String(error && error.stack || error) }));`,
      args,
    }).then((reply) => {
      if (reply.error !== undefined) throw new Error(`in the page: ${reply.error}`);
      return reply.ok;
    });
  }

  /** Sets how long a script may run (ms). */
  timeouts(script) {
    return this.#command("POST", "/timeouts", { script });
  }

  /** Sets the window's size (px). */
  size(width, height) {
    return this.#command("POST", "/window/rect", { width, height });
  }

  /** The page as a PNG's bytes. */
  async screenshot() {
    return Buffer.from(await this.#command("GET", "/screenshot"), "base64");
  }

  /** The browser console's entries since the last call: `[{ level, message }]`. */
  console() {
    return this.#command("POST", "/se/log", { type: "browser" });
  }

  async quit() {
    try {
      await this.#command("DELETE", "");
    } finally {
      this.driver.kill();
    }
  }
}
