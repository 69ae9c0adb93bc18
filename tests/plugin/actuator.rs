//! An actuator profile in the plugin (MODEL.md §18), through its CLAP entry point as a host
//! drives it: a state holding a shipped profile's name or a profile's text, with the felt flag,
//! bounces the samples of `sake-glug render --actuator X [--felt]` of the same automation, saves
//! and reloads to the same bytes and samples; a state without one is byte for byte today's; a
//! bad profile in a state changes nothing.

use std::path::Path;

use sake_glug_actuator::{ActuatorProfile, Equalise};
use sake_glug_plugin::{ACTUATOR_FELT_KEY, ACTUATOR_KEY};
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

/// A profile of one's own, with less headroom than the model's ceiling.
const OWN_PROFILE: &str = "name = \"bench\"\n\
                           response = [[40.0, -20.0], [120.0, -3.0], [300.0, 0.0], [1000.0, -6.0]]\n\
                           band_hz = [60.0, 800.0]\n\
                           max_amplitude = 0.5\n\
                           sample_rate_hz = 48000\n";

/// What `sake-glug render SCENE --actuator X [--felt]` renders (src/render.rs: the profile found
/// by name or path, equalised by `--felt`, its response set on the scene).
fn cli_render(profile: ActuatorProfile, felt: bool) -> Vec<f32> {
    let profile = if felt {
        profile.equalising(Equalise::Felt)
    } else {
        profile
    };
    let mut scene = Scene::parse(SCENE).unwrap();
    scene.actuator = Some(profile.response());
    let (samples, _) = render_scene_to_vec(&scene).unwrap();
    assert_eq!(samples.len(), TOTAL);
    samples
}

/// The state bytes of `instance` with the actuator's fields set as a state holds them (nice-plug
/// keeps each field as JSON text).
fn with_actuator_fields(instance: &ClapInstance, saved: &str, felt: bool) -> Vec<u8> {
    let mut json = json_of(&instance.save());
    json["fields"][ACTUATOR_KEY] = serde_json::to_string(saved).unwrap().into();
    json["fields"][ACTUATOR_FELT_KEY] = felt.to_string().into();
    bytes_of(&json)
}

/// A new instance with the seed and tilt of [`SCENE`], and the actuator `saved` in its state.
fn with_actuator(saved: &str, felt: bool) -> ClapInstance {
    let instance = ClapInstance::new();
    instance.set_text("Seed", "7");
    instance.set_text("Tilt", "90");
    assert!(instance.load(&with_actuator_fields(&instance, saved, felt)));
    instance
}

fn bounce(instance: &mut ClapInstance, block: usize) -> Vec<f32> {
    instance.activate(RATE);
    let changes: Vec<ParamChange> = vec![instance.change(TILT_AT, "Tilt", "135")];
    instance.render_automated(TOTAL, block, &changes)
}

fn plain() -> Vec<f32> {
    render_scene_to_vec(&Scene::parse(SCENE).unwrap())
        .unwrap()
        .0
}

#[test]
fn a_bounce_with_a_shipped_profile_is_the_render_with_that_actuator() {
    for (name, felt) in [("haptuator-mark2", false), ("lra", true), ("phone", false)] {
        let expected = cli_render(ActuatorProfile::find(name).unwrap(), felt);
        assert_ne!(
            expected,
            plain(),
            "{name}: the profile must change the sound"
        );
        for block in [64, 4096] {
            let rendered = bounce(&mut with_actuator(name, felt), block);
            let first_difference = (0..TOTAL).find(|&n| rendered[n] != expected[n]);
            assert_eq!(first_difference, None, "{name}, felt {felt}, block {block}");
        }
    }
}

#[test]
fn a_bounce_with_a_profile_of_ones_own_is_the_render_with_that_file() {
    let file = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(file.path(), OWN_PROFILE).unwrap();
    let path = file.path().to_str().unwrap();
    let expected = cli_render(ActuatorProfile::find(path).unwrap(), false);
    let peak = expected.iter().fold(0.0f32, |peak, y| peak.max(y.abs()));
    assert!(
        peak > 0.0 && peak <= 0.5,
        "within the profile's headroom: {peak}"
    );
    let rendered = bounce(&mut with_actuator(OWN_PROFILE, false), 512);
    assert_eq!((0..TOTAL).find(|&n| rendered[n] != expected[n]), None);
}

#[test]
fn a_state_with_an_actuator_reloads_to_the_same_bytes_and_samples() {
    for (saved, felt) in [("dualsense", true), (OWN_PROFILE, false)] {
        let mut original = with_actuator(saved, felt);
        let bytes = original.save();
        let json = json_of(&bytes);
        assert_eq!(
            json["fields"][ACTUATOR_KEY],
            serde_json::to_string(saved).unwrap()
        );
        assert_eq!(json["fields"][ACTUATOR_FELT_KEY], felt.to_string());
        assert_saved_state_valid(&bytes);
        let mut reopened = ClapInstance::new();
        assert!(reopened.load(&bytes));
        assert_eq!(reopened.save(), bytes);
        assert_eq!(bounce(&mut original, 512), bounce(&mut reopened, 1000));
    }
}

/// A state fixture of tests/fixtures/state.
fn state_fixture(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/state")
            .join(name),
    )
    .unwrap()
}

/// The state a fresh instance saves today: written by the plugin once the glide's parameters
/// came (issue 45; `SAKE_GLUG_WRITE_STATE=1` writes it anew, as a change of the state's format
/// must be deliberate).
fn todays_state() -> Vec<u8> {
    if std::env::var_os("SAKE_GLUG_WRITE_STATE").is_some() {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/state/v3-glide.state");
        std::fs::write(path, ClapInstance::new().save()).unwrap();
    }
    state_fixture("v3-glide.state")
}

/// The state a fresh instance saved before actuators (written by the plugin at main e888c234).
fn state_before_actuators() -> Vec<u8> {
    state_fixture("v1-before-actuators.state")
}

#[test]
fn a_state_without_an_actuator_is_todays_and_clears_one() {
    let fresh = ClapInstance::new();
    assert_eq!(fresh.save(), todays_state());
    let with_one = with_actuator("lra", true);
    assert_ne!(with_one.save(), todays_state());
    assert!(with_one.load(&todays_state()));
    assert_eq!(with_one.save(), todays_state(), "the actuator is gone");
    // A state from before actuators and before the headspace law loads as today's fresh one: no
    // actuator, the parameters added since at their defaults.
    let mut with_one = with_actuator("lra", true);
    assert!(with_one.load(&state_before_actuators()));
    assert_eq!(
        with_one.save(),
        todays_state(),
        "an older state loads as today's"
    );
    // So does one saved before the glide (MODEL.md §5.2): its parameters at their defaults.
    let before_the_glide = with_actuator("lra", true);
    assert!(before_the_glide.load(&state_fixture("v2-headspace-law.state")));
    assert_eq!(before_the_glide.save(), todays_state());
    let mut fresh = fresh;
    assert_eq!(bounce(&mut with_one, 512), bounce(&mut fresh, 512));
}

#[test]
fn a_bad_actuator_in_a_state_is_refused_and_changes_nothing() {
    let mut instance = with_actuator("lra", false);
    let before = instance.save();
    let other = ClapInstance::new();
    other.set_text("Tilt", "120");
    for bad in [
        "no-such-device",                                       // neither a name nor TOML
        &OWN_PROFILE.replace("[60.0, 800.0]", "[800.0, 60.0]"), // band out of order
        &OWN_PROFILE.replace("max_amplitude = 0.5", "max_amplitude = 0.0"),
    ] {
        assert!(ActuatorProfile::parse(bad).is_err(), "{bad}");
        instance.load(&with_actuator_fields(&other, bad, false));
        assert_eq!(instance.save(), before, "{bad:?} changed the state");
    }
    let mut untouched = with_actuator("lra", false);
    assert_eq!(bounce(&mut instance, 512), bounce(&mut untouched, 512));
}
