//! `sake-glug render --model MODEL.toml SCENE.toml` (MODEL.md §12.1): the scene's keys over the
//! model's over the defaults, exactly the merged scene written out by hand; a model with
//! anything but the bottle and the liquid in it is refused by key.

use std::path::Path;

use crate::command::{files_in, sake_glug, sake_glug_within};
use sake_glug_model_file::{ModelFile, ModelFileError};

const MODEL: &str = "\
viscosity_c = 0.3712
pour_time_s = 4.37
[bottle]
pocket_ml = 4.213
[glug]
f1_hz = 81.234
b1_per_s = 52.17
[amplitude]
silent_below_ml = 95.5
spread = 0.2
[curves]
rest = [[60.0, 1.0], [90.0, 0.4], [120.0, 0.0]]
drain = [[0.0, 0.0], [80.0, 0.2], [135.0, 1.0], [180.0, 0.9]]
";

/// Sets the viscosity, B1 and the rest curve itself: those it keeps.
const SCENE: &str = "\
seed = 3
duration_s = 3.0
tilt_deg = [[0.0, 90.0], [0.4, 140.0]]
viscosity_c = 0.42
[glug]
b1_per_s = 40.0
[curves]
rest = [[60.0, 1.0], [100.0, 0.2], [115.0, 0.0]]
";

/// [`SCENE`] with every key it leaves out taken from [`MODEL`], by hand.
const MERGED: &str = "\
seed = 3
duration_s = 3.0
tilt_deg = [[0.0, 90.0], [0.4, 140.0]]
viscosity_c = 0.42
pour_time_s = 4.37
[bottle]
pocket_ml = 4.213
[glug]
b1_per_s = 40.0
f1_hz = 81.234
[amplitude]
silent_below_ml = 95.5
spread = 0.2
[curves]
rest = [[60.0, 1.0], [100.0, 0.2], [115.0, 0.0]]
drain = [[0.0, 0.0], [80.0, 0.2], [135.0, 1.0], [180.0, 0.9]]
";

fn render(directory: &Path, args: &[&str]) -> Vec<u8> {
    let output = sake_glug(directory, args);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::read(directory.join(args.last().unwrap())).unwrap()
}

#[test]
fn render_with_a_model_is_the_merged_scene_written_out_by_hand() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path();
    for (name, text) in [
        ("model.toml", MODEL),
        ("scene.toml", SCENE),
        ("merged.toml", MERGED),
    ] {
        std::fs::write(path.join(name), text).unwrap();
    }
    let layered = render(
        path,
        &[
            "render",
            "--model",
            "model.toml",
            "scene.toml",
            "-o",
            "a.wav",
        ],
    );
    let by_hand = render(path, &["render", "merged.toml", "-o", "b.wav"]);
    let scene_alone = render(path, &["render", "scene.toml", "-o", "c.wav"]);
    assert!(
        layered == by_hand,
        "render --model differs from the merged scene"
    );
    assert!(layered != scene_alone, "the model must change the sound");
    // The built-in pour on the model's bottle: the default scene with the model's keys.
    let built_in = render(path, &["render", "--model", "model.toml", "-o", "d.wav"]);
    std::fs::write(
        path.join("default.toml"),
        format!("{}{MODEL}", sake_glug_render::DEFAULT_SCENE),
    )
    .unwrap();
    assert!(built_in == render(path, &["render", "default.toml", "-o", "e.wav"]));
}

#[test]
fn a_model_holds_only_the_bottle_and_the_liquid() {
    for (text, key) in [
        ("tilt_deg = [[0.0, 90.0], [1.0, 135.0]]", "`tilt_deg`"),
        (
            "viscosity_c = { csv = \"log.csv\", column = \"c\" }",
            "`viscosity_c`",
        ),
        ("midi_take = \"take.mid\"", "`midi_take`"),
        ("[midi]\nmidi_channel = 2", "`midi.midi_channel`"),
        ("sample_rate = 25000", "`sample_rate`"),
        ("seed = 4", "`seed`"),
        ("deterministic = true", "`deterministic`"),
        ("[output]\ndrain = \"follow\"", "`output.drain`"),
        ("[glug]\nf1_hz_typo = 3.0", "`glug.f1_hz_typo`"),
    ] {
        let error = ModelFile::parse("m", text).unwrap_err();
        assert!(
            matches!(error, ModelFileError::NotAModelKey { .. }),
            "{text}: {error:?}"
        );
        let message = error.to_string();
        assert!(message.contains(key), "{text}: {message}");
    }
    // A model key in the wrong section, or in none, is named where it belongs (issue 40).
    for (text, expected) in [
        (
            "capacity_ml = 500",
            "`capacity_ml` is not a model key here: did you mean `[bottle] capacity_ml`?",
        ),
        (
            "[glug]\npocket_ml = 4",
            "`glug.pocket_ml` is not a model key here: did you mean `[bottle] pocket_ml`?",
        ),
        (
            "rest = [[0.0, 1.0], [90.0, 0.5]]",
            "`rest` is not a model key here: did you mean `[curves] rest`?",
        ),
    ] {
        let error = ModelFile::parse("m", text).unwrap_err();
        assert!(
            matches!(error, ModelFileError::Misplaced { .. }),
            "{text}: {error:?}"
        );
        assert_eq!(error.to_string(), expected);
    }
    for (text, expected) in [
        ("[glug]\nf1_hz = -1.0", "`glug.f1_hz` = -1 is out of range"),
        ("viscosity_c = 1.5", "`viscosity_c` = 1.5 is out of range"),
        (
            "[bottle]\ncapacity_ml = 80.0\n[amplitude]\nsilent_below_ml = 90.0",
            "must lie below `bottle.capacity_ml`",
        ),
        (
            "[curves]\ndrain = [[0.0, 0.0], [90.0, 0.5]]",
            "`curves.drain`",
        ),
        ("[curves]\nrest = [[0.0, 1.0], \"x\"]", "`curves.rest`"),
        ("[glug]\nf1_hz = \"high\"", "`glug.f1_hz`"),
        ("f1_hz = ", "invalid model"),
    ] {
        let message = ModelFile::parse("m", text).unwrap_err().to_string();
        assert!(message.contains(expected), "{text}: {message}");
    }
    let model = ModelFile::parse("m", "viscosity_c = 1\n[glug]\nf2_hz = 310").unwrap();
    assert_eq!(
        model.controls().viscosity,
        Some(1.0),
        "integers are numbers"
    );
    assert_eq!(model.config().frequency_hz, [80.0, 310.0]);
}

#[test]
fn a_bad_model_is_refused_on_the_command_line_before_anything_is_rendered() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path();
    std::fs::write(path.join("bad.toml"), "tilt_deg = [[0.0, 135.0]]\n").unwrap();
    // A FIFO would wait for a writer for ever if it were opened as a file is.
    let fifo = std::process::Command::new("mkfifo")
        .arg(path.join("fifo.toml"))
        .status()
        .unwrap();
    assert!(fifo.success());
    for (model, expected) in [
        ("bad.toml", "`tilt_deg` does not belong in a model"),
        ("missing.toml", "cannot read model file missing.toml"),
        ("fifo.toml", "not a regular file"),
    ] {
        let args = ["render", "--model", model, "-o", "out.wav"];
        let output = sake_glug_within(path, &args, std::time::Duration::from_secs(60));
        assert_eq!(output.status.code(), Some(2));
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(expected), "{stderr}");
        assert_eq!(
            files_in(path),
            ["bad.toml", "fifo.toml"],
            "nothing is written"
        );
    }
}
