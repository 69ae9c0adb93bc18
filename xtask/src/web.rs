//! `cargo xtask web`: the npm package of web/ built from crates/web, and its tests.
//!
//! - [`build`]: the binding crate for wasm32-unknown-unknown (one release build), its JS glue
//!   by wasm-bindgen-cli of the crate's exact version, the engine's tables as an ES module, the
//!   package's THIRD-PARTY.md (cargo-about, as the release's), all in the package's dist/ folder
//!   (not committed),
//!   then `npm pack` into <target dir>/web/.
//! - [`test`]: web/test/ under Node.js's own test runner: the packed tarball installed into an
//!   empty folder and rendering the CLI's samples, its TypeScript types checked by the pinned
//!   `tsc`, 128-frame blocks at 44.1 and 48 kHz, the haptics against the CLI's clips, bad input;
//!   then the page and an OfflineAudioContext render through the AudioWorklet in headless
//!   Chromium, driven by chromedriver.
//! - [`figures`]: the size and speed of docs/guide/web.md, measured (`cargo xtask docs web`).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Context;
use sake_glug_engine::{Constant, Control, Preset, PresetValue, PRESETS};
use serde_json::{json, Value};

use crate::{cargo, target_dir};

/// The package's folder.
const WEB: &str = "web";
/// What the build writes into the package (ignored by git).
const DIST: &str = "web/dist";
/// The Rust target of the .wasm.
const WASM_TARGET: &str = "wasm32-unknown-unknown";
/// The oldest Node.js the package supports, its `engines` in web/package.json.
const MIN_NODE: u32 = 20;
/// The TypeScript check's files: the example, its tsconfig, and the npm manifest and lock that
/// pin TypeScript.
const TYPES: &str = "web/test/types";

/// What building and testing the package needs that is missing here, each with how to get it
/// (.ci/run gets them all): the Rust target, wasm-bindgen-cli of the lock's version, Node.js
/// and npm. Empty when nothing is.
pub fn missing_tools() -> Vec<String> {
    let mut missing = Vec::new();
    let has_target = Command::new("rustc")
        .args(["--print", "target-libdir", "--target", WASM_TARGET])
        .output()
        .ok()
        .filter(|out| out.status.success())
        .map(|out| PathBuf::from(String::from_utf8_lossy(&out.stdout).trim()))
        .is_some_and(|libdir| {
            std::fs::read_dir(libdir).is_ok_and(|mut files| {
                files.any(|file| {
                    file.is_ok_and(|file| file.file_name().to_string_lossy().starts_with("libstd-"))
                })
            })
        });
    if !has_target {
        missing.push(format!(
            "the Rust target (`rustup target add {WASM_TARGET}`)"
        ));
    }
    if let Err(error) = require_wasm_bindgen() {
        missing.push(format!("{error:#}"));
    }
    match Command::new("node").arg("--version").output() {
        Err(_) => missing.push("node (Debian's `nodejs`)".into()),
        Ok(out) => {
            // The package asks for Node.js 20 (web/package.json's engines) and is tested there
            // alone: an older one would test what the guide does not claim.
            let version = String::from_utf8_lossy(&out.stdout).trim().to_owned();
            let major = version
                .trim_start_matches('v')
                .split('.')
                .next()
                .and_then(|major| major.parse::<u32>().ok());
            if major.is_none_or(|major| major < MIN_NODE) {
                missing.push(format!("Node.js {MIN_NODE} or newer, not {version}"));
            }
        }
    }
    if Command::new("npm").arg("--version").output().is_err() {
        missing.push("npm (Debian's `npm`)".into());
    }
    missing
}

/// The package built, packed and tested against the release CLI at `cli`, as `cargo xtask test`
/// runs it. Where its tools are missing, skipped with a line naming them, as the Windows release
/// is, but under CI (`$CI` set), which must run it, an error.
pub fn build_and_test(cli: &Path) -> anyhow::Result<()> {
    let missing = missing_tools();
    if !missing.is_empty() {
        let line = format!("the web package needs {}", missing.join("; "));
        anyhow::ensure!(std::env::var_os("CI").is_none(), "{line}");
        println!("{line}; skipped, with its tests");
        return Ok(());
    }
    let tarball = build()?;
    test(&tarball, cli)
}

/// The .wasm, its glue and tables in the package's dist/, and the packed tarball; returns its
/// path.
pub fn build() -> anyhow::Result<PathBuf> {
    let bindgen = require_wasm_bindgen()?;
    cargo(&[
        "build",
        "--release",
        "--locked",
        "--target",
        WASM_TARGET,
        "--package",
        "sake-glug-web",
    ])?;
    let wasm = target_dir().join(format!("{WASM_TARGET}/release/sake_glug_web.wasm"));
    let dist = Path::new(DIST);
    crate::dist::fresh_folder(dist)?;
    let status = Command::new(&bindgen)
        .args([
            "--target",
            "web",
            "--remove-name-section",
            "--remove-producers-section",
            "--out-dir",
            DIST,
        ])
        .arg(&wasm)
        .status()
        .context("running wasm-bindgen")?;
    anyhow::ensure!(status.success(), "wasm-bindgen failed ({status})");
    std::fs::write(dist.join("tables.js"), tables())?;
    // The project's licence, which the package carries.
    std::fs::copy("LICENSE", dist.join("LICENSE"))?;
    let notices = dist.join("THIRD-PARTY.md");
    crate::dist::third_party(
        &notices,
        WASM_TARGET,
        &[(
            "The web package, `sake-glug` on npm (its WebAssembly)",
            "crates/web/Cargo.toml",
            "",
        )],
    )?;
    let text = std::fs::read_to_string(&notices)?;
    std::fs::write(
        &notices,
        text.replace("`cargo xtask dist`", "`cargo xtask web`"),
    )?;
    let wasm_bytes = std::fs::metadata(dist.join("sake_glug_web_bg.wasm"))?.len();
    println!("web: web/dist/sake_glug_web_bg.wasm is {wasm_bytes} bytes");
    pack()
}

/// The tarball `npm pack` writes of web/, in <target dir>/web/.
fn pack() -> anyhow::Result<PathBuf> {
    let out = std::path::absolute(target_dir().join("web"))?;
    std::fs::create_dir_all(&out)?;
    let listing = crate::dist::output_of(
        Command::new("npm")
            .current_dir(WEB)
            .args(["pack", "--json", "--pack-destination"])
            .arg(&out),
    )
    .context("npm pack (Debian's `npm` package; .ci/run installs it)")?;
    let listing: Value = serde_json::from_str(&listing)?;
    let name = listing[0]["filename"]
        .as_str()
        .context("npm pack named no tarball")?;
    let tarball = out.join(name);
    println!(
        "web: {} ({} bytes)",
        tarball.display(),
        std::fs::metadata(&tarball)?.len()
    );
    Ok(tarball)
}

/// wasm-bindgen-cli at exactly the version of the wasm-bindgen crate in Cargo.lock (the glue it
/// writes must match the crate), or an error naming the command that installs it.
fn require_wasm_bindgen() -> anyhow::Result<String> {
    let lock = std::fs::read_to_string("Cargo.lock")?;
    let version = lock
        .split("[[package]]")
        .find(|package| package.contains("\nname = \"wasm-bindgen\"\n"))
        .and_then(|package| {
            package
                .lines()
                .find_map(|line| line.strip_prefix("version = \""))
        })
        .map(|version| version.trim_end_matches('"').to_owned())
        .context("Cargo.lock names no wasm-bindgen")?;
    let install = format!("cargo install wasm-bindgen-cli --version {version}");
    let found = Command::new("wasm-bindgen").arg("--version").output();
    match found {
        Ok(out)
            if String::from_utf8_lossy(&out.stdout).trim() == format!("wasm-bindgen {version}") =>
        {
            Ok("wasm-bindgen".into())
        }
        Ok(out) => anyhow::bail!(
            "the web package needs wasm-bindgen {version}, found `{}`: {install}",
            String::from_utf8_lossy(&out.stdout).trim()
        ),
        Err(_) => anyhow::bail!("the web package needs wasm-bindgen {version}: {install}"),
    }
}

/// The engine's tables as an ES module (dist/tables.js of the package): the controls, the presets and the
/// model's constants, each as the engine declares it, for the worklet's AudioParams, the API's
/// checks before a call reaches the engine, and the page's sliders.
fn tables() -> String {
    let quantity = |quantity: &sake_glug_engine::Quantity| {
        let (knob_min, knob_max) = quantity.knob_bounds();
        json!({
            "name": quantity.name,
            "unit": quantity.unit.trim(),
            "key": quantity.scene_key,
            "id": quantity.param_id,
            "note": quantity.note,
            "min": quantity.range.min,
            "max": quantity.range.max,
            "default": quantity.range.default,
            "knobMin": knob_min,
            "knobMax": knob_max,
            "decimals": quantity.knob.decimals,
        })
    };
    let controls: Vec<Value> = Control::ALL
        .iter()
        .map(|control| quantity(control.quantity()))
        .collect();
    let constants: Vec<Value> = Constant::ALL
        .iter()
        .map(|constant| quantity(constant.quantity()))
        .collect();
    let presets: Vec<Value> = PRESETS
        .iter()
        .map(|preset: &Preset| {
            let values: serde_json::Map<String, Value> = preset
                .menu_values()
                .map(|value| match value {
                    PresetValue::Control(control, value) => {
                        (control.quantity().scene_key.to_owned(), json!(value))
                    }
                    PresetValue::Constant(constant, value) => {
                        (constant.quantity().scene_key.to_owned(), json!(value))
                    }
                })
                .collect();
            json!({
                "id": preset.id,
                "name": preset.name,
                "description": preset.description,
                "values": values,
            })
        })
        .collect();
    let constant = |name: &str, value: Value| {
        format!(
            "export const {name} = {};\n",
            serde_json::to_string_pretty(&value).expect("JSON")
        )
    };
    format!(
        "// The engine's tables (crates/engine/src: controls.rs, config.rs, presets.rs), written \
         by `cargo xtask web`.\n// Do not edit: change the engine's tables.\n{}{}{}{}",
        constant("VERSION", json!(env!("CARGO_PKG_VERSION"))),
        constant("CONTROLS", Value::Array(controls)),
        constant("CONSTANTS", Value::Array(constants)),
        constant("PRESETS", Value::Array(presets)),
    )
}

/// The guide's picture of the page that pours.
pub const SCREENSHOT: &str = "docs/web-page.png";

/// The page in headless Chromium after a Render, as a PNG at `out`, drawn by
/// web/test/support/screenshot.mjs.
pub fn screenshot(out: &Path) -> anyhow::Result<()> {
    let status = Command::new("node")
        .current_dir(WEB)
        .arg("test/support/screenshot.mjs")
        .arg(std::path::absolute(out)?)
        .status()
        .context("running node (Debian's `nodejs`)")?;
    anyhow::ensure!(status.success(), "the page's screenshot failed ({status})");
    Ok(())
}

/// The npm package's tests (web/test/) with Node.js's test runner, the packed `tarball`
/// installed from scratch, compared with the release CLI's renders.
pub fn test(tarball: &Path, cli: &Path) -> anyhow::Result<()> {
    // The suites are the files named *.test.mjs (the rest of test/ is what they share).
    let mut suites: Vec<String> = std::fs::read_dir(Path::new(WEB).join("test"))?
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter(|name| name.ends_with(".test.mjs"))
        .map(|name| format!("test/{name}"))
        .collect();
    suites.sort();
    // The tests' folders (the empty folder the tarball installs into, the CLI's renders), made
    // afresh each run.
    let work = std::path::absolute(target_dir().join("web/work"))?;
    crate::dist::fresh_folder(&work)?;
    let typescript = typescript()?;
    let status = Command::new("node")
        .current_dir(WEB)
        .args(["--test", "--test-reporter=spec"])
        .args(&suites)
        .env("SAKE_GLUG_TARBALL", tarball)
        .env("SAKE_GLUG_CLI", std::path::absolute(cli)?)
        .env("SAKE_GLUG_WORK", &work)
        .env("SAKE_GLUG_TYPESCRIPT", typescript)
        .status()
        .context("running node (Debian's `nodejs`; .ci/run installs it)")?;
    anyhow::ensure!(
        status.success(),
        "the web package's tests failed ({status})"
    );
    Ok(())
}

/// The TypeScript that types.test.mjs checks the package's types with: the version
/// web/test/types/package-lock.json pins (with its hash), installed by `npm ci` into
/// <target dir>/web/typescript, again only when the lock changes. `--prefer-offline` takes it from
/// npm's cache where it is, so a machine that has installed it once needs no registry. Returns
/// the installed package's folder.
fn typescript() -> anyhow::Result<PathBuf> {
    let folder = std::path::absolute(target_dir().join("web/typescript"))?;
    let installed = folder.join("node_modules/typescript");
    let lock = std::fs::read(Path::new(TYPES).join("package-lock.json"))?;
    let current = std::fs::read(folder.join("package-lock.json")).ok();
    if current.as_deref() == Some(&lock[..]) && installed.join("bin/tsc").exists() {
        return Ok(installed);
    }
    std::fs::create_dir_all(&folder)?;
    for file in ["package.json", "package-lock.json"] {
        std::fs::copy(Path::new(TYPES).join(file), folder.join(file))?;
    }
    let status = Command::new("npm")
        .current_dir(&folder)
        .args(["ci", "--prefer-offline", "--no-audit", "--no-fund"])
        .status()
        .context("running npm (Debian's `npm`; .ci/run installs it)")?;
    anyhow::ensure!(
        status.success(),
        "installing TypeScript for the web package's type check failed ({status})"
    );
    Ok(installed)
}

/// The guide's page on the package, whose block `web-figures` [`figures`] writes.
pub const GUIDE: &str = "docs/guide/web.md";

/// The package's size and speed for the guide, measured in one run on the package that
/// [`build`] wrote: the .wasm and the JavaScript modules a page loads, raw and gzipped; a minute
/// of continuous glugs rendered by the release CLI at `cli`, by the package in Node.js and in
/// headless Chromium, and through its AudioWorklet there (web/test/support/speed.mjs times
/// them). `Ok(None)`, with a line saying why, where Chromium is not installed.
pub fn figures(cli: &Path) -> anyhow::Result<Option<String>> {
    let dist = Path::new(DIST);
    let wasm = std::fs::read(dist.join("sake_glug_web_bg.wasm"))?;
    // Every JavaScript file of the package's API, glue, tables and worklet (not the demo's).
    let mut scripts: Vec<PathBuf> = [dist.join("sake_glug_web.js"), dist.join("tables.js")].into();
    for entry in std::fs::read_dir(Path::new(WEB).join("src"))? {
        let path = entry?.path();
        if path.extension().is_some_and(|extension| extension == "js") {
            scripts.push(path);
        }
    }
    let (mut script_bytes, mut script_gzipped) = (0, 0);
    for script in &scripts {
        let text = std::fs::read(script)?;
        script_bytes += text.len();
        script_gzipped += gzipped_len(&text)?;
    }

    // The renders' folder (a minute's WAV file), made afresh each run as the tests' is.
    let work = std::path::absolute(target_dir().join("web/speed"))?;
    crate::dist::fresh_folder(&work)?;
    let out = crate::dist::output_of(
        Command::new("node")
            .current_dir(WEB)
            .arg("test/support/speed.mjs")
            .env("SAKE_GLUG_CLI", std::path::absolute(cli)?)
            .env("SAKE_GLUG_WORK", &work),
    )
    .context("timing the web package (node: Debian's `nodejs`)")?;
    let speed: Value = serde_json::from_str(&out)?;
    if let Some(missing) = speed["missing"].as_str() {
        println!("{GUIDE}: web-figures kept: Chromium is needed to time the page ({missing})");
        return Ok(None);
    }
    let number = |key: &str| speed[key].as_f64().context("speed.mjs left out a figure");
    let seconds = number("seconds")?;
    let times = |key: &str| -> anyhow::Result<f64> {
        let ms = speed["ms"][key]
            .as_f64()
            .context("speed.mjs left out a time")?;
        Ok(seconds / (ms / 1e3))
    };
    let worklet = times("worklet")?;
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|text| text.split_whitespace().next().map(str::to_owned))
        .unwrap_or_else(|| "unknown".into());
    Ok(Some(format!(
        "\nChromium {chromium}, Node.js {node}; the machine's load average {load} at the end.\n\n\
         | the package's | bytes | gzipped |\n\
         |---|---:|---:|\n\
         | engine, `sake_glug_web_bg.wasm` | {wasm} | {wasm_gz} |\n\
         | JavaScript: the API, the worklet, wasm-bindgen's glue, the tables ({files} files) | \
         {script_bytes} | {script_gzipped} |\n\n\
         A minute of continuous glugs ({capacity:.0} ml bottle, tilt {tilt}°, pour time {pour} s, \
         {rate} Hz, {units} units),\nthe best of {runs} runs of each:\n\n\
         | render | × real time |\n\
         |---|---:|\n\
         | `sake-glug render` natively: the whole process, its WAV file written | {cli:.0}× |\n\
         | the package's `render` in Node.js, 4096-frame blocks | {node_speed:.0}× |\n\
         | the package's `render` on the page's thread in Chromium, 4096-frame blocks | \
         {page:.0}× |\n\
         | `renderInContext`: the AudioWorklet in an OfflineAudioContext, 128-frame blocks | \
         {worklet:.0}× |\n\n\
         At the AudioWorklet's speed a live node takes about {share:.1} % of one core.\n",
        chromium = speed["chromium"].as_str().unwrap_or("(version unknown)"),
        node = speed["node"].as_str().unwrap_or("(version unknown)"),
        wasm = thousands(wasm.len()),
        wasm_gz = thousands(gzipped_len(&wasm)?),
        files = scripts.len(),
        script_bytes = thousands(script_bytes),
        script_gzipped = thousands(script_gzipped),
        capacity = number("capacityMl")?,
        tilt = number("tiltDeg")?,
        pour = number("pourTimeS")?,
        rate = number("sampleRate")?,
        units = number("units")?,
        runs = number("runs")?,
        cli = times("cli")?,
        node_speed = times("node")?,
        page = times("page")?,
        share = 100.0 / worklet,
    )))
}

/// The length of `bytes` gzipped at the best compression, as a server would send them
/// pre-compressed.
fn gzipped_len(bytes: &[u8]) -> anyhow::Result<usize> {
    use std::io::Write;
    let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    encoder.write_all(bytes)?;
    Ok(encoder.finish()?.len())
}

/// `n` with a comma between each three digits, as the guide writes byte counts.
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut text = String::new();
    for (k, digit) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k).is_multiple_of(3) {
            text.push(',');
        }
        text.push(digit);
    }
    text
}
