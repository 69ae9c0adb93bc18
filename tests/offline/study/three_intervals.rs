//! The triangle and ABX designs in the runner: three stimuli a trial from two, every arrangement
//! `repetitions` times in the participant's seeded order; the log's `correct` column says whether
//! the odd one (triangle) or the one X is (ABX) was chosen, and `analyze discrimination` reads
//! it. Also the logs of earlier runners (fewer columns) on `--resume`, and a dry run whose
//! answers end before the first.

use std::path::Path;

use super::{log_rows, refused, session, session_output, spec, SHORT_PAIRED};
use sake_glug_study::{order_seed, plan_trials, Design};

fn study(design: &str) -> String {
    format!(
        r#"
design = "{design}"
duration_s = 0.3
gap_s = 0.1
repetitions = 2
seed = 5
equalize = "rms"
[stimuli.model]
preset = "water"
viscosity_c = 0.0
[stimuli.recording]
preset = "water"
"#
    )
}

/// The log's rows as maps from column to cell.
fn rows(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|record| {
            let record = record.unwrap();
            header
                .iter()
                .zip(record.iter())
                .map(|(column, cell)| (column.to_owned(), cell.to_owned()))
                .collect()
        })
        .collect()
}

#[test]
fn each_stimulus_is_the_odd_one_at_each_place_in_the_participants_order() {
    let triangle = spec(&study("triangle")).unwrap();
    assert_eq!(triangle.design, Design::Triangle);
    assert_eq!(triangle.question, "Two are alike: which one is different?");
    let seed = order_seed(triangle.seed, "p1");
    let trials = plan_trials(&triangle, seed);
    assert_eq!(trials.len(), 12, "6 arrangements × 2");
    for odd in 0..2 {
        for place in 1..=3u8 {
            let count = trials
                .iter()
                .filter(|trial| {
                    let at = trial.at(place).unwrap();
                    at == odd && trial.played().filter(|&s| s == odd).count() == 1
                })
                .count();
            assert_eq!(count, 2, "stimulus {odd} odd at place {place}");
        }
    }
    assert_ne!(
        trials,
        plan_trials(&triangle, order_seed(triangle.seed, "p2"))
    );

    let abx = spec(&study("abx")).unwrap();
    let trials = plan_trials(&abx, order_seed(abx.seed, "p1"));
    assert_eq!(trials.len(), 8, "4 arrangements × 2");
    for (a, x) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        let count = trials
            .iter()
            .filter(|trial| trial.first == a && trial.third == Some(x))
            .count();
        assert_eq!(count, 2, "A {a}, X {x}");
        assert!(trials.iter().all(|trial| trial.first != trial.second));
    }
    // Two stimuli, no target.
    let error = spec(&study("triangle").replace(
        "[stimuli.recording]",
        "[stimuli.third]\n[stimuli.recording]",
    ))
    .unwrap_err()
    .to_string();
    assert!(error.contains("a triangle study has two"), "{error}");
    let error = spec(&study("abx").replace("seed = 5", "seed = 5\ntarget = \"model\""))
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("`target` does not belong to the abx design"),
        "{error}"
    );
}

/// Always key 3 in the triangle, always key 1 in ABX: right exactly when the third is the odd
/// one, and when X is the first; the third stimulus, its gain and its params are logged, the
/// dry run writes three files a trial, and the analysis reads the log.
#[test]
fn a_triangle_and_an_abx_session_log_whether_the_answer_was_right() {
    for (design, key, trials) in [("triangle", "3", 12), ("abx", "1", 8)] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("study.toml"), study(design)).unwrap();
        // An answer no trial takes is asked again: 3 in ABX, 4 in the triangle.
        let wrong = if design == "abx" { "3\n" } else { "4\n" };
        let input = format!("\n{wrong}{}", format!("{key}\n").repeat(trials));
        session(dir.path(), "p1", "log.csv", &["--dry-run", "dry"], &input);
        let rows = rows(&dir.path().join("log.csv"));
        assert_eq!(rows.len(), trials, "{design}");
        for row in &rows {
            assert_eq!(row["design"], design);
            assert_eq!(row["pressed"], key);
            let played = [&row["first"], &row["second"], &row["third"]];
            let right = match design {
                "triangle" => played.iter().filter(|&&name| *name == row["third"]).count() == 1,
                _ => row["third"] == row["first"],
            };
            assert_eq!(row["correct"], if right { "1" } else { "0" }, "{row:?}");
            assert!(!row["third_gain_db"].is_empty() && !row["third_params"].is_empty());
        }
        let files = std::fs::read_dir(dir.path().join("dry")).unwrap().count();
        assert_eq!(files, 3 * trials + 1, "three files a trial and the list");
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
        assert!(analysed.status.success());
        let json: serde_json::Value = serde_json::from_slice(&analysed.stdout).unwrap();
        assert_eq!(json["design"], design);
        assert_eq!(json["trials"], trials);
        let right = rows.iter().filter(|row| row["correct"] == "1").count();
        assert_eq!(json["correct"], right);
        // Key 3 names the odd one in 2 of the triangle's 6 arrangements; key 1 names X in 2 of
        // ABX's 4.
        let expected = if design == "triangle" {
            trials / 3
        } else {
            trials / 2
        };
        assert_eq!(right, expected, "{design}: balanced arrangements");
    }
}

/// A triangle session whose answers end after 5 trials is resumed: the same order, the same
/// rows as one run in one go (response times aside).
#[test]
fn a_triangle_session_resumes_in_its_order() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), study("triangle")).unwrap();
    let output = session_output(
        dir.path(),
        "p3",
        "cut.csv",
        &["--dry-run", "a"],
        &format!("\n{}", "2\n".repeat(5)),
    );
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(log_rows(&dir.path().join("cut.csv")).len(), 5);
    session(
        dir.path(),
        "p3",
        "cut.csv",
        &["--dry-run", "a", "--resume"],
        &format!("\n{}", "2\n".repeat(7)),
    );
    session(
        dir.path(),
        "p3",
        "whole.csv",
        &["--dry-run", "b"],
        &format!("\n{}", "2\n".repeat(12)),
    );
    let without_times = |path: &Path| {
        rows(path)
            .into_iter()
            .map(|mut row| {
                row.remove("rt_s");
                row
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(
        without_times(&dir.path().join("cut.csv")),
        without_times(&dir.path().join("whole.csv"))
    );
}

/// The log as an earlier runner wrote it: without `columns`.
fn older(path: &Path, columns: &[&str]) {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().clone();
    let kept: Vec<usize> = (0..header.len())
        .filter(|&index| !columns.contains(&&header[index]))
        .collect();
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer
        .write_record(kept.iter().map(|&index| &header[index]))
        .unwrap();
    for record in reader.records() {
        let record = record.unwrap();
        writer
            .write_record(kept.iter().map(|&index| &record[index]))
            .unwrap();
    }
    std::fs::write(path, writer.into_inner().unwrap()).unwrap();
}

/// The columns added since the first runner.
const NEWER: [&str; 6] = [
    "practice",
    "correct",
    "third",
    "third_gain_db",
    "third_onset_frame",
    "third_params",
];

/// A paired log from before the `practice`, `correct` and third-stimulus columns resumes in its
/// own columns (the paired session leaves them all blank); a triangle log without `correct` is
/// refused, naming it, and kept as it was.
#[test]
fn an_earlier_runners_log_resumes_in_its_columns_or_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), SHORT_PAIRED).unwrap();
    let output = session_output(
        dir.path(),
        "p1",
        "old.csv",
        &["--dry-run", "d"],
        &format!("\n{}", "1\n".repeat(4)),
    );
    assert_eq!(output.status.code(), Some(1));
    older(&dir.path().join("old.csv"), &NEWER);
    session(
        dir.path(),
        "p1",
        "old.csv",
        &["--dry-run", "d", "--resume"],
        &format!("\n{}", "1\n".repeat(8)),
    );
    let mut reader = csv::Reader::from_path(dir.path().join("old.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    assert!(NEWER
        .iter()
        .all(|column| !header.iter().any(|h| h == *column)));
    let records: Vec<_> = reader.records().map(Result::unwrap).collect();
    assert_eq!(records.len(), 12);
    assert!(records.iter().all(|record| record.len() == header.len()));
    let analysed = std::process::Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir.path())
        .args(["analyze", "paired", "--dry-run-logs", "old.csv"])
        .output()
        .unwrap();
    assert!(
        analysed.status.success(),
        "{}",
        String::from_utf8_lossy(&analysed.stderr)
    );

    std::fs::write(dir.path().join("study.toml"), study("triangle")).unwrap();
    let output = session_output(
        dir.path(),
        "p1",
        "tri.csv",
        &["--dry-run", "t"],
        &format!("\n{}", "1\n".repeat(3)),
    );
    assert_eq!(output.status.code(), Some(1));
    older(&dir.path().join("tri.csv"), &["correct"]);
    let before = std::fs::read(dir.path().join("tri.csv")).unwrap();
    let output = session_output(
        dir.path(),
        "p1",
        "tri.csv",
        &["--dry-run", "t", "--resume"],
        "\n1\n",
    );
    refused(
        &output,
        &["tri.csv, line 1", "an earlier runner's log", "`correct`"],
    );
    assert_eq!(std::fs::read(dir.path().join("tri.csv")).unwrap(), before);

    // A log from before the dry run's mark cannot take a dry run's marked rows.
    std::fs::write(dir.path().join("study.toml"), SHORT_PAIRED).unwrap();
    let output = session_output(
        dir.path(),
        "p1",
        "unmarked.csv",
        &["--dry-run", "u"],
        &format!("\n{}", "1\n".repeat(4)),
    );
    assert_eq!(output.status.code(), Some(1));
    older(&dir.path().join("unmarked.csv"), &["dry_run"]);
    let output = session_output(
        dir.path(),
        "p1",
        "unmarked.csv",
        &["--dry-run", "u", "--resume"],
        "\n1\n",
    );
    refused(
        &output,
        &[
            "unmarked.csv, line 1",
            "an earlier runner's log",
            "`dry_run`",
        ],
    );
}

/// `experiment … --dry-run DIR` with stdin closed waited for answers and exited 1 (issue 40):
/// answers that end before the first one end the dry run as --no-answers does, exit status 0,
/// saying so; answers that end later are still an interrupted session (exit 1).
#[test]
fn a_dry_run_whose_answers_end_before_the_first_ends_there() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), study("triangle")).unwrap();
    for input in ["", "\n"] {
        let log = format!("log{}.csv", input.len());
        let folder = format!("dry{}", input.len());
        let output = session(dir.path(), "p1", &log, &["--dry-run", &folder], input);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("ended before the first one") && stderr.contains("--no-answers"),
            "{stderr}"
        );
        assert!(dir.path().join(&folder).join("trials.csv").exists());
        assert!(log_rows(&dir.path().join(&log)).is_empty());
    }
    let output = session_output(
        dir.path(),
        "p1",
        "later.csv",
        &["--dry-run", "later"],
        "\n1\n",
    );
    assert_eq!(output.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&output.stderr).contains("after 1 of 12 trials"));
}
