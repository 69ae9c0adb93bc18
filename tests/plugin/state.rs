//! State saved to bytes and loaded from those bytes through nice-plug's real state path (the
//! CLAP state extension of the exported plugin, [`ClapInstance`]), as a host saves and reopens a
//! project: the reopened instance saves the very same bytes and renders the very same samples.

use serde_json::json;

use crate::clap_host::ClapInstance;
use crate::fuzz::checks::{assert_saved_state_valid, bytes_of, float_quantity, json_of};
use sake_glug_engine::config;

/// Every parameter, by the name a host lists, with a value other than its default.
const CHANGED: [(&str, &str); 24] = [
    ("Tilt", "131.25"),
    ("Viscosity", "0.123"),
    ("Fill level", "93.5"),
    ("Pour time", "4.2"),
    ("Output gain", "-7.25"),
    ("f1", "84.5"),
    ("f2", "311.7"),
    ("B1", "47.5"),
    ("B2", "36.1"),
    ("Pocket volume", "4.75"),
    ("Capacity", "350"),
    ("Timing spread", "0.2"),
    ("Frequency spread", "0.075"),
    ("Decay spread", "0.4"),
    ("Headspace", "45.5"),
    ("f1 headspace exponent", "0.5"),
    ("f2 headspace exponent", "-0.25"),
    ("f1 glide ratio", "1.75"),
    ("f2 glide ratio", "0.6"),
    ("f1 glide time", "12.5"),
    ("f2 glide time", "40"),
    ("Seed", "123"),
    ("Drain mode", "Follow"),
    ("Output ceiling", "-0.5"),
];

/// The saved MIDI settings (persisted fields, no parameters): channel 5, tilt 7-bit on CC 1,
/// viscosity on CC 74, fill unmapped. nice-plug saves each field as a JSON string.
const MIDI_FIELDS: [(&str, &str); 5] = [
    ("midi_channel", "4"),
    ("midi_cc_tilt", "1"),
    ("midi_cc_tilt_lsb", "255"),
    ("midi_cc_viscosity", "74"),
    ("midi_cc_fill", "255"),
];

/// An instance with every parameter changed by a host's automation and the MIDI settings
/// changed (there is no other way in from outside than a state: the editor sets them).
fn changed_instance() -> ClapInstance {
    let instance = ClapInstance::new();
    for (name, text) in CHANGED {
        instance.set_text(name, text);
    }
    let mut json = json_of(&instance.save());
    for (field, value) in MIDI_FIELDS {
        json["fields"][field] = serde_json::Value::String(value.into());
    }
    assert!(instance.load(&bytes_of(&json)));
    instance
}

#[test]
fn a_state_saved_to_bytes_loads_from_them_and_sounds_the_same() {
    let mut original = changed_instance();
    let saved = original.save();
    let json = json_of(&saved);
    for (field, value) in MIDI_FIELDS {
        assert_eq!(json["fields"][field], value, "{field}");
    }
    let defaults = ClapInstance::new().save();
    assert_ne!(defaults, saved, "the test must change the state");
    let default_json = json_of(&defaults);
    let params = json["params"].as_object().unwrap();
    assert_eq!(params.len(), CHANGED.len());
    for (id, value) in params {
        assert_ne!(&default_json["params"][id], value, "{id} kept its default");
    }

    // A new instance, as a host reopening the project: load the bytes, save them again.
    let mut reopened = ClapInstance::new();
    assert!(reopened.load(&saved));
    assert_eq!(reopened.save(), saved);

    // The same sound, whatever the host's block size.
    original.activate(48_000.0);
    reopened.activate(48_000.0);
    let heard = original.render(48_000, 512);
    assert!(
        heard.iter().any(|y| y.abs() > 0.01),
        "the changed state must glug"
    );
    assert_eq!(heard, reopened.render(48_000, 4096));
}

#[test]
fn bytes_that_are_not_a_state_are_refused_and_change_nothing() {
    let instance = changed_instance();
    let before = instance.save();
    for bad in [
        &b""[..],
        &[0u8; 8][..],
        &b"\x05\0\0\0\0\0\0\0{\"a\":"[..],
        &b"\xff\xff\xff\xff\xff\xff\xff\xff{}"[..],
    ] {
        assert!(!instance.load(bad), "{bad:?} was accepted");
        assert_eq!(instance.save(), before, "{bad:?} changed the state");
    }
}

/// The state a new instance saves, with `value` for the parameter `id`.
fn crafted(id: &str, value: serde_json::Value) -> Vec<u8> {
    let mut json = json_of(&ClapInstance::new().save());
    json["params"][id] = value;
    bytes_of(&json)
}

/// The value `id` has in `bytes`.
fn saved_value(bytes: &[u8], id: &str) -> serde_json::Value {
    json_of(bytes)["params"][id].clone()
}

// A drain index out of range was taken as it was, and the next save panicked indexing the ids
// (inside a C callback, so the host aborted).
#[test]
fn an_enum_index_out_of_range_loads_as_the_default() {
    let defaults = ClapInstance::new().save();
    for index in [2, -1, i32::MAX, i32::MIN] {
        let instance = changed_instance();
        assert!(instance.load(&crafted("drain", json!({ "i32": index }))));
        let saved = instance.save();
        assert_saved_state_valid(&saved);
        assert_eq!(
            saved_value(&saved, "drain"),
            saved_value(&defaults, "drain")
        );
    }
    for unknown in ["sideways", "", "Follow"] {
        let instance = changed_instance();
        assert!(instance.load(&crafted("drain", json!({ "string": unknown }))));
        let saved = instance.save();
        assert_saved_state_valid(&saved);
        assert_eq!(
            saved_value(&saved, "drain"),
            saved_value(&defaults, "drain")
        );
    }
}

// A float beyond f32's range read as ±inf, saved as `null`, and the plugin then refused its own
// state: the project lost every setting of the instance.
#[test]
fn a_float_out_of_range_loads_clamped_and_one_not_finite_as_the_default() {
    let defaults = ClapInstance::new().save();
    let floats: Vec<String> = json_of(&defaults)["params"]
        .as_object()
        .unwrap()
        .iter()
        .filter(|(_, value)| value.get("f32").is_some())
        .map(|(id, _)| id.clone())
        .collect();
    assert_eq!(floats.len(), 22, "every float parameter");
    // The saved f32, read back as one (JSON holds its shortest decimal).
    let f32_of = |value: serde_json::Value| value["f32"].as_f64().map(|v| v as f32);
    for id in &floats {
        let (min, max) = float_quantity(id).unwrap().knob_bounds();
        let default = f32_of(saved_value(&defaults, id));
        for (written, expected) in [
            (1e39, default),
            (-1e39, default),
            (1e30, Some(max as f32)),
            (-1e30, Some(min as f32)),
        ] {
            let instance = changed_instance();
            assert!(
                instance.load(&crafted(id, json!({ "f32": written }))),
                "{id}"
            );
            let saved = instance.save();
            assert_saved_state_valid(&saved);
            assert_eq!(
                f32_of(saved_value(&saved, id)),
                expected,
                "{id} = {written}"
            );
        }
    }
}

#[test]
fn a_seed_out_of_range_or_a_value_of_the_wrong_type_is_brought_into_range() {
    let defaults = ClapInstance::new().save();
    let max = config::SEED.range.max as i32;
    for (id, written, expected) in [
        ("seed", json!({ "i32": i32::MAX }), json!({ "i32": max })),
        ("seed", json!({ "i32": -5 }), json!({ "i32": 0 })),
        (
            "seed",
            json!({ "f32": 3.0 }),
            saved_value(&defaults, "seed"),
        ),
        ("tilt", json!({ "i32": 3 }), saved_value(&defaults, "tilt")),
        (
            "drain",
            json!({ "bool": true }),
            saved_value(&defaults, "drain"),
        ),
    ] {
        let instance = changed_instance();
        assert!(instance.load(&crafted(id, written.clone())));
        let saved = instance.save();
        assert_saved_state_valid(&saved);
        assert_eq!(saved_value(&saved, id), expected, "{id} = {written}");
    }
}

#[test]
fn persisted_fields_out_of_range_load_as_what_they_mean() {
    let defaults = json_of(&ClapInstance::new().save());
    let default_of = |field: &str| defaults["fields"][field].as_str().unwrap().to_owned();
    for (field, written, expected) in [
        // A MIDI byte above 127 (or a channel above 15) means off, and is saved as off.
        ("midi_channel", "16", "255".to_owned()),
        ("midi_cc_tilt", "200", "255".to_owned()),
        // Not a byte at all: the default.
        ("midi_cc_viscosity", "-1", default_of("midi_cc_viscosity")),
        ("midi_cc_fill", "1e3", default_of("midi_cc_fill")),
        ("midi_cc_tilt_lsb", "null", default_of("midi_cc_tilt_lsb")),
        // An OSC axis that is no axis: the default axis.
        ("osc_axis", "200", default_of("osc_axis")),
    ] {
        let instance = changed_instance();
        let mut json = json_of(&instance.save());
        json["fields"][field] = json!(written);
        assert!(instance.load(&bytes_of(&json)), "{field} = {written}");
        let saved = instance.save();
        assert_saved_state_valid(&saved);
        assert_eq!(
            json_of(&saved)["fields"][field],
            json!(expected),
            "{field} = {written}"
        );
    }
}
