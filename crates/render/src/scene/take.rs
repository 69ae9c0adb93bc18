//! A scene's recorded MIDI take: its bytes, read within their limit, and its messages at the
//! scene's sample rate.

use std::path::{Path, PathBuf};

use super::SceneError;
use sake_glug_device::midi_take::{read_midi_take, TimedInput, MAX_TAKE_BYTES};
use sake_glug_io::read;

/// A recorded Standard MIDI File take: its bytes, and its messages at the scene's sample rate.
#[derive(Debug, Clone, PartialEq)]
pub struct MidiTake {
    /// Where it was read from.
    pub path: PathBuf,
    pub(super) bytes: Vec<u8>,
    /// Every note-on and CC, at the first sample at or after its time.
    pub events: Vec<TimedInput>,
}

impl MidiTake {
    /// Reads the take at `path` for a render at `sample_rate` (Hz).
    pub fn load(path: &Path, sample_rate: u32) -> Result<Self, SceneError> {
        let bytes =
            read::bytes_within(path, MAX_TAKE_BYTES).map_err(|source| SceneError::TakeFile {
                path: path.to_owned(),
                source,
            })?;
        Self::from_bytes(path, bytes, sample_rate)
    }

    pub(super) fn from_bytes(
        path: &Path,
        bytes: Vec<u8>,
        sample_rate: u32,
    ) -> Result<Self, SceneError> {
        let events = read_midi_take(&bytes, sample_rate).map_err(|source| SceneError::Take {
            path: path.to_owned(),
            source,
        })?;
        Ok(Self {
            path: path.to_owned(),
            bytes,
            events,
        })
    }
}
