//! The `sake-glug` command line run as a user runs it, and what it leaves in a folder.

use std::path::Path;
use std::process::{Command, Output};

/// Runs `sake-glug ARGS` in `directory`.
pub fn sake_glug(directory: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(directory)
        .args(args)
        .output()
        .unwrap()
}

/// [`sake_glug`] for a command that must end by itself within `limit`: one that does not is
/// killed and the test fails (rather than hanging the suite).
pub fn sake_glug_within(directory: &Path, args: &[&str], limit: std::time::Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(directory)
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!(
                "`sake-glug {}` did not end within {limit:?}",
                args.join(" ")
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// The names of the files in `directory`, sorted.
pub fn files_in(directory: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(directory)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
