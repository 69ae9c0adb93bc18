//! The dry run: scripted (#30), bounded, cleaned up after, and open to every user (#31).

use std::path::Path;
use std::process::{Command, Output};

use super::{answers, finish, refused, run, SHORT_PAIRED};

fn study() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), SHORT_PAIRED).unwrap();
    dir
}

fn names(folder: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Without a terminal a dry run wrote its files, then waited for answers and exited 1
/// ("the answers ended (stdin closed) after 0 of 18 trials"). With `--no-answers` it writes the
/// folder and exits 0, and keeps no log.
#[test]
fn a_scripted_dry_run_writes_the_folder_and_exits_0() {
    let dir = study();
    let output = scripted_dry_run(dir.path());
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(names(&dir.path().join("dry")).len(), 2 * 12 + 1);
    assert_eq!(names(dir.path()), ["dry", "study.toml"]);
    // It names no log, and needs a dry run.
    for extra in [&["--log", "l.csv", "--dry-run", "d"][..], &[]] {
        let output = run(
            dir.path(),
            &[
                &["study.toml", "--participant", "p1", "--no-answers"][..],
                extra,
            ]
            .concat(),
            "",
        );
        assert_eq!(output.status.code(), Some(2));
    }
}

/// `repetitions = 1000000` with a 1 s stimulus wrote 66 GB and filled the disk. A session has at
/// most 10,000 trials, refused with the figure before anything is rendered or written.
#[test]
fn a_session_past_the_trial_limit_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let spec = SHORT_PAIRED.replace("repetitions = 2", "repetitions = 1000000");
    std::fs::write(dir.path().join("study.toml"), spec).unwrap();
    let output = scripted_dry_run(dir.path());
    refused(
        &output,
        &[
            "6 ordered pairs × `repetitions` = 1000000 make 6000000 trials",
            "at most 10000",
        ],
    );
    assert_eq!(names(dir.path()), ["study.toml"]);
}

/// A dry run larger than its disk's free space is refused with the figure, and leaves nothing.
/// The disk is a 64 kB tmpfs in a mount namespace of the run's own (root only: skipped, with a
/// message, where `unshare` cannot make one).
#[test]
fn a_dry_run_larger_than_the_free_space_is_refused_with_the_figure() {
    let dir = study();
    std::fs::create_dir(dir.path().join("small")).unwrap();
    let script = "mount -t tmpfs -o size=64k tmpfs small || exit 77; \
                  \"$0\" experiment study.toml --participant p1 --dry-run small/dry --no-answers; \
                  status=$?; echo \"left: $(ls -A small)\"; exit $status";
    let output = Command::new("unshare")
        .current_dir(dir.path())
        .args(["--mount", "--propagation", "private", "sh", "-c", script])
        .arg(env!("CARGO_BIN_EXE_sake-glug"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.code() == Some(77)
        || (output.status.code() == Some(1) && stderr.starts_with("unshare"))
    {
        eprintln!("skipped: no mount namespace here ({})", stderr.trim());
        return;
    }
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--dry-run small/dry: its stimuli and trial list: it needs ")
            && stderr.contains("kB, and its disk has ")
            && stderr.contains("kB free"),
        "{stderr}"
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout.ends_with("left: \n"),
        "nothing left on the small disk: {stdout}"
    );
}

/// Killed dry runs left `.DIR.sake-glug-*.tmp` folders that nothing removed. The next dry run to
/// the same folder removes those of processes that are gone, and no other.
#[test]
fn a_killed_dry_runs_temporary_folder_is_removed_by_the_next() {
    let dir = study();
    // No process has a pid this large (Linux's limit is 2^22).
    let dead = dir.path().join(".dry.sake-glug-4294967290.AbC123.tmp");
    let alive = dir
        .path()
        .join(format!(".dry.sake-glug-{}.AbC123.tmp", std::process::id()));
    for folder in [&dead, &alive] {
        std::fs::create_dir(folder).unwrap();
        std::fs::write(folder.join("trial-001-1-model.wav"), "RIFF").unwrap();
    }
    let output = scripted_dry_run(dir.path());
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(!dead.exists(), "the dead process's folder is removed");
    assert!(alive.exists(), "a running process's folder is kept");
}

/// The dry run's temporary folder was made with a file's mode (0644: no one may enter it), so
/// every user but root failed with "Permission denied". Run here as `nobody` (uid 65534), from
/// a child that drops root before it runs the command; skipped, with a message, when the suite
/// does not run as root.
#[test]
fn a_dry_run_works_for_a_user_who_is_not_root() {
    use std::os::unix::fs::PermissionsExt;
    use std::os::unix::process::CommandExt;
    if unsafe { libc::geteuid() } != 0 {
        eprintln!("skipped: run as root, the test runs the dry run as nobody");
        return;
    }
    let dir = study();
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o777)).unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_sake-glug"));
    command.current_dir(dir.path()).args([
        "experiment",
        "study.toml",
        "--participant",
        "p1",
        "--log",
        "l.csv",
        "--dry-run",
        "dry",
    ]);
    // SAFETY: setgroups, setgid and setuid are async-signal-safe; they run between fork and exec.
    unsafe {
        command.pre_exec(|| {
            const NOBODY: u32 = 65534;
            if libc::setgroups(0, std::ptr::null()) != 0
                || libc::setgid(NOBODY) != 0
                || libc::setuid(NOBODY) != 0
            {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let mut child = command
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    std::io::Write::write_all(&mut stdin, answers(12).as_bytes()).unwrap();
    drop(stdin);
    let output = finish(child);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let dry = dir.path().join("dry");
    let meta = std::fs::metadata(&dry).unwrap();
    assert_eq!(std::os::unix::fs::MetadataExt::uid(&meta), 65534);
    assert_eq!(names(&dry).len(), 2 * 12 + 1);
    assert_eq!(
        meta.permissions().mode() & 0o700,
        0o700,
        "{:o}",
        meta.permissions().mode()
    );
}

/// `experiment study.toml --participant p1 --dry-run dry --no-answers` in `dir`: a scripted dry
/// run into `dir/dry`.
fn scripted_dry_run(dir: &Path) -> Output {
    run(
        dir,
        &[
            "study.toml",
            "--participant",
            "p1",
            "--dry-run",
            "dry",
            "--no-answers",
        ],
        "",
    )
}

/// A session's log and its dry run go into folders that do not exist yet: made, as every
/// written file's folder is (issue 49).
#[test]
fn the_log_and_the_dry_run_make_their_folders() {
    let dir = study();
    let output = run(
        dir.path(),
        &[
            "study.toml",
            "--participant",
            "p1",
            "--log",
            "logs/p1/log.csv",
            "--dry-run",
            "runs/p1/dry",
        ],
        &answers(12),
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(names(&dir.path().join("runs/p1/dry")).len(), 2 * 12 + 1);
    assert!(dir.path().join("logs/p1/log.csv").is_file());
}

/// A dry run looked like real data (issue 49): its prompt said "listen…" without naming the
/// files to play, and `analyze` reported its log as a result. Each trial's prompt now names its
/// files in the folder (the practice trials' too), each row of the log is marked `dry_run` 1,
/// and `analyze` refuses such a log unless `--dry-run-logs` is given, and then says so.
#[test]
fn a_dry_run_names_its_files_and_its_log_is_no_result() {
    let dir = tempfile::tempdir().unwrap();
    let spec = SHORT_PAIRED.replace("equalize = \"peak\"", "equalize = \"peak\"\npractice = 2");
    std::fs::write(dir.path().join("study.toml"), spec).unwrap();
    let output = run(
        dir.path(),
        &[
            "study.toml",
            "--participant",
            "p1",
            "--log",
            "log.csv",
            "--dry-run",
            "dry",
        ],
        &answers(2 + 12),
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert!(!stdout.contains("listen"), "{stdout}");
    let folder = names(&dir.path().join("dry"));
    let list = super::log_rows(&dir.path().join("dry/trials.csv"));
    let cued = |line: &str| -> Vec<String> {
        let files = line
            .split_once(": play ")
            .and_then(|(_, rest)| rest.strip_suffix(" (in dry)…"))
            .unwrap_or_else(|| panic!("no files in `{line}`"));
        files.split(", then ").map(str::to_owned).collect()
    };
    let (mut practice, mut trials) = (0, 0);
    // A prompt follows the previous trial's question on its line.
    for line in stdout.lines() {
        if let Some(at) = line.find("Practice trial ") {
            let line = &line[at..];
            practice += 1;
            let files = cued(line);
            assert_eq!(files.len(), 2, "{line}");
            assert!(files.iter().all(|file| folder.contains(file)), "{line}");
        } else if let Some(at) = line.find("Trial ") {
            let line = &line[at..];
            let number: usize = line["Trial ".len()..]
                .split('/')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            let row = &list[number - 1];
            // The files the trial list gives the trial, in the order played.
            assert_eq!(cued(line), [&row[3], &row[4]], "{line}");
            trials += 1;
        }
    }
    assert_eq!(trials, 12, "{stdout}");
    assert_eq!(practice, 2, "{stdout}");
    assert_eq!(folder.len(), 2 * 2 + 2 * 12 + 1, "{folder:?}");

    let log = dir.path().join("log.csv");
    let header = csv::Reader::from_path(&log)
        .unwrap()
        .headers()
        .unwrap()
        .clone();
    let dry_run = header
        .iter()
        .position(|column| column == "dry_run")
        .unwrap();
    assert!(super::log_rows(&log).iter().all(|row| &row[dry_run] == "1"));

    let analyze = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_sake-glug"))
            .current_dir(dir.path())
            .args(["analyze", "paired", "log.csv"])
            .args(extra)
            .output()
            .unwrap()
    };
    let refused = analyze(&[]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("log.csv, line 4") && stderr.contains("a dry run's trial"),
        "{stderr}"
    );
    assert!(stderr.contains("--dry-run-logs"), "{stderr}");
    let read = analyze(&["--dry-run-logs", "--json"]);
    let stderr = String::from_utf8_lossy(&read.stderr);
    assert!(read.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: 12 of these trials were answered in a dry run"),
        "{stderr}"
    );
    let json: serde_json::Value = serde_json::from_slice(&read.stdout).unwrap();
    assert_eq!(json["dry_run_trials"], 12);
    assert_eq!(json["trials"], 12);
}
