//! What every fuzz target feeds and asserts: one function per target, named as its folders under
//! fuzz/corpus/ and fuzz/regressions/. libFuzzer calls them with coverage guidance
//! (fuzz/fuzz_targets/, `cargo xtask fuzz`); the ordinary test suite calls them on every input
//! kept in those folders (tests/plugin/fuzz.rs includes this file). The property of all of them:
//! never a panic, never a hang, and either a valid result or a refusal that says why.

use std::path::Path;

use serde_json::Value;

use sake_glug_device::axis::Axis;
use sake_glug_device::csv_lane::{read_csv_lane, CsvLaneSpec};
use sake_glug_device::midi_take::read_midi_take;
use sake_glug_device::osc::{decode_osc, OscControl};
use sake_glug_engine::config::{self, CEILING_DB};
use sake_glug_engine::{Constant, Control, DrainMode, Quantity};
use sake_glug_plugin::parse_number;
use sake_glug_render::{Automation, Scene, MAX_DURATION_S};

use crate::clap_host::ClapInstance;

/// What a target does with one input.
pub type Check = fn(&[u8]);

/// Every target by the name of its folders, and what it does with one input.
pub const TARGETS: [(&str, Check); 7] = [
    ("scene_toml", scene_toml),
    ("automation_lanes", automation_lanes),
    ("csv_lane", csv_lane),
    ("midi_take", midi_take),
    ("osc_packet", osc_packet),
    ("parameter_text", parameter_text),
    ("state", state),
];

/// A scene file (`Scene::parse`): a valid scene holds every value in its range.
pub fn scene_toml(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match Scene::parse(text) {
        Ok(scene) => assert_scene_valid(&scene),
        Err(error) => assert!(!error.to_string().is_empty()),
    }
}

fn assert_scene_valid(scene: &Scene) {
    assert!(config::SAMPLE_RATE_HZ.contains(scene.sample_rate as f64));
    assert!(scene
        .duration_s
        .is_none_or(|duration| duration > 0.0 && duration <= MAX_DURATION_S));
    for &control in Control::ALL {
        let automation = &scene.lanes[control];
        assert!(
            automation
                .values()
                .all(|value| control.range().contains(value)),
            "{control:?}: {automation:?}"
        );
        if let Automation::Points(points) = automation {
            assert!(!points.is_empty());
            assert!(points
                .iter()
                .all(|point| point.0.is_finite() && point.0 >= 0.0));
            assert!(points.windows(2).all(|pair| pair[0].0 <= pair[1].0));
        }
    }
    assert_eq!(scene.config, scene.config.sanitized());
}

/// The automation lanes of a scene file: the lane the engine gets for a block says what
/// `value_at` says at each of its samples, at the start and around every point (where a lane
/// changes).
pub fn automation_lanes(data: &[u8]) {
    /// Samples in a block; blocks start half of this before a point.
    const BLOCK: usize = 64;
    /// Points looked at per lane: enough to cross every kind of segment, bounded in time.
    const POINTS: usize = 16;
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(scene) = Scene::parse(text) else {
        return;
    };
    assert_scene_valid(&scene);
    let sample_rate = scene.sample_rate as f64;
    let mut buffer = vec![0.0; BLOCK];
    for &control in Control::ALL {
        let automation = &scene.lanes[control];
        let times = match automation {
            Automation::Constant(_) => &[][..],
            Automation::Points(points) => &points[..points.len().min(POINTS)],
        };
        let firsts = std::iter::once(0).chain(times.iter().map(|point| {
            let sample = (point.0.min(MAX_DURATION_S) * sample_rate) as u64;
            sample.saturating_sub(BLOCK as u64 / 2)
        }));
        for first in firsts {
            let lane = automation.lane(first, sample_rate, &mut buffer);
            for index in 0..BLOCK {
                let expected = automation.value_at((first + index as u64) as f64 / sample_rate);
                let got = lane.at(index);
                assert!(
                    control.range().contains(got) && got == expected,
                    "{control:?}, sample {}: lane {got} against {expected}",
                    first + index as u64
                );
            }
        }
    }
}

/// A CSV log (`read_csv_lane`) read as a column and as a gravity vector: times finite, in order
/// and not negative, every value finite.
pub fn csv_lane(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let specs = [
        CsvLaneSpec::Column("fill".into()),
        CsvLaneSpec::Column("time_s".into()),
        CsvLaneSpec::Gravity {
            columns: ["ax".into(), "ay".into(), "az".into()],
            axis: Axis::MinusZ,
        },
    ];
    for spec in specs {
        match read_csv_lane(text, Path::new("fuzz.csv"), &spec) {
            Ok(points) => {
                assert!(!points.is_empty());
                assert!(points
                    .iter()
                    .all(|&(time, value)| time >= 0.0 && time.is_finite() && value.is_finite()));
                assert!(points.windows(2).all(|pair| pair[0].0 <= pair[1].0));
            }
            Err(error) => assert!(!error.to_string().is_empty()),
        }
    }
}

/// A MIDI take file (`read_midi_take`) at the lowest, a usual and the highest sample rate a
/// caller can pass: messages in order of their samples.
pub fn midi_take(data: &[u8]) {
    for sample_rate in [1, 48_000, u32::MAX] {
        match read_midi_take(data, sample_rate) {
            Ok(take) => assert!(take.windows(2).all(|pair| pair[0].sample <= pair[1].sample)),
            Err(error) => assert!(!error.to_string().is_empty()),
        }
    }
}

/// An OSC packet (`decode_osc`) for two bottle axes: finite controls, or an error and no control
/// at all.
pub fn osc_packet(data: &[u8]) {
    for axis in [Axis::PlusZ, Axis::MinusX] {
        let mut controls = Vec::new();
        match decode_osc(data, axis, &mut |control| controls.push(control)) {
            Ok(()) => assert!(
                controls.iter().all(|control| match control {
                    OscControl::Set(_, value) => value.is_finite(),
                    OscControl::Refill => true,
                }),
                "{controls:?}"
            ),
            Err(error) => {
                assert!(!error.to_string().is_empty());
                assert!(
                    controls.is_empty(),
                    "{controls:?} applied from a bad packet"
                );
            }
        }
    }
}

/// What a person types into a parameter (`parse_number`): a finite number, which reads back
/// from its own text.
pub fn parameter_text(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Some(value) = parse_number(text) {
        assert!(value.is_finite());
        assert_eq!(parse_number(&value.to_string()), Some(value));
    }
}

/// Saved state bytes, loaded through the plugin's CLAP entry point as a host reopens a project:
/// a state it takes holds only valid values, and what it then saves loads again as itself; a
/// state it refuses changes nothing.
pub fn state(data: &[u8]) {
    let instance = ClapInstance::new();
    let before = instance.save();
    if instance.load(data) {
        assert_parameters_valid(&instance);
        assert_saved_state_valid(&instance.save());
    } else {
        assert_eq!(
            instance.save(),
            before,
            "a refused state changed the plugin"
        );
    }
}

/// Every parameter's CLAP value finite and within the range the plugin declares.
fn assert_parameters_valid(instance: &ClapInstance) {
    for (name, value, min, max) in instance.parameter_values() {
        assert!(
            value.is_finite() && (min..=max).contains(&value),
            "{name:?} = {value} outside {min}..{max}"
        );
    }
}

/// The JSON of saved state bytes (the CLAP stream carries the length first, as 8 bytes).
pub fn json_of(bytes: &[u8]) -> Value {
    let length = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(length, bytes.len() - 8);
    serde_json::from_slice(&bytes[8..]).unwrap()
}

/// State bytes of `json`, as the CLAP stream carries them.
pub fn bytes_of(json: &Value) -> Vec<u8> {
    let text = serde_json::to_vec(json).unwrap();
    let mut bytes = (text.len() as u64).to_le_bytes().to_vec();
    bytes.extend(text);
    bytes
}

/// A float parameter as the engine's tables declare it (its knob range, its default).
pub fn float_quantity(id: &str) -> Option<&'static Quantity> {
    Control::ALL
        .iter()
        .map(|control| control.quantity())
        .chain(Constant::ALL.iter().map(|constant| constant.quantity()))
        .chain([&CEILING_DB])
        .find(|quantity| quantity.param_id == id)
}

/// What a host needs of state bytes the plugin saved: a new instance loads them and saves them
/// again byte for byte, and they hold only values the parameters can take (every float finite
/// and in its range, the seed in its range, the drain mode one of the scene's names).
pub fn assert_saved_state_valid(bytes: &[u8]) {
    let reopened = ClapInstance::new();
    assert!(reopened.load(bytes), "the plugin refuses its own state");
    assert_eq!(reopened.save(), bytes, "save, load, save changed the state");
    let json = json_of(bytes);
    for (id, value) in json["params"].as_object().unwrap() {
        let valid = if let Some(quantity) = float_quantity(id) {
            let (min, max) = quantity.knob_bounds();
            // JSON holds the shortest decimal that reads back as the f32.
            value["f32"]
                .as_f64()
                .is_some_and(|v| (min as f32..=max as f32).contains(&(v as f32)))
        } else if id == config::SEED.param_id {
            value["i32"]
                .as_f64()
                .is_some_and(|v| config::SEED.range.contains(v))
        } else if id == config::DRAIN.param_id {
            value["string"]
                .as_str()
                .is_some_and(|name| serde_json::from_value::<DrainMode>(name.into()).is_ok())
        } else {
            panic!("an unknown parameter {id} was saved");
        };
        assert!(valid, "{id} = {value}");
    }
}
