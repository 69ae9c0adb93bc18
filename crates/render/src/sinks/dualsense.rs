//! The DualSense's file (`dualsense`, a 4-channel `.wav`): what the controller plays over USB
//! audio, 48 kHz, 16-bit, channels 1–2 its speaker/headset audio and 3–4 its left and right
//! actuators. The actuators get the glug (the render's own samples), the audio channels the
//! glug or silence, by [`AudioChannels`].

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use hound::{SampleFormat, WavSpec, WavWriter};

use super::{OutputError, PendingFile, Sink, SinkContext};
use crate::RenderSummary;

/// The rate the controller's USB audio interface runs at.
pub const DUALSENSE_RATE_HZ: u32 = 48_000;

/// Its channels: audio left and right, then the left and right actuator.
pub const DUALSENSE_CHANNELS: u16 = 4;

/// What the audio channels of a file that also drives actuators hold (the DualSense's two, the
/// Android Ogg's one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AudioChannels {
    /// Silence: the speaker stays quiet, only the actuators play.
    #[default]
    Silent,
    /// The glug itself, heard as it is felt.
    Glug,
}

impl AudioChannels {
    /// Every choice, with the name the command line uses for it.
    pub const ALL: [(Self, &'static str); 2] = [(Self::Silent, "silent"), (Self::Glug, "glug")];
}

impl std::str::FromStr for AudioChannels {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .find(|(_, name)| *name == text)
            .map(|(audio, _)| *audio)
            .ok_or_else(|| format!("unknown audio `{text}`: use silent or glug"))
    }
}

/// Bytes of one frame (4 channels of 16 bits).
const FRAME_BYTES: u64 = DUALSENSE_CHANNELS as u64 * 2;

/// The most frames a file can hold: its sizes are 32-bit byte counts (a 1 kB allowance for the
/// header).
const MAX_FRAMES: u64 = (u32::MAX as u64 - 1024) / FRAME_BYTES;

/// The sink of a `dualsense` output: refused up front for a scene not rendered at 48 kHz (the
/// controller plays nothing else, and the render's own samples are what it should play, not a
/// resampled copy), or too long for a WAV file.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let (path, scene) = (context.path, context.scene);
    if scene.sample_rate != DUALSENSE_RATE_HZ {
        return Err(OutputError::WrongRate {
            path: path.to_owned(),
            format: "dualsense",
            needed_hz: DUALSENSE_RATE_HZ,
            scene_hz: scene.sample_rate,
        });
    }
    if let Some(samples) = scene.duration_samples() {
        check_length(path, samples)?;
    }
    let file = PendingFile::beside(path, "").map_err(OutputError::io(path))?;
    let writer = file.writer().map_err(OutputError::io(path))?;
    let spec = WavSpec {
        channels: DUALSENSE_CHANNELS,
        sample_rate: DUALSENSE_RATE_HZ,
        bits_per_sample: 16,
        sample_format: SampleFormat::Int,
    };
    let writer = WavWriter::new(writer, spec).map_err(encode_error(path))?;
    Ok(Box::new(DualSenseFile {
        file,
        writer,
        audio: context.options.platforms.audio_channels,
        frames: 0,
    }))
}

fn check_length(path: &Path, frames: u64) -> Result<(), OutputError> {
    if frames <= MAX_FRAMES {
        return Ok(());
    }
    Err(OutputError::TooLongFor {
        path: path.to_owned(),
        format: "dualsense",
        max_s: MAX_FRAMES as f64 / DUALSENSE_RATE_HZ as f64,
    })
}

fn encode_error(path: &Path) -> impl FnOnce(hound::Error) -> OutputError + '_ {
    move |source| {
        OutputError::Wav(super::WavError::Encode {
            path: path.to_owned(),
            source,
        })
    }
}

/// A 4-channel file being written to its temporary file.
struct DualSenseFile {
    file: PendingFile,
    writer: WavWriter<BufWriter<File>>,
    audio: AudioChannels,
    frames: u64,
}

/// A sample in [−1, 1] as a 16-bit integer, rounded and saturated as the mono WAV's s16.
fn to_i16(sample: f32) -> i16 {
    (sample as f64 * 32_768.0)
        .round()
        .clamp(-32_768.0, 32_767.0) as i16
}

impl Sink for DualSenseFile {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        self.frames += block.len() as u64;
        check_length(self.file.path(), self.frames)?;
        let path = self.file.path().to_owned();
        let mut frames = self.writer.get_i16_writer(block.len() as u32 * 4);
        for &sample in block {
            let glug = to_i16(sample);
            let audio = match self.audio {
                AudioChannels::Silent => 0,
                AudioChannels::Glug => glug,
            };
            for channel in [audio, audio, glug, glug] {
                frames.write_sample(channel);
            }
        }
        frames.flush().map_err(encode_error(&path))
    }

    fn finish(self: Box<Self>, _: &RenderSummary) -> Result<PendingFile, OutputError> {
        let Self { file, writer, .. } = *self;
        writer.finalize().map_err(encode_error(file.path()))?;
        Ok(file)
    }
}
