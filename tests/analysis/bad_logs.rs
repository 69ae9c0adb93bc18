//! Bad logs: a clear error naming the file, the line and the column, exit status 1, no output
//! and no plot; never a panic or a made-up result.

use crate::analyze;

/// Runs `analyze DESIGN log.csv --plot out.png` on `log`; returns stderr after checking that it
/// failed cleanly.
fn refused(design: &str, log: Option<&str>) -> String {
    let folder = tempfile::tempdir().unwrap();
    if let Some(log) = log {
        std::fs::write(folder.path().join("log.csv"), log).unwrap();
    }
    let output = analyze(folder.path(), &[design, "log.csv", "--plot", "out.png"]);
    let stderr = String::from_utf8(output.stderr).unwrap();
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(output.stdout.is_empty(), "no result printed");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!folder.path().join("out.png").exists());
    stderr
}

fn assert_names(stderr: &str, parts: &[&str]) {
    for part in parts {
        assert!(stderr.contains(part), "no `{part}` in: {stderr}");
    }
}

const PAIRED_HEADER: &str = "participant,first,second,answer\n";

#[test]
fn a_missing_log_is_named() {
    assert_names(&refused("paired", None), &["log.csv"]);
    assert_names(&refused("constant", None), &["log.csv"]);
}

#[test]
fn a_missing_column_is_named_with_every_needed_column() {
    let stderr = refused("paired", Some("participant,first,second\np1,a,b\n"));
    assert_names(&stderr, &["log.csv", "`answer`", "`participant`"]);
    let stderr = refused("constant", Some("participant,level\np1,0.3\n"));
    assert_names(&stderr, &["log.csv", "`chose_comparison`"]);
}

#[test]
fn an_answer_that_is_neither_stimulus_is_named_with_its_line_and_column() {
    let log = format!("{PAIRED_HEADER}p1,a,b,a\np1,b,a,a\np1,a,c,c\np1,b,c,x\n");
    assert_names(
        &refused("paired", Some(&log)),
        &["log.csv, line 5", "column `answer`", "`x`"],
    );
    // A known stimulus that this trial did not present.
    let log = format!("{PAIRED_HEADER}p1,a,b,a\np1,b,c,a\n");
    assert_names(
        &refused("paired", Some(&log)),
        &["line 3", "`answer`", "neither"],
    );
}

#[test]
fn an_empty_stimulus_name_and_a_pair_of_one_stimulus_are_refused() {
    let log = format!("{PAIRED_HEADER}p1,a,,a\n");
    assert_names(
        &refused("paired", Some(&log)),
        &["line 2", "`second`", "empty"],
    );
    let log = format!("{PAIRED_HEADER}p1,a,a,a\n");
    assert_names(&refused("paired", Some(&log)), &["line 2", "`second`"]);
}

#[test]
fn fewer_than_two_stimuli_or_a_pair_never_compared_is_refused() {
    assert_names(
        &refused("paired", Some(PAIRED_HEADER)),
        &["log.csv", "no trials"],
    );
    let log = format!("{PAIRED_HEADER}p1,a,b,a\np1,c,d,c\n");
    assert_names(
        &refused("paired", Some(&log)),
        &["log.csv", "never compared"],
    );
}

#[test]
fn a_row_of_another_length_is_named_with_its_line() {
    let log = format!("{PAIRED_HEADER}p1,a,b,a\np1,a,b\n");
    assert_names(
        &refused("paired", Some(&log)),
        &["log.csv, line 3", "3 fields"],
    );
}

const CONSTANT_HEADER: &str = "participant,level,chose_comparison\n";

#[test]
fn a_non_numeric_level_or_answer_is_named_with_its_line_and_column() {
    let log = format!("{CONSTANT_HEADER}p1,0.2,1\np1,thick,0\n");
    assert_names(
        &refused("constant", Some(&log)),
        &["line 3", "column `level`", "`thick`"],
    );
    let log = format!("{CONSTANT_HEADER}p1,0.2,1\np1,NaN,0\n");
    assert_names(&refused("constant", Some(&log)), &["line 3", "`level`"]);
    let log = format!("{CONSTANT_HEADER}p1,0.2,yes\n");
    assert_names(
        &refused("constant", Some(&log)),
        &["line 2", "`chose_comparison`", "`yes`"],
    );
}

#[test]
fn trials_at_fewer_than_two_levels_or_answers_that_never_change_are_refused() {
    let log = format!("{CONSTANT_HEADER}p1,0.2,1\np1,0.2,0\n");
    assert_names(&refused("constant", Some(&log)), &["log.csv", "1 level"]);
    assert_names(
        &refused("constant", Some(CONSTANT_HEADER)),
        &["log.csv", "0 level"],
    );
    let log = format!("{CONSTANT_HEADER}p1,0.2,0\np1,0.3,0\np1,0.4,1\np1,0.5,1\n");
    assert_names(
        &refused("constant", Some(&log)),
        &["log.csv", "no finite fit"],
    );
}

/// Names in a log are the participant's or the runner's text: the report shows them with their
/// control characters escaped, so a log cannot steer the terminal it is read on.
#[test]
fn names_with_control_characters_are_shown_escaped() {
    let folder = tempfile::tempdir().unwrap();
    let bell = "ring\u{7}";
    let escape = "red\u{1b}[31m";
    let paired = format!("{PAIRED_HEADER}p1,{bell},{escape},{bell}\np1,{escape},{bell},{bell}\n");
    std::fs::write(folder.path().join("paired.csv"), paired).unwrap();
    let constant = "participant,level,chose_comparison\n\
                    p\u{1b}]0;x\u{7},0.2,0\np\u{1b}]0;x\u{7},0.2,1\np\u{1b}]0;x\u{7},0.3,1\n\
                    p\u{1b}]0;x\u{7},0.4,1\np\u{1b}]0;x\u{7},0.4,0\np\u{1b}]0;x\u{7},0.5,1\n";
    std::fs::write(folder.path().join("constant.csv"), constant).unwrap();
    for args in [
        ["paired", "paired.csv"].as_slice(),
        ["constant", "constant.csv", "--resamples", "20"].as_slice(),
    ] {
        let output = analyze(folder.path(), args);
        let stdout = String::from_utf8(output.stdout).unwrap();
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        assert!(
            stdout.chars().all(|c| !c.is_control() || c == '\n'),
            "{args:?}: a raw control character in:\n{stdout:?}"
        );
        assert!(
            stdout.contains("\\u{1b}"),
            "{args:?}: the name is shown escaped"
        );
    }
}
