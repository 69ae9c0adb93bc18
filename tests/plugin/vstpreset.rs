//! The presets as VST3 preset files (`.vstpreset`), the preset mechanism VST3 hosts offer: a
//! host lists the files of a plugin's preset folder and loads one by handing its component state
//! to the plugin's `IComponent::setState`. `presets/vst3/<name>.vstpreset` is, for each preset,
//! the state the plugin's own wrapper saves once a host has set the preset's parameters on a new
//! instance (as the editor's menu does), so the files cannot drift from the menu; it is laid out
//! as Steinberg's format says. With `SAKE_GLUG_WRITE_PRESETS=1` (what `cargo xtask docs` sets)
//! the test writes the files instead of checking them.
//!
//! The layout is Steinberg's (VST3 SDK, "Preset Format"), all integers little-endian:
//!
//! ```text
//! 0   'VST3'                              4 bytes
//! 4   format version, 1                   int32
//! 8   the class ID as 32 hex digits       32 bytes ASCII
//! 40  offset of the chunk list            int64
//! 48  'Comp' data: the component state    what IComponent::getState writes
//! …   'List'                              4 bytes
//!     entry count, 1                      int32
//!     'Comp', its offset (48), its size   4 bytes, int64, int64
//! ```
//!
//! There is no 'Cont' chunk: nice-plug's edit controller keeps no state of its own. The list comes
//! last, as Steinberg's own writer puts it. The whole format is a 48-byte header and a 24-byte
//! table, written here rather than taken from a crate (no well-kept one writes it).

use std::path::{Path, PathBuf};

use nice_plug::prelude::Vst3Plugin;
use sake_glug_engine::{Knob, PresetValue};
use sake_glug_engine::{Preset, PRESETS};
use sake_glug_plugin::exact;
use sake_glug_plugin::SakeGlugVst3;

use crate::clap_host::ClapInstance;

/// The format version Steinberg's files carry.
const FORMAT_VERSION: i32 = 1;
/// Bytes before the first chunk: id, version, class ID, chunk-list offset.
const HEADER_SIZE: usize = 4 + 4 + 32 + 8;

/// The class ID as a preset file (and a host's project) spells it: the 16 bytes of
/// `VST3_CLASS_ID` as 32 upper-case hex digits, on every platform (nice-plug reorders the bytes
/// on Windows so that the COM GUID spells the same digits).
fn class_id_text(class_id: &[u8; 16]) -> String {
    class_id.iter().map(|byte| format!("{byte:02X}")).collect()
}

/// A preset file for the plugin with `class_id` whose component state is `component_state`.
fn vstpreset(class_id: &[u8; 16], component_state: &[u8]) -> Vec<u8> {
    let list_offset = HEADER_SIZE + component_state.len();
    let mut file = Vec::with_capacity(list_offset + 4 + 4 + 4 + 8 + 8);
    file.extend_from_slice(b"VST3");
    file.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    file.extend_from_slice(class_id_text(class_id).as_bytes());
    file.extend_from_slice(&(list_offset as i64).to_le_bytes());
    file.extend_from_slice(component_state);
    file.extend_from_slice(b"List");
    file.extend_from_slice(&1i32.to_le_bytes());
    file.extend_from_slice(b"Comp");
    file.extend_from_slice(&(HEADER_SIZE as i64).to_le_bytes());
    file.extend_from_slice(&(component_state.len() as i64).to_le_bytes());
    file
}

/// The preset file of `preset`: a new instance, through its CLAP entry as a host makes one, the
/// preset's parameters set as a host sets them (their text, the plugin's own parse), and the
/// state its wrapper saves.
fn preset_file(preset: &Preset) -> Vec<u8> {
    let instance = ClapInstance::new();
    for (name, _, value) in preset_parameters(preset) {
        instance.set_text(name, &value.to_string());
    }
    // The CLAP stream is the state's length, then the state nice-plug's VST3 wrapper saves too.
    vstpreset(&SakeGlugVst3::VST3_CLASS_ID, &instance.save()[8..])
}

/// The file's name: the preset's name, which hosts show as the preset's.
fn file_name(preset: &Preset) -> String {
    format!("{}.vstpreset", preset.name)
}

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/vst3")
}

fn committed(preset: &Preset) -> Vec<u8> {
    let path = folder().join(format!("{}.vstpreset", preset.name));
    std::fs::read(&path)
        .unwrap_or_else(|error| panic!("{}: {error} (run `cargo xtask docs`)", path.display()))
}

/// A preset file read as a host's reader (Steinberg's `PresetFile`) reads it.
struct PresetFile {
    version: i32,
    class_id: [u8; 16],
    /// (chunk id, offset, size), as the chunk list gives them.
    chunks: Vec<([u8; 4], usize, usize)>,
}

fn int32(bytes: &[u8], at: usize) -> i32 {
    i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

fn int64(bytes: &[u8], at: usize) -> usize {
    let value = i64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    usize::try_from(value).expect("offsets and sizes are not negative")
}

/// Reads the header and the chunk list, checking what Steinberg's format requires of them.
fn parse(bytes: &[u8]) -> PresetFile {
    assert_eq!(&bytes[..4], b"VST3", "header id");
    let version = int32(bytes, 4);
    // 32 ASCII hex digits, two per byte, as the SDK's FUID::fromString reads them.
    let digits = std::str::from_utf8(&bytes[8..40]).expect("the class ID is ASCII");
    assert!(
        digits
            .chars()
            .all(|c| c.is_ascii_digit() || ('A'..='F').contains(&c)),
        "upper-case hex, as FUID::toString writes: {digits}"
    );
    let mut class_id = [0u8; 16];
    for (index, byte) in class_id.iter_mut().enumerate() {
        *byte = u8::from_str_radix(&digits[2 * index..2 * index + 2], 16).unwrap();
    }
    let list = int64(bytes, 40);
    assert!(
        (48..bytes.len()).contains(&list),
        "the chunk list at {list} lies after the header, inside the file"
    );
    assert_eq!(&bytes[list..list + 4], b"List", "the chunk list's id");
    let count = int32(bytes, list + 4) as usize;
    let entries = list + 8;
    assert_eq!(
        entries + count * 20,
        bytes.len(),
        "the list's {count} entries end the file"
    );
    let chunks: Vec<_> = (0..count)
        .map(|index| {
            let entry = entries + index * 20;
            let id: [u8; 4] = bytes[entry..entry + 4].try_into().unwrap();
            (id, int64(bytes, entry + 4), int64(bytes, entry + 12))
        })
        .collect();
    // The data area runs from the header to the list, each chunk after the one before.
    let mut end = 48;
    for &(id, offset, size) in &chunks {
        assert!(
            offset >= end && offset + size <= list,
            "chunk {:?} at {offset}, {size} bytes, outside the data area 48..{list}",
            String::from_utf8_lossy(&id)
        );
        end = offset + size;
    }
    PresetFile {
        version,
        class_id,
        chunks,
    }
}

/// The component state of a preset file: its 'Comp' chunk.
fn component_state(bytes: &[u8]) -> &[u8] {
    let file = parse(bytes);
    let &(_, offset, size) = file
        .chunks
        .iter()
        .find(|(id, _, _)| id == b"Comp")
        .expect("a 'Comp' chunk");
    &bytes[offset..offset + size]
}

/// The same state as the CLAP state stream carries it: its length, then the same JSON.
fn clap_stream(component_state: &[u8]) -> Vec<u8> {
    let mut bytes = (component_state.len() as u64).to_le_bytes().to_vec();
    bytes.extend_from_slice(component_state);
    bytes
}

/// Each parameter a preset sets, by the name a host lists, with its knob and the preset's value.
fn preset_parameters(preset: &Preset) -> Vec<(&'static str, Knob, f64)> {
    preset
        .values
        .iter()
        .map(|value| {
            let (quantity, value) = match *value {
                PresetValue::Control(control, value) => (control.quantity(), value),
                PresetValue::Constant(constant, value) => (constant.quantity(), value),
            };
            (quantity.name, quantity.knob, value)
        })
        .collect()
}

#[test]
fn every_vstpreset_file_is_the_presets_own() {
    if std::env::var_os("SAKE_GLUG_WRITE_PRESETS").is_some() {
        std::fs::create_dir_all(folder()).unwrap();
        for preset in &PRESETS {
            let path = folder().join(file_name(preset));
            std::fs::write(&path, preset_file(preset)).unwrap();
            println!("{} written", path.display());
        }
    }
    for preset in &PRESETS {
        assert!(
            committed(preset) == preset_file(preset),
            "presets/vst3/{} is stale (run `cargo xtask docs`)",
            file_name(preset)
        );
    }
    let files = std::fs::read_dir(folder()).unwrap().count();
    assert_eq!(files, PRESETS.len(), "no file without a preset");
}

#[test]
fn each_file_is_laid_out_as_steinbergs_format_says() {
    for preset in &PRESETS {
        let bytes = committed(preset);
        let file = parse(&bytes);
        assert_eq!(file.version, 1, "{}", preset.name);
        assert_eq!(
            file.class_id,
            SakeGlugVst3::VST3_CLASS_ID,
            "{}: the class ID the VST3 plugin registers",
            preset.name
        );
        let ids: Vec<_> = file.chunks.iter().map(|(id, _, _)| id).collect();
        assert_eq!(ids, [b"Comp"], "{}: the component state only", preset.name);
        assert_eq!(
            file.chunks[0].1, 48,
            "{}: the state right after the header",
            preset.name
        );
    }
}

#[test]
fn each_files_state_loads_in_the_plugin_as_the_preset() {
    let fresh = ClapInstance::new();
    let names: Vec<String> = fresh
        .parameter_values()
        .into_iter()
        .map(|(name, ..)| name.into_string().unwrap())
        .collect();
    for preset in &PRESETS {
        let bytes = committed(preset);
        let state = component_state(&bytes);
        // An instance a user has already moved away from the defaults: the preset must bring
        // back every parameter it does not set, not only set its own.
        let instance = ClapInstance::new();
        instance.set_text("Tilt", "120");
        instance.set_text("Output gain", "-20");
        instance.set_text("Seed", "77");
        assert!(
            instance.load(&clap_stream(state)),
            "{}: the plugin refused the state",
            preset.name
        );

        let expected = preset_parameters(preset);
        for name in &names {
            let shown = instance.shown(name);
            match expected.iter().find(|(set, ..)| set == name) {
                Some((_, knob, value)) => {
                    let number: f32 = shown.split_whitespace().next().unwrap().parse().unwrap();
                    assert_eq!(
                        exact(knob, number),
                        *value,
                        "{}: {name} shows {shown}",
                        preset.name
                    );
                }
                None => assert_eq!(
                    shown,
                    fresh.shown(name),
                    "{}: {name} is not at its default",
                    preset.name
                ),
            }
        }
        // What the plugin saves holding the preset is the file's state, to the byte: the
        // persisted fields at their defaults too, and nothing the wrapper would not write.
        assert_eq!(
            String::from_utf8_lossy(&instance.save()[8..]),
            String::from_utf8_lossy(state),
            "{}",
            preset.name
        );
    }
}
