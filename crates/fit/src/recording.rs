//! One recording, fitted (MODEL.md §13): its samples read and checked, its units found and
//! fitted, its weight log read and its drain line and rest level drawn. Only what the estimates,
//! the report and the plots need is kept: the units, the spectrum and the first seconds of the
//! samples; the samples go once the recording is fitted, so that a session's recordings are held
//! one at a time.

use super::audio::Audio;
use super::error::FitError;
use super::session::RecordingSpec;
use super::spectrum::Spectrum;
use super::stats::{median, Line};
use super::units::{fit_units, DetectedUnit, UnitFit};
use super::weight::WeightLog;

/// A weight log whose last second falls by less than this share of the pour's rate (and less than
/// [`FLAT_ML`]) has stopped pouring: its end is the rest level.
const FLAT_SHARE: f64 = 0.03;
const FLAT_ML: f64 = 0.5;
/// The end of a weight log read for its rest level (s).
const REST_TAIL_S: f64 = 1.0;
/// The samples kept for the plots (s from the start).
pub const EXCERPT_S: f64 = 10.0;
/// A recording whose units explain less than this share of its energy is warned about.
pub const LOW_EXPLAINED: f64 = 0.5;

/// A unit with the volume in the bottle at its onset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedUnit {
    /// Its fit.
    pub fit: UnitFit,
    /// V_i (ml; NaN where unknown).
    pub volume_ml: f64,
}

/// The straight drain of one recording (paper eq. 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrainLine {
    /// V(t) = line.at(t) while it pours; −slope is the outflow rate k (ml/s).
    pub line: Line,
    /// From the weight log (else from the glug count × pocket).
    pub from_weight: bool,
    /// The time span it was fitted over (s).
    pub span_s: (f64, f64),
}

impl DrainLine {
    /// The outflow rate k (ml/s).
    pub fn rate_ml_per_s(&self) -> f64 {
        -self.line.slope
    }
}

/// One recording, fitted.
#[derive(Debug, Clone)]
pub struct RecordingFit {
    /// As the session gives it.
    pub spec: RecordingSpec,
    /// Sample rate (Hz).
    pub sample_rate: u32,
    /// Length (s).
    pub duration_s: f64,
    /// Its first [`EXCERPT_S`] seconds (DC removed), for the plots.
    pub excerpt: Vec<f32>,
    /// Samples in runs of clipped samples.
    pub clipped: usize,
    /// Its units used, with their volumes.
    pub units: Vec<FittedUnit>,
    /// Every unit detected, used or not, and why not.
    pub detected: Vec<DetectedUnit>,
    /// The share of its energy the units used explain.
    pub explained: f64,
    /// Its spectrum.
    pub spectrum: Spectrum,
    /// f1, f2 where eq. 1's fits started (Hz).
    pub start_hz: [f64; 2],
    /// The weight log, as volumes.
    pub weight: Option<WeightLog>,
    /// The drain line, if one could be drawn.
    pub drain: Option<DrainLine>,
    /// What remained once it stopped pouring (ml), if the log shows it.
    pub rest_ml: Option<f64>,
}

impl RecordingFit {
    /// The name the report, the JSON and the units table give it: its file, as the session or the
    /// command line names it.
    pub fn name(&self) -> String {
        self.spec.audio.to_string_lossy().into_owned()
    }

    /// Units detected whose fit was rejected.
    pub fn rejected(&self) -> usize {
        self.detected
            .iter()
            .filter(|d| d.rejection.is_some())
            .count()
    }
}

/// Reads, detects and fits one recording, its drain line and rest level from its weight log.
pub(crate) fn fit_recording(
    spec: &RecordingSpec,
    capacity_ml: f64,
    warnings: &mut Vec<String>,
) -> Result<RecordingFit, FitError> {
    let audio_key = spec.audio_key.clone();
    let audio = Audio::read(&spec.audio, &audio_key)?;
    let weight = spec
        .weight
        .as_ref()
        .map(|weight| WeightLog::read(weight, &spec.key, spec.start_ml, capacity_ml))
        .transpose()?;
    if audio.clipped > 0 {
        warnings.push(format!(
            "`{audio_key}`: {} samples are clipped (runs at full scale): the amplitudes of the \
             units there are too low",
            audio.clipped
        ));
    }
    if let Some(missing) = audio.missing {
        warnings.push(format!(
            "`{audio_key}`: the file ends {missing} samples before its header says: the samples \
             there are fitted"
        ));
    }
    let found = fit_units(&audio.samples, audio.sample_rate);
    if found.detected.is_empty() {
        warnings.push(format!("`{audio_key}`: no glugs found"));
    } else if found.units.len() * 2 < found.detected.len() {
        warnings.push(format!(
            "`{audio_key}`: only {} of its {} detected units are described by the paper's model \
             (see the reasons in the units table)",
            found.units.len(),
            found.detected.len()
        ));
    }
    if !found.detected.is_empty() && found.explained < LOW_EXPLAINED {
        warnings.push(format!(
            "`{audio_key}`: the units fitted explain only {:.0} % of its energy: the paper's \
             model describes this recording poorly",
            100.0 * found.explained
        ));
    }
    let excerpt_len =
        ((EXCERPT_S * f64::from(audio.sample_rate)) as usize).min(audio.samples.len());
    let mut recording = RecordingFit {
        spec: spec.clone(),
        sample_rate: audio.sample_rate,
        duration_s: audio.duration_s(),
        excerpt: audio.samples[..excerpt_len].to_vec(),
        clipped: audio.clipped,
        units: found
            .units
            .iter()
            .map(|&fit| FittedUnit {
                fit,
                volume_ml: f64::NAN,
            })
            .collect(),
        detected: found.detected,
        explained: found.explained,
        spectrum: found.spectrum,
        start_hz: found.start_hz,
        weight,
        drain: None,
        rest_ml: None,
    };
    drop(audio);
    if let Some(log) = &recording.weight {
        let (first, last) = match (recording.units.first(), recording.units.last()) {
            (Some(first), Some(last)) => (first.fit.onset_s, last.fit.onset_s),
            _ => (0.0, recording.duration_s),
        };
        let during: Vec<(f64, f64)> = log
            .points
            .iter()
            .copied()
            .filter(|&(t, _)| t >= first && t <= last)
            .collect();
        match Line::through(&during).filter(|line| line.slope < 0.0) {
            Some(line) => {
                recording.drain = Some(DrainLine {
                    line,
                    from_weight: true,
                    span_s: (first, last),
                });
                for unit in &mut recording.units {
                    unit.volume_ml = line.at(unit.fit.onset_s).clamp(0.0, capacity_ml);
                }
            }
            None => warnings.push(format!(
                "`{}.weight`: fewer than 3 falling readings while it glugs: no drain line",
                spec.key
            )),
        }
        recording.rest_ml = rest_level(log, recording.drain.as_ref());
        if recording.rest_ml.is_none() {
            warnings.push(format!(
                "`{}.weight`: the log still falls at its end: the rest level at {}° is unknown",
                spec.key, spec.tilt_deg
            ));
        }
    }
    Ok(recording)
}

/// The level the log settles at, if its last second is flat.
fn rest_level(log: &WeightLog, drain: Option<&DrainLine>) -> Option<f64> {
    let end_s = log.points.last()?.0;
    let tail: Vec<f64> = log
        .points
        .iter()
        .filter(|p| p.0 >= end_s - REST_TAIL_S)
        .map(|p| p.1)
        .collect();
    let fall = log.volume_at(end_s - REST_TAIL_S) - log.points.last()?.1;
    let allowed = drain.map_or(FLAT_ML, |d| (FLAT_SHARE * d.rate_ml_per_s()).max(FLAT_ML));
    (tail.len() >= 2 && fall.abs() <= allowed).then(|| median(&tail).max(0.0))
}
