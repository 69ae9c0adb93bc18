//! A recording's samples: any WAV hound reads, at 8 kHz or more, its first channel, with its DC
//! offset removed; silence refused, clipping counted.

use sake_glug_io::read::{self, InputKind};
use std::path::Path;

use super::error::FitError;

/// The lowest sample rate the fit accepts (Hz): the glug's components lie below 1 kHz.
pub const MIN_SAMPLE_RATE_HZ: u32 = 8_000;

/// A peak (after the offset is removed) at or below which a recording counts as silent: below
/// the step of a 24-bit file.
const SILENT_PEAK: f64 = 1e-7;

/// Samples at or beyond this fraction of full scale count as clipped, when in a run of
/// [`CLIPPED_RUN`] or more.
const CLIPPED_LEVEL: f64 = 0.999;
const CLIPPED_RUN: usize = 3;

/// One recording's first channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Audio {
    /// Sample rate (Hz).
    pub sample_rate: u32,
    /// The samples, full scale ±1, the mean removed.
    pub samples: Vec<f64>,
    /// The mean that was removed (the DC offset).
    pub offset: f64,
    /// Samples in runs of clipped samples.
    pub clipped: usize,
}

impl Audio {
    /// Reads the WAV at `path` (named `key` in messages).
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
        let samples: Vec<f64> = match spec.sample_format {
            hound::SampleFormat::Float => reader
                .samples::<f32>()
                .step_by(channels)
                .map(|sample| sample.map(f64::from))
                .collect::<Result<_, _>>()
                .map_err(wav_error)?,
            hound::SampleFormat::Int => {
                let full_scale = (1u64 << (spec.bits_per_sample - 1)) as f64;
                reader
                    .samples::<i32>()
                    .step_by(channels)
                    .map(|sample| sample.map(|value| value as f64 / full_scale))
                    .collect::<Result<_, _>>()
                    .map_err(wav_error)?
            }
        };
        Self::from_samples(samples, spec.sample_rate, path, key)
    }

    /// The recording of `samples` at `sample_rate`, checked as a file's would be.
    pub fn from_samples(
        mut samples: Vec<f64>,
        sample_rate: u32,
        path: &Path,
        key: &str,
    ) -> Result<Self, FitError> {
        let clipped = clipped_samples(&samples);
        let finite = samples.iter().all(|sample| sample.is_finite());
        let offset = if finite && !samples.is_empty() {
            samples.iter().sum::<f64>() / samples.len() as f64
        } else {
            0.0
        };
        samples.iter_mut().for_each(|sample| *sample -= offset);
        let peak = samples.iter().fold(0.0f64, |peak, &y| peak.max(y.abs()));
        if !finite || peak <= SILENT_PEAK {
            return Err(FitError::Silent {
                key: key.to_owned(),
                path: path.to_owned(),
                peak: if finite { peak } else { f64::NAN },
            });
        }
        Ok(Self {
            sample_rate,
            samples,
            offset,
            clipped,
        })
    }

    /// Length (s).
    pub fn duration_s(&self) -> f64 {
        self.samples.len() as f64 / self.sample_rate as f64
    }
}

/// Samples in runs of at least [`CLIPPED_RUN`] at or beyond [`CLIPPED_LEVEL`] of full scale.
fn clipped_samples(samples: &[f64]) -> usize {
    let mut clipped = 0;
    let mut run = 0;
    for &sample in samples.iter().chain(std::iter::once(&0.0)) {
        if sample.abs() >= CLIPPED_LEVEL {
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
