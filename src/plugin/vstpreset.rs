//! The presets as VST3 preset files (`.vstpreset`), the preset mechanism VST3 hosts offer: a
//! host lists the files of a plugin's preset folder and loads one by handing its component
//! state to the plugin's `IComponent::setState`.
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

use std::io;
use std::path::{Path, PathBuf};

use nice_plug::prelude::*;

use crate::engine::{Preset, PRESETS};
use crate::files::temp_file_builder;
use crate::plugin::presets::{preset_state, state_bytes};
use crate::plugin::SakeGlugVst3;

/// The format version Steinberg's files carry.
pub const FORMAT_VERSION: i32 = 1;
/// Bytes before the first chunk: id, version, class ID, chunk-list offset.
pub const HEADER_SIZE: usize = 4 + 4 + 32 + 8;

/// The class ID as a preset file (and a host's project) spells it: the 16 bytes of
/// [`Vst3Plugin::VST3_CLASS_ID`] as 32 upper-case hex digits, on every platform (nice-plug
/// reorders the bytes on Windows so that the COM GUID spells the same digits).
pub fn class_id_text(class_id: &[u8; 16]) -> String {
    class_id.iter().map(|byte| format!("{byte:02X}")).collect()
}

/// A preset file for the plugin with `class_id` whose component state is `component_state`.
pub fn vstpreset(class_id: &[u8; 16], component_state: &[u8]) -> Vec<u8> {
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

/// The preset file of `preset`: the state nice-plug's VST3 wrapper saves for it.
pub fn preset_file(preset: &Preset) -> Vec<u8> {
    vstpreset(
        &SakeGlugVst3::VST3_CLASS_ID,
        &state_bytes(&preset_state(preset)),
    )
}

/// The file's name: the preset's name, which hosts show as the preset's.
pub fn file_name(preset: &Preset) -> String {
    format!("{}.vstpreset", preset.name)
}

/// Writes every preset's file into `folder` (made if missing); the paths written. Each file is
/// written beside its target and renamed over it once complete, so none is ever left half
/// written, with the permissions of any new file.
pub fn write_all(folder: &Path) -> io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(folder)?;
    PRESETS
        .iter()
        .map(|preset| {
            let path = folder.join(file_name(preset));
            let mut file = temp_file_builder().tempfile_in(folder)?;
            io::Write::write_all(&mut file, &preset_file(preset))?;
            file.persist(&path).map_err(|error| error.error)?;
            Ok(path)
        })
        .collect()
}
