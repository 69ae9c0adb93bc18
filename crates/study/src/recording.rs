//! A recorded stimulus (`audio = "FILE.wav"`, `start_s`): the spec's `duration_s` of a WAV file
//! from `start_s`, its first channel, read through the one reader (`sake_glug_io`) and hound.
//! Refused, with the file and the reason: a file that is not a WAV hound reads, a rate it cannot
//! be played at, an excerpt running past the file's end, silence, clipping and samples that are
//! not numbers (MODEL.md §15). At another rate than the interface's, the excerpt is resampled
//! with the project's one resampler ([`Resample`]) after these checks, once: every presentation
//! plays the same samples.

use std::path::{Path, PathBuf};

use sake_glug_io::read::{self, InputKind};
use sake_glug_io::text::printable;
use sake_glug_render::Resample;

/// The rates a recording may have (Hz): those a sound card plays.
pub const RECORDING_RATES_HZ: std::ops::RangeInclusive<u32> = 8_000..=384_000;

/// A peak at or below which a recording counts as silent: below the step of a 24-bit file.
const SILENT_PEAK: f64 = 1e-7;

/// Samples at or beyond this fraction of full scale count as clipped, in a run of
/// [`CLIPPED_RUN`] or more: a recording flattened by its converter is not the bottle.
const CLIPPED_LEVEL: f32 = 0.999;
const CLIPPED_RUN: usize = 3;

/// A recording named by a spec: where it is, where its excerpt starts, its rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// The file, as found from the spec's folder.
    pub path: PathBuf,
    /// Where the excerpt starts (s).
    pub start_s: f64,
    /// The file's sample rate (Hz), read from its header when the spec is loaded.
    pub sample_rate: u32,
}

impl Recording {
    /// The recording at `path` (its header read and checked), its excerpt from `start_s`.
    pub fn open(path: PathBuf, start_s: f64) -> Result<Self, String> {
        if !(start_s.is_finite() && start_s >= 0.0) {
            return Err(format!("`start_s` = {start_s}: a time from 0 (s)"));
        }
        let reader = wav_reader(&path)?;
        let sample_rate = reader.spec().sample_rate;
        if !RECORDING_RATES_HZ.contains(&sample_rate) {
            return Err(format!(
                "{}: at {sample_rate} Hz, a rate no interface plays (from {} to {} Hz)",
                shown(&path),
                RECORDING_RATES_HZ.start(),
                RECORDING_RATES_HZ.end()
            ));
        }
        Ok(Self {
            path,
            start_s,
            sample_rate,
        })
    }

    /// The excerpt of `duration_s` from `start_s`, its first channel, full scale ±1, for an
    /// interface at `sample_rate` Hz (resampled if the file's rate is another: then exactly
    /// `duration_s` × `sample_rate` samples, rounded, as a rendered stimulus has); or why it
    /// cannot be played.
    pub fn excerpt(&self, duration_s: f64, sample_rate: u32) -> Result<Vec<f32>, String> {
        let samples = self.excerpt_at_its_rate(duration_s)?;
        if self.sample_rate == sample_rate {
            return Ok(samples);
        }
        let mut resampled = Vec::new();
        let mut keep = |block: &[f64]| -> Result<(), std::convert::Infallible> {
            resampled.extend(block.iter().map(|&sample| sample as f32));
            Ok(())
        };
        let mut resample = Resample::new(self.sample_rate, sample_rate);
        let Ok(()) = resample.push(&samples, &mut keep);
        let Ok(()) = resample.finish(&mut keep);
        // ⌈n·to/from⌉ out may pass the rounded length by a sample.
        let length = (duration_s * f64::from(sample_rate)).round() as usize;
        resampled.resize(length, 0.0);
        Ok(resampled)
    }

    /// The excerpt at the file's own rate, checked.
    fn excerpt_at_its_rate(&self, duration_s: f64) -> Result<Vec<f32>, String> {
        let path = shown(&self.path);
        let mut reader = wav_reader(&self.path)?;
        let spec = reader.spec();
        let channels = usize::from(spec.channels.max(1));
        let rate = f64::from(self.sample_rate);
        let start = (self.start_s * rate).round() as u64;
        let length = (duration_s * rate).round() as u64;
        let frames = u64::from(reader.duration());
        if start + length > frames {
            return Err(format!(
                "{path}: holds {:.3} s, and the excerpt runs from `start_s` = {} s for the \
                 spec's `duration_s` = {duration_s} s, to {:.3} s: too short",
                frames as f64 / rate,
                self.start_s,
                (start + length) as f64 / rate
            ));
        }
        let wav_error = |error: hound::Error| format!("{path}: {error}");
        // The one reader reads forward only: the samples before the excerpt are read past.
        let skipped = start as usize * channels;
        let wanted = (length as usize) * channels;
        let interleaved: Vec<f32> = match spec.sample_format {
            hound::SampleFormat::Float => reader
                .samples::<f32>()
                .skip(skipped)
                .take(wanted)
                .collect::<Result<_, _>>()
                .map_err(wav_error)?,
            hound::SampleFormat::Int => {
                let full_scale = 2f32.powi(i32::from(spec.bits_per_sample) - 1);
                reader
                    .samples::<i32>()
                    .skip(skipped)
                    .take(wanted)
                    .map(|sample| sample.map(|sample| sample as f32 / full_scale))
                    .collect::<Result<_, _>>()
                    .map_err(wav_error)?
            }
        };
        if interleaved.len() < wanted {
            return Err(format!(
                "{path}: ends before its header says, within the excerpt: too short"
            ));
        }
        let samples: Vec<f32> = interleaved.iter().step_by(channels).copied().collect();
        if let Some(at) = samples.iter().position(|sample| !sample.is_finite()) {
            return Err(format!(
                "{path}: sample {} of the excerpt is not a number",
                start + at as u64
            ));
        }
        let peak = samples
            .iter()
            .fold(0.0f64, |peak, &sample| peak.max(f64::from(sample.abs())));
        if peak <= SILENT_PEAK {
            return Err(format!(
                "{path}: the excerpt is silent (its peak {peak:.1e} of full scale)"
            ));
        }
        let clipped = clipped_samples(&samples);
        if clipped > 0 {
            return Err(format!(
                "{path}: the excerpt is clipped ({clipped} samples in runs of {CLIPPED_RUN} or \
                 more at full scale): a flattened recording is not what was heard"
            ));
        }
        Ok(samples)
    }
}

/// The samples in runs of [`CLIPPED_RUN`] or more at [`CLIPPED_LEVEL`] of full scale or beyond.
fn clipped_samples(samples: &[f32]) -> usize {
    let mut clipped = 0;
    let mut run = 0;
    for &sample in samples {
        if sample.abs() >= CLIPPED_LEVEL {
            run += 1;
        } else {
            if run >= CLIPPED_RUN {
                clipped += run;
            }
            run = 0;
        }
    }
    if run >= CLIPPED_RUN {
        clipped += run;
    }
    clipped
}

type WavReader = hound::WavReader<std::io::BufReader<read::InputReader>>;

/// The WAV at `path` opened through the one reader, or why not.
fn wav_reader(path: &Path) -> Result<WavReader, String> {
    let input = read::open(path, InputKind::RECORDING).map_err(|error| error.to_string())?;
    hound::WavReader::new(std::io::BufReader::new(input))
        .map_err(|error| format!("{}: not a WAV file hound reads: {error}", shown(path)))
}

fn shown(path: &Path) -> String {
    printable(&path.to_string_lossy()).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_is_counted_in_runs_only() {
        assert_eq!(clipped_samples(&[1.0, 0.5, 1.0, 1.0, 0.2]), 0);
        assert_eq!(clipped_samples(&[0.1, 1.0, -1.0, 0.9995, 0.2]), 3);
        assert_eq!(clipped_samples(&[1.0; 4]), 4);
    }
}
