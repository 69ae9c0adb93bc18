//! The fuzz targets in the ordinary test suite. Every input that coverage-guided fuzzing kept
//! (fuzz/corpus/<target>/, a minimised corpus) or that once crashed a target
//! (fuzz/regressions/<target>/) goes through that target's own check ([`checks`], the file the
//! libFuzzer targets call) without libFuzzer. Then property-based fuzz tests (proptest, 256 cases
//! a run) for the plugin's saved state, with the same check, and for the MIDI CC decoder against
//! an independent model of its mapping table.

use proptest::prelude::*;

use std::path::Path;

use crate::clap_host::ClapInstance;
use crate::support::fuzz::{self, any_number};
use sake_glug_device::midi::{CcDecoder, MidiMap};
use sake_glug_engine::Control;

/// What each target feeds and asserts, shared with the libFuzzer targets.
#[path = "../../fuzz/src/checks.rs"]
pub mod checks;

#[test]
fn every_input_kept_by_the_fuzzers_passes_its_target() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let targets: Vec<&str> = checks::TARGETS.iter().map(|(name, _)| *name).collect();
    for folder in ["corpus", "regressions"] {
        for entry in std::fs::read_dir(fuzz.join(folder)).unwrap() {
            let name = entry.unwrap().file_name();
            let name = name.to_string_lossy();
            assert!(
                targets.contains(&&*name),
                "fuzz/{folder}/{name} is no target"
            );
        }
    }
    for (target, check) in checks::TARGETS {
        let mut inputs = 0;
        for folder in ["corpus", "regressions"] {
            let Ok(entries) = std::fs::read_dir(fuzz.join(folder).join(target)) else {
                continue;
            };
            for entry in entries {
                let path = entry.unwrap().path();
                let data = std::fs::read(&path).unwrap();
                if let Err(panic) = std::panic::catch_unwind(|| check(&data)) {
                    let message = panic
                        .downcast_ref::<String>()
                        .map(String::as_str)
                        .or(panic.downcast_ref::<&str>().copied())
                        .unwrap_or("");
                    panic!("{}: {message}", path.display());
                }
                inputs += 1;
            }
        }
        assert!(inputs > 0, "no input kept for {target}");
    }
}

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

#[test]
fn fuzz_plugin_state_bytes() {
    let template: serde_json::Value = checks::json_of(&ClapInstance::new().save());
    fuzz::run(
        "plugin state bytes (CLAP state load)",
        state_bytes(template),
        |bytes| {
            checks::state(&bytes);
            Ok(())
        },
    );
}

/// The decoder's 14-bit tilt, written out again from the guide's table (docs/guide/tilt-device.md).
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
