//! The 2AFC design in the runner: two stimuli, the `target` first in half the trials (each
//! order `repetitions` times, shuffled from the participant's seed); the log says whether the
//! target was chosen, and `sake-glug analyze discrimination` reads it.

use super::{log_rows, session, spec};
use sake_glug_study::{order_seed, plan_trials, Design};

const TWO_AFC: &str = r#"
design = "2afc"
target = "recording"
duration_s = 0.3
gap_s = 0.1
repetitions = 4
seed = 3
equalize = "rms"
[stimuli.model]
preset = "water"
viscosity_c = 0.0
[stimuli.recording]
preset = "water"
"#;

#[test]
fn the_target_is_first_in_half_the_trials_in_the_participants_order() {
    let parsed = spec(TWO_AFC).unwrap();
    assert_eq!(parsed.design, Design::TwoAfc);
    assert_eq!(parsed.stimuli[0].name, "recording");
    assert_eq!(parsed.question, "Which one is `recording`?");
    let seed = order_seed(parsed.seed, "p1");
    let trials = plan_trials(&parsed, seed);
    assert_eq!(trials.len(), 8);
    let target_first = trials.iter().filter(|trial| trial.first == 0).count();
    assert_eq!(target_first, 4);
    assert!(trials.iter().all(|trial| trial.first != trial.second));
    assert_ne!(trials, plan_trials(&parsed, order_seed(parsed.seed, "p2")));
}

#[test]
fn a_2afc_session_logs_whether_the_target_was_chosen_and_is_analysed() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), TWO_AFC).unwrap();
    // Always the first: right exactly when the target came first.
    session(
        dir.path(),
        "p1",
        "log.csv",
        &["--dry-run", "dry"],
        &format!("\n{}", "1\n".repeat(8)),
    );
    let rows = log_rows(&dir.path().join("log.csv"));
    let header = csv::Reader::from_path(dir.path().join("log.csv"))
        .unwrap()
        .headers()
        .unwrap()
        .clone();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(rows.len(), 8);
    for row in &rows {
        assert_eq!(&row[column("design")], "2afc");
        let right = &row[column("first")] == "recording";
        assert_eq!(&row[column("correct")], if right { "1" } else { "0" });
    }
    let analysed = std::process::Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir.path())
        .args([
            "analyze",
            "discrimination",
            "--json",
            "--dry-run-logs",
            "log.csv",
        ])
        .output()
        .unwrap();
    assert!(
        analysed.status.success(),
        "{}",
        String::from_utf8_lossy(&analysed.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&analysed.stdout).unwrap();
    assert_eq!(json["design"], "2afc");
    assert_eq!(json["trials"], 8);
    assert_eq!(json["correct"], 4);
}

#[test]
fn a_bad_2afc_spec_is_refused_by_key() {
    for (from, to, message) in [
        ("target = \"recording\"\n", "", "missing field `target`"),
        (
            "target = \"recording\"",
            "target = \"bottle\"",
            "`target` = \"bottle\" is not a stimulus",
        ),
        (
            "[stimuli.recording]",
            "[stimuli.third]\n[stimuli.recording]",
            "a 2AFC study has two",
        ),
        (
            "design = \"2afc\"",
            "design = \"paired\"",
            "`target` does not belong to the paired design",
        ),
    ] {
        let error = spec(&TWO_AFC.replace(from, to)).unwrap_err().to_string();
        assert!(error.contains(message), "{to}: {error}");
    }
}
