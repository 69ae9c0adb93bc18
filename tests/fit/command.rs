//! `sake-glug fit` run as a user runs it: the exit status and the message for bad input and bad
//! arguments, the files a fit leaves (all of them, or none), and the fitted model played by
//! `sake-glug render`.

use std::process::{Command, Output};

use super::*;

/// Runs `sake-glug ARGS` in `folder`.
fn sake_glug(folder: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(folder)
        .args(args)
        .output()
        .unwrap()
}

/// The names of the files in `folder`, sorted.
fn files_in(folder: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Asserts that `output` ended with `code` and that its stderr names every one of `parts`.
fn assert_refused(output: &Output, code: i32, parts: &[&str]) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(code), "stderr: {stderr}");
    for part in parts {
        assert!(stderr.contains(part), "`{part}` missing from: {stderr}");
    }
}

const FIT_ALL: [&str; 8] = [
    "fit",
    "-o",
    "model.toml",
    "--report",
    "fit.md",
    "--plot",
    "fit.png",
    "session.toml",
];

/// A session of one recording `a.wav`, written with `samples` at `rate`.
fn session_of(folder: &Path, samples: &[f32], rate: u32) {
    write_wav(&folder.join("a.wav"), samples, rate);
    std::fs::write(
        folder.join("session.toml"),
        "[[recording]]\naudio = \"a.wav\"\ntilt_deg = 135\nstart_ml = 300\n",
    )
    .unwrap();
}

#[test]
fn bad_input_exits_1_naming_the_file_and_the_key_and_writes_nothing() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    let output = sake_glug(dir, &["fit", "absent.toml", "-o", "model.toml"]);
    assert_refused(&output, 1, &["error:", "absent.toml"]);
    std::fs::write(
        dir.join("session.toml"),
        "[[recording]]\naudio = \"gone.wav\"\ntilt_deg = 135\nstart_ml = 300\n",
    )
    .unwrap();
    let before = files_in(dir);
    let output = sake_glug(dir, &FIT_ALL);
    assert_refused(&output, 1, &["recording[0].audio", "gone.wav"]);
    assert_eq!(files_in(dir), before, "a refused fit wrote something");
    session_of(dir, &vec![0.1; 8000], 4000);
    let before = files_in(dir);
    let output = sake_glug(dir, &FIT_ALL);
    assert_refused(&output, 1, &["recording[0].audio", "a.wav", "4000 Hz"]);
    assert_eq!(files_in(dir), before, "a refused fit wrote something");
    session_of(dir, &vec![0.0; 25_000], 25_000);
    let output = sake_glug(dir, &FIT_ALL);
    assert_refused(&output, 1, &["recording[0].audio", "a.wav", "silent"]);
    assert_eq!(files_in(dir), before, "a refused fit wrote something");
}

#[test]
fn bad_arguments_exit_2() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    session_of(dir, &vec![0.0; 25_000], 25_000);
    let before = files_in(dir);
    assert_refused(&sake_glug(dir, &["fit"]), 2, &["SESSION"]);
    assert_refused(
        &sake_glug(dir, &["fit", "session.toml"]),
        2,
        &["nothing to write"],
    );
    assert_refused(
        &sake_glug(
            dir,
            &["fit", "session.toml", "-o", "m.toml", "--frobnicate"],
        ),
        2,
        &["--frobnicate"],
    );
    assert_refused(
        &sake_glug(
            dir,
            &["fit", "session.toml", "-o", "m.toml", "--out-dir", "d"],
        ),
        2,
        &["--out-dir"],
    );
    assert_eq!(files_in(dir), before, "a refused command wrote something");
}

/// A poured bottle (3 s from full at 135°, 25 kHz, noise 40 dB below the glugs) as a session.
fn good_session(folder: &Path) {
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 3.0\n");
    let take = Take {
        name: "a",
        rendered: &rendered,
        tilt_deg: 135.0,
        liquid: None,
        weight: false,
        noise_db: Some(-40.0),
    };
    write_session(folder, 300.0, &[take]);
}

#[test]
fn a_good_session_writes_the_model_the_report_and_the_plot_and_the_model_renders() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    good_session(dir);
    let output = sake_glug(dir, &FIT_ALL);
    assert_refused(
        &output,
        0,
        &[
            "audible glug units fitted",
            "model.toml",
            "fit.md",
            "fit.png",
        ],
    );
    // Its count names what the render's summary names: a recording carries audible units only,
    // so they are called so, and the ones used are a part of them (issue 40).
    let stderr = String::from_utf8_lossy(&output.stderr);
    let counts = stderr
        .lines()
        .find_map(|line| line.strip_prefix("a.wav: "))
        .and_then(|rest| rest.split_once(" audible glug units, "))
        .and_then(|(heard, rest)| Some((heard, rest.split_once(" used, explaining ")?.0)))
        .unwrap_or_else(|| panic!("no \"a.wav: N audible glug units, M used\" in: {stderr}"));
    let (heard, used): (usize, usize) = (counts.0.parse().unwrap(), counts.1.parse().unwrap());
    assert!(used <= heard && used > 10, "{stderr}");
    assert_eq!(
        files_in(dir),
        ["a.wav", "fit.md", "fit.png", "model.toml", "session.toml"]
    );
    let report = std::fs::read_to_string(dir.join("fit.md")).unwrap();
    assert!(report.contains("glug.f1_hz"), "{report}");
    // A negative intercept reads as a subtraction, not "+ -0.19" (issue 40).
    assert!(
        report.contains("Amplitude law (fig. 7): Asum = ") && !report.contains("+ -"),
        "{report}"
    );
    let png = std::fs::read(dir.join("fit.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"), "fit.png is no PNG");
    // The model plays, and its glugs are the fitted ones: fitted again, f1 and f2 agree.
    let model = dir.join("model.toml");
    let output = sake_glug(dir, &["render", "model.toml", "-o", "played.wav"]);
    assert_refused(&output, 0, &[]);
    let fitted = fit(&dir.join("session.toml"));
    std::fs::write(
        dir.join("played.toml"),
        "[[recording]]\naudio = \"played.wav\"\ntilt_deg = 135\nstart_ml = 300\n",
    )
    .unwrap();
    let played = fit(&dir.join("played.toml"));
    for key in ["glug.f1_hz", "glug.f2_hz"] {
        let (truth, again) = (estimate(&fitted, 0, key), estimate(&played, 0, key));
        assert!(
            (again / truth - 1.0).abs() < 0.02,
            "{key}: the model's render gives {again}, the model {truth} ({})",
            model.display()
        );
    }
    // It is a model file too: the plugin and `--model` take it, under another scene's tilt.
    std::fs::write(
        dir.join("upright.toml"),
        "duration_s = 1.0\ntilt_deg = 0.0\n",
    )
    .unwrap();
    let output = sake_glug(
        dir,
        &[
            "render",
            "--model",
            "model.toml",
            "upright.toml",
            "-o",
            "upright.wav",
        ],
    );
    assert_refused(&output, 0, &[]);
    sake_glug_model_file::ModelFile::load(&model).expect("the fitted model is a model file");
}

#[test]
fn a_fit_whose_last_file_cannot_be_written_leaves_no_file_and_keeps_the_old_ones() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    good_session(dir);
    std::fs::write(dir.join("model.toml"), "# the old model\n").unwrap();
    // The plot's path is a folder: renaming the finished plot over it fails last.
    std::fs::create_dir(dir.join("fit.png")).unwrap();
    let before = files_in(dir);
    let output = sake_glug(dir, &FIT_ALL);
    assert_refused(&output, 1, &["fit"]);
    assert_eq!(files_in(dir), before, "a failed fit left a file");
    assert_eq!(
        std::fs::read_to_string(dir.join("model.toml")).unwrap(),
        "# the old model\n"
    );
}

/// A clip is enough: `fit CLIP.wav` without a session writes the model, the units table, the
/// JSON on stdout and the comparison picture; the model plays at the clip's glug rate.
#[test]
fn a_clip_alone_is_fitted_with_every_output() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 3.0\n");
    let mut samples = rendered.samples.clone();
    let sigma = glug_rms(&samples) * 0.01;
    add_noise(&mut samples, sigma, 9);
    write_wav(&dir.join("clip.wav"), &samples, 25_000);
    let output = sake_glug(
        dir,
        &[
            "fit",
            "clip.wav",
            "-o",
            "model.toml",
            "--units",
            "units.csv",
            "--compare",
            "compare.png",
            "--plot",
            "fit.png",
            "--report",
            "fit.md",
            "--json",
        ],
    );
    assert_refused(
        &output,
        0,
        &["clip.wav", "audible glug units, ", "explaining"],
    );
    let units = std::fs::read_to_string(dir.join("units.csv")).unwrap();
    let mut lines = units.lines();
    assert_eq!(
        lines.next(),
        Some("recording,onset_s,f1_hz,f2_hz,b1_per_s,b2_per_s,a1,a2,used,reason,volume_ml,f1_model_hz,f2_model_hz,f1_glide_ratio,f1_glide_ms,f2_glide_ratio,f2_glide_ms")
    );
    let rows: Vec<&str> = lines.collect();
    assert!(rows.len() >= 20, "{units}");
    assert!(
        rows.iter().all(|row| row.starts_with("clip.wav,")),
        "{units}"
    );
    // `used` and `reason` are the 9th and 10th columns; a used unit's volume and its model's
    // frequencies follow.
    assert!(
        rows.iter().any(|row| {
            let cells: Vec<&str> = row.split(',').collect();
            cells[8] == "1" && cells[9].is_empty() && !cells[10].is_empty()
        }),
        "no used unit has an empty reason and a volume: {units}"
    );
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("one JSON object");
    let (detected, used) = (
        json["units"]["detected"].as_u64().unwrap(),
        json["units"]["used"].as_u64().unwrap(),
    );
    assert_eq!(detected as usize, rows.len());
    assert!(used * 10 >= detected * 9, "{used} of {detected}");
    assert!(
        json["explained"]["clip.wav"].as_f64().unwrap() > 0.9,
        "{json}"
    );
    let f1 = &json["estimates"]["glug.f1_hz"];
    assert!(
        (f1["value"].as_f64().unwrap() / 80.0 - 1.0).abs() < 0.03,
        "{f1}"
    );
    assert!(
        f1["low"].as_f64().unwrap() <= f1["value"].as_f64().unwrap(),
        "{f1}"
    );
    assert_eq!(f1["n"].as_u64(), Some(used));
    // No weight log: the pocket keeps its default, with no number and no interval of its own.
    assert!(json["estimates"]["bottle.pocket_ml"].is_null(), "{json}");
    for png in ["compare.png", "fit.png"] {
        assert!(std::fs::read(dir.join(png))
            .unwrap()
            .starts_with(b"\x89PNG"));
    }
    let model = std::fs::read_to_string(dir.join("model.toml")).unwrap();
    assert!(model.contains("pour_time_s"), "{model}");
    let report = std::fs::read_to_string(dir.join("fit.md")).unwrap();
    assert!(report.contains("| clip.wav |"), "{report}");
}

/// A model fitted from the first four glugs of a pour (300 → 280 ml) records the volumes it saw;
/// played as a whole pour it warns that it goes far beyond them, and played within them it does
/// not (issue 49).
#[test]
fn a_model_of_a_few_glugs_warns_when_played_far_beyond_their_volumes() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 0.42\n");
    write_wav(&dir.join("clip.wav"), &rendered.samples, 25_000);
    let output = sake_glug(dir, &["fit", "clip.wav", "-o", "model.toml"]);
    assert_refused(&output, 0, &["model.toml"]);
    let model = sake_glug_model_file::ModelFile::load(&dir.join("model.toml")).unwrap();
    let fitted = model
        .fitted_volumes()
        .expect("the model records its volumes");
    assert!(
        (270.0..=285.0).contains(&fitted.lowest_ml) && fitted.highest_ml <= 300.0,
        "{fitted:?}"
    );
    let output = sake_glug(dir, &["render", "model.toml", "-o", "full.wav"]);
    assert_refused(
        &output,
        0,
        &["warning: model: its glugs come at", "`fit.volumes_ml`"],
    );
    // Half a second from full: glugs down to about 270 ml, within the margin.
    std::fs::write(dir.join("short.toml"), "duration_s = 0.5\n").unwrap();
    let output = sake_glug(
        dir,
        &[
            "render",
            "--model",
            "model.toml",
            "short.toml",
            "-o",
            "short.wav",
        ],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success() && !stderr.contains("warning"),
        "{stderr}"
    );
}

/// Clips and a session do not mix; the clips' bottle is not a session's.
#[test]
fn clip_options_with_a_session_and_mixed_inputs_exit_2() {
    let folder = tempfile::tempdir().unwrap();
    let dir = folder.path();
    good_session(dir);
    let before = files_in(dir);
    for args in [
        &[
            "fit",
            "session.toml",
            "--capacity-ml",
            "500",
            "-o",
            "m.toml",
        ][..],
        &["fit", "session.toml", "a.wav", "-o", "m.toml"][..],
    ] {
        let output = sake_glug(dir, args);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
    }
    assert_eq!(files_in(dir), before);
    let output = sake_glug(dir, &["fit", "a.wav", "--tilt-deg", "200", "-o", "m.toml"]);
    assert_refused(&output, 1, &["--tilt-deg 200"]);
}
