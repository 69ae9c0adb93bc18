//! `cargo xtask`: nice-plug's bundler, plus the project's two everyday jobs.
//!
//! - `cargo xtask pour`: build the plugin bundles and render the built-in scene to `pour.wav`.
//! - `cargo xtask test`: every test: formatting and lints, the Rust suites, then the bundles in a
//!   real VST3 host.
//! - `cargo xtask docs`: regenerates every table and picture of docs/ from the current code (the
//!   accuracy table and plot, the stability report, the pour plot), stamped with the commit and
//!   the machine. docs/scaling.md's benchmark block is the benchmarks' own.
//! - `cargo xtask fuzz`: every fuzz target (tests named `fuzz_…`) with a million cases each
//!   (`FUZZ_CASES` to change it), summarised in docs/fuzzing.md.
//!
//! Each product is built with only its features: the bundles with `editor` (which brings
//! `plugin`), the command line with `cli`, so neither compiles the other's crates.

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
        Some("fuzz") => {
            nice_plug_xtask::chdir_workspace_root()?;
            fuzz()
        }
        _ => nice_plug_xtask::main(),
    }
}

/// The CLAP and VST3 bundles under target/bundled/, and the release CLI beside them.
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
    build_cli()
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
/// of the release CLI, written between its markers with the commit and the machine it ran on.
fn docs() -> nice_plug_xtask::Result<()> {
    let cli = &cli_path();
    let catalogue = output(cli, &["stability", "--catalogue"])?;
    replace_block("docs/stability.md", "stability-catalogue", &catalogue)?;
    println!("accuracy: every path at 1 s, 1 min and 1 h (a few minutes)");
    let started = std::time::Instant::now();
    let table = output(cli, &["accuracy", "--plot", "docs/accuracy.png"])?;
    let accuracy_stamp = stamp(started.elapsed());
    replace_block(
        "docs/accuracy.md",
        "accuracy-table",
        &format!("{accuracy_stamp}\n{table}"),
    )?;
    println!("stability: every case at the report's lengths, 24 h renders (several minutes)");
    let started = std::time::Instant::now();
    let report = output(cli, &["stability"])?;
    let stability_stamp = stamp(started.elapsed());
    replace_block(
        "docs/stability.md",
        "stability-report",
        &format!("{stability_stamp}\n{report}"),
    )?;
    // The README's example of the pour plot: the default scene.
    run(
        cli,
        &[
            "render",
            "-o",
            "target/pour-plot.haptic",
            "--plot",
            "docs/pour-plot.png",
        ],
    )
}

/// The release CLI: under the target directory cargo uses (CARGO_TARGET_DIR if set).
fn cli_path() -> String {
    let target = std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".into());
    format!("{target}/release/sake-glug")
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

/// Runs every fuzz target (test functions named `fuzz_…`) with `FUZZ_CASES` cases each (a
/// million by default) in the test profile, debug assertions and overflow checks on, and writes
/// their summary lines to docs/fuzzing.md.
fn fuzz() -> nice_plug_xtask::Result<()> {
    let cases = std::env::var("FUZZ_CASES").unwrap_or_else(|_| "1000000".into());
    let started = std::time::Instant::now();
    let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args([
            "test",
            "--all-features",
            "--tests",
            "fuzz_",
            "--",
            "--nocapture",
        ])
        .args(["--test-threads", "1"])
        .env("PROPTEST_CASES", &cases)
        .stderr(std::process::Stdio::inherit())
        .output()?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    print!("{stdout}");
    let rows: Vec<String> = stdout
        .lines()
        // libtest may print "test NAME ... " before the harness's line.
        .filter_map(|line| line.split_once("fuzz-summary ").map(|(_, row)| row))
        .map(|row| format!("{row} |"))
        .collect();
    let mut table = String::from("| target | cases | time (s) | result |\n|---|---:|---:|---|\n");
    for row in &rows {
        table += row;
        table.push('\n');
    }
    if !out.status.success() {
        table += "\nThe run FAILED (a target panicked, hung or aborted): see its output.\n";
    }
    let fuzz_stamp = stamp(started.elapsed())
        .replace("cargo xtask docs", "cargo xtask fuzz")
        .replace(
            "(release build)",
            "(test profile: optimised, debug assertions on)",
        );
    replace_block(
        "docs/fuzzing.md",
        "fuzz-results",
        &format!("{fuzz_stamp}\n{table}"),
    )?;
    if rows.is_empty() || !out.status.success() {
        anyhow::bail!("the fuzz run failed or found no target");
    }
    Ok(())
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

/// The bundles loaded in pedalboard, in a virtual environment made on first use.
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
