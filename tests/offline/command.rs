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

/// The names of the files in `directory`, sorted.
pub fn files_in(directory: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(directory)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
