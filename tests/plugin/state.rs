//! State saved to bytes and loaded from those bytes through nice-plug's real state path (the
//! CLAP state extension of the exported plugin, [`ClapInstance`]), as a host saves and reopens a
//! project: the reopened instance saves the very same bytes and renders the very same samples.

use crate::clap_host::ClapInstance;

/// Every parameter, by the name a host lists, with a value other than its default.
const CHANGED: [(&str, &str); 17] = [
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

/// The JSON inside saved state bytes (CLAP's stream carries an 8-byte length first).
fn json_of(bytes: &[u8]) -> serde_json::Value {
    let length = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(length, bytes.len() - 8);
    serde_json::from_slice(&bytes[8..]).unwrap()
}

fn bytes_of(json: &serde_json::Value) -> Vec<u8> {
    let text = serde_json::to_vec(json).unwrap();
    let mut bytes = (text.len() as u64).to_le_bytes().to_vec();
    bytes.extend(text);
    bytes
}

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
