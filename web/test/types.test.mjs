// The package's TypeScript types (src/index.d.ts), as a TypeScript user meets them: the packed
// tarball installed into an empty folder, test/types/pour.ts (the README's ten lines, more of the
// API, and calls the types must refuse) checked by `tsc --noEmit` with strict options and the
// declarations themselves checked (no skipLibCheck), under a bundler's module resolution and
// under Node.js's; and the values the types declare are the ones the package exports.
// TypeScript is the version test/types/package-lock.json pins, which `cargo xtask web test`
// installs and names in SAKE_GLUG_TYPESCRIPT.

import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { copyFileSync, writeFileSync } from "node:fs";
import { createRequire } from "node:module";
import { join } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";
import { workFolder } from "./support/cli.mjs";

const TARBALL = process.env.SAKE_GLUG_TARBALL;
const TYPESCRIPT = process.env.SAKE_GLUG_TYPESCRIPT;
const TYPES = fileURLToPath(new URL("types/", import.meta.url));
const skip = !TARBALL || !TYPESCRIPT ? "run these tests with `cargo xtask web test`" : false;

/** A folder with the tarball installed and the example beside it, made once. */
let installed;
function project() {
  if (installed) return installed;
  const folder = workFolder("types");
  writeFileSync(join(folder, "package.json"), JSON.stringify({ name: "a-game", private: true, type: "module" }));
  execFileSync("npm", ["install", "--no-audit", "--no-fund", "--offline", TARBALL], { cwd: folder, stdio: "pipe" });
  for (const file of ["pour.ts", "tsconfig.json"]) copyFileSync(join(TYPES, file), join(folder, file));
  installed = folder;
  return folder;
}

/** `tsc -p` in the project with `args`; its output, or the error that carries it. */
function tsc(args) {
  const cwd = project();
  try {
    execFileSync("node", [join(TYPESCRIPT, "bin", "tsc"), "-p", ".", ...args], { cwd, encoding: "utf8", stdio: "pipe" });
    return "";
  } catch (error) {
    return `${error.stdout}${error.stderr}` || String(error);
  }
}

test("the README's example and the API's calls type-check, and the bad calls are refused (bundler resolution)", { skip }, () => {
  assert.equal(tsc([]), "", "tsc's errors");
});

test("the same under Node.js's module resolution", { skip }, () => {
  assert.equal(tsc(["--module", "nodenext", "--moduleResolution", "nodenext"]), "", "tsc's errors");
});

test("the values the types declare are the package's exports", { skip }, async () => {
  const ts = createRequire(import.meta.url)(TYPESCRIPT);
  const folder = project();
  const entry = join(folder, "node_modules", "sake-glug", "src", "index.d.ts");
  const program = ts.createProgram([entry], { noEmit: true, lib: ["lib.es2022.d.ts", "lib.dom.d.ts"], types: [] });
  const checker = program.getTypeChecker();
  const declared = checker
    .getExportsOfModule(checker.getSymbolAtLocation(program.getSourceFile(entry)))
    .filter((symbol) => symbol.flags & ts.SymbolFlags.Value)
    .map((symbol) => symbol.name)
    .sort();
  const module = await import(pathToFileURL(join(folder, "node_modules", "sake-glug", "src", "index.js")));
  assert.deepEqual(declared, Object.keys(module).sort());
});
