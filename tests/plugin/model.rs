//! A model file in the plugin (MODEL.md §12.1), through its CLAP entry point as a host drives it:
//! a state holding a model bounces the samples of `sake-glug render --model` of the same
//! automation, reloads to the same samples, and a bad model in a state changes nothing.

use std::path::Path;

use nice_plug::prelude::Param;
use sake_glug_model_file::ModelFile;
use sake_glug_plugin::{model_values, GlugParams, MODEL_KEY, MODEL_NAME_KEY};
use sake_glug_render::{render_scene_to_vec, Scene};

use crate::clap_host::{ClapInstance, ParamChange};
use crate::fuzz::checks::{assert_saved_state_valid, bytes_of, json_of};

const RATE: f64 = 48_000.0;
const TOTAL: usize = 96_000;
/// Where the host's automation tilts the bottle from 90° to 135°.
const TILT_AT: u64 = 24_000;

/// The same automation as a scene: seed 7, held at 90°, a step to 135° at 0.5 s.
const SCENE: &str = "seed = 7\nduration_s = 2.0\n\
                     tilt_deg = [[0.0, 90.0], [0.5, 90.0], [0.5, 135.0]]\n";

fn fitted() -> ModelFile {
    model_fixture("fitted")
}

/// `tests/fixtures/models/<name>.toml`.
fn model_fixture(name: &str) -> ModelFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/models")
        .join(format!("{name}.toml"));
    ModelFile::load(&path).unwrap()
}

/// The state bytes of `instance` with a model's fields holding `name` and `text` as they are
/// (nice-plug keeps each field as JSON: a string field is a quoted string).
fn with_model_fields(instance: &ClapInstance, name: &str, text: &str) -> Vec<u8> {
    let mut json = json_of(&instance.save());
    for (key, value) in [(MODEL_NAME_KEY, name), (MODEL_KEY, text)] {
        json["fields"][key] = serde_json::to_string(value).unwrap().into();
    }
    bytes_of(&json)
}

/// A new instance with `model` loaded as the editor loads it (its parameters through the host,
/// its text into the state), the seed and tilt of [`SCENE`] set.
fn loaded(model: &ModelFile) -> ClapInstance {
    let instance = ClapInstance::new();
    for (param, value) in model_values(model, &GlugParams::default()) {
        instance.set_text(param.name(), &value.to_string());
    }
    instance.set_text("Seed", "7");
    instance.set_text("Tilt", "90");
    assert!(instance.load(&with_model_fields(&instance, model.name(), model.text())));
    instance
}

fn automation(instance: &ClapInstance) -> Vec<ParamChange> {
    vec![instance.change(TILT_AT, "Tilt", "135")]
}

fn bounce(instance: &mut ClapInstance, block: usize) -> Vec<f32> {
    instance.activate(RATE);
    let changes = automation(instance);
    instance.render_automated(TOTAL, block, &changes)
}

#[test]
fn a_bounce_with_a_model_in_the_state_is_the_render_with_that_model() {
    // The fitted model, one whose pitch follows its headspace (MODEL.md §5.1) and one whose
    // glugs glide (§5.2), which the editor loads through those rules' parameters.
    for name in ["fitted", "falling-pitch", "gliding"] {
        a_bounce_plays(&model_fixture(name));
    }
}

/// A bounce with `model` in the state is the render with it, at host blocks of 64 and 4096.
fn a_bounce_plays(model: &ModelFile) {
    let model = model.clone();
    let scene = Scene::parse_with_model(SCENE, Path::new(""), &model).unwrap();
    let (expected, _) = render_scene_to_vec(&scene).unwrap();
    assert_eq!(expected.len(), TOTAL);
    let plain = render_scene_to_vec(&Scene::parse(SCENE).unwrap())
        .unwrap()
        .0;
    assert_ne!(expected, plain, "the model must change the sound");
    for block in [64, 4096] {
        let rendered = bounce(&mut loaded(&model), block);
        let first_difference = (0..TOTAL).find(|&n| rendered[n] != expected[n]);
        assert_eq!(first_difference, None, "block {block}");
    }
}

#[test]
fn a_state_with_a_model_reloads_to_the_same_samples() {
    let model = fitted();
    let mut original = loaded(&model);
    let saved = original.save();
    let json = json_of(&saved);
    assert_eq!(json["fields"][MODEL_NAME_KEY], "\"fitted\"");
    assert_saved_state_valid(&saved);
    let mut reopened = ClapInstance::new();
    assert!(reopened.load(&saved));
    assert_eq!(reopened.save(), saved);
    assert_eq!(bounce(&mut original, 512), bounce(&mut reopened, 1000));
}

#[test]
fn a_state_without_a_model_loads_as_before_and_clears_one() {
    let fixture = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/state/v0-session.state"),
    )
    .unwrap();
    let fresh = ClapInstance::new();
    assert!(fresh.load(&fixture));
    let mut with_model = loaded(&fitted());
    assert!(with_model.load(&fixture));
    let saved = with_model.save();
    assert_eq!(saved, fresh.save(), "the model is gone from the state");
    assert!(json_of(&saved)["fields"].get(MODEL_KEY).is_none());
    let mut fresh = fresh;
    assert_eq!(bounce(&mut with_model, 512), bounce(&mut fresh, 512));
}

#[test]
fn a_bad_model_in_a_state_is_refused_and_changes_nothing() {
    let model = fitted();
    let mut instance = loaded(&model);
    let before = instance.save();
    let other = ClapInstance::new();
    other.set_text("Tilt", "120");
    for bad in [
        "f1_hz = ",                                    // not TOML
        "[glug]\nf1_hz = -3.0",                        // out of range
        "tilt_deg = [[0.0, 90.0]]",                    // automation
        "sample_rate = 48000",                         // a render setting
        "[curves]\ndrain = [[0.0, 0.0], [90.0, 0.5]]", // h(135°) is not 1
    ] {
        assert!(ModelFile::parse("bad", bad).is_err(), "{bad}");
        instance.load(&with_model_fields(&other, "bad", bad));
        assert_eq!(instance.save(), before, "{bad:?} changed the state");
    }
    let mut untouched = loaded(&model);
    assert_eq!(bounce(&mut instance, 512), bounce(&mut untouched, 512));
}
