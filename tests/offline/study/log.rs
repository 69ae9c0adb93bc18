//! The trial log under attack: `--resume` cut files before checking them, two sessions wrote over
//! each other, a FIFO as the log blocked, an answer naming no stimulus was resumed, and names
//! that a spreadsheet runs went into it raw. The log is checked whole before anything is
//! written, never shortened, appended to only, locked for its session, a regular file only, and
//! its formula-like cells are written as text and read back as the names they were.

use std::io::{BufRead, BufReader, Write};
use std::path::Path;

use super::{answers, finish, log_rows, refused, run, start, SHORT_PAIRED};

/// SHORT_PAIRED's trials: 3 stimuli, 6 ordered pairs, 2 repetitions.
const TRIALS: usize = 12;

fn args<'a>(participant: &'a str, log: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["study.toml", "--participant", participant, "--log", log];
    args.extend_from_slice(extra);
    args
}

/// A folder with SHORT_PAIRED as `study.toml`.
fn study() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), SHORT_PAIRED).unwrap();
    dir
}

/// A whole session of participant `p7` logged in `log.csv` (its dry run in `dry`).
fn finished_log(dir: &Path) -> Vec<u8> {
    let output = run(
        dir,
        &args("p7", "log.csv", &["--dry-run", "dry"]),
        &answers(TRIALS),
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::read(dir.join("log.csv")).unwrap()
}

/// `printf 'l1\nlast' > notes.txt; … --log notes.txt --resume` exited 2 and cut "last"; a PNG
/// lost 1,061 bytes. Both are refused as they are.
#[test]
fn a_file_that_is_not_a_log_is_refused_untouched() {
    let dir = study();
    let png: Vec<u8> = b"\x89PNG\r\n\x1a\n"
        .iter()
        .copied()
        .chain((0..2000u32).map(|i| (i * 7 % 251) as u8))
        .collect();
    for (name, bytes) in [("notes.txt", b"l1\nlast".to_vec()), ("picture.png", png)] {
        std::fs::write(dir.path().join(name), &bytes).unwrap();
        let output = run(
            dir.path(),
            &args("P1", name, &["--dry-run", "d", "--resume"]),
            "",
        );
        refused(&output, &[name, "line 1"]);
        assert_eq!(
            std::fs::read(dir.path().join(name)).unwrap(),
            bytes,
            "{name}"
        );
    }
    assert!(
        !dir.path().join("d").exists(),
        "no dry run for a refused log"
    );
}

/// A finished log without its final line break, resumed by mistake as another participant, lost
/// its last trial though the resume was refused. It is refused for the participant, then (as the
/// right participant) for the torn line, and kept byte for byte.
#[test]
fn a_log_ending_in_a_torn_row_is_reported_and_kept() {
    let dir = study();
    let mut log = finished_log(dir.path());
    assert_eq!(log.pop(), Some(b'\n'));
    std::fs::write(dir.path().join("log.csv"), &log).unwrap();
    let other = run(
        dir.path(),
        &args("p8", "log.csv", &["--dry-run", "dry", "--resume"]),
        &answers(TRIALS),
    );
    refused(&other, &["log.csv, line 2: participant `p7`"]);
    assert_eq!(std::fs::read(dir.path().join("log.csv")).unwrap(), log);
    let same = run(
        dir.path(),
        &args("p7", "log.csv", &["--dry-run", "dry", "--resume"]),
        &answers(TRIALS),
    );
    refused(
        &same,
        &[
            "log.csv, line 13",
            "without a line break",
            "nothing was changed",
        ],
    );
    assert_eq!(std::fs::read(dir.path().join("log.csv")).unwrap(), log);
    // Cut mid-row, as a crash mid-write leaves it: the same.
    let torn = &log[..log.len() - 20];
    std::fs::write(dir.path().join("log.csv"), torn).unwrap();
    let again = run(
        dir.path(),
        &args("p7", "log.csv", &["--dry-run", "dry", "--resume"]),
        &answers(TRIALS),
    );
    refused(&again, &["line 13", "without a line break"]);
    assert_eq!(std::fs::read(dir.path().join("log.csv")).unwrap(), torn);
}

/// `--resume` accepted a log whose answer named no stimulus of its trial, and `analyze` then
/// refused the whole log. Every row is checked against the spec: the answer, the key pressed.
#[test]
fn resume_checks_every_answer_against_the_spec() {
    let dir = study();
    let log = String::from_utf8(finished_log(dir.path())).unwrap();
    let mut lines: Vec<String> = log.lines().map(str::to_owned).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let answer = header.iter().position(|&name| name == "answer").unwrap();
    let pressed = header.iter().position(|&name| name == "pressed").unwrap();
    // Keep 4 rows: a session stopped after its fourth trial.
    lines.truncate(5);
    let edit = |row: usize, column: usize, value: &str| {
        let mut lines = lines.clone();
        let mut fields: Vec<String> = lines[row].split(',').map(str::to_owned).collect();
        fields[column] = value.to_owned();
        lines[row] = fields.join(",");
        lines.join("\n") + "\n"
    };
    // The params are quoted fields with commas: edit the columns before them only.
    assert!(answer < 6 && pressed < 7);
    for (bad, expected) in [
        (edit(3, answer, "ghost"), "answer `ghost`"),
        (edit(3, pressed, "3"), "key 3 pressed"),
        // The other stimulus of the trial with the key unchanged.
        (
            {
                let fields: Vec<&str> = lines[3].split(',').collect();
                let other = if fields[answer] == fields[3] {
                    fields[4]
                } else {
                    fields[3]
                };
                edit(3, answer, other)
            },
            "chooses",
        ),
    ] {
        std::fs::write(dir.path().join("log.csv"), &bad).unwrap();
        let output = run(
            dir.path(),
            &args("p7", "log.csv", &["--dry-run", "dry", "--resume"]),
            &answers(TRIALS),
        );
        refused(&output, &["log.csv, line 4", expected]);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("log.csv")).unwrap(),
            bad
        );
    }
    // As logged, it resumes after its fourth trial.
    let kept = lines.join("\n") + "\n";
    std::fs::write(dir.path().join("log.csv"), &kept).unwrap();
    let output = run(
        dir.path(),
        &args("p7", "log.csv", &["--dry-run", "dry", "--resume"]),
        &answers(TRIALS - 4),
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(String::from_utf8_lossy(&output.stdout).contains("Resuming after trial 4 of 12"));
    assert_eq!(log_rows(&dir.path().join("log.csv")).len(), TRIALS);
}

/// Two `--resume` runs on one log both ended "Done", their rows over each other's and the file
/// ending in a torn field. The log is locked for its session: the second is refused at once.
#[test]
fn a_second_session_on_a_log_is_refused_while_the_first_runs() {
    let dir = study();
    let mut first = start(dir.path(), &args("p7", "log.csv", &["--dry-run", "dry"]));
    let mut stdout = BufReader::new(first.stdout.take().unwrap());
    // Once it asks to begin, it holds the log.
    let mut line = String::new();
    while !line.starts_with("Press Enter") {
        line.clear();
        assert_ne!(
            stdout.read_line(&mut line).unwrap(),
            0,
            "the first session ended"
        );
    }
    for extra in [&["--resume"][..], &[]] {
        let second = run(
            dir.path(),
            &args(
                "p7",
                "log.csv",
                &[&["--dry-run", "dry"][..], extra].concat(),
            ),
            &answers(TRIALS),
        );
        let expected = if extra.is_empty() {
            "already exists"
        } else {
            "another session is writing to this log"
        };
        refused(&second, &[expected]);
    }
    let mut stdin = first.stdin.take().unwrap();
    stdin.write_all(answers(TRIALS).as_bytes()).unwrap();
    drop(stdin);
    let rest = std::io::read_to_string(stdout).unwrap();
    assert!(rest.contains("Done: 12 trials"), "{rest}");
    let output = finish(first);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let rows = log_rows(&dir.path().join("log.csv"));
    assert_eq!(rows.len(), TRIALS);
    for (index, row) in rows.iter().enumerate() {
        assert_eq!(&row[1], (index + 1).to_string().as_str());
    }
    // Ended, it lets the next session in: a finished log resumes to "Done" at once.
    let again = run(
        dir.path(),
        &args("p7", "log.csv", &["--dry-run", "dry", "--resume"]),
        "",
    );
    assert!(
        again.status.success(),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
}

/// A FIFO named as the log waited for a reader (opened to write); a device was written to.
/// Both are refused at once, for a new session and for a resumed one.
#[test]
fn a_fifo_or_a_device_as_the_log_is_refused_at_once() {
    let dir = study();
    let fifo = dir.path().join("pipe.csv");
    let name = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
    for log in [fifo.to_str().unwrap(), "/dev/null"] {
        for extra in [&[][..], &["--resume"]] {
            let output = run(
                dir.path(),
                &args("p7", log, &[&["--dry-run", "dry"][..], extra].concat()),
                &answers(TRIALS),
            );
            refused(&output, &["not a regular file"]);
        }
    }
    assert!(!dir.path().join("dry").exists());
}

/// Participant IDs and stimulus names went raw into the log and the trial list, where a
/// spreadsheet runs `=cmd|' /C calc'!A0`. Every such cell is written as text (a leading `'`), and
/// read back by `--resume` and by `analyze` as the name it was.
#[test]
fn names_a_spreadsheet_would_run_are_written_as_text_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let names = ["=HYPERLINK(\"http://evil\",\"x\")", "+1+1", "@SUM(1)"];
    let mut spec = String::from(
        "design = \"paired\"\nduration_s = 0.3\ngap_s = 0.1\nrepetitions = 1\nseed = 2\n",
    );
    for (name, viscosity) in names.iter().zip([0.0, 0.5, 1.0]) {
        spec += &format!("[stimuli.{name:?}]\nviscosity_c = {viscosity}\n");
    }
    std::fs::write(dir.path().join("study.toml"), spec).unwrap();
    let participant = "=cmd|' /C calc'!A0";
    let session = args(participant, "log.csv", &["--dry-run", "dry"]);
    // Three answers, then the session stops; resumed, it reads its rows back.
    let output = run(dir.path(), &session, "\n1\n2\n1\n");
    assert_eq!(output.status.code(), Some(1));
    let output = run(
        dir.path(),
        &[&session[..], &["--resume"]].concat(),
        &answers(3),
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for file in ["log.csv", "dry/trials.csv"] {
        let rows = log_rows(&dir.path().join(file));
        assert_eq!(rows.len(), 6, "{file}");
        for row in &rows {
            // A number is a number to a spreadsheet, whatever its sign.
            for cell in row.iter().filter(|cell| cell.parse::<f64>().is_err()) {
                assert!(
                    !cell.starts_with(['=', '+', '-', '@', '\t', '\r']),
                    "{file}: a cell a spreadsheet runs: {cell:?}"
                );
            }
        }
    }
    let log = log_rows(&dir.path().join("log.csv"));
    assert_eq!(&log[0][0], &format!("'{participant}"));
    let analyze = std::process::Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir.path())
        .args(["analyze", "paired", "log.csv", "--json", "--dry-run-logs"])
        .output()
        .unwrap();
    assert!(
        analyze.status.success(),
        "{}",
        String::from_utf8_lossy(&analyze.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&analyze.stdout).unwrap();
    let mut read: Vec<&str> = json["stimuli"]
        .as_array()
        .unwrap()
        .iter()
        .map(|name| name.as_str().unwrap())
        .collect();
    read.sort_unstable();
    let mut written = names.to_vec();
    written.sort_unstable();
    assert_eq!(read, written);
}
