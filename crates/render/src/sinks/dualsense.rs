//! The DualSense's file (`dualsense`, a 4-channel `.wav`): what the controller plays over USB
//! audio, 48 kHz, 16-bit, channels 1–2 its speaker/headset audio and 3–4 its left and right
//! actuators. The actuators get the glug (the render's own samples at 48 kHz; a scene at another
//! rate is resampled, [`Resample`]), the audio channels the glug or silence, by
//! [`AudioChannels`].

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use hound::{SampleFormat, WavSpec, WavWriter};
use sake_glug_io::read::{self, InputKind};

use super::read_back::{HapticChannel, ReadBack};
use super::{OutputError, OutputFormat, PendingFile, Sink, SinkContext};
use crate::resample::Resample;
use crate::{RenderSummary, Scene};

/// `dualsense` (`.wav`): 4 channels at 48 kHz (another rate resampled), the DualSense's audio
/// and actuators.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "dualsense",
    extension: "wav",
    by_extension: false,
    built: true,
    open,
    read_back: Some(ReadBack::Waveform {
        limits,
        haptic: Some(HapticChannel {
            rate: |_| DUALSENSE_RATE_HZ,
            read_peak: actuators_peak,
        }),
    }),
    carries_c: "the waveform on both actuators (c·a at f1, (1 − c)·a at f2), 16-bit",
};

/// The rate the controller's USB audio interface runs at.
pub const DUALSENSE_RATE_HZ: u32 = 48_000;

/// What the controller took of a scene's render: its samples, resampled if the scene is not at
/// 48 kHz.
fn limits(scene: &Scene) -> String {
    if scene.sample_rate == DUALSENSE_RATE_HZ {
        "48 kHz, the scene's own rate (another is resampled: rubato's FFT resampler)".to_owned()
    } else {
        format!(
            "48 kHz, resampled from the scene's {} Hz (rubato's FFT resampler)",
            scene.sample_rate
        )
    }
}

/// Its channels: audio left and right, then the left and right actuator.
pub const DUALSENSE_CHANNELS: u16 = 4;

/// The actuators' channels (from 0) of a frame.
const ACTUATOR_CHANNELS: std::ops::Range<usize> = 2..4;

/// The largest |sample| of a written file's actuator channels (0..1 of full scale).
fn actuators_peak(path: &Path) -> Result<f64, OutputError> {
    let file = read::open(path, InputKind::WRITTEN)?;
    let mut reader =
        hound::WavReader::new(std::io::BufReader::new(file)).map_err(encode_error(path))?;
    let mut peak = 0i32;
    for (index, sample) in reader.samples::<i16>().enumerate() {
        let sample = sample.map_err(encode_error(path))?;
        if ACTUATOR_CHANNELS.contains(&(index % DUALSENSE_CHANNELS as usize)) {
            peak = peak.max(i32::from(sample).abs());
        }
    }
    Ok(f64::from(peak) / 32_768.0)
}

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

/// The sink of a `dualsense` output: refused up front if too long for a WAV file. A scene at
/// 48 kHz gives the controller its own samples; one at another rate is resampled to 48 kHz.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let (path, scene) = (context.path, context.scene);
    if let Some(samples) = scene.duration_samples() {
        check_length(
            path,
            Resample::output_len(scene.sample_rate, DUALSENSE_RATE_HZ, samples),
        )?;
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
        actuator_gain: 1.0,
        frames: 0,
        resample: (scene.sample_rate != DUALSENSE_RATE_HZ)
            .then(|| Resample::new(scene.sample_rate, DUALSENSE_RATE_HZ)),
    }))
}

fn check_length(path: &Path, frames: u64) -> Result<(), OutputError> {
    if frames <= MAX_FRAMES {
        return Ok(());
    }
    Err(OutputError::TooLongFor {
        path: path.to_owned(),
        format: FORMAT.name,
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
    /// The actuators' gain over the samples heard (`--haptic-peak`).
    actuator_gain: f64,
    /// Frames written.
    frames: u64,
    /// The render's samples on their way to 48 kHz, for a scene at another rate.
    resample: Option<Resample>,
}

/// A sample in [−1, 1] as a 16-bit integer, rounded and saturated as the mono WAV's s16.
fn to_i16(sample: f64) -> i16 {
    (sample * 32_768.0).round().clamp(-32_768.0, 32_767.0) as i16
}

/// How the frames are made of the samples: what the audio channels hold, the actuators' gain.
#[derive(Clone, Copy)]
struct Channels {
    audio: AudioChannels,
    actuator_gain: f64,
}

/// Writes a frame for each of `samples` (at 48 kHz): the glug on the actuators at their gain,
/// the audio as `audio` says.
fn write_frames(
    writer: &mut WavWriter<BufWriter<File>>,
    path: &Path,
    channels: Channels,
    frames: &mut u64,
    samples: impl ExactSizeIterator<Item = f64>,
) -> Result<(), OutputError> {
    *frames += samples.len() as u64;
    check_length(path, *frames)?;
    let mut out = writer.get_i16_writer(samples.len() as u32 * 4);
    for sample in samples {
        let glug = to_i16(sample * channels.actuator_gain);
        let audio = match channels.audio {
            AudioChannels::Silent => 0,
            AudioChannels::Glug => to_i16(sample),
        };
        for channel in [audio, audio, glug, glug] {
            out.write_sample(channel);
        }
    }
    out.flush().map_err(encode_error(path))
}

impl Sink for DualSenseFile {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        let Self {
            file,
            writer,
            audio,
            actuator_gain,
            frames,
            resample,
        } = self;
        let path = file.path();
        let channels = Channels {
            audio: *audio,
            actuator_gain: *actuator_gain,
        };
        let mut write =
            |samples: &[f64]| write_frames(writer, path, channels, frames, samples.iter().copied());
        match resample {
            None => write_frames(
                writer,
                path,
                channels,
                frames,
                block.iter().map(|&y| f64::from(y)),
            ),
            Some(resample) => resample.push(block, &mut write),
        }
    }

    fn haptic_gain(&mut self, gain: f64) {
        self.actuator_gain = gain;
    }

    fn memory_bytes(&self) -> u64 {
        self.resample.as_ref().map_or(0, Resample::memory_bytes)
    }

    fn finish(self: Box<Self>, _: &RenderSummary) -> Result<PendingFile, OutputError> {
        let Self {
            file,
            mut writer,
            audio,
            actuator_gain,
            mut frames,
            resample,
        } = *self;
        if let Some(resample) = resample {
            let path = file.path();
            let channels = Channels {
                audio,
                actuator_gain,
            };
            resample.finish(&mut |samples: &[f64]| {
                write_frames(
                    &mut writer,
                    path,
                    channels,
                    &mut frames,
                    samples.iter().copied(),
                )
            })?;
        }
        writer.finalize().map_err(encode_error(file.path()))?;
        Ok(file)
    }
}
