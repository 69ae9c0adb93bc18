//! Fuzz targets for what the plugin reads from outside: its saved state (bytes a host hands
//! back from a project, through nice-plug's state deserialisation in the CLAP state extension)
//! and the MIDI CC decoder of the tilt device. Property: never a panic, never a hang, and either
//! a valid result or a refusal. `cargo xtask fuzz` runs a million cases of each; a normal test
//! run, proptest's default of 256.

use proptest::prelude::*;

use crate::clap_host::ClapInstance;
use crate::support::fuzz::{self, any_number};
use sake_glug::device::midi::{CcDecoder, MidiMap};
use sake_glug::engine::Control;

/// A JSON value of any kind, numbers from every corner.
fn json_value() -> impl Strategy<Value = serde_json::Value> {
    use serde_json::{Number, Value};
    prop_oneof![
        4 => any_number().prop_map(|x| Number::from_f64(x).map_or(Value::Null, Value::Number)),
        2 => (-2_000_000_000i64..2_000_000_000).prop_map(Value::from),
        1 => any::<bool>().prop_map(Value::Bool),
        2 => "[a-zA-Z0-9 .-]{0,12}".prop_map(Value::String),
        1 => Just(Value::Null),
        1 => Just(serde_json::json!([1, 2])),
    ]
}

/// Saved state bytes: a real state with its values, fields and length mutated, or bytes of any
/// kind.
fn state_bytes(template: serde_json::Value) -> impl Strategy<Value = Vec<u8>> {
    let params: Vec<String> = template["params"]
        .as_object()
        .unwrap()
        .keys()
        .cloned()
        .collect();
    let fields: Vec<String> = template["fields"]
        .as_object()
        .unwrap()
        .keys()
        .cloned()
        .collect();
    let param_changes = prop::collection::vec(
        (
            prop::sample::select(params),
            // None: the parameter is left out of the state.
            prop::option::weighted(0.8, json_value()),
        ),
        0..6,
    );
    let field_changes = prop::collection::vec(
        (
            prop::sample::select(fields),
            prop_oneof![
                (0u32..400).prop_map(|n| n.to_string()),
                "[-0-9a-z\"]{0,6}".prop_map(String::from),
            ],
        ),
        0..4,
    );
    let extra = prop::option::of(("[a-z]{1,8}", json_value()));
    let mutated = (
        param_changes,
        field_changes,
        extra,
        prop::option::of(any::<u16>()),
        prop_oneof![3 => Just(None), 1 => any::<i8>().prop_map(Some)],
    )
        .prop_map(move |(params, fields, extra, cut, length_error)| {
            let mut json = template.clone();
            for (id, value) in params {
                match value {
                    Some(value) => json["params"][id] = value,
                    None => {
                        json["params"].as_object_mut().unwrap().remove(&id);
                    }
                }
            }
            for (id, value) in fields {
                json["fields"][id] = serde_json::Value::String(value);
            }
            if let Some((key, value)) = extra {
                json["params"][key] = value;
            }
            let mut text = serde_json::to_vec(&json).unwrap();
            if let Some(cut) = cut {
                text.truncate(cut as usize % (text.len() + 1));
            }
            let length = text.len() as i64 + length_error.map_or(0, i64::from);
            let mut bytes = (length.max(0) as u64).to_le_bytes().to_vec();
            bytes.extend(text);
            bytes
        });
    prop_oneof![
        6 => mutated,
        1 => prop::collection::vec(any::<u8>(), 0..64),
        1 => prop::collection::vec(any::<u8>(), 0..64).prop_map(|tail| {
            let mut bytes = (tail.len() as u64).to_le_bytes().to_vec();
            bytes.extend(tail);
            bytes
        }),
    ]
}

/// Every parameter's CLAP value, checked finite and within the range the plugin declares.
fn assert_parameters_valid(instance: &ClapInstance) -> Result<(), TestCaseError> {
    for (name, value, min, max) in instance.parameter_values() {
        prop_assert!(
            value.is_finite() && (min..=max).contains(&value),
            "{} = {} outside {}..{}",
            name.to_string_lossy(),
            value,
            min,
            max
        );
    }
    Ok(())
}

#[test]
fn fuzz_plugin_state_bytes() {
    // One instance for every case, as a host reloading projects into the same plugin.
    let instance = ClapInstance::new();
    let template: serde_json::Value = {
        let bytes = instance.save();
        serde_json::from_slice(&bytes[8..]).unwrap()
    };
    fuzz::run(
        "plugin state bytes (CLAP state load)",
        state_bytes(template),
        |bytes| {
            let before = instance.save();
            if instance.load(&bytes) {
                // A state it took holds only valid values, and saves and reloads as itself.
                assert_parameters_valid(&instance)?;
                let saved = instance.save();
                prop_assert!(instance.load(&saved));
                prop_assert_eq!(&instance.save(), &saved);
            } else {
                // A state it refused changed nothing.
                prop_assert_eq!(
                    &instance.save(),
                    &before,
                    "a refused state changed the plugin"
                );
            }
            Ok(())
        },
    );
}

/// The decoder's 14-bit tilt, written out again from the README's table.
fn tilt_of(msb: u8, lsb: u8) -> f64 {
    (msb as f64 * 128.0 + lsb as f64) / 16383.0 * 180.0
}

#[test]
fn fuzz_midi_cc_decoder() {
    let message = (any::<u8>(), any::<u8>(), any::<u8>());
    let take = (any::<[u8; 5]>(), prop::collection::vec(message, 0..40));
    fuzz::run("MIDI CC decoder (device::midi)", take, |(raw, messages)| {
        let map = MidiMap::from_raw(raw);
        // Saved settings read back as themselves.
        prop_assert_eq!(MidiMap::from_raw(map.to_raw()), map);
        prop_assert!(map.channel.is_none_or(|c| c < 16));
        let mut decoder = CcDecoder::default();
        // An independent model of what the decoder must do.
        let (mut msb, mut lsb) = (None::<u8>, 0u8);
        for (channel, cc, value) in messages {
            let decoded = decoder.feed(&map, channel, cc, value);
            let listening = map.channel.is_none_or(|c| c == channel) && cc < 128;
            let value = value.min(127);
            let expected = if !listening {
                None
            } else if Some(cc) == map.cc[Control::Tilt] {
                match map.tilt_lsb {
                    Some(_) => {
                        msb = Some(value);
                        Some((Control::Tilt, tilt_of(value, lsb)))
                    }
                    None => Some((Control::Tilt, value as f64 / 127.0 * 180.0)),
                }
            } else if map.tilt_lsb.is_some() && Some(cc) == map.tilt_lsb {
                lsb = value;
                msb.map(|msb| (Control::Tilt, tilt_of(msb, value)))
            } else if Some(cc) == map.cc[Control::Viscosity] {
                Some((Control::Viscosity, value as f64 / 127.0))
            } else if Some(cc) == map.cc[Control::Fill] {
                Some((Control::Fill, value as f64 / 127.0 * 100.0))
            } else {
                None
            };
            match (decoded, expected) {
                (None, None) => {}
                (Some((target, got)), Some((want_target, want))) => {
                    prop_assert_eq!(target, want_target);
                    let range = target.range();
                    prop_assert!(range.contains(got), "{:?} = {} out of range", target, got);
                    prop_assert!(
                        (got - want).abs() <= 1e-9 * range.max,
                        "{got} against {want}"
                    );
                }
                (got, want) => prop_assert!(false, "decoded {got:?}, expected {want:?}"),
            }
        }
        Ok(())
    });
}
