//! `cargo xtask`: nice-plug's bundler, plus the project's two everyday jobs.
//!
//! - `cargo xtask pour`: build the plugin bundles and render the built-in scene to `pour.wav`.
//! - `cargo xtask test`: every test: formatting and lints, the Rust suites, then the bundles in a
//!   real VST3 host and the standalone app under a JACK server.
//! - `cargo xtask docs`: regenerates the generated blocks of docs/ from the current code.
//!
//! Each product is built with only its features: the bundles with `editor` (which brings
//! `plugin`), the command line with `cli`, the standalone app with `standalone`, so none compiles
//! another's crates.

use std::path::Path;
use std::process::Command;

fn main() -> nice_plug_xtask::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("pour") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_release()?;
            run("target/release/sake-glug", &["render", "-o", "pour.wav"])
        }
        Some("test") => {
            nice_plug_xtask::chdir_workspace_root()?;
            cargo(&["fmt", "--all", "--check"])?;
            cargo(&[
                "clippy",
                "--workspace",
                "--all-targets",
                "--all-features",
                "--",
                "-D",
                "warnings",
            ])?;
            // All features, assert_process_allocs among them: the dev profile keeps the debug
            // assertions it needs.
            cargo(&["test", "--workspace", "--no-fail-fast", "--all-features"])?;
            build_release()?;
            host_tests()
        }
        Some("docs") => {
            nice_plug_xtask::chdir_workspace_root()?;
            build_cli()?;
            docs()
        }
        _ => nice_plug_xtask::main(),
    }
}

/// The CLAP and VST3 bundles under target/bundled/, and the release CLI and standalone app
/// beside them.
fn build_release() -> nice_plug_xtask::Result<()> {
    nice_plug_xtask::main_with_args(
        "cargo xtask",
        [
            "bundle",
            "sake_glug",
            "--release",
            "--no-default-features",
            "--features",
            "editor",
        ]
        .map(String::from),
    )?;
    build_cli()?;
    // The standalone app (JACK and ALSA: libjack and libasound at build time).
    cargo(&[
        "build",
        "--release",
        "--bin",
        "sake-glug-standalone",
        "--no-default-features",
        "--features",
        "standalone",
    ])
}

/// The release command line alone, with only its features.
fn build_cli() -> nice_plug_xtask::Result<()> {
    cargo(&[
        "build",
        "--release",
        "--bin",
        "sake-glug",
        "--no-default-features",
        "--features",
        "cli",
    ])
}

/// Regenerates what docs/ shows from the code: each generated block is the output of a command
/// of the release CLI, written between its markers.
fn docs() -> nice_plug_xtask::Result<()> {
    let catalogue = output("target/release/sake-glug", &["stability", "--catalogue"])?;
    replace_block("docs/stability.md", "stability-catalogue", &catalogue)?;
    // The README's example of the pour plot: the default scene.
    run(
        "target/release/sake-glug",
        &[
            "render",
            "-o",
            "target/pour-plot.haptic",
            "--plot",
            "docs/pour-plot.png",
        ],
    )
}

/// Replaces the text between `<!-- generated:NAME:begin -->` and `<!-- generated:NAME:end -->`.
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
    let python = ".venv/bin/python";
    if !Path::new(python).exists() {
        run("python3", &["-m", "venv", ".venv"])?;
    }
    run(
        python,
        &[
            "-m",
            "pip",
            "install",
            "--quiet",
            "-r",
            "tests/host/requirements.txt",
        ],
    )?;
    run(python, &["-m", "pytest", "tests/host", "-q"])
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
