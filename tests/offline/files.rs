//! What a render leaves on disk, whatever happens to it: its targets replaced all or nothing, in
//! their permissions, one render's set at a time; no temporary file after an error or a signal,
//! and none after a `kill -9` once the next render to the same target has run.

use std::fs;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use sake_glug_render::{
    render_to_files, Output, OutputError, OutputOptions, RenderObserver, Scene,
};

use crate::command::{files_in, sake_glug};

/// A day at 768 kHz of an upright bottle: silent, so fast and light, and too long to end on
/// its own during a test. Its clips are written only at the end, so nothing grows on disk.
const ENDLESS: &str = "duration_s = 86400.0\nsample_rate = 768000\n";

/// `sake-glug ARGS` in `directory`, running.
fn spawn(directory: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(directory)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// The renderer's temporary files in `directory`.
fn temporaries(directory: &Path) -> Vec<String> {
    files_in(directory)
        .into_iter()
        .filter(|name| name.contains(".sake-glug-"))
        .collect()
}

/// Waits until the render has opened its `count` temporary files.
fn wait_for_temporaries(directory: &Path, count: usize) {
    let started = Instant::now();
    while temporaries(directory).len() < count {
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "no temporary files"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

fn send(signal: &str, child: &Child) {
    let sent = Command::new("kill")
        .args(["-s", signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
}

#[test]
fn a_signal_stops_the_render_removes_its_temporary_files_and_sets_the_status() {
    for (signal, status) in [("INT", 130), ("TERM", 143), ("HUP", 129)] {
        let directory = tempfile::tempdir().unwrap();
        let dir = directory.path();
        fs::write(dir.join("day.toml"), ENDLESS).unwrap();
        let child = spawn(
            dir,
            &["render", "day.toml", "-o", "d.csv", "-o", "d.haptic"],
        );
        wait_for_temporaries(dir, 2);
        send(signal, &child);
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(status), "SIG{signal}: {stderr}");
        assert!(
            stderr.contains(&format!("stopped by SIG{signal}")),
            "{stderr}"
        );
        assert_eq!(files_in(dir), ["day.toml"], "SIG{signal}");
    }
}

#[test]
fn a_second_signal_ends_the_render_at_once_and_still_removes_its_temporary_files() {
    // The shell's `kill` builtin sends both before the render can act on the first. Two of the
    // same signal sent at once may reach it as one; two different ones are always two, in
    // either order.
    let number = |name| match name {
        "INT" => 2,
        _ => 15,
    };
    for (first, second) in [
        ("INT", "TERM"),
        ("TERM", "INT"),
        ("INT", "INT"),
        ("TERM", "TERM"),
    ] {
        let directory = tempfile::tempdir().unwrap();
        let dir = directory.path();
        fs::write(dir.join("day.toml"), ENDLESS).unwrap();
        let mut child = spawn(
            dir,
            &["render", "day.toml", "-o", "d.csv", "-o", "d.haptic"],
        );
        wait_for_temporaries(dir, 2);
        let sent = Command::new("sh")
            .args(["-c", &format!("kill -s {first} $0 && kill -s {second} $0")])
            .arg(child.id().to_string())
            .status()
            .unwrap();
        assert!(sent.success());
        let started = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if started.elapsed() > Duration::from_secs(60) {
                child.kill().unwrap();
                panic!("SIG{first} then SIG{second}: the render did not end");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        // 128 + the number of the signal it names as the one that stopped it.
        let ended_by = [first, second]
            .into_iter()
            .find(|name| output.status.code() == Some(128 + number(*name)));
        let Some(ended_by) = ended_by else {
            panic!("SIG{first} then SIG{second}: {output:?}");
        };
        assert!(
            stderr.contains(&format!("stopped by SIG{ended_by}")),
            "{stderr}"
        );
        assert_eq!(files_in(dir), ["day.toml"], "SIG{first} then SIG{second}");
    }
}

#[test]
fn what_a_killed_render_left_goes_with_the_next_render_to_the_same_target() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    fs::write(dir.join("day.toml"), ENDLESS).unwrap();
    fs::write(dir.join("short.toml"), "duration_s = 0.1\n").unwrap();
    let mut child = spawn(dir, &["render", "day.toml", "-o", "d.haptic"]);
    wait_for_temporaries(dir, 1);
    child.kill().unwrap();
    child.wait().unwrap();
    let left = temporaries(dir);
    assert_eq!(left.len(), 1, "kill -9 cannot be caught");
    assert!(left[0].starts_with(".d.haptic.sake-glug-"), "{left:?}");
    // Another target in the same folder leaves it alone; the same target removes it.
    assert!(
        sake_glug(dir, &["render", "short.toml", "-o", "other.haptic"])
            .status
            .success()
    );
    assert_eq!(temporaries(dir), left);
    assert!(sake_glug(dir, &["render", "short.toml", "-o", "d.haptic"])
        .status
        .success());
    assert_eq!(
        files_in(dir),
        ["d.haptic", "day.toml", "other.haptic", "short.toml"]
    );
}

#[test]
fn a_folder_among_the_targets_is_refused_before_the_render_and_changes_nothing() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    fs::write(dir.join("keep.wav"), "old").unwrap();
    fs::create_dir(dir.join("isdir.haptic")).unwrap();
    let output = sake_glug(dir, &["render", "-o", "keep.wav", "-o", "isdir.haptic"]);
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("isdir.haptic") && stderr.contains("it is a folder"),
        "{stderr}"
    );
    assert_eq!(fs::read_to_string(dir.join("keep.wav")).unwrap(), "old");
    assert_eq!(files_in(dir), ["isdir.haptic", "keep.wav"]);
    // Before a single block is rendered.
    let mut blocks = 0;
    let targets =
        [dir.join("keep.wav"), dir.join("isdir.haptic")].map(|path| Output::of_path(path).unwrap());
    let scene = Scene::default();
    let options = OutputOptions::default();
    let result = render_to_files(&scene, "default", &targets, &options, |_| blocks += 1);
    assert!(result.is_err());
    assert_eq!(blocks, 0);
}

/// Calls `act` once, after the first block of the render.
struct AfterFirstBlock<F: FnMut()>(Option<F>);

impl<F: FnMut()> RenderObserver for AfterFirstBlock<F> {
    fn progress(&mut self, _rendered: u64) {
        if let Some(mut act) = self.0.take() {
            act();
        }
    }
}

#[test]
fn a_target_that_becomes_a_folder_during_the_render_changes_no_target() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let (kept, folder) = (dir.join("keep.wav"), dir.join("late.haptic"));
    fs::write(&kept, "old").unwrap();
    let scene = Scene::parse("duration_s = 0.5\ntilt_deg = 135.0\n").unwrap();
    let error = render_to_files(
        &scene,
        "late",
        &[
            Output::of_path(&kept).unwrap(),
            Output::of_path(&folder).unwrap(),
        ],
        &OutputOptions::default(),
        AfterFirstBlock(Some(|| fs::create_dir(&folder).unwrap())),
    )
    .unwrap_err();
    assert!(
        matches!(&error, OutputError::Io { path, .. } if *path == folder),
        "{error}"
    );
    assert_eq!(fs::read_to_string(&kept).unwrap(), "old");
    assert_eq!(files_in(dir), ["keep.wav", "late.haptic"]);
}

/// While another render holds the folder's lock, a render's files wait: two renders of one set
/// of targets replace them one set after the other, never mixed. (`/proc/locks` shows the
/// render waiting for the lock.)
#[cfg(target_os = "linux")]
#[test]
fn a_render_replaces_its_targets_only_while_it_holds_their_folders_lock() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let lock = fs::File::open(dir).unwrap();
    lock.lock().unwrap();
    let mut child = spawn(dir, &["render", "-o", "pour.wav", "-o", "pour.csv"]);
    let waiting = format!(" {} ", child.id());
    let started = Instant::now();
    while !fs::read_to_string("/proc/locks")
        .unwrap()
        .lines()
        .any(|line| line.contains("-> FLOCK") && line.contains(&waiting))
    {
        assert!(child.try_wait().unwrap().is_none(), "it did not wait");
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "it never got there"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(!dir.join("pour.wav").exists() && !dir.join("pour.csv").exists());
    lock.unlock().unwrap();
    assert!(child.wait().unwrap().success());
    assert_eq!(files_in(dir), ["pour.csv", "pour.wav"]);
}

#[cfg(unix)]
#[test]
fn a_replaced_target_keeps_its_mode_and_owner_and_hard_links_keep_the_old_file() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let target = dir.join("pour.wav");
    fs::write(&target, "old").unwrap();
    fs::set_permissions(&target, fs::Permissions::from_mode(0o600)).unwrap();
    // Given to another owner where this runs as root (nobody else may give a file away).
    let given_away = std::os::unix::fs::chown(&target, Some(4321), Some(4321)).is_ok();
    fs::hard_link(&target, dir.join("link.wav")).unwrap();
    assert!(sake_glug(dir, &["render", "-o", "pour.wav"])
        .status
        .success());
    let meta = fs::metadata(&target).unwrap();
    assert_eq!(meta.permissions().mode() & 0o777, 0o600);
    if given_away {
        assert_eq!((meta.uid(), meta.gid()), (4321, 4321));
    }
    assert!(meta.len() > 1000, "the new render");
    assert_eq!(fs::read_to_string(dir.join("link.wav")).unwrap(), "old");
}

#[test]
fn a_closed_stdout_ends_the_printing_not_the_batch() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let scenes: Vec<String> = (1..=3).map(|n| format!("s{n}.toml")).collect();
    for (seed, scene) in scenes.iter().enumerate() {
        let text = format!("duration_s = 0.2\ntilt_deg = 135.0\nseed = {seed}\n");
        fs::write(dir.join(scene), text).unwrap();
    }
    let mut args = vec!["render", "--out-dir", "out"];
    args.extend(scenes.iter().map(String::as_str));
    let batch = |stdout: Stdio| {
        let _ = fs::remove_dir_all(dir.join("out"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_sake-glug"))
            .current_dir(dir)
            .args(&args)
            .stdout(stdout)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // A reader that has gone, as `| head -1` leaves it.
        drop(child.stdout.take());
        let output = child.wait_with_output().unwrap();
        assert_eq!(files_in(&dir.join("out")), ["s1.wav", "s2.wav", "s3.wav"]);
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        assert!(!stderr.contains("panicked"), "{stderr}");
        (output.status.code(), stderr)
    };
    let (status, stderr) = batch(Stdio::piped());
    assert_eq!(status, Some(0), "{stderr}");
    // A full disk is an error, told once every scene is written.
    let full = fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let (status, stderr) = batch(Stdio::from(full));
    assert_eq!(status, Some(1), "{stderr}");
    assert!(
        stderr.contains("cannot print the summary") && stderr.contains("No space left"),
        "{stderr}"
    );
}

/// With stderr on a terminal (the progress bar), the summary still goes to stdout: `> log`
/// keeps it. `script` gives the command a terminal.
#[cfg(target_os = "linux")]
#[test]
fn the_summary_goes_to_stdout_when_stderr_is_a_terminal() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let command = format!(
        "'{}' render -o pour.wav > log",
        env!("CARGO_BIN_EXE_sake-glug")
    );
    let status = Command::new("script")
        .current_dir(dir)
        .args(["-qec", &command, "/dev/null"])
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success());
    let log = fs::read_to_string(dir.join("log")).unwrap();
    assert!(
        log.contains("glug units") && log.contains("pour.wav"),
        "{log:?}"
    );
}

/// A disk that fills while the plot is written (a file size limit stands in for it): the
/// message names the plot asked for, not its temporary file, and nothing is left.
#[cfg(unix)]
#[test]
fn a_plot_that_cannot_be_written_is_named_by_its_target() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let command = format!(
        "trap '' XFSZ; ulimit -f 64; exec '{}' render -o pour.png",
        env!("CARGO_BIN_EXE_sake-glug")
    );
    let output = Command::new("sh")
        .current_dir(dir)
        .args(["-c", &command])
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("cannot write pour.png") && !stderr.contains(".sake-glug-"),
        "{stderr}"
    );
    assert!(files_in(dir).is_empty());
}

/// Clips keep every glug: a day of the densest pour is refused before it starts, with the
/// memory it would need, and nothing is written.
#[cfg(target_os = "linux")]
#[test]
fn a_render_that_cannot_fit_in_memory_is_refused_before_it_starts() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let scene = "duration_s = 86400.0\nsample_rate = 768000\ntilt_deg = 135.0\n\
                 pour_time_s = 0.01\n[bottle]\npocket_ml = 0.001\n[output]\ndrain = \"follow\"\n";
    fs::write(dir.join("dense.toml"), scene).unwrap();
    for output in ["d.haptic", "d.png"] {
        let mut child = spawn(dir, &["render", "dense.toml", "-o", output]);
        let started = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if started.elapsed() > Duration::from_secs(10) {
                child.kill().unwrap();
                panic!("{output}: the render started");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let result = child.wait_with_output().unwrap();
        assert_eq!(result.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(
            stderr.contains("may need") && stderr.contains(" TB of memory"),
            "{stderr}"
        );
        assert_eq!(files_in(dir), ["dense.toml"]);
    }
}

#[test]
fn an_out_dir_that_is_a_file_is_a_command_line_error() {
    let directory = tempfile::tempdir().unwrap();
    fs::write(directory.path().join("clips"), "").unwrap();
    let output = sake_glug(directory.path(), &["render", "--out-dir", "clips"]);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--out-dir clips: it is a file, not a folder"),
        "{stderr}"
    );
}

/// Every command that writes makes the folder it writes into, as `--out-dir` does: the guide's
/// `--variations 12 -o out/pour.wav` failed when `out/` did not exist, naming its hidden
/// temporary file (issue 49). A folder that cannot be made is named, never a temporary file.
#[test]
fn a_missing_folder_is_made_and_one_that_cannot_be_is_named() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let output = sake_glug(
        dir,
        &[
            "render",
            "--variations",
            "2",
            "-o",
            "out/pour.wav",
            "-o",
            "out/clips/pour.haptic",
            "--plot",
            "plots/pour.png",
        ],
    );
    assert!(output.status.success(), "{output:?}");
    assert_eq!(
        files_in(&dir.join("out")),
        [
            "clips",
            "pour.variations.csv",
            "pour.variations.json",
            "pour_01.wav",
            "pour_02.wav"
        ]
    );
    assert_eq!(
        files_in(&dir.join("out/clips")),
        ["pour_01.haptic", "pour_02.haptic"]
    );
    assert_eq!(files_in(&dir.join("plots")), ["pour_01.png", "pour_02.png"]);

    fs::write(dir.join("taken"), "").unwrap();
    let output = sake_glug(dir, &["render", "-o", "taken/pour.wav"]);
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("cannot make its folder taken") && !stderr.contains(".sake-glug-"),
        "{stderr}"
    );
}
