//! Android's haptic-coupled audio (`android-ogg`, `.ogg`): an Ogg Vorbis stream of one audio
//! channel and one haptic channel, the haptic channels counted in the `ANDROID_HAPTIC` comment.
//! Android's media extractor reads that comment and plays the last channels on the vibrator,
//! in step with the audio (`MediaPlayer`, `Ringtone`, `SoundPool` on a device with haptic
//! playback). The haptic channel holds the glug; the audio channel the glug or silence
//! ([`AudioChannels`]). Encoded by libvorbis (aoTuV) through `vorbis_rs`; lossy.

#[cfg(feature = "ogg")]
use std::fs::File;
#[cfg(feature = "ogg")]
use std::io::{BufWriter, Write};
#[cfg(feature = "ogg")]
use std::num::{NonZeroU32, NonZeroU8};

#[cfg(feature = "ogg")]
use vorbis_rs::{VorbisBitrateManagementStrategy, VorbisEncoder, VorbisEncoderBuilder};

use super::read_back::{no_limits, HapticChannel, ReadBack};
#[cfg(feature = "ogg")]
use super::{AudioChannels, PendingFile};
use super::{OutputError, OutputFormat, Sink, SinkContext};
#[cfg(feature = "ogg")]
use crate::RenderSummary;

/// `.ogg`: Android's haptic-coupled Ogg Vorbis (feature `ogg`; a build without it refuses one
/// by name).
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "android-ogg",
    extension: "ogg",
    by_extension: true,
    built: cfg!(feature = "ogg"),
    open,
    read_back: Some(ReadBack::Waveform {
        limits: no_limits,
        haptic: Some(HapticChannel {
            rate: |scene| scene.sample_rate,
            read_peak: haptic_peak,
        }),
    }),
    carries_c: "the waveform on the haptic channel, Vorbis-coded (lossy)",
};

/// The Vorbis comment that counts the haptic channels (the last channels of the stream).
pub const ANDROID_HAPTIC_TAG: &str = "ANDROID_HAPTIC";

/// Channels of the stream: one audio, then one haptic.
pub const ANDROID_OGG_CHANNELS: u8 = 2;

/// Vorbis' quality (−0.2..1): 0.9 keeps the glug's 80–300 Hz within a fraction of a dB; the
/// file is still a tenth of a 16-bit WAV's size.
#[cfg(feature = "ogg")]
const QUALITY: f32 = 0.9;

/// The largest |sample| of a written file's haptic channel (0..1 of full scale), decoded as a
/// player decodes it (so the Vorbis coding's error is in it).
#[cfg(feature = "ogg")]
fn haptic_peak(path: &std::path::Path) -> Result<f64, OutputError> {
    let error = |message: String| OutputError::Ogg {
        path: path.to_owned(),
        message,
    };
    let file = sake_glug_io::read::open(path, sake_glug_io::read::InputKind::WRITTEN)?;
    let mut decoder = vorbis_rs::VorbisDecoder::new(std::io::BufReader::new(file))
        .map_err(|e| error(e.to_string()))?;
    let haptic = usize::from(ANDROID_OGG_CHANNELS) - 1;
    let mut peak = 0.0f64;
    while let Some(block) = decoder
        .decode_audio_block()
        .map_err(|e| error(e.to_string()))?
    {
        if let Some(channel) = block.samples().get(haptic) {
            peak = channel
                .iter()
                .fold(peak, |peak, &y| peak.max(f64::from(y).abs()));
        }
    }
    Ok(peak)
}

/// A build without the `ogg` feature writes no `.ogg`, so it has none to read back.
#[cfg(not(feature = "ogg"))]
fn haptic_peak(path: &std::path::Path) -> Result<f64, OutputError> {
    Err(OutputError::Ogg {
        path: path.to_owned(),
        message: "this build reads no Ogg Vorbis (feature `ogg`)".into(),
    })
}

/// Without the `ogg` feature an `.ogg` is refused by name, not taken for an unknown format.
#[cfg(not(feature = "ogg"))]
fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    Err(OutputError::Ogg {
        path: context.path.to_owned(),
        message: "this build writes no Ogg Vorbis (feature `ogg`)".into(),
    })
}

/// The sink of an `android-ogg` output.
#[cfg(feature = "ogg")]
fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let path = context.path;
    let file = PendingFile::beside(path, "").map_err(OutputError::io(path))?;
    let writer = file.writer().map_err(OutputError::io(path))?;
    let vorbis_error = |e: vorbis_rs::VorbisError| OutputError::Ogg {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let sample_rate =
        NonZeroU32::new(context.scene.sample_rate).ok_or_else(|| OutputError::Ogg {
            path: path.to_owned(),
            message: "a sample rate of 0 Hz".into(),
        })?;
    let channels = NonZeroU8::new(ANDROID_OGG_CHANNELS).expect("2 channels");
    // The stream's serial is the seed's low bits: the same render gives the same bytes.
    let serial = context.scene.config.seed as i32;
    let mut builder = VorbisEncoderBuilder::new_with_serial(sample_rate, channels, writer, serial);
    builder.bitrate_management_strategy(VorbisBitrateManagementStrategy::QualityVbr {
        target_quality: QUALITY,
    });
    builder
        .comment_tags([
            ("ENCODER", concat!("Sake Glug ", env!("CARGO_PKG_VERSION"))),
            ("TITLE", context.scene_name),
            (ANDROID_HAPTIC_TAG, "1"),
        ])
        .map_err(vorbis_error)?;
    let encoder = builder.build().map_err(vorbis_error)?;
    Ok(Box::new(OggFile {
        file,
        encoder,
        audio: context.options.platforms.audio_channels,
        haptic_gain: 1.0,
        silence: Vec::new(),
        haptic: Vec::new(),
    }))
}

/// An Ogg Vorbis stream being written to its temporary file.
#[cfg(feature = "ogg")]
struct OggFile {
    file: PendingFile,
    encoder: VorbisEncoder<BufWriter<File>>,
    audio: AudioChannels,
    /// The haptic channel's gain over the samples heard (`--haptic-peak`).
    haptic_gain: f32,
    /// A block of silence for the audio channel, reused from block to block.
    silence: Vec<f32>,
    /// The haptic channel's block at its gain, reused from block to block.
    haptic: Vec<f32>,
}

#[cfg(feature = "ogg")]
impl OggFile {
    fn error(&self) -> impl FnOnce(vorbis_rs::VorbisError) -> OutputError + '_ {
        |e| OutputError::Ogg {
            path: self.file.path().to_owned(),
            message: e.to_string(),
        }
    }
}

#[cfg(feature = "ogg")]
impl Sink for OggFile {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        self.silence.resize(block.len(), 0.0);
        let audio: &[f32] = match self.audio {
            AudioChannels::Silent => &self.silence,
            AudioChannels::Glug => block,
        };
        let haptic: &[f32] = if self.haptic_gain == 1.0 {
            block
        } else {
            self.haptic.clear();
            self.haptic
                .extend(block.iter().map(|&y| y * self.haptic_gain));
            &self.haptic
        };
        let result = self.encoder.encode_audio_block([audio, haptic]);
        result.map_err(self.error())
    }

    fn haptic_gain(&mut self, gain: f64) {
        self.haptic_gain = gain as f32;
    }

    fn finish(self: Box<Self>, _: &RenderSummary) -> Result<PendingFile, OutputError> {
        let Self { file, encoder, .. } = *self;
        let path = file.path().to_owned();
        let mut writer = encoder.finish().map_err(|e| OutputError::Ogg {
            path: path.clone(),
            message: e.to_string(),
        })?;
        writer.flush().map_err(OutputError::io(&path))?;
        Ok(file)
    }
}
