//! A recording's samples: any WAV hound reads, at 8 kHz or more, its first channel as f32 (all a
//! fit keeps of it while it runs: MODEL.md §13), with its DC offset removed. Refused: a recording
//! too long for the memory there is (before it is read, with the figures), non-finite samples
//! (with their count and the first), an isolated spike, and silence; clipping counted, and a file
//! that ends before its header says kept as far as it goes (warned).

use sake_glug_io::read::{self, InputKind};
use std::path::Path;

use super::error::{FitError, SampleFault};

/// The lowest sample rate the fit accepts (Hz): the glug's components lie below 1 kHz.
pub const MIN_SAMPLE_RATE_HZ: u32 = 8_000;

/// A peak (after the offset is removed) at or below which a recording counts as silent: below
/// the step of a 24-bit file.
const SILENT_PEAK: f64 = 1e-7;

/// Samples at or beyond this fraction of full scale count as clipped, when in a run of
/// [`CLIPPED_RUN`] or more.
const CLIPPED_LEVEL: f64 = 0.999;
const CLIPPED_RUN: usize = 3;

/// A peak more than this many times every sample further than [`SPIKE_GUARD_S`] from it is an
/// isolated spike (60 dB): no glug rises from nothing to its peak and back within 2 ms.
const SPIKE_RATIO: f64 = 1_000.0;
const SPIKE_GUARD_S: f64 = 0.001;

/// Bytes a fit holds per sample of the recording it is fitting: the samples and what is left of
/// them once the units found so far are taken out (f32 each). Every other buffer is a unit's.
pub const FIT_BYTES_PER_SAMPLE: u64 = 8;

/// One recording's first channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Audio {
    /// Sample rate (Hz).
    pub sample_rate: u32,
    /// The samples, full scale ±1, the mean removed.
    pub samples: Vec<f32>,
    /// The mean that was removed (the DC offset).
    pub offset: f64,
    /// Samples in runs of clipped samples.
    pub clipped: usize,
    /// Samples the header announced but the file did not hold, if it ends early.
    pub missing: Option<u64>,
}

impl Audio {
    /// Reads the WAV at `path` (named `key` in messages); refuses up front one whose fit would
    /// need more memory than the system has available.
    pub fn read(path: &Path, key: &str) -> Result<Self, FitError> {
        let wav_error = |source| FitError::Wav {
            key: key.to_owned(),
            path: path.to_owned(),
            source,
        };
        let input =
            read::open(path, InputKind::RECORDING).map_err(|source| FitError::RecordingRead {
                key: key.to_owned(),
                source,
            })?;
        let mut reader =
            hound::WavReader::new(std::io::BufReader::new(input)).map_err(wav_error)?;
        let spec = reader.spec();
        if spec.sample_rate < MIN_SAMPLE_RATE_HZ {
            return Err(FitError::RateTooLow {
                key: key.to_owned(),
                path: path.to_owned(),
                rate: spec.sample_rate,
                min: MIN_SAMPLE_RATE_HZ,
            });
        }
        let channels = spec.channels.max(1) as usize;
        let frames = u64::from(reader.len()) / channels as u64;
        let needed = frames.saturating_mul(FIT_BYTES_PER_SAMPLE);
        if let Some(available) = sake_glug_render::available_bytes().filter(|&a| needed > a) {
            return Err(FitError::TooLarge {
                key: key.to_owned(),
                path: path.to_owned(),
                samples: frames,
                needed,
                available,
            });
        }
        // A header may announce more than the file holds: reserve no more than 16 Mi samples.
        let mut samples = Vec::with_capacity(frames.min(1 << 24) as usize);
        let outcome = match spec.sample_format {
            hound::SampleFormat::Float => collect(
                reader.samples::<f32>().step_by(channels),
                &mut samples,
                |y| y,
            ),
            hound::SampleFormat::Int => {
                let full_scale = (1u64 << (spec.bits_per_sample - 1)) as f64;
                collect(
                    reader.samples::<i32>().step_by(channels),
                    &mut samples,
                    |y| (y as f64 / full_scale) as f32,
                )
            }
        };
        let missing = match outcome {
            Ok(()) => None,
            // A file cut short (a copy interrupted, a game's archive): what is there is kept.
            Err(hound::Error::IoError(error))
                if error.kind() == std::io::ErrorKind::UnexpectedEof && !samples.is_empty() =>
            {
                Some(frames.saturating_sub(samples.len() as u64))
            }
            Err(error) => return Err(wav_error(error)),
        };
        let mut audio = Self::from_samples(samples, spec.sample_rate, path, key)?;
        audio.missing = missing;
        Ok(audio)
    }

    /// The recording of `samples` at `sample_rate`, checked as a file's would be.
    pub fn from_samples(
        mut samples: Vec<f32>,
        sample_rate: u32,
        path: &Path,
        key: &str,
    ) -> Result<Self, FitError> {
        let fault = |fault| FitError::Samples {
            key: key.to_owned(),
            path: path.to_owned(),
            fault,
        };
        let non_finite = samples.iter().filter(|y| !y.is_finite()).count();
        if let Some(first) = samples.iter().position(|y| !y.is_finite()) {
            return Err(fault(SampleFault::NonFinite {
                count: non_finite,
                first,
                first_s: first as f64 / sample_rate as f64,
            }));
        }
        if let Some(spike) = isolated_spike(&samples, sample_rate) {
            return Err(fault(spike));
        }
        let clipped = clipped_samples(&samples);
        let offset = if samples.is_empty() {
            0.0
        } else {
            samples.iter().map(|&y| f64::from(y)).sum::<f64>() / samples.len() as f64
        };
        samples
            .iter_mut()
            .for_each(|sample| *sample = (f64::from(*sample) - offset) as f32);
        let peak = samples
            .iter()
            .fold(0.0f64, |peak, &y| peak.max(f64::from(y).abs()));
        if peak <= SILENT_PEAK {
            return Err(FitError::Silent {
                key: key.to_owned(),
                path: path.to_owned(),
                peak,
            });
        }
        Ok(Self {
            sample_rate,
            samples,
            offset,
            clipped,
            missing: None,
        })
    }

    /// Length (s).
    pub fn duration_s(&self) -> f64 {
        self.samples.len() as f64 / self.sample_rate as f64
    }
}

/// Collects `samples` into `into` as f32 until the first error, which it returns.
fn collect<T>(
    samples: impl Iterator<Item = Result<T, hound::Error>>,
    into: &mut Vec<f32>,
    convert: impl Fn(T) -> f32,
) -> Result<(), hound::Error> {
    for sample in samples {
        into.push(convert(sample?));
    }
    Ok(())
}

/// The largest sample, if it is [`SPIKE_RATIO`] times every sample further than
/// [`SPIKE_GUARD_S`] from it.
fn isolated_spike(samples: &[f32], sample_rate: u32) -> Option<SampleFault> {
    let (at, peak) = samples
        .iter()
        .enumerate()
        .map(|(n, y)| (n, f64::from(y.abs())))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let guard = (SPIKE_GUARD_S * sample_rate as f64) as usize;
    let others = samples[..at.saturating_sub(guard)]
        .iter()
        .chain(&samples[(at + guard + 1).min(samples.len())..])
        .fold(0.0f64, |largest, y| largest.max(f64::from(y.abs())));
    let ratio = peak / others;
    (peak > SILENT_PEAK && ratio > SPIKE_RATIO).then(|| SampleFault::Spike {
        at,
        at_s: at as f64 / sample_rate as f64,
        value: f64::from(samples[at]),
        ratio,
    })
}

/// Samples in runs of at least [`CLIPPED_RUN`] at or beyond [`CLIPPED_LEVEL`] of full scale.
fn clipped_samples(samples: &[f32]) -> usize {
    let mut clipped = 0;
    let mut run = 0;
    for &sample in samples.iter().chain(std::iter::once(&0.0)) {
        if f64::from(sample.abs()) >= CLIPPED_LEVEL {
            run += 1;
        } else {
            if run >= CLIPPED_RUN {
                clipped += run;
            }
            run = 0;
        }
    }
    clipped
}
