//! The analysis of study logs (`sake-glug analyze`): Thurstone scaling of paired comparisons,
//! the psychometric fit of constant stimuli and the coverage of its intervals, checked by
//! simulation; bad logs refused with file, line and column; hostile logs (too many stimuli, a
//! device, a log given twice, random answers) refused or reported for what they are; the JSON
//! shapes; the plan of a constant-stimuli study, its coverage checked by simulation.

mod bad_logs;
mod constant;
mod discrimination;
mod hostile_logs;
mod paired;
mod plan;

use std::path::Path;
use std::process::{Command, Output};

/// Runs `sake-glug analyze ARGS` in `directory`.
pub fn analyze(directory: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(directory)
        .arg("analyze")
        .args(args)
        .output()
        .unwrap()
}

/// The JSON object a successful `--json` run printed.
pub fn json_of(output: &Output) -> serde_json::Value {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("one JSON object")
}
