//! The `sake-glug render` command as a user runs it.

use std::time::Duration;

use crate::command::{files_in, sake_glug, sake_glug_within};
use sake_glug_render::{render_scene, render_scene_to_vec, RenderError, Scene};

#[test]
fn with_no_scene_it_renders_the_default_pour_to_pour_wav() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(directory.path(), &["render"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let summary = String::from_utf8_lossy(&output.stdout);
    assert!(
        summary.contains("pour.wav") && summary.contains("glug units"),
        "{summary}"
    );
    assert!(
        output.stderr.is_empty(),
        "no progress bar when stderr is not a terminal"
    );
    let reader = hound::WavReader::open(directory.path().join("pour.wav")).unwrap();
    let spec = reader.spec();
    assert_eq!(
        (spec.channels, spec.sample_rate, spec.bits_per_sample),
        (1, 48_000, 32)
    );
    assert_eq!(spec.sample_format, hound::SampleFormat::Float);
    let seconds = reader.duration() as f64 / 48_000.0;
    assert!((5.0..5.6).contains(&seconds), "{seconds} s");
    assert_eq!(files_in(directory.path()), ["pour.wav"]);
    #[cfg(unix)]
    {
        // Readable like any new file, not private like the temporary file it was written as.
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(directory.path().join("pour.wav"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o600, 0o600);
        assert_ne!(mode & 0o044, 0, "mode {mode:o}");
    }
}

/// A report alone writes no audio (issue 40: `--fidelity` without `-o` once overwrote
/// ./pour.wav); with `-o` it writes what it is asked to.
#[test]
fn a_fidelity_report_alone_writes_no_file() {
    let directory = tempfile::tempdir().unwrap();
    std::fs::write(directory.path().join("pour.wav"), b"mine").unwrap();
    let output = sake_glug(directory.path(), &["render", "--fidelity"]);
    assert!(output.status.success());
    assert!(String::from_utf8_lossy(&output.stdout).starts_with("| format |"));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("no file written"), "{stderr}");
    assert_eq!(files_in(directory.path()), ["pour.wav"]);
    assert_eq!(
        std::fs::read(directory.path().join("pour.wav")).unwrap(),
        b"mine"
    );
    let asked = sake_glug(
        directory.path(),
        &["render", "--fidelity", "-o", "asked.wav"],
    );
    assert!(asked.status.success());
    assert_eq!(files_in(directory.path()), ["asked.wav", "pour.wav"]);
}

#[test]
fn integer_formats_and_sample_rate_override_are_written_as_asked() {
    let directory = tempfile::tempdir().unwrap();
    for (format, bits) in [("s16", 16), ("s24", 24)] {
        let name = format!("{format}.wav");
        let args = [
            "render",
            "-o",
            &name,
            "--sample-format",
            format,
            "--sample-rate",
            "96000",
        ];
        assert!(sake_glug(directory.path(), &args).status.success());
        let mut reader = hound::WavReader::open(directory.path().join(&name)).unwrap();
        let spec = reader.spec();
        assert_eq!((spec.bits_per_sample, spec.sample_rate), (bits, 96_000));
        let peak = reader
            .samples::<i32>()
            .map(|s| s.unwrap().abs())
            .max()
            .unwrap();
        let full_scale = 1 << (bits - 1);
        // The default pour peaks around −8 dBFS.
        assert!(
            peak > full_scale / 4 && peak < full_scale / 2,
            "{format}: peak {peak}"
        );
    }
}

#[test]
fn the_old_format_flag_is_refused_by_the_name_of_the_new_one() {
    let directory = tempfile::tempdir().unwrap();
    for args in [
        &["render", "-o", "pour.wav", "--format", "s24"][..],
        &["render", "--format=s16"],
        &["render", "--format"],
    ] {
        let output = sake_glug(directory.path(), args);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains("--sample-format"), "{args:?}: {stderr}");
        assert!(files_in(directory.path()).is_empty(), "{args:?}");
    }
}

/// Renders `scene` from a file and checks that it is refused with `expected` in the message and
/// that nothing but the scene is left in the directory.
fn assert_refused(scene: &str, expected: &str) {
    let directory = tempfile::tempdir().unwrap();
    std::fs::write(directory.path().join("scene.toml"), scene).unwrap();
    let output = sake_glug(directory.path(), &["render", "scene.toml", "-o", "out.wav"]);
    assert_eq!(output.status.code(), Some(1), "{scene}");
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(message.contains(expected), "{scene}: {message}");
    assert_eq!(files_in(directory.path()), ["scene.toml"]);
}

#[test]
fn a_bad_scene_is_refused_by_name_and_leaves_no_file() {
    assert_refused(
        "viscosity_c = 2.0\n",
        "`viscosity_c` = 2 is out of range: allowed 0 to 1",
    );
}

#[test]
fn a_scene_that_never_falls_silent_is_refused_and_leaves_no_file() {
    // Follow mode at a steady fill glugs for ever, and a decay of 0 rings for ever: without a
    // duration the render cannot end.
    assert_refused(
        "tilt_deg = 135.0\n[output]\ndrain = \"follow\"\n",
        "give it a duration_s",
    );
    assert_refused(
        "tilt_deg = 135.0\n[glug]\nb1_per_s = 0.0\n",
        "give it a duration_s",
    );
}

#[test]
fn a_decay_too_slow_to_end_is_refused_before_anything_is_rendered() {
    // 1e-6 /s takes 160 days to reach −120 dB: without a duration the render could only stop at
    // the 24 h limit, after about 16 GB.
    let scene = Scene::parse("tilt_deg = 135.0\n[glug]\nb2_per_s = 1e-6\n").unwrap();
    let mut blocks = 0;
    let result = render_scene(
        &scene,
        |_: &[f32]| {
            blocks += 1;
            Err(RenderError::NeverSettles)
        },
        &mut |_| {},
    );
    let message = result.unwrap_err().to_string();
    assert_eq!(blocks, 0, "the render started: {message}");
    assert!(
        message.contains("`glug.b2_per_s` = 0.000001 /s")
            && message.contains("give it a duration_s"),
        "{message}"
    );
    // The same scene with a duration renders; and with c = 0 (no f1 component) a B1 of 0
    // cannot ring, so it is not refused.
    let timed = Scene::parse("duration_s = 0.5\ntilt_deg = 135.0\n[glug]\nb2_per_s = 1e-6\n");
    assert!(render_scene_to_vec(&timed.unwrap()).is_ok());
    let no_f1 = Scene::parse("tilt_deg = 135.0\nviscosity_c = 0.0\n[glug]\nb1_per_s = 0.0\n");
    assert!(render_scene_to_vec(&no_f1.unwrap()).is_ok());
    assert_refused(
        "tilt_deg = 135.0\n[glug]\nb2_per_s = 1e-6\n",
        "a glug needs 13815511 s to decay to −120 dB",
    );
}

/// A sample rate on the command line is checked before anything is rendered, as a command-line
/// error (exit status 2), with the message a scene's `sample_rate` gets.
#[test]
fn a_bad_sample_rate_is_refused_on_the_command_line_as_in_a_scene() {
    let directory = tempfile::tempdir().unwrap();
    for (rate, expected) in [
        ("44100.9", "`sample_rate` = 44100.9 is not a whole number: a sample rate counts whole samples per second"),
        ("0", "`sample_rate` = 0 is out of range: allowed 1000 to 768000"),
        ("10", "`sample_rate` = 10 is out of range"),
        ("nan", "`sample_rate` = NaN is out of range"),
        ("fast", "`fast` is not a number of Hz"),
    ] {
        let output = sake_glug(
            directory.path(),
            &["render", "--sample-rate", rate, "-o", "out.wav"],
        );
        assert_eq!(output.status.code(), Some(2), "{rate}");
        let message = String::from_utf8_lossy(&output.stderr);
        assert!(
            message.starts_with("error: ") && message.contains(expected),
            "{rate}: {message}"
        );
        assert!(files_in(directory.path()).is_empty());
    }
    let in_scene = Scene::parse("sample_rate = 44100.9")
        .unwrap_err()
        .to_string();
    assert_eq!(
        in_scene,
        "`sample_rate` = 44100.9 is not a whole number: a sample rate counts whole samples per second"
    );
}

#[test]
fn bad_arguments_are_errors_not_panics() {
    let directory = tempfile::tempdir().unwrap();
    let cases: [&[&str]; 2] = [
        &["render", "missing.toml"],
        &["render", "-o", "/proc/no/such/dir/out.wav"],
    ];
    for args in cases {
        let output = sake_glug(directory.path(), args);
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        let message = String::from_utf8_lossy(&output.stderr);
        assert!(
            message.starts_with("error: ") && !message.contains("panicked"),
            "{message}"
        );
    }
    assert!(files_in(directory.path()).is_empty());
}

/// `sake-glug --help` and `experiment --help` name every design of the study's own list, each
/// discrimination design with its task, and the command that plans one (issue 49): a design
/// added to the list and left out of the help turns this red.
#[test]
fn the_help_names_every_design_and_the_plan() {
    use sake_glug_study::{Design, DISCRIMINATE_DESIGNS};
    let directory = tempfile::tempdir().unwrap();
    // Its words, whatever width clap wraps them at (its `wrap_help`, which a workspace build
    // unifies in, wraps at 100 columns; a build of the CLI alone does not wrap).
    let help = |args: &[&str]| {
        let output = sake_glug(directory.path(), args);
        assert!(output.status.success(), "{args:?}");
        let text = String::from_utf8(output.stdout).unwrap();
        text.split_whitespace().collect::<Vec<_>>().join(" ")
    };
    let root = help(&["--help"]);
    let experiment = help(&["experiment", "--help"]);
    for text in [&root, &experiment] {
        for design in Design::ALL {
            assert!(text.contains(design.name()), "{}: {text}", design.name());
        }
        assert!(text.contains("analyze plan discrimination"), "{text}");
    }
    for design in DISCRIMINATE_DESIGNS {
        let named = format!("`{}`: {}", design.name(), design.task());
        assert!(experiment.contains(&named), "{named}: {experiment}");
    }
}

#[test]
fn the_accuracy_lengths_are_taken_as_the_help_shows_them() {
    let directory = tempfile::tempdir().unwrap();
    let help = sake_glug(directory.path(), &["accuracy", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("[default: 1 60 3600]"), "{help}");
    // Space-separated as in the help, and comma-separated, short renders at a low rate so the
    // test is quick: every length asked for has its rows.
    for lengths in [&["0.01", "0.02"][..], &["0.01,0.02"]] {
        let mut args = vec!["accuracy", "--sample-rate", "1000", "--lengths"];
        args.extend(lengths);
        let output = sake_glug(directory.path(), &args);
        let table = String::from_utf8_lossy(&output.stdout);
        for label in ["| 0.01 s |", "| 0.02 s |"] {
            assert!(
                table.contains(label),
                "{args:?}: no {label} row in\n{table}"
            );
        }
    }
}

#[test]
fn accuracy_refuses_lengths_and_rates_it_cannot_render() {
    let directory = tempfile::tempdir().unwrap();
    for args in [
        &["--lengths", "inf"][..],
        &["--lengths", "nan"],
        &["--lengths", "0"],
        &["--lengths", "1e9"],
        &["--sample-rate", "1e12"],
        &["--sample-rate", "0"],
        &["--sample-rate", "nan"],
        &["--sample-rate", "44100.5"],
    ] {
        let mut command = vec!["accuracy"];
        command.extend(args);
        // Before these were refused, `--lengths inf` rendered for ever.
        let output = sake_glug_within(directory.path(), &command, Duration::from_secs(20));
        let message = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {message}");
        assert!(output.stdout.is_empty(), "{args:?}: nothing rendered");
        assert!(
            message.contains(args[0]),
            "{args:?} names the option: {message}"
        );
    }
}

#[test]
fn an_output_can_name_its_format_before_its_file() {
    let directory = tempfile::tempdir().unwrap();
    // The name picks the format whatever the extension says; a prefix that names no format is
    // part of the file's name.
    let output = sake_glug(
        directory.path(),
        &["render", "-o", "wav:pour.bin", "-o", "take:2.wav"],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(files_in(directory.path()), ["pour.bin", "take:2.wav"]);
    let a = std::fs::read(directory.path().join("pour.bin")).unwrap();
    let b = std::fs::read(directory.path().join("take:2.wav")).unwrap();
    assert_eq!(a, b);
    let missing = sake_glug(directory.path(), &["render", "-o", "wav:"]);
    assert_eq!(missing.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&missing.stderr);
    assert!(
        stderr.contains("a file is missing after the format"),
        "{stderr}"
    );
}

/// A preset name is outside text: echoed in an error, its control characters are escaped and
/// a long one is cut (a terminal obeys a raw ESC).
#[test]
fn an_unknown_preset_is_quoted_escaped_and_cut() {
    let directory = tempfile::tempdir().unwrap();
    let name = format!("x\u{1b}[31m{}", "y".repeat(200));
    for args in [vec!["render", "--preset", &name], vec!["presets", &name]] {
        let output = sake_glug(directory.path(), &args);
        assert!(!output.status.success(), "{args:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!stderr.contains('\u{1b}'), "{args:?}: {stderr:?}");
        assert!(stderr.contains("x\\u{1b}[31m"), "{args:?}: {stderr:?}");
        assert!(!stderr.contains(&"y".repeat(40)), "{args:?}: {stderr:?}");
    }
}
