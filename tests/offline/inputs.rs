//! The files a scene names for its CSV lanes and its MIDI take: regular files only, read with a
//! size limit, listed with whether they lie outside the scene's folder; and no message that
//! quotes a file it should not, or echoes a control character from a scene.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::mpsc;
use std::time::Duration;

use sake_glug_device::csv_lane::MAX_CSV_LANE_BYTES;
use sake_glug_device::midi_take::MAX_TAKE_BYTES;
use sake_glug_io::ReadFailure;
use sake_glug_render::{InputFile, Scene, SceneError, MAX_SCENE_BYTES};

use crate::command::sake_glug_within;

/// A CSV take with a `tilt` and a `visc` column.
const TAKE_CSV: &str = "time_s,tilt,visc\n0,90,1.0\n0.5,135,1.0\n";

/// A format 0 MIDI take: one CC 16 at time 0.
fn take_mid() -> Vec<u8> {
    let track: &[u8] = &[0x00, 0xB0, 16, 96, 0x00, 0xFF, 0x2F, 0x00];
    let mut file = b"MThd\0\0\0\x06\0\0\0\x01\x01\xE0MTrk".to_vec();
    file.extend((track.len() as u32).to_be_bytes());
    file.extend(track);
    file
}

/// `run` on a thread of its own, failing the test if it has not returned in 10 s: reading a FIFO
/// would wait for a writer for ever.
fn without_hanging<T: Send + 'static>(run: impl FnOnce() -> T + Send + 'static) -> T {
    let (sender, receiver) = mpsc::channel();
    std::thread::spawn(move || sender.send(run()));
    receiver
        .recv_timeout(Duration::from_secs(10))
        .expect("reading the scene hangs")
}

/// The scene `text` in `folder` (written there as scene.toml), loaded on its own thread.
fn load(folder: &Path, text: &str) -> Result<Scene, SceneError> {
    let path = folder.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    without_hanging(move || Scene::load(&path))
}

/// A FIFO at `path`, made by mkfifo(1).
fn make_fifo(path: &Path) {
    let status = Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
}

/// No control character in `message` but the line breaks of toml's own layout.
fn assert_printable(message: &str) {
    let raw: Vec<char> = message
        .chars()
        .filter(|&character| character.is_control() && character != '\n')
        .collect();
    assert!(raw.is_empty(), "{raw:?} echoed raw in {message:?}");
}

#[test]
fn files_inside_and_outside_the_folder_are_read_and_listed() {
    let root = tempfile::tempdir().unwrap();
    let scenes = root.path().join("scenes");
    let elsewhere = root.path().join("elsewhere");
    std::fs::create_dir_all(&scenes).unwrap();
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::fs::write(scenes.join("inside.csv"), TAKE_CSV).unwrap();
    std::fs::write(elsewhere.join("take.csv"), TAKE_CSV).unwrap();
    std::fs::write(elsewhere.join("take.mid"), take_mid()).unwrap();
    std::os::unix::fs::symlink(elsewhere.join("take.csv"), scenes.join("link.csv")).unwrap();
    let absolute = elsewhere.join("take.csv");
    let scene = load(
        &scenes,
        &format!(
            "tilt_deg = {{ csv = '{}', column = 'tilt' }}\n\
             viscosity_c = {{ csv = 'inside.csv', column = 'visc' }}\n\
             fill_percent = {{ csv = 'link.csv', column = 'visc' }}\n\
             midi_take = '../elsewhere/take.mid'\n",
            absolute.display()
        ),
    )
    .unwrap();
    let input = |key, path: PathBuf, outside_folder| InputFile {
        key,
        path,
        outside_folder,
    };
    assert_eq!(
        scene.inputs,
        [
            input("tilt_deg", absolute, true),
            input("viscosity_c", scenes.join("inside.csv"), false),
            input("fill_percent", scenes.join("link.csv"), true),
            input("midi_take", scenes.join("../elsewhere/take.mid"), true),
        ]
    );
    assert_eq!(scene.lanes.tilt_deg.last_time_s(), 0.5);
    assert!(scene.take.is_some());

    // A take given on the command line replaces the scene's own in the list.
    let given = elsewhere.join("take.mid");
    let scene = scene.with_midi_take(&given).unwrap();
    assert_eq!(scene.inputs.len(), 4);
    assert_eq!(scene.inputs[3], input("midi_take", given, false));
}

#[test]
fn a_fifo_is_refused_without_waiting_for_a_writer() {
    let folder = tempfile::tempdir().unwrap();
    let fifo = folder.path().join("pipe");
    make_fifo(&fifo);

    let error = load(
        folder.path(),
        "tilt_deg = { csv = 'pipe', column = 'tilt' }\n",
    )
    .unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::CsvFile {
                key: "tilt_deg",
                source: ReadFailure::NotAFile(_),
                ..
            }
        ),
        "{error:?}"
    );
    let message = error.to_string();
    let expected = format!(
        "cannot read CSV lane `tilt_deg` file {}: it is a FIFO (named pipe), not a regular file",
        fifo.display()
    );
    assert_eq!(message, expected);

    let error = load(folder.path(), "midi_take = 'pipe'\n").unwrap_err();
    assert!(matches!(error, SceneError::TakeFile { .. }), "{error:?}");
    let expected = format!(
        "cannot read MIDI take {}: it is a FIFO (named pipe), not a regular file",
        fifo.display()
    );
    assert_eq!(error.to_string(), expected);

    // The command line's take as well.
    let error = without_hanging(move || Scene::default().with_midi_take(&fifo)).unwrap_err();
    assert!(error.to_string().contains("FIFO"), "{error}");
}

#[test]
fn a_fifo_swapped_in_after_the_check_does_not_hang_the_read() {
    // A link that another thread keeps pointing at a take, then at a FIFO: a read that checks
    // the path and then opens it can find the take, then open the FIFO and wait for a writer.
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(folder.path().join("take.mid"), take_mid()).unwrap();
    make_fifo(&folder.path().join("pipe"));
    let link = folder.path().join("input.mid");
    std::os::unix::fs::symlink("take.mid", &link).unwrap();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let swapper = {
        let (folder, link, stop) = (folder.path().to_owned(), link.clone(), stop.clone());
        std::thread::spawn(move || {
            let staged = folder.join("staged");
            for target in ["pipe", "take.mid"].iter().cycle() {
                if stop.load(std::sync::atomic::Ordering::Relaxed) {
                    break;
                }
                std::os::unix::fs::symlink(target, &staged).unwrap();
                std::fs::rename(&staged, &link).unwrap();
            }
        })
    };
    let (takes, fifos) = without_hanging(move || {
        let (mut takes, mut fifos) = (0, 0);
        while takes < 200 || fifos < 200 {
            match Scene::default().with_midi_take(&link) {
                Ok(_) => takes += 1,
                Err(SceneError::TakeFile {
                    source: ReadFailure::NotAFile(_),
                    ..
                }) => fifos += 1,
                Err(error) => panic!("{error}"),
            }
        }
        (takes, fifos)
    });
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    swapper.join().unwrap();
    assert!(takes >= 200 && fifos >= 200);
}

#[test]
fn devices_and_folders_are_refused_as_not_regular_files() {
    let folder = tempfile::tempdir().unwrap();
    let error = load(folder.path(), "midi_take = '/dev/zero'\n").unwrap_err();
    assert_eq!(
        error.to_string(),
        "cannot read MIDI take /dev/zero: it is a device, not a regular file"
    );
    let error = load(
        folder.path(),
        "viscosity_c = { csv = '/dev/zero', column = 'visc' }\n",
    )
    .unwrap_err();
    assert!(error.to_string().contains("it is a device"), "{error}");
    let error = load(folder.path(), "tilt_deg = { csv = '.', column = 'tilt' }\n").unwrap_err();
    assert!(
        error
            .to_string()
            .ends_with("it is a folder, not a regular file"),
        "{error}"
    );
}

#[test]
fn a_file_over_the_limit_is_refused_from_its_size() {
    let folder = tempfile::tempdir().unwrap();
    // Sparse: the size is set without writing a byte.
    let sparse = |name: &str, size: u64| {
        let file = std::fs::File::create(folder.path().join(name)).unwrap();
        file.set_len(size).unwrap();
    };
    sparse("big.csv", MAX_CSV_LANE_BYTES + 1);
    sparse("big.mid", MAX_TAKE_BYTES + 1);

    let error = load(
        folder.path(),
        "tilt_deg = { csv = 'big.csv', column = 'tilt' }\n",
    )
    .unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::CsvFile {
                source: ReadFailure::TooLarge { .. },
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        error.to_string().ends_with(
            "big.csv: it is 268435457 bytes, over the limit of 268435456 bytes (256 MiB)"
        ),
        "{error}"
    );

    let error = load(folder.path(), "midi_take = 'big.mid'\n").unwrap_err();
    assert!(
        error
            .to_string()
            .ends_with("big.mid: it is 16777217 bytes, over the limit of 16777216 bytes (16 MiB)"),
        "{error}"
    );
}

#[test]
fn a_missing_csv_lane_or_take_is_named_as_such() {
    let folder = tempfile::tempdir().unwrap();
    let error = load(
        folder.path(),
        "tilt_deg = { csv = 'nope.csv', column = 'tilt' }\n",
    )
    .unwrap_err();
    let message = error.to_string();
    let expected = format!(
        "cannot read CSV lane `tilt_deg` file {}: ",
        folder.path().join("nope.csv").display()
    );
    assert!(message.starts_with(&expected), "{message}");
    assert!(
        matches!(
            error,
            SceneError::CsvFile {
                source: ReadFailure::Io(_),
                ..
            }
        ),
        "{error:?}"
    );

    let error = load(folder.path(), "midi_take = 'nope.mid'\n").unwrap_err();
    let expected = format!(
        "cannot read MIDI take {}: ",
        folder.path().join("nope.mid").display()
    );
    assert!(error.to_string().starts_with(&expected), "{error}");
}

#[test]
fn a_csv_lane_that_is_not_text_is_refused_at_its_line() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(
        folder.path().join("t.csv"),
        b"time_s,tilt\n0,90\n0.5,\xff\n",
    )
    .unwrap();
    let error = load(
        folder.path(),
        "tilt_deg = { csv = 't.csv', column = 'tilt' }\n",
    )
    .unwrap_err();
    assert!(
        error
            .to_string()
            .ends_with("t.csv: line 3 is not UTF-8 text"),
        "{error}"
    );
}

#[test]
fn errors_quote_nothing_of_a_file_that_is_no_take() {
    const SECRET: &str = "SECRET-9f2c";
    let folder = tempfile::tempdir().unwrap();
    // A file like /etc/passwd named as a lane, and as a take.
    let passwd =
        format!("root{SECRET}:x:0:0:root:/root:/bin/bash\nuser:x:1000:1000::/home:/bin/sh\n");
    std::fs::write(folder.path().join("passwd"), &passwd).unwrap();
    for text in [
        "tilt_deg = { csv = 'passwd', column = 'tilt' }\n",
        "tilt_deg = { csv = 'passwd', accel = ['ax', 'ay', 'az'] }\n",
        "midi_take = 'passwd'\n",
    ] {
        let message = load(folder.path(), text).unwrap_err().to_string();
        assert!(!message.contains(SECRET), "{message}");
        assert!(!message.contains("/bin/bash"), "{message}");
    }

    // A field at fault is quoted, but only its start.
    let long_field = format!("{SECRET}{}", "x".repeat(1000));
    std::fs::write(
        folder.path().join("t.csv"),
        format!("time_s,tilt\n0,90\n0.5,{long_field}\n"),
    )
    .unwrap();
    let message = load(
        folder.path(),
        "tilt_deg = { csv = 't.csv', column = 'tilt' }\n",
    )
    .unwrap_err()
    .to_string();
    assert!(
        message.ends_with(&format!(
            "line 3, column \"tilt\": \"{SECRET}xxxxxxxxxxxxxxxxxxxxx…\" is not a number"
        )),
        "{message}"
    );
}

#[test]
fn control_characters_from_a_scene_are_escaped_in_its_errors() {
    let folder = tempfile::tempdir().unwrap();
    let esc = '\u{1b}';
    let cases = [
        // Raw in the file: the message gives the place, never the line (it may be a file's worth).
        (
            format!("seed = \"{esc}]0;retitled\u{7}\"\n"),
            "line 1, column 9: invalid basic string",
        ),
        (format!("{esc}[31m = 1\n"), "line 1, column "),
        // Escaped in TOML, so read into a key or a value.
        (
            "\"\\u001b[2J\" = 1\n".to_owned(),
            "unknown field `\\u{1b}[2J`",
        ),
        (
            "[output]\n\"\\u001b[2J\\n\" = 1\n".to_owned(),
            "unknown field `\\u{1b}[2J\\n` in [output]",
        ),
        (
            "tilt_deg = { csv = 't.csv', \"\\u001b[2J\" = 1 }\n".to_owned(),
            "`\\u{1b}[2J`",
        ),
        ("seed = \"\\u001b[2J\"\n".to_owned(), "\\u{1b}[2J"),
        (
            "tilt_deg = { csv = \"\\u001b[2J.csv\", column = 'tilt' }\n".to_owned(),
            "\\u{1b}[2J.csv: ",
        ),
        (
            "midi_take = \"\\u001b[2J.mid\"\n".to_owned(),
            "\\u{1b}[2J.mid: ",
        ),
    ];
    for (text, shown) in cases {
        let message = load(folder.path(), &text).unwrap_err().to_string();
        assert_printable(&message);
        assert!(message.contains(shown), "{message:?} lacks {shown:?}");
    }
    // One line, the place and what: a line at fault a megabyte long is not echoed.
    let message = Scene::parse(&format!("seed = \"{esc}{}\"\n", "x".repeat(1 << 20)))
        .unwrap_err()
        .to_string();
    assert!(
        message.lines().count() == 1 && message.len() < 200,
        "{message}"
    );
}

#[test]
fn the_summary_names_a_file_read_from_outside_the_scene_folder() {
    let root = tempfile::tempdir().unwrap();
    let scenes = root.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    std::fs::write(root.path().join("lane.csv"), "time_s,v\n0,90\n1,135\n").unwrap();
    std::fs::write(scenes.join("inside.csv"), "time_s,v\n0,0.3\n").unwrap();
    std::fs::write(
        scenes.join("scene.toml"),
        "duration_s = 0.5\ntilt_deg = { csv = \"../lane.csv\", column = \"v\" }\n\
         viscosity_c = { csv = \"inside.csv\", column = \"v\" }\n",
    )
    .unwrap();
    let output = crate::command::sake_glug(&scenes, &["render", "scene.toml", "-o", "x.wav"]);
    assert!(output.status.success());
    let stdout = String::from_utf8(output.stdout).unwrap();
    assert!(
        stdout.contains("read from outside the scene's folder: ") && stdout.contains("lane.csv"),
        "{stdout}"
    );
    assert!(!stdout.contains("inside.csv"), "{stdout}");
}

/// `Scene::load` of `path`, on its own thread.
fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    let path = path.to_owned();
    without_hanging(move || Scene::load(&path))
}

#[test]
fn a_scene_that_is_a_fifo_or_a_device_is_refused_not_waited_for() {
    let folder = tempfile::tempdir().unwrap();
    let fifo = folder.path().join("scene.toml");
    make_fifo(&fifo);
    let error = load_scene_file(&fifo).unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::Read {
                source: ReadFailure::NotAFile(_),
                ..
            }
        ),
        "{error:?}"
    );
    assert_eq!(
        error.to_string(),
        format!(
            "cannot read scene file {}: it is a FIFO (named pipe), not a regular file",
            fifo.display()
        )
    );
    // /dev/zero is read for ever; a folder means nothing.
    let error = load_scene_file(Path::new("/dev/zero")).unwrap_err();
    assert_eq!(
        error.to_string(),
        "cannot read scene file /dev/zero: it is a device, not a regular file"
    );
    let error = load_scene_file(folder.path()).unwrap_err();
    assert!(
        error
            .to_string()
            .ends_with("it is a folder, not a regular file"),
        "{error}"
    );

    // And the command line says so and ends (exit 1, a bad scene), writing nothing.
    for scene in [fifo.to_str().unwrap(), "/dev/zero"] {
        let output = sake_glug_within(
            folder.path(),
            &["render", scene, "-o", "out.wav"],
            Duration::from_secs(60),
        );
        assert_eq!(output.status.code(), Some(1), "{output:?}");
        let message = String::from_utf8_lossy(&output.stderr);
        assert!(message.contains("not a regular file"), "{message}");
        assert_eq!(crate::command::files_in(folder.path()), ["scene.toml"]);
    }
}

#[test]
fn a_scene_over_the_limit_is_refused_from_its_size() {
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("big.toml");
    // Sparse: the size is set without writing a byte.
    let file = std::fs::File::create(&path).unwrap();
    file.set_len(MAX_SCENE_BYTES + 1).unwrap();
    let error = load_scene_file(&path).unwrap_err();
    assert!(
        matches!(
            error,
            SceneError::Read {
                source: ReadFailure::TooLarge { .. },
                ..
            }
        ),
        "{error:?}"
    );
    assert!(
        error
            .to_string()
            .ends_with("big.toml: it is 16777217 bytes, over the limit of 16777216 bytes (16 MiB)"),
        "{error}"
    );
    // At the limit it is read (and refused for what it holds: 16 MiB of NUL bytes).
    file.set_len(MAX_SCENE_BYTES).unwrap();
    let error = load_scene_file(&path).unwrap_err();
    assert!(matches!(error, SceneError::Syntax(_)), "{error:?}");
}

#[test]
fn a_scene_that_is_not_text_is_refused_at_its_line() {
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("scene.toml");
    std::fs::write(&path, b"viscosity_c = 0.5\n# \xff\n").unwrap();
    let error = load_scene_file(&path).unwrap_err();
    assert_eq!(
        error.to_string(),
        format!(
            "cannot read scene file {}: line 2 is not UTF-8 text",
            path.display()
        )
    );
}
