//! What participants expect of a study, in every design: the spec's `instructions` shown before
//! the first trial, `practice` trials played first and logged as practice (which the analyses
//! leave out), `break_every` trials a pause that the participant ends; the seeded order and
//! `--resume` as before.

use std::io::Write;

use super::{answers, log_rows, run, session, spec, start, wait_for_rows, SHORT_PAIRED};
use sake_glug_study::{order_seed, plan_practice, plan_trials};

/// SHORT_PAIRED (12 trials) with instructions, 3 practice trials and a break every 5.
fn expecting() -> String {
    SHORT_PAIRED.replace(
        "equalize = \"peak\"",
        "equalize = \"peak\"\ninstructions = \"Feel each pour.\\nThen say which.\"\npractice = \
         3\nbreak_every = 5",
    )
}

#[test]
fn instructions_practice_and_breaks_come_as_the_spec_says() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), expecting()).unwrap();
    // Enter, 3 practice answers, 5 answers, a break's Enter, 5, a break's Enter, 2.
    let input = format!(
        "\n{}{}\n{}\n{}",
        "2\n".repeat(3),
        "1\n".repeat(5),
        "1\n".repeat(5),
        "1\n".repeat(2)
    );
    let output = session(dir.path(), "p1", "log.csv", &["--dry-run", "dry"], &input);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let instructions = stdout.find("Feel each pour.\nThen say which.\nPress Enter to begin.");
    let first_practice = stdout.find("Practice trial 1/3");
    let begins = stdout.find("Practice over: the study begins.");
    let first_trial = stdout.find("Trial 1/12");
    assert!(
        instructions < first_practice && first_practice < begins && begins < first_trial,
        "{stdout}"
    );
    assert!(instructions.is_some(), "{stdout}");
    assert_eq!(
        stdout.matches("Break (").count(),
        2,
        "after 5 and 10: {stdout}"
    );
    assert!(stdout.contains("Break (5 of 12 trials done)"), "{stdout}");
    assert!(stdout.contains("Done: 12 trials"), "{stdout}");

    // Practice first, marked, numbered apart; the study's trials in the seeded order.
    let rows = log_rows(&dir.path().join("log.csv"));
    assert_eq!(rows.len(), 15);
    let header = csv::Reader::from_path(dir.path().join("log.csv"))
        .unwrap()
        .headers()
        .unwrap()
        .clone();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let parsed = spec(&expecting()).unwrap();
    let seed = order_seed(parsed.seed, "p1");
    let practice = plan_practice(&parsed, seed);
    let trials = plan_trials(&parsed, seed);
    assert_eq!(practice.len(), 3);
    for (index, row) in rows.iter().enumerate() {
        let (is_practice, number, trial) = match index < 3 {
            true => ("1", index + 1, practice[index]),
            false => ("0", index - 2, trials[index - 3]),
        };
        assert_eq!(&row[column("practice")], is_practice, "row {index}");
        assert_eq!(row[column("trial")], number.to_string(), "row {index}");
        assert_eq!(
            &row[column("first")],
            parsed.stimuli[trial.first].name.as_str()
        );
        assert_eq!(
            &row[column("second")],
            parsed.stimuli[trial.second].name.as_str()
        );
    }
    // The practice order is not the study's beginning (its seed is its own).
    assert_ne!(practice[..], trials[..3]);

    // The analysis reads the 12 trials of the study, not the practice.
    let analysed = std::process::Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir.path())
        .args(["analyze", "paired", "--json", "--dry-run-logs", "log.csv"])
        .output()
        .unwrap();
    assert!(analysed.status.success());
    let json: serde_json::Value = serde_json::from_slice(&analysed.stdout).unwrap();
    assert_eq!(json["trials"], 12);
}

#[test]
fn a_session_killed_in_its_practice_resumes_in_its_practice() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), expecting()).unwrap();
    let log = dir.path().join("log.csv");
    let args = [
        "study.toml",
        "--participant",
        "p2",
        "--log",
        "log.csv",
        "--dry-run",
        "dry",
    ];
    let mut child = start(dir.path(), &args);
    let mut stdin = child.stdin.take().unwrap();
    for (answer, rows) in [("", 0), ("1", 1), ("2", 2)] {
        writeln!(stdin, "{answer}").unwrap();
        stdin.flush().unwrap();
        wait_for_rows(&log, rows);
    }
    child.kill().unwrap();
    child.wait().unwrap();

    let mut resumed = args.to_vec();
    resumed.push("--resume");
    // Enter, the last practice trial, 5, a break, 5, a break, 2.
    let input = format!(
        "\n1\n{}\n{}\n{}",
        "1\n".repeat(5),
        "1\n".repeat(5),
        "1\n".repeat(2)
    );
    let output = run(dir.path(), &resumed, &input);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("Resuming after trial 2 of 15."), "{stdout}");
    assert!(stdout.contains("Practice trial 3/3"), "{stdout}");
    assert!(!stdout.contains("Practice trial 2/3"), "{stdout}");
    let rows = log_rows(&log);
    assert_eq!(rows.len(), 15);
}

#[test]
fn a_spec_without_them_runs_as_before() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), SHORT_PAIRED).unwrap();
    let output = session(
        dir.path(),
        "p3",
        "log.csv",
        &["--dry-run", "dry"],
        &answers(12),
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        !stdout.contains("Practice") && !stdout.contains("Break"),
        "{stdout}"
    );
    let log = dir.path().join("log.csv");
    let header = csv::Reader::from_path(&log)
        .unwrap()
        .headers()
        .unwrap()
        .clone();
    let practice = header.iter().position(|h| h == "practice").unwrap();
    assert!(log_rows(&log).iter().all(|row| &row[practice] == "0"));
}

#[test]
fn bad_expectations_are_refused_by_key() {
    for (text, key) in [
        ("practice = 101", "`practice` = 101"),
        ("break_every = 0", "`break_every` = 0"),
        ("instructions = \"  \"", "`instructions` is empty"),
        ("practice = -1", "`practice`"),
    ] {
        let error = spec(&SHORT_PAIRED.replace("seed = 9", &format!("seed = 9\n{text}")))
            .unwrap_err()
            .to_string();
        assert!(error.contains(key), "{text}: {error}");
    }
}
