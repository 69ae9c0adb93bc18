//! The WAV sink: the mono output streamed to a temporary file beside the target as it is
//! rendered, refused up front when the render is known to be too long for a WAV file.
//!
//! hound writes the header; the samples are converted a block at a time and written as one
//! buffer (hound takes f32 and 24-bit samples only one by one), and once complete the two sizes of
//! the header are set as hound sets them. The files are byte for byte what hound alone writes.

use std::io::{BufWriter, Cursor, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use hound::{SampleFormat as HoundFormat, WavSpec, WavWriter};

use super::read_back::{no_limits, ReadBack};
use super::{OutputError, OutputFormat, PendingFile, Sink, SinkContext};
use crate::RenderSummary;

/// `.wav`: the mono output, for an actuator driven from an audio interface.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "wav",
    extension: "wav",
    by_extension: true,
    built: true,
    open,
    read_back: Some(ReadBack::Waveform {
        limits: no_limits,
        haptic: None,
    }),
    carries_c: WAVEFORM_CARRIES_C,
};

/// What carries c in a file of the render's samples: the samples themselves.
pub(super) const WAVEFORM_CARRIES_C: &str = "the waveform itself (c·a at f1, (1 − c)·a at f2)";

/// The sink of a `.wav` output.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let (path, scene) = (context.path, context.scene);
    let format = context.options.sample_format;
    if let Some(samples) = scene.duration_samples() {
        WavFile::check_length(path, samples, scene.sample_rate, format)?;
    }
    Ok(Box::new(WavFile::create(path, scene.sample_rate, format)?))
}

impl Sink for WavFile {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        Ok(self.write(block)?)
    }

    fn clipped(&self) -> Option<Clipped> {
        (self.clipped > 0).then(|| Clipped {
            path: self.file.path().to_owned(),
            samples: self.clipped,
            format: self.format,
        })
    }

    fn finish(self: Box<Self>, _: &RenderSummary) -> Result<PendingFile, OutputError> {
        Ok(self.complete()?)
    }
}

/// Full scale of a waveform file's samples: a sample beyond ±1 clips, saturated in an integer
/// file, and by a player or a converter in a float one.
const FULL_SCALE: f32 = 1.0;

/// A waveform file some of whose samples pass full scale (issue 49: `--loudness -16
/// --sample-format s16` clipped 107 samples and said nothing): the render warns, naming it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{}: {samples} samples pass full scale{}; lower --loudness, or hold the peak with \
     --true-peak -1",
    path.display(),
    match format {
        SampleFormat::F32 => " (kept in the float file: a player or a converter to integers clips them)",
        SampleFormat::S24 | SampleFormat::S16 => ", clipped in the file",
    }
)]
pub struct Clipped {
    /// The file asked for.
    pub path: PathBuf,
    /// How many of its samples pass full scale.
    pub samples: u64,
    /// Its sample format.
    pub format: SampleFormat,
}

/// The sample format of a WAV file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SampleFormat {
    /// 32-bit float.
    #[default]
    F32,
    /// 24-bit integer.
    S24,
    /// 16-bit integer.
    S16,
}

impl SampleFormat {
    /// Every format, with the name the command line uses for it.
    pub const ALL: [(SampleFormat, &'static str); 3] = [
        (SampleFormat::F32, "f32"),
        (SampleFormat::S24, "s24"),
        (SampleFormat::S16, "s16"),
    ];
}

impl std::str::FromStr for SampleFormat {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .find(|(_, name)| *name == text)
            .map(|(format, _)| *format)
            .ok_or_else(|| format!("unknown sample format `{text}`: use f32, s24 or s16"))
    }
}

/// Why a WAV file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WavError {
    /// The file system refused.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file asked for.
        path: PathBuf,
        /// What the file system said.
        source: std::io::Error,
    },
    /// The render is longer than a WAV file can hold: its sizes are 32-bit byte counts.
    #[error(
        "{}: {samples} samples of {} would pass the 4 GiB a WAV file can hold (at most \
         {max_samples} samples, {max_hours:.2} h at {sample_rate} Hz); give the scene a shorter \
         duration_s, {}or write a .csv instead",
        path.display(),
        format.name(),
        format.narrower_advice()
    )]
    TooLong {
        /// The file asked for.
        path: PathBuf,
        /// Samples the render has or would have.
        samples: u64,
        /// The most samples a file of this format can hold.
        max_samples: u64,
        /// That many samples in hours.
        max_hours: f64,
        /// Sample rate (Hz).
        sample_rate: u32,
        /// Sample format.
        format: SampleFormat,
    },
    /// The WAV encoder refused.
    #[error("cannot write {}: {source}", path.display())]
    Encode {
        /// The file asked for.
        path: PathBuf,
        /// What the encoder said.
        source: hound::Error,
    },
}

/// A mono WAV file being written; it replaces its target only once complete and committed.
pub(crate) struct WavFile {
    file: PendingFile,
    writer: BufWriter<std::fs::File>,
    format: SampleFormat,
    sample_rate: u32,
    /// Samples written so far, held against [`WavFile::max_samples`].
    written: u64,
    /// Length of hound's header: the data's size is its last 4 bytes.
    header_len: u64,
    /// A block of samples in the file's format, reused from block to block.
    bytes: Vec<u8>,
    /// Samples written beyond full scale (|y| > 1): an integer format saturates them.
    clipped: u64,
}

/// Bytes kept free of the 32-bit RIFF size for the headers: hound's largest header (the
/// extensible format chunk) is well under this.
const HEADER_ALLOWANCE_BYTES: u64 = 1024;

impl WavFile {
    /// The most samples a mono file of `format` can hold: the RIFF and data sizes are u32 byte
    /// counts, so past about 4 GiB they would wrap and the file would be corrupt.
    pub fn max_samples(format: SampleFormat) -> u64 {
        (u32::MAX as u64 - HEADER_ALLOWANCE_BYTES) / format.bytes_per_sample() as u64
    }

    /// Refuses a render of `samples` samples that a WAV file cannot hold, before anything is
    /// written.
    pub fn check_length(
        path: &Path,
        samples: u64,
        sample_rate: u32,
        format: SampleFormat,
    ) -> Result<(), WavError> {
        let max_samples = Self::max_samples(format);
        if samples <= max_samples {
            return Ok(());
        }
        Err(WavError::TooLong {
            path: path.to_owned(),
            samples,
            max_samples,
            max_hours: max_samples as f64 / sample_rate.max(1) as f64 / 3600.0,
            sample_rate,
            format,
        })
    }

    /// Starts a mono file of `format` at `sample_rate` (Hz), to appear at `path` when committed.
    pub fn create(path: &Path, sample_rate: u32, format: SampleFormat) -> Result<Self, WavError> {
        let io_error = |source| WavError::Io {
            path: path.to_owned(),
            source,
        };
        let file = PendingFile::beside(path, "").map_err(io_error)?;
        let spec = wav_spec(sample_rate, format);
        let encode_error = |source| WavError::Encode {
            path: path.to_owned(),
            source,
        };
        // hound's header for this spec, as it writes it for a file without samples.
        let mut header = Cursor::new(Vec::new());
        WavWriter::new(&mut header, spec)
            .and_then(WavWriter::finalize)
            .map_err(encode_error)?;
        let header = header.into_inner();
        let mut writer = file.writer().map_err(io_error)?;
        writer.write_all(&header).map_err(io_error)?;
        Ok(Self {
            file,
            writer,
            format,
            sample_rate,
            written: 0,
            header_len: header.len() as u64,
            bytes: Vec::new(),
            clipped: 0,
        })
    }

    /// Appends samples; refuses (and so writes no file) once the file would pass the size a
    /// WAV can hold, as a render whose length was not known up front may.
    pub fn write(&mut self, samples: &[f32]) -> Result<(), WavError> {
        let written = self.written + samples.len() as u64;
        Self::check_length(self.file.path(), written, self.sample_rate, self.format)?;
        self.written = written;
        // Counted only in a block whose peak (a vectorised maximum) passes full scale: a
        // sample-by-sample count cost four instructions a sample of every render.
        if sake_glug_engine::peak(samples) > FULL_SCALE {
            self.clipped += samples.iter().filter(|y| y.abs() > FULL_SCALE).count() as u64;
        }
        let bytes: &[u8] = match self.format {
            // A little-endian machine holds f32 samples as the file does: no conversion at all.
            SampleFormat::F32 if cfg!(target_endian = "little") => bytemuck::cast_slice(samples),
            // Otherwise one loop per format, with the width known to the compiler.
            SampleFormat::F32 => convert::<4>(&mut self.bytes, samples, f32::to_le_bytes),
            SampleFormat::S24 => convert::<3>(&mut self.bytes, samples, |y| {
                let [low, middle, high, _] = quantize(y, 23).to_le_bytes();
                [low, middle, high]
            }),
            SampleFormat::S16 => convert::<2>(&mut self.bytes, samples, |y| {
                (quantize(y, 15) as i16).to_le_bytes()
            }),
        };
        self.writer.write_all(bytes).map_err(|source| WavError::Io {
            path: self.file.path().to_owned(),
            source,
        })
    }

    /// Completes the file (the sizes in its header), still in its temporary file.
    pub fn complete(self) -> Result<PendingFile, WavError> {
        let data_bytes = self.written * self.format.bytes_per_sample() as u64;
        // Where hound puts them: the RIFF size (all but its first 8 bytes) at 4, the data's
        // size in the last 4 bytes of the header. Both fit in 32 bits: `write` saw to it.
        let sizes = [
            (4, self.header_len - 8 + data_bytes),
            (self.header_len - 4, data_bytes),
        ];
        let Self {
            file, mut writer, ..
        } = self;
        let io_error = |source| WavError::Io {
            path: file.path().to_owned(),
            source,
        };
        for (offset, size) in sizes {
            writer
                .seek(SeekFrom::Start(offset))
                .and_then(|_| writer.write_all(&(size as u32).to_le_bytes()))
                .map_err(io_error)?;
        }
        writer.flush().map_err(io_error)?;
        Ok(file)
    }
}

impl SampleFormat {
    /// The name the command line uses for it.
    fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(format, _)| *format == self)
            .map_or("", |(_, name)| name)
    }

    /// "write s24 or s16, ": the formats whose files hold more samples, as advice; nothing for
    /// the narrowest.
    fn narrower_advice(self) -> String {
        let narrower: Vec<&str> = Self::ALL
            .iter()
            .filter(|(format, _)| format.bytes_per_sample() < self.bytes_per_sample())
            .map(|(_, name)| *name)
            .collect();
        if narrower.is_empty() {
            String::new()
        } else {
            format!("write {} (--sample-format), ", narrower.join(" or "))
        }
    }

    /// Bytes one sample takes in the file.
    fn bytes_per_sample(self) -> usize {
        match self {
            SampleFormat::F32 => 4,
            SampleFormat::S24 => 3,
            SampleFormat::S16 => 2,
        }
    }
}

/// The header of a mono file of `format` at `sample_rate` (Hz).
fn wav_spec(sample_rate: u32, format: SampleFormat) -> WavSpec {
    let (bits_per_sample, sample_format) = match format {
        SampleFormat::F32 => (32, HoundFormat::Float),
        SampleFormat::S24 => (24, HoundFormat::Int),
        SampleFormat::S16 => (16, HoundFormat::Int),
    };
    WavSpec {
        channels: 1,
        sample_rate,
        bits_per_sample,
        sample_format,
    }
}

/// `samples` in a format of `WIDTH` bytes per sample, in `bytes` (reused from block to block).
#[inline]
fn convert<'a, const WIDTH: usize>(
    bytes: &'a mut Vec<u8>,
    samples: &[f32],
    encode: impl Fn(f32) -> [u8; WIDTH],
) -> &'a [u8] {
    bytes.resize(samples.len() * WIDTH, 0);
    for (to, &y) in bytes.chunks_exact_mut(WIDTH).zip(samples) {
        to.copy_from_slice(&encode(y));
    }
    bytes
}

/// Rounds a sample in [−1, 1] to a signed integer of `fraction_bits` + 1 bits, saturating.
fn quantize(sample: f32, fraction_bits: u32) -> i32 {
    let full_scale = (1i64 << fraction_bits) as f64;
    (sample as f64 * full_scale)
        .round()
        .clamp(-full_scale, full_scale - 1.0) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_length_limit_sits_just_under_4_gib_of_data() {
        let limit = |format| WavFile::max_samples(format) as f64;
        // 4 GiB of f32 at 48 kHz is 6.2 h; at 768 kHz, 23 min.
        assert!((limit(SampleFormat::F32) / 48_000.0 / 3600.0 - 6.21).abs() < 0.01);
        assert!((limit(SampleFormat::F32) / 768_000.0 / 60.0 - 23.3).abs() < 0.1);
        assert!(limit(SampleFormat::S16) > 2.0 * limit(SampleFormat::F32) - 1.0);
        let path = Path::new("long.wav");
        let max = WavFile::max_samples(SampleFormat::S24);
        assert!(WavFile::check_length(path, max, 48_000, SampleFormat::S24).is_ok());
        let error = WavFile::check_length(path, max + 1, 48_000, SampleFormat::S24).unwrap_err();
        assert!(matches!(error, WavError::TooLong { .. }));
        assert!(error.to_string().contains("4 GiB"), "{error}");
    }

    /// Each format is told of the narrower ones only: an s16 render is not told to write s16.
    #[test]
    fn a_too_long_render_is_told_only_of_narrower_formats() {
        let path = Path::new("long.wav");
        let advice = |format| {
            let samples = WavFile::max_samples(format) + 1;
            let error = WavFile::check_length(path, samples, 48_000, format).unwrap_err();
            let message = error.to_string();
            let start = message.find("duration_s, ").unwrap() + "duration_s, ".len();
            message[start..].to_owned()
        };
        assert_eq!(
            advice(SampleFormat::F32),
            "write s24 or s16 (--sample-format), or write a .csv instead"
        );
        assert_eq!(
            advice(SampleFormat::S24),
            "write s16 (--sample-format), or write a .csv instead"
        );
        assert_eq!(advice(SampleFormat::S16), "or write a .csv instead");
    }

    /// Every format, written in blocks, against the same samples written by hound alone, one
    /// by one as the renderer used to: the same bytes.
    #[test]
    fn files_are_byte_for_byte_what_hound_writes() {
        let dir = tempfile::tempdir().unwrap();
        let mut samples: Vec<f32> = (0..10_001)
            .map(|i| (i as f32 * 0.0137).sin() * 1.2)
            .collect();
        samples.extend([0.0, -0.0, 1.0, -1.0, 2.0, -2.0, 1e-30, f32::MIN_POSITIVE]);
        for (format, name) in SampleFormat::ALL {
            for len in [0, 1, 2, 3, samples.len()] {
                let ours = dir.path().join(format!("ours-{name}-{len}.wav"));
                let mut file = WavFile::create(&ours, 44_100, format).unwrap();
                for block in samples[..len].chunks(777) {
                    file.write(block).unwrap();
                }
                PendingFile::commit_all(vec![file.complete().unwrap()]).unwrap();
                let theirs = dir.path().join(format!("hound-{name}-{len}.wav"));
                write_with_hound(&theirs, &samples[..len], format);
                assert!(
                    std::fs::read(&ours).unwrap() == std::fs::read(&theirs).unwrap(),
                    "{name}, {len} samples"
                );
            }
        }
    }

    fn write_with_hound(path: &Path, samples: &[f32], format: SampleFormat) {
        let spec = wav_spec(44_100, format);
        let mut writer = WavWriter::create(path, spec).unwrap();
        for &y in samples {
            match format {
                SampleFormat::F32 => writer.write_sample(y),
                SampleFormat::S24 => writer.write_sample(quantize(y, 23)),
                SampleFormat::S16 => writer.write_sample(quantize(y, 15) as i16),
            }
            .unwrap();
        }
        writer.finalize().unwrap();
    }

    #[test]
    fn quantize_rounds_and_saturates() {
        assert_eq!(quantize(0.5, 15), 16_384);
        assert_eq!(quantize(1.0, 15), 32_767);
        assert_eq!(quantize(-1.0, 15), -32_768);
        assert_eq!(quantize(-2.0, 23), -8_388_608);
    }
}
