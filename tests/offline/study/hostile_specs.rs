//! Specs as a careless user or a malicious file writes them: a stimulus that names another file
//! printed that file's first line, a long field was echoed whole, a day-long stimulus aborted the
//! runner. Messages quote a short cut of a field and never a line of another file; what cannot
//! fit in memory is refused with the figure.

use std::path::Path;
use std::process::Command;

use super::{finish, refused, SHORT_PAIRED};
use sake_glug_study::Spec;

/// The longest message a refusal of a spec may print: a few lines, whatever the spec holds.
const MAX_MESSAGE_CHARS: usize = 600;

fn error_in(dir: &Path, text: &str) -> String {
    let path = dir.join("study.toml");
    std::fs::write(&path, text).unwrap();
    let message = Spec::load(&path).unwrap_err().to_string();
    assert!(
        message.chars().count() < MAX_MESSAGE_CHARS,
        "{} characters: {}…",
        message.chars().count(),
        message.chars().take(300).collect::<String>()
    );
    assert!(message.chars().all(|c| !c.is_control()), "{message:?}");
    message
}

/// `[stimuli.c] model = "/etc/passwd"` printed the file's first line (toml's message shows the
/// line it stops at). The message says where and what, never the line.
#[test]
fn a_stimulus_naming_another_file_never_prints_its_lines() {
    let dir = tempfile::tempdir().unwrap();
    let secret = "SECRET first line: hunter2";
    std::fs::write(
        dir.path().join("notes.txt"),
        format!("{secret}\nline two\n"),
    )
    .unwrap();
    let mut files = vec![dir.path().join("notes.txt")];
    if Path::new("/etc/passwd").exists() {
        files.push("/etc/passwd".into());
    }
    for file in files {
        let first_line = std::fs::read_to_string(&file)
            .unwrap()
            .lines()
            .next()
            .unwrap()
            .to_owned();
        for key in ["model", "scene"] {
            let text = format!(
                "{SHORT_PAIRED}[stimuli.c]\n{key} = {:?}\n",
                file.to_str().unwrap()
            );
            let message = error_in(dir.path(), &text);
            assert!(message.contains("stimulus `c`"), "{message}");
            assert!(message.contains("not TOML: line 1, column"), "{message}");
            assert!(!message.contains(&first_line), "{message}");
            assert!(
                !message.contains("hunter2") && !message.contains("root:"),
                "{message}"
            );
        }
    }
}

/// A long field was echoed whole (50 MB on stderr). A field is quoted cut to 32 characters,
/// wherever it is: the design, a preset, a stimulus's name, a file's name, a key of a scene file.
#[test]
fn a_long_field_is_quoted_cut_short() {
    let dir = tempfile::tempdir().unwrap();
    let long = "x".repeat(900_000);
    let cut = format!("{}…", "x".repeat(32));
    let specs = [
        SHORT_PAIRED.replace("design = \"paired\"", &format!("design = \"{long}\"")),
        SHORT_PAIRED.replace(
            "preset = \"water\"\n[stimuli.high]",
            &format!("preset = \"{long}\"\n[stimuli.high]"),
        ),
        format!("{SHORT_PAIRED}[stimuli.{long}]\nviscosity_c = 2.0\n"),
        format!("{SHORT_PAIRED}[stimuli.c]\nscene = \"{long}.toml\"\n"),
        format!("{SHORT_PAIRED}[stimuli.c]\nscene = \"long-key.toml\"\n"),
        format!("{SHORT_PAIRED}{long} = 1\n"),
    ];
    std::fs::write(
        dir.path().join("long-key.toml"),
        format!("{} = 1.0\n", "k".repeat(10_000_000)),
    )
    .unwrap();
    for (index, text) in specs.iter().enumerate() {
        let message = error_in(dir.path(), text);
        assert!(
            message.contains(&cut) || message.contains(&format!("{}…", "k".repeat(32))),
            "spec {index}: {message}"
        );
    }
}

/// `duration_s = 86400` (which the spec allows) aborted the runner within 5 s under 4 GB: its
/// stimuli are held in memory. Refused before anything is rendered, with what they need.
#[test]
fn a_day_long_stimulus_is_refused_with_the_memory_it_needs() {
    use std::os::unix::process::CommandExt;
    let dir = tempfile::tempdir().unwrap();
    let spec = std::fs::read_to_string(super::experiments().join("paired-waves.toml"))
        .unwrap()
        .replace("duration_s = 5.0", "duration_s = 86400.0");
    std::fs::write(dir.path().join("day.toml"), spec).unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_sake-glug"));
    command.current_dir(dir.path()).args([
        "experiment",
        "day.toml",
        "--participant",
        "P1",
        "--dry-run",
        "dry",
        "--no-answers",
    ]);
    // SAFETY: only setrlimit, async-signal-safe, runs between fork and exec.
    unsafe {
        command.pre_exec(|| {
            const FOUR_GB: u64 = 4 << 30;
            let limit = libc::rlimit {
                rlim_cur: FOUR_GB,
                rlim_max: FOUR_GB,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let child = command
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let output = finish(child);
    refused(
        &output,
        &[
            "day.toml: the 3 stimuli of 86400 s at 48000 Hz",
            "49.8 GB (16.6 GB each)",
        ],
    );
    assert!(!dir.path().join("dry").exists());
}
