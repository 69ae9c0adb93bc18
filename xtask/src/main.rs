//! `cargo xtask`: nice-plug's bundler, plus the project's two everyday jobs.
//!
//! - `cargo xtask pour`: build the plugin bundles, the CLI, the C library and the standalone app,
//!   and render the built-in scene to `pour.wav`. The CLI plays studies (its `audio`) wherever the
//!   app can be built. Without the app's libraries (pkg-config's `alsa` and `jack`) it
//!   skips the app and ends with one line naming the `apt-get install` that adds them.
//! - `cargo xtask test`: every test: formatting and lints, the Rust suites, then the bundles in a
//!   real VST3 host and the standalone app under a JACK server, the npm package in Node.js and
//!   headless Chromium, the Windows release under Wine
//!   (where MinGW-w64, NSIS and Wine are installed; CI installs them), then the Python package installed
//!   into the virtual environment and its pytest suite. Without the app's libraries it
//!   stops at once, naming the `apt-get install`.
//! - `cargo xtask docs [--bench]`: regenerates every table and picture of docs/ from the current
//!   code (the accuracy table and plot, the stability report, the pour plot, the presets as
//!   scene files and VST3 preset files, a VST3 ramp measured in Ardour when it is installed, the
//!   standalone app's live latency under a JACK server when one can run, the paper's numbers,
//!   the web package's size and speed),
//!   stamped with the commit and the machine, and the cost
//!   figures of docs/scaling.md (callgrind, when valgrind is installed; the render benchmark's
//!   last report, or a new one with `--bench`).
//! - `cargo xtask docs paper`: only docs/paper.md, the paper's numbers beside the product's
//!   (which `cargo xtask docs` also writes).
//! - `cargo xtask docs web`: only the web package's size and speed in docs/guide/web.md (which
//!   `cargo xtask docs` also writes where the package's tools and Chromium are installed).
//! - `cargo xtask latency`: only the live-latency figures of `cargo xtask docs`
//!   (docs/latency.md).
//! - `cargo xtask screenshots`: the editor in a real window (the standalone app under Xvfb), idle
//!   and while a phone's OSC gravity pours, written to docs/editor-idle.png and
//!   docs/editor-pouring.png.
//! - `cargo xtask fuzz`: every libFuzzer target of fuzz/ (`cargo install cargo-fuzz`) for
//!   `FUZZ_SECONDS` each (60 by default), keeping their minimised corpora and any failing input
//!   as a regression the ordinary tests replay; summarised in docs/fuzzing.md.
//! - `cargo xtask web [test | screenshot]`: the npm package of web/ (the engine in WebAssembly,
//!   its JS glue, the engine's tables) packed into target/web/ (web.rs); with `test`, its tests
//!   in Node.js and headless Chromium against the release CLI; with `screenshot`, the page that
//!   pours in headless Chromium, for the guide (docs/web-page.png).
//! - `cargo xtask wheel`: the Python package (python/) as a wheel in target/wheels/, built by
//!   maturin from the virtual environment.
//! - `cargo xtask dist`: the release in target/dist/ (the Debian package, the tarball with its
//!   install.sh, the wheel, THIRD-PARTY.md), packed from the release builds that `cargo xtask
//!   test` makes (built first if they are not; see dist.rs).
//! - `cargo xtask dist windows [--profile windows-test]`: the Windows installer and zip, and the
//!   Python package's win_amd64 wheel, in target/dist/, cross-built with MinGW-w64 (windows.rs;
//!   the wheel by maturin from the virtual environment); with the `windows-test` profile (built
//!   without link-time optimisation, as `cargo xtask test` builds it for its Wine tests), in
//!   target/dist-windows-test/.
//!
//! Each product is built with only its features: the bundles with `editor` (which brings
//! `plugin`), the command line with `cli`, the standalone app with `standalone`, so none compiles
//! another's crates.

use std::path::{Path, PathBuf};
use std::process::Command;

mod dist;
mod paper;
mod screenshots;
mod web;
mod windows;

/// An error is said in one line, without the backtrace anyhow adds under `RUST_BACKTRACE`: it
/// tells what is wrong with the machine or the code, not where in the xtask it was noticed.
fn main() -> std::process::ExitCode {
    match xtask() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn xtask() -> nice_plug_xtask::Result<()> {
    // Read before nice-plug's bundler runs: it clears cargo's variables for its own builds.
    TARGET_DIR.get_or_init(|| {
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| PathBuf::from("target"), PathBuf::from)
    });
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("pour") => {
            nice_plug_xtask::chdir_workspace_root()?;
            let missing = standalone_missing();
            build_bundles_and_cli()?;
            build_c_library()?;
            if missing.is_empty() {
                build_standalone()?;
            }
            run(&cli(), &["render", "-o", "pour.wav"])?;
            if !missing.is_empty() {
                println!(
                    "{}",
                    standalone_skipped(
                        "the standalone app, and the CLI's audio (`experiment`, `measure-actuator`),",
                        &missing
                    )
                );
            }
            Ok(())
        }
        Some("test") => {
            nice_plug_xtask::chdir_workspace_root()?;
            // Clippy and the suites build every feature, the standalone app's among them.
            require_standalone("cargo xtask test")?;
            // Each stage says how long it took: CI's budget is an hour on two cores, and a run
            // that nears it should show where its time went.
            timed("fmt", || cargo(&["fmt", "--all", "--check"]))?;
            timed("clippy", || {
                cargo(&[
                    "clippy",
                    "--workspace",
                    "--all-targets",
                    "--all-features",
                    "--",
                    "-D",
                    "warnings",
                ])?;
                // The command line with its default features (no `audio`, as the main job builds
                // it where the app's libraries are missing): code behind a feature must compile,
                // and cleanly, without it too.
                cargo(&["clippy", "-p", "sake-glug", "--", "-D", "warnings"])
            })?;
            // All features, assert_process_allocs among them: the dev profile keeps the debug
            // assertions it needs.
            timed("the Rust suites", || {
                cargo(&["test", "--workspace", "--no-fail-fast", "--all-features"])
            })?;
            timed("the release builds", || {
                build_bundles()?;
                // With audio (the app's libraries are there): a study played on JACK and ALSA.
                build_cli()?;
                build_standalone()?;
                // The C library that the examples of examples/ link (tests/host/test_capi.py).
                build_c_library()
            })?;
            // The npm package (web/): the engine in WebAssembly, in Node.js and headless
            // Chromium, against the CLI just built (skipped where its tools are missing, but
            // under CI).
            timed("the web package", || web::build_and_test(Path::new(&cli())))?;
            timed("the wheel", build_wheel)?;
            // The release packed from those builds, for the host tests to install and check.
            timed("the release", dist)?;
            // The Windows release, built faster than the shipped one, for tests/host/test_windows.py
            // to install and run under Wine.
            timed("the Windows release", windows_test_dist)?;
            timed("the host tests", host_tests)?;
            timed("the Python package's tests", python_tests)
        }
        // The Windows release alone, beside whatever target/dist holds.
        // `--profile windows-test`: the build `cargo xtask test` checks, in target/dist-windows-test.
        Some("dist") if args.get(1).is_some_and(|arg| arg == "windows") => {
            nice_plug_xtask::chdir_workspace_root()?;
            let profile = match &args[2..] {
                [] => windows::RELEASE_PROFILE,
                [option, profile] if option == "--profile" => profile.as_str(),
                _ => anyhow::bail!(
                    "cargo xtask dist windows takes only `--profile NAME`, not `{}`",
                    args[2..].join(" ")
                ),
            };
            windows_dist(profile)
        }
        Some("dist") => {
            nice_plug_xtask::chdir_workspace_root()?;
            require_standalone("cargo xtask dist")?;
            // The builds of `cargo xtask test`, with the same features: nothing is built twice.
            build_bundles()?;
            build_cli()?;
            build_standalone()?;
            build_c_library()?;
            build_wheel()?;
            dist()
        }
        // The npm package of web/ (the engine in WebAssembly), packed into target/web/;
        // `cargo xtask web test` runs its tests against the release CLI, `cargo xtask web
        // screenshot` draws the page for the guide.
        Some("web") => {
            nice_plug_xtask::chdir_workspace_root()?;
            let tarball = web::build()?;
            match args.get(1).map(String::as_str) {
                Some("test") => {
                    build_cli()?;
                    web::test(&tarball, Path::new(&cli()))
                }
                Some("screenshot") => web::screenshot(Path::new(web::SCREENSHOT)),
                Some(other) => {
                    anyhow::bail!("cargo xtask web takes `test` or `screenshot`, not `{other}`")
                }
                None => Ok(()),
            }
        }
        Some("wheel") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_wheel()
        }
        Some("docs") if args.get(1).is_some_and(|arg| arg == "paper") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_cli()?;
            paper::paper()
        }
        // The fit's tables of the development clips and family (docs/fit.md), each written by
        // the test that holds it.
        Some("docs")
            if args
                .get(1)
                .is_some_and(|arg| arg == "fit" || arg == "family") =>
        {
            nice_plug_xtask::chdir_workspace_root()?;
            fit_docs(&args[1])
        }
        // The web package's size and speed alone (docs/guide/web.md): the package built, and a
        // minute of glugs timed in Node.js and Chromium, in seconds.
        Some("docs") if args.get(1).is_some_and(|arg| arg == "web") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_cli()?;
            web_figures()
        }
        // The cost figures alone (callgrind, and the benchmark's report with --bench): seconds,
        // where the whole of `docs` renders for minutes.
        Some("docs") if args.get(1).is_some_and(|arg| arg == "scaling") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_cli()?;
            scaling_docs(args.iter().any(|arg| arg == "--bench"))
        }
        Some("docs") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_cli()?;
            let started = std::time::SystemTime::now();
            docs()?;
            scaling_docs(args.iter().any(|arg| arg == "--bench"))?;
            pictures_not_regenerated(started)
        }
        Some("latency") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_cli()?;
            live_latency()
        }
        Some("fuzz") => {
            nice_plug_xtask::chdir_workspace_root()?;
            fuzz()
        }
        Some("screenshots") => {
            nice_plug_xtask::chdir_workspace_root()?;
            screenshots::check_tools()?;
            require_standalone("cargo xtask screenshots")?;
            build_standalone()?;
            let cpu = screenshots::screenshots(
                &target_dir().join("release/sake-glug-standalone"),
                &target_dir().join("screenshots"),
            )?;
            replace_block(SOUND_DESIGNER_PAGE, "editor-cpu", &format!("{cpu}.\n"))
        }
        _ => nice_plug_xtask::main(),
    }
}

/// The Windows installer and zip of `profile`, built and packed (windows.rs), and the wheel
/// beside them; says how long the wheel's build took (docs/testing.md).
fn windows_dist(profile: &str) -> nice_plug_xtask::Result<()> {
    windows::build(profile)?;
    let started = std::time::Instant::now();
    let wheels = windows::wheel_dir(profile);
    // Emptied first: only this build's wheel is taken.
    dist::fresh_folder(&wheels)?;
    maturin_build(&[
        "--profile",
        profile,
        "--target",
        windows::TARGET,
        "--out",
        &wheels.to_string_lossy(),
    ])?;
    println!(
        "windows: the wheel built with the {profile} profile in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    let out = windows::dist_dir(profile);
    for artefact in windows::dist(&windows::Built::here(profile)?, &out)? {
        println!(
            "dist: {} ({} bytes)",
            artefact.display(),
            artefact.metadata()?.len()
        );
    }
    Ok(())
}

/// The Windows release that tests/host/test_windows.py runs under Wine, in the faster-built
/// profile. Where MinGW-w64, NSIS or the Rust target are missing, skipped with a line naming
/// what to install (the module is then skipped too), as the host tests skip an optional tool,
/// but under CI (`$CI` set), which must run it, an error.
fn windows_test_dist() -> nice_plug_xtask::Result<()> {
    if let Err(missing) = windows::require_tools("cargo xtask test") {
        if std::env::var_os("CI").is_some() {
            return Err(missing);
        }
        println!("{missing:#}; skipped, with its tests under Wine");
        return Ok(());
    }
    windows_dist(windows::TEST_PROFILE)
}

/// The CLAP and VST3 bundles under target/bundled/, and the release CLI beside them.
fn build_bundles_and_cli() -> nice_plug_xtask::Result<()> {
    build_bundles()?;
    build_cli()
}

/// The CLAP and VST3 bundles under target/bundled/.
fn build_bundles() -> nice_plug_xtask::Result<()> {
    nice_plug_xtask::main_with_args(
        "cargo xtask",
        ["bundle", "sake-glug-plugin", "--release"].map(String::from),
    )
}

/// What the standalone app links against, as pkg-config names each library, and the Debian
/// package that provides it.
const STANDALONE_LIBRARIES: [(&str, &str); 2] =
    [("alsa", "libasound2-dev"), ("jack", "libjack-jackd2-dev")];

/// The Debian packages the standalone app still needs here, asked of pkg-config as the build
/// scripts of `alsa-sys` and `jack-sys` will ask it (`$PKG_CONFIG`, its search path); without
/// pkg-config, pkg-config and every library. Empty when the app can be built.
fn standalone_missing() -> Vec<&'static str> {
    let pkg_config = std::env::var("PKG_CONFIG").unwrap_or_else(|_| "pkg-config".into());
    if Command::new(&pkg_config).arg("--version").output().is_err() {
        return std::iter::once("pkg-config")
            .chain(STANDALONE_LIBRARIES.map(|(_, package)| package))
            .collect();
    }
    STANDALONE_LIBRARIES
        .iter()
        .filter(|(library, _)| {
            !Command::new(&pkg_config)
                .args(["--exists", library])
                .status()
                .is_ok_and(|status| status.success())
        })
        .map(|(_, package)| *package)
        .collect()
}

/// The one line a command that went on without the standalone app's libraries ends with.
fn standalone_skipped(what: &str, missing: &[&str]) -> String {
    format!(
        "{what} skipped: its libraries are missing; `sudo apt-get install {}` enables it",
        missing.join(" ")
    )
}

/// Fails at once, in one line naming the packages, if the standalone app cannot be built here
/// (rather than in a build script's panic minutes later).
fn require_standalone(command: &str) -> nice_plug_xtask::Result<()> {
    let missing = standalone_missing();
    if !missing.is_empty() {
        anyhow::bail!(
            "{command} needs the standalone app and its libraries: sudo apt-get install {}",
            missing.join(" ")
        );
    }
    Ok(())
}

/// The standalone app (JACK and ALSA: libjack and libasound at build time).
fn build_standalone() -> nice_plug_xtask::Result<()> {
    cargo(&[
        "build",
        "--release",
        "--package",
        "sake-glug-plugin",
        "--bin",
        "sake-glug-standalone",
        "--features",
        "standalone",
    ])
}

/// The C library (crates/capi): target/release/libsake_glug.so and libsake_glug.a, for
/// include/sake_glug.h.
fn build_c_library() -> nice_plug_xtask::Result<()> {
    cargo(&["build", "--release", "--package", "sake-glug-c"])?;
    // A program linked with -lsake_glug asks the loader for the soname (crates/capi/build.rs),
    // so it is linked to beside the library, as an installed library's is.
    let library = target_dir().join("release/libsake_glug.so");
    let soname = dist::soname(&library)?;
    let link = library.with_file_name(&soname);
    if link.symlink_metadata().is_ok() {
        std::fs::remove_file(&link)?;
    }
    std::os::unix::fs::symlink("libsake_glug.so", link)?;
    Ok(())
}

/// The Python package as a manylinux wheel in <target dir>/wheels, built by maturin from the
/// virtual environment (one release build, in the workspace's target directory).
fn build_wheel() -> nice_plug_xtask::Result<()> {
    maturin_build(&["--release"])
}

/// The Python package built into a wheel by maturin from the virtual environment, `how` saying
/// its profile (and target, and folder, where not the host's and target/wheels).
fn maturin_build(how: &[&str]) -> nice_plug_xtask::Result<()> {
    let python = venv(PYTHON_REQUIREMENTS)?;
    run_in_venv(
        &maturin_of(&python),
        &[&["build", "-m", "python/Cargo.toml"], how].concat(),
    )
}

/// The release packed into target/dist/ from what the build made; says how long it took.
fn dist() -> nice_plug_xtask::Result<()> {
    let started = std::time::Instant::now();
    let built = dist::Built::under(&target_dir())?;
    for artefact in dist::dist(&built, &target_dir().join("dist"))? {
        println!(
            "dist: {} ({} bytes)",
            artefact.display(),
            artefact.metadata()?.len()
        );
    }
    println!("dist: packed in {:.1} s", started.elapsed().as_secs_f64());
    Ok(())
}

/// The release command line: with `ogg`, and with `audio` (JACK and ALSA) where the app's
/// libraries are.
fn build_cli() -> nice_plug_xtask::Result<()> {
    // Every command builds the same CLI, so none rebuilds another's: with the audio of
    // `experiment` and `measure-actuator` wherever the standalone app's libraries are.
    let features = if standalone_missing().is_empty() {
        "ogg,audio"
    } else {
        "ogg"
    };
    cargo(&[
        "build",
        "--release",
        "--package",
        "sake-glug",
        "--bin",
        "sake-glug",
        "--features",
        features,
    ])
}

/// Where cargo builds: `$CARGO_TARGET_DIR` as the xtask started with it, else `target/`.
static TARGET_DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();

fn target_dir() -> PathBuf {
    TARGET_DIR.get_or_init(|| PathBuf::from("target")).clone()
}

/// The release command line that `build_cli` built.
fn cli() -> String {
    target_dir()
        .join("release/sake-glug")
        .to_string_lossy()
        .into_owned()
}

/// Regenerates what docs/ shows from the code: each generated block is the output of a command
/// of the release CLI, written between its markers with the commit and the machine it ran on.
fn docs() -> nice_plug_xtask::Result<()> {
    let catalogue = output(&cli(), &["stability", "--catalogue"])?;
    replace_block("docs/stability.md", "stability-catalogue", &catalogue)?;
    println!("accuracy: every path at 1 s, 1 min and 1 h (a few minutes)");
    let started = std::time::Instant::now();
    let table = output(&cli(), &["accuracy", "--plot", "docs/accuracy.png"])?;
    let accuracy_stamp = stamp(started.elapsed());
    replace_block(
        "docs/accuracy.md",
        "accuracy-table",
        &format!("{accuracy_stamp}\n{table}"),
    )?;
    println!("stability: every case at the report's lengths, 24 h renders (several minutes)");
    let started = std::time::Instant::now();
    let report = output(&cli(), &["stability"])?;
    let stability_stamp = stamp(started.elapsed());
    replace_block(
        "docs/stability.md",
        "stability-report",
        &format!("{stability_stamp}\n{report}"),
    )?;
    // The presets as scene files, from the presets the plugin's menu offers.
    std::fs::create_dir_all("presets")?;
    for line in output(&cli(), &["presets"])?.lines() {
        let id = line.split_whitespace().next().unwrap_or_default();
        let scene = output(&cli(), &["presets", id])?;
        std::fs::write(format!("presets/{id}.toml"), scene)?;
        println!("presets/{id}.toml written");
    }
    // And as VST3 preset files: the state the plugin's own wrapper saves once a host has set a
    // preset's parameters, which the plugin test that checks the files writes when asked to.
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(["test", "--all-features", "--test", "plugin", "vstpreset"])
        .env("SAKE_GLUG_WRITE_PRESETS", "1")
        .status()?;
    if !status.success() {
        anyhow::bail!("writing presets/vst3 through the plugin test failed ({status})");
    }
    // The guide's table of parameters, from the engine's tables.
    let parameters = output(&cli(), &["parameters"])?;
    replace_block(SOUND_DESIGNER_PAGE, "parameters", &parameters)?;
    // The guide's table of what each format keeps of the default pour, measured.
    let measured = target_dir().join("fidelity-pour.wav");
    let fidelity = output(
        &cli(),
        &["render", "--fidelity", "-o", &measured.to_string_lossy()],
    )?;
    replace_block(HAPTIC_DESIGNER_PAGE, "fidelity", &fidelity)?;
    // The guide's example of the pour plot: the default scene.
    let clip = target_dir().join("pour-plot.haptic");
    run(
        &cli(),
        &[
            "render",
            "-o",
            &clip.to_string_lossy(),
            "--plot",
            "docs/pour-plot.png",
        ],
    )?;
    paper::paper()?;
    vst3_ramp_figures()?;
    live_latency()?;
    web_figures()
}

/// docs/guide/web.md's size and speed of the web package, built afresh (web.rs, `figures`);
/// kept, with a line saying so, where its tools are missing.
fn web_figures() -> nice_plug_xtask::Result<()> {
    let missing = web::missing_tools();
    if !missing.is_empty() {
        println!(
            "{}: web-figures kept: the web package needs {}",
            web::GUIDE,
            missing.join("; ")
        );
        return Ok(());
    }
    web::build()?;
    let started = std::time::Instant::now();
    match web::figures(Path::new(&cli()))? {
        Some(figures) => replace_block(
            web::GUIDE,
            "web-figures",
            &format!("{}{figures}", stamp(started.elapsed())),
        ),
        None => Ok(()),
    }
}

/// docs/latency.md's figures: the standalone app under a JACK server with 64-frame periods,
/// timed from a tilt message to its effect by tests/host/latency.py (a JACK client in Python:
/// nothing here links libjack); kept, with a line saying so, where it cannot run.
fn live_latency() -> nice_plug_xtask::Result<()> {
    let python = ".venv/bin/python";
    let missing = standalone_missing();
    let has_jackd = Command::new("jackd").arg("--version").output().is_ok();
    if !missing.is_empty() || !has_jackd || !Path::new(python).exists() {
        println!(
            "docs/latency.md: live-latency kept: it needs the standalone app's libraries, jackd \
             (`sudo apt-get install libasound2-dev libjack-jackd2-dev jackd2`) and the host \
             tests' .venv (`cargo xtask test` makes it)"
        );
        return Ok(());
    }
    build_standalone()?;
    println!("live latency: a few hundred tilt messages through JACK (a few minutes)");
    let started = std::time::Instant::now();
    let app = target_dir().join("release/sake-glug-standalone");
    let figures = output(
        python,
        &[
            "tests/host/latency.py",
            "--app",
            &app.to_string_lossy(),
            "--cli",
            &cli(),
        ],
    )?;
    let latency_stamp = stamp(started.elapsed());
    replace_block(
        "docs/latency.md",
        "live-latency",
        &format!(
            "{latency_stamp}
{figures}"
        ),
    )
}

/// The pictures of docs/ that `cargo xtask docs` does not draw, and the command that does.
const PICTURES_ELSEWHERE: [(&str, &str); 3] = [
    ("docs/editor-idle.png", "cargo xtask screenshots"),
    ("docs/editor-pouring.png", "cargo xtask screenshots"),
    (web::SCREENSHOT, "cargo xtask web screenshot"),
];

/// Says which pictures of docs/ this run did not regenerate (older than `started`), and what
/// would: a picture left stale is then a choice, not an oversight.
fn pictures_not_regenerated(started: std::time::SystemTime) -> nice_plug_xtask::Result<()> {
    let mut stale = Vec::new();
    for entry in std::fs::read_dir("docs")? {
        let path = entry?.path();
        if path.extension().is_none_or(|extension| extension != "png") {
            continue;
        }
        if std::fs::metadata(&path)?.modified()? >= started {
            continue;
        }
        let shown = path.display().to_string();
        let by = PICTURES_ELSEWHERE
            .iter()
            .find(|(picture, _)| *picture == shown)
            .map_or(
                "nothing known: remove it or teach an xtask to draw it",
                |(_, by)| by,
            );
        stale.push(format!("  {shown} (regenerated by {by})"));
    }
    stale.sort();
    if stale.is_empty() {
        println!("every picture of docs/ was regenerated");
    } else {
        println!(
            "pictures of docs/ not regenerated by this run:\n{}",
            stale.join("\n")
        );
    }
    Ok(())
}

/// The guide's figures of a ramp in a VST3 host, measured by the Ardour host test (which
/// rewrites them when asked to); skipped, with a line saying so, where Ardour is not installed.
fn vst3_ramp_figures() -> nice_plug_xtask::Result<()> {
    let has_ardour = Command::new("ardour7-lua")
        .arg("--version")
        .output()
        .is_ok();
    let python = ".venv/bin/python";
    if !has_ardour || !Path::new(python).exists() {
        println!(
            "docs/guide/sound-designer.md: vst3-ramps kept: it needs Ardour 7 (`sudo apt-get install ardour`) and \
             the host tests' .venv (`cargo xtask test` makes it)"
        );
        return Ok(());
    }
    build_bundles_and_cli()?;
    let status = Command::new(python)
        .args(["-m", "pytest", "-q", "tests/host/test_ardour.py"])
        .env("SAKE_GLUG_WRITE_DOCS", "1")
        .status()?;
    if !status.success() {
        anyhow::bail!("measuring the VST3 ramp in Ardour failed ({status})");
    }
    println!("{SOUND_DESIGNER_PAGE}: vst3-ramps regenerated");
    Ok(())
}

/// Seconds of the two renders whose difference gives the cost of a minute of pouring: start-up,
/// scene parsing and file creation cancel out.
const CALLGRIND_RENDERS_S: [u32; 2] = [1, 61];

/// docs/scaling.md's cost figures: instructions per output sample from callgrind (when valgrind
/// is installed), and the reports of the benchmarks that write one (each run first with `bench`).
fn scaling_docs(bench: bool) -> nice_plug_xtask::Result<()> {
    if Command::new("valgrind").arg("--version").output().is_ok() {
        let figure = instructions_per_sample()?;
        replace_block("docs/scaling.md", "callgrind", &figure)?;
    } else {
        println!("valgrind is not installed: docs/scaling.md keeps its callgrind figure");
    }
    for name in REPORTING_BENCHES {
        if bench {
            cargo(&["bench", "--bench", name])?;
        }
        let report = target_dir().join(format!("bench-{name}.md"));
        match std::fs::read_to_string(&report) {
            Ok(text) => replace_block("docs/scaling.md", &format!("bench-{name}"), &text)?,
            Err(_) => println!(
                "no {} (`cargo bench --bench {name}` writes it): docs/scaling.md keeps its \
                 figures",
                report.display()
            ),
        }
    }
    Ok(())
}

/// The benchmarks whose report (benches/report.rs) docs/scaling.md holds, each in a block of
/// its own.
const REPORTING_BENCHES: [&str; 2] = ["render", "capi"];

/// Instructions per output sample of `sake-glug render` on a minute of continuous pouring
/// (follow mode, held full at 135°, writing an f32 WAV): callgrind's count for a 61 s render
/// less that for a 1 s render, over 60 s of samples.
fn instructions_per_sample() -> nice_plug_xtask::Result<String> {
    let sample_rate = 48_000u64;
    let dir = target_dir().join("callgrind");
    std::fs::create_dir_all(&dir)?;
    let mut counts = Vec::new();
    for seconds in CALLGRIND_RENDERS_S {
        let scene = dir.join(format!("pouring-{seconds}s.toml"));
        std::fs::write(
            &scene,
            format!(
                "sample_rate = {sample_rate}\nduration_s = {seconds}\ntilt_deg = 135.0\n\
                 [output]\ndrain = \"follow\"\n"
            ),
        )?;
        let profile = dir.join(format!("pouring-{seconds}s.callgrind"));
        let wav = dir.join(format!("pouring-{seconds}s.wav"));
        let status = Command::new("valgrind")
            .arg("--tool=callgrind")
            .arg(format!("--callgrind-out-file={}", profile.display()))
            .arg(cli())
            .arg("render")
            .arg(&scene)
            .arg("-o")
            .arg(&wav)
            .output()?
            .status;
        if !status.success() {
            anyhow::bail!("callgrind of the {seconds} s render failed ({status})");
        }
        let text = std::fs::read_to_string(&profile)?;
        let total: u64 = text
            .lines()
            .find_map(|line| line.strip_prefix("summary:"))
            .and_then(|count| count.trim().parse().ok())
            .ok_or_else(|| anyhow::anyhow!("{} has no summary line", profile.display()))?;
        counts.push((seconds, total, profile));
    }
    let [(short_s, short, ref short_profile), (long_s, long, ref long_profile)] =
        [counts[0].clone(), counts[1].clone()];
    let samples = (long_s - short_s) as u64 * sample_rate;
    let per_sample = long.saturating_sub(short) as f64 / samples as f64;
    let mut text = format!(
        "At commit {}: **{per_sample:.1} instructions per output sample** ({long} instructions \
         for {long_s} s, {short} for {short_s} s, {samples} samples apart; \
         `valgrind --tool=callgrind`, release CLI, f32 WAV at {sample_rate} Hz).\n\n\
         Where they go (each function's own instructions, the same difference):\n\n\
         | instructions per sample | function |\n|---:|---|\n",
        commit()
    );
    let short_costs = function_costs(short_profile)?;
    let mut rows: Vec<(f64, String)> = function_costs(long_profile)?
        .into_iter()
        .map(|(function, cost)| {
            let before = short_costs.get(&function).copied().unwrap_or(0);
            (
                cost.saturating_sub(before) as f64 / samples as f64,
                function,
            )
        })
        .collect();
    rows.sort_by(|a, b| b.0.total_cmp(&a.0));
    let shown = rows.iter().take_while(|(cost, _)| *cost >= 0.1).take(12);
    let mut listed = 0.0;
    for (cost, function) in shown {
        text.push_str(&format!("| {cost:.1} | `{function}` |\n"));
        listed += cost;
    }
    text.push_str(&format!(
        "| {:.1} | everything else |\n",
        per_sample - listed
    ));
    Ok(text)
}

/// Each function's own instruction count in a callgrind profile, as `callgrind_annotate` lists
/// them (the binary's name dropped).
fn function_costs(
    profile: &Path,
) -> nice_plug_xtask::Result<std::collections::HashMap<String, u64>> {
    let listing = output(
        "callgrind_annotate",
        &["--threshold=100", &profile.to_string_lossy()],
    )?;
    let mut costs = std::collections::HashMap::new();
    for line in listing.lines() {
        let Some((count, rest)) = line.trim_start().split_once(' ') else {
            continue;
        };
        let Ok(count) = count.replace(',', "").parse::<u64>() else {
            continue;
        };
        let Some((_, location)) = rest.split_once(')') else {
            continue;
        };
        let location = location.trim();
        let function = location
            .split_once(':')
            .map_or(location, |(_, function)| function);
        let function = function.split(" [").next().unwrap_or(function).trim();
        if function.is_empty() || location.starts_with("PROGRAM TOTALS") {
            continue;
        }
        *costs.entry(function.to_owned()).or_insert(0) += count;
    }
    Ok(costs)
}

/// The commit the docs are generated from, marked `-dirty` with uncommitted changes.
fn commit() -> String {
    output("git", &["describe", "--always", "--dirty"])
        .map_or_else(|_| "unknown".into(), |text| text.trim().to_owned())
}

/// Where and on what a figure was measured: the commit (and whether the tree had uncommitted
/// changes to the code), the machine, and how long the run took.
fn stamp(took: std::time::Duration) -> String {
    let commit = output("git", &["rev-parse", "--short", "HEAD"])
        .map(|c| c.trim().to_string())
        .unwrap_or_else(|_| "unknown".into());
    let dirty = !Command::new("git")
        .args([
            "diff",
            "--quiet",
            "HEAD",
            "--",
            "src",
            "Cargo.toml",
            "Cargo.lock",
            "xtask",
        ])
        .status()
        .is_ok_and(|status| status.success());
    let arch = output("uname", &["-m"]).map_or("unknown".into(), |a| a.trim().to_string());
    let cores = output("nproc", &[]).map_or("?".into(), |n| n.trim().to_string());
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|line| line.starts_with("model name"))
                .and_then(|line| line.split(':').nth(1))
                .map(|model| model.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    format!(
        "Generated by `cargo xtask docs` at commit {commit}{} (release build) on {arch}, {cores} \
         cores, {cpu}; the run took {:.0} s.\n",
        if dirty {
            " with uncommitted changes"
        } else {
            ""
        },
        took.as_secs_f64()
    )
}

/// The fuzz crate (cargo-fuzz's layout), a workspace of its own.
const FUZZ_DIR: &str = "fuzz";

/// Runs every libFuzzer target of fuzz/ for `FUZZ_SECONDS` each (60 by default) on its kept
/// corpus and its regressions, keeps any input that fails as a regression, minimises the corpus,
/// and writes what it ran to docs/fuzzing.md. The ordinary test suite replays both folders
/// (tests/plugin/fuzz.rs).
fn fuzz() -> nice_plug_xtask::Result<()> {
    let seconds: u64 = match std::env::var("FUZZ_SECONDS") {
        Ok(text) => text
            .parse()
            .map_err(|_| anyhow::anyhow!("FUZZ_SECONDS={text:?} is not a whole number"))?,
        Err(_) => 60,
    };
    if !fuzz_command(&["--version"])
        .output()
        .is_ok_and(|out| out.status.success())
    {
        anyhow::bail!("`cargo fuzz` is missing: install it with `cargo install cargo-fuzz`");
    }
    let started = std::time::Instant::now();
    let list = fuzz_command(&["list"]).output()?;
    if !list.status.success() {
        anyhow::bail!("`cargo fuzz list` failed ({})", list.status);
    }
    let list = String::from_utf8(list.stdout)?;
    // One build for every target; each run below finds it done.
    let status = fuzz_command(&["build"]).status()?;
    if !status.success() {
        anyhow::bail!("`cargo fuzz build` failed ({status})");
    }
    let mut runs = Vec::new();
    for target in list.lines().map(str::trim) {
        runs.push(fuzz_target(target, seconds)?);
    }
    let mut table = String::from(
        "| target | seconds | executions | per second | corpus kept | found |\n\
         |---|---:|---:|---:|---:|---|\n",
    );
    for run in &runs {
        let found = run.regression.as_ref().map_or("nothing".into(), |name| {
            format!("**{name}**, kept in fuzz/regressions/{}/", run.target)
        });
        table += &format!(
            "| {} | {} | {} | {} | {} inputs, {} bytes | {found} |\n",
            run.target,
            run.seconds,
            run.executions,
            run.executions / run.seconds.max(1),
            run.corpus_files,
            run.corpus_bytes,
        );
    }
    let fuzz_stamp = stamp(started.elapsed())
        .replace("cargo xtask docs", "cargo xtask fuzz")
        .replace(
            "(release build)",
            "(libFuzzer: release build, debug assertions and overflow checks on)",
        );
    replace_block(
        "docs/fuzzing.md",
        "fuzz-results",
        &format!("{fuzz_stamp}\n{table}"),
    )?;
    let found: Vec<String> = runs
        .iter()
        .filter_map(|run| Some(format!("{} in {}", run.regression.as_ref()?, run.target)))
        .collect();
    if !found.is_empty() {
        anyhow::bail!("fuzzing found {}", found.join(", "));
    }
    Ok(())
}

/// What one target's run did.
struct FuzzRun {
    target: String,
    seconds: u64,
    executions: u64,
    corpus_files: usize,
    corpus_bytes: u64,
    /// The failing input kept as a regression (crash-…, timeout-… or oom-…), if any.
    regression: Option<String>,
}

/// Fuzzes `target` for `seconds` on its corpus (libFuzzer adds there every input that reaches
/// new code) and its regressions; keeps a failing input as a regression; minimises the corpus.
fn fuzz_target(target: &str, seconds: u64) -> nice_plug_xtask::Result<FuzzRun> {
    let fuzz = Path::new(FUZZ_DIR);
    let corpus = Path::new("corpus").join(target);
    let regressions = Path::new("regressions").join(target);
    // Where cargo-fuzz has libFuzzer write a failing input.
    let artifacts = fuzz.join("artifacts").join(target);
    std::fs::create_dir_all(fuzz.join(&corpus))?;
    std::fs::create_dir_all(&artifacts)?;
    let known = files_in(&artifacts)?;
    let mut folders = vec![corpus.clone()];
    if fuzz.join(&regressions).is_dir() {
        folders.push(regressions.clone());
    }
    println!("fuzz {target}: {seconds} s");
    let out = fuzz_command(&["run", target])
        .args(&folders)
        .arg("--")
        .arg(format!("-max_total_time={seconds}"))
        .arg("-print_final_stats=1")
        // An input that runs this long is a hang, kept as a regression like a crash.
        .arg("-timeout=10")
        .stdout(std::process::Stdio::inherit())
        .output()?;
    let log = String::from_utf8_lossy(&out.stderr);
    let executions = log
        .lines()
        .find_map(|line| line.strip_prefix("stat::number_of_executed_units:"))
        .and_then(|count| count.trim().parse().ok())
        .unwrap_or(0);
    let regression = if out.status.success() {
        None
    } else {
        // libFuzzer's account of it: the panic, the input, the stack.
        eprintln!("{log}");
        let new = files_in(&artifacts)?
            .into_iter()
            .find(|path| !known.contains(path));
        let Some(new) = new else {
            anyhow::bail!("fuzz target {target} failed without keeping an input");
        };
        let name = new.file_name().unwrap().to_string_lossy().into_owned();
        std::fs::create_dir_all(fuzz.join(&regressions))?;
        std::fs::copy(&new, fuzz.join(&regressions).join(&name))?;
        Some(name)
    };
    // The fewest inputs that reach all the code the corpus reaches.
    let status = fuzz_command(&["cmin", target]).arg(&corpus).status()?;
    if !status.success() {
        anyhow::bail!("`cargo fuzz cmin {target}` failed ({status})");
    }
    let files = files_in(&fuzz.join(&corpus))?;
    let mut corpus_bytes = 0;
    for file in &files {
        corpus_bytes += std::fs::metadata(file)?.len();
    }
    Ok(FuzzRun {
        target: target.to_owned(),
        seconds,
        executions,
        corpus_files: files.len(),
        corpus_bytes,
        regression,
    })
}

/// `cargo fuzz <args>` in the fuzz crate: stable Rust accepts cargo-fuzz's unstable flags with
/// `RUSTC_BOOTSTRAP=1`; no address sanitizer (the targets are Rust, and it makes them about five
/// times slower); builds beside the workspace's, in their own target triple's folder.
fn fuzz_command(args: &[&str]) -> Command {
    let mut command = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    command
        .current_dir(FUZZ_DIR)
        .env("RUSTC_BOOTSTRAP", "1")
        .arg("fuzz")
        .args(args);
    if matches!(args.first(), Some(&("build" | "run" | "cmin"))) {
        let target_dir = std::path::absolute(target_dir()).unwrap_or_else(|_| target_dir());
        command
            .args(["--sanitizer", "none", "--target-dir"])
            .arg(target_dir);
    }
    command
}

/// The files in `folder`, sorted.
fn files_in(folder: &Path) -> nice_plug_xtask::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(folder)? {
        files.push(entry?.path());
    }
    files.sort();
    Ok(files)
}

/// Replaces the text between `<!-- generated:NAME:begin -->` and `<!-- generated:NAME:end -->`.
/// The guide's pages that hold blocks the code writes (`<!-- generated:NAME:begin -->`).
const SOUND_DESIGNER_PAGE: &str = "docs/guide/sound-designer.md";
const HAPTIC_DESIGNER_PAGE: &str = "docs/guide/haptic-designer.md";

/// docs/fit.md's tables of the development clips (`fit`) and of the development family of
/// simulated bottles (`family`, 10–15 minutes), each written by the fit suite's test that
/// holds it (in the profile the tests run in, as CI runs it). The held-out tables are written
/// once, when the fit is tuned, by their own tests: never by a command that runs while tuning.
fn fit_docs(which: &str) -> nice_plug_xtask::Result<()> {
    // The family's development table alone (its test is ignored, as the held-out family's is);
    // every real recording's table, the held-out sets' among them, which CI does not run.
    let args: &[&str] = match which {
        "family" => &[
            "test",
            "--all-features",
            "--test",
            "fit",
            "family::the_development_family_is_fitted_within_tolerance",
            "--",
            "--exact",
            "--ignored",
        ],
        _ => &[
            "test",
            "--all-features",
            "--test",
            "fit",
            "listening::",
            "--",
            "--include-ignored",
        ],
    };
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args(args)
        .env("SAKE_GLUG_WRITE_FIT_TABLES", "1")
        .status()?;
    if !status.success() {
        anyhow::bail!("writing docs/fit.md through the fit suite failed ({status})");
    }
    Ok(())
}

fn replace_block(file: &str, name: &str, content: &str) -> nice_plug_xtask::Result<()> {
    let text = std::fs::read_to_string(file)?;
    let begin = format!("<!-- generated:{name}:begin -->\n");
    let end = format!("<!-- generated:{name}:end -->");
    let (Some(start), Some(stop)) = (text.find(&begin), text.find(&end)) else {
        anyhow::bail!("{file} has no block {name}");
    };
    let updated = format!("{}{content}{}", &text[..start + begin.len()], &text[stop..]);
    std::fs::write(file, updated)?;
    println!("{file}: {name} regenerated");
    Ok(())
}

fn output(program: &str, args: &[&str]) -> nice_plug_xtask::Result<String> {
    let out = Command::new(program).args(args).output()?;
    if !out.status.success() {
        anyhow::bail!("`{program} {}` failed ({})", args.join(" "), out.status);
    }
    Ok(String::from_utf8(out.stdout)?)
}

/// The bundles loaded in pedalboard and the standalone app under JACK, in a virtual environment
/// made on first use.
fn host_tests() -> nice_plug_xtask::Result<()> {
    let python = venv("tests/host/requirements.txt")?;
    run(&python, &["-m", "pytest", "tests/host", "-q"])
}

/// What building the Python package needs besides pip (maturin).
const PYTHON_REQUIREMENTS: &str = "python/requirements.txt";

/// The release's wheel (target/dist, as `dist` packed it) installed into the virtual
/// environment, then the package's tests, which compare it with the release CLI (pytest and
/// NumPy come with the host tests' requirements).
fn python_tests() -> nice_plug_xtask::Result<()> {
    let python = venv(PYTHON_REQUIREMENTS)?;
    let built = dist::Built::under(&target_dir())?;
    let wheel = target_dir().join("dist").join(
        built
            .wheel
            .file_name()
            .ok_or_else(|| anyhow::anyhow!("the wheel has no name"))?,
    );
    run_in_venv(
        &python,
        &[
            "-m",
            "pip",
            "install",
            "--quiet",
            "--force-reinstall",
            "--no-deps",
            &wheel.to_string_lossy(),
        ],
    )?;
    run_in_venv(&python, &["-m", "pytest", "python/tests", "-q"])
}

/// The virtual environment's Python (.venv, made on first use) with `requirements` installed.
fn venv(requirements: &str) -> nice_plug_xtask::Result<String> {
    let python = ".venv/bin/python";
    if !Path::new(python).exists() {
        run("python3", &["-m", "venv", ".venv"])?;
    }
    run(
        python,
        &["-m", "pip", "install", "--quiet", "-r", requirements],
    )?;
    Ok(python.into())
}

/// The maturin that `venv` installed beside `python`.
fn maturin_of(python: &str) -> String {
    Path::new(python)
        .with_file_name("maturin")
        .to_string_lossy()
        .into_owned()
}

/// Runs `program` as the activated virtual environment would (its bin/ first on PATH, where the
/// build backend looks for maturin), building in the xtask's target directory (nice-plug's
/// bundler clears cargo's variables), which the tests also read to find the CLI.
fn run_in_venv(program: &str, args: &[&str]) -> nice_plug_xtask::Result<()> {
    let bin = std::path::absolute(".venv/bin")?;
    let path = std::env::var_os("PATH").unwrap_or_default();
    let path = std::env::join_paths(std::iter::once(bin).chain(std::env::split_paths(&path)))?;
    let target_dir = std::path::absolute(target_dir())?;
    let status = Command::new(program)
        .args(args)
        .env("PATH", path)
        .env("CARGO_TARGET_DIR", target_dir)
        .status()?;
    if status.success() {
        Ok(())
    } else {
        anyhow::bail!("`{program} {}` failed ({status})", args.join(" "))
    }
}

/// Runs one stage of `cargo xtask test` and prints how long it took, whether it passed or not.
fn timed(
    stage: &str,
    work: impl FnOnce() -> nice_plug_xtask::Result<()>,
) -> nice_plug_xtask::Result<()> {
    let start = std::time::Instant::now();
    let outcome = work();
    println!(
        "cargo xtask test: {stage}: {:.0} s{}",
        start.elapsed().as_secs_f64(),
        if outcome.is_ok() { "" } else { " (failed)" }
    );
    outcome
}

fn cargo(args: &[&str]) -> nice_plug_xtask::Result<()> {
    run(
        &std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()),
        args,
    )
}

fn run(program: &str, args: &[&str]) -> nice_plug_xtask::Result<()> {
    let status = Command::new(program).args(args).status()?;
    if status.success() {
        Ok(())
    } else {
        anyhow::bail!("`{program} {}` failed ({status})", args.join(" "))
    }
}
