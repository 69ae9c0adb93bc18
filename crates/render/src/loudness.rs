//! The level of a render's waveform files (MODEL.md §19): its loudness measured as ITU-R
//! BS.1770-4 defines it and EBU R128 gates it (integrated loudness, loudness range, true peak
//! oversampled 4×), by the `ebur128` crate; and the one gain that brings it to the loudness or
//! under the true-peak ceiling asked for (`--loudness`, `--true-peak`).
//!
//! The gain is found on a first pass of the render (the same samples, as every render is
//! deterministic) and applied to the samples of the second before any sink hears them, so every
//! waveform file of the render (WAV, CSV, DualSense, Android's Ogg) carries it. The haptic clips
//! are written from the glugs, not the samples: `--haptic-peak` sets their drive
//! ([`HapticPeak`]).

use std::fmt;
use std::str::FromStr;

use ebur128::{EbuR128, Mode};

use crate::render::{render_scene, RenderError, RenderObserver};
use crate::resample::Resample;
use crate::scene::Scene;

/// EBU R128's gating block: a render shorter than this has no gated block, hence no integrated
/// loudness (s).
pub const GATING_BLOCK_S: f64 = 0.4;

/// The loudness a target may ask for (LUFS): from very quiet to full-scale square waves.
pub const LOUDNESS_RANGE_LUFS: std::ops::RangeInclusive<f64> = -70.0..=0.0;

/// The true-peak ceiling a target may ask for (dBTP).
pub const TRUE_PEAK_RANGE_DBTP: std::ops::RangeInclusive<f64> = -60.0..=0.0;

/// How far under a `--true-peak` ceiling the gain aims (dB, MODEL.md §19). The files hold each
/// sample times the gain as an f32, and their true peak, measured again on those samples, can
/// come out a few f32 steps above the first pass's peak times the gain: aimed at −1 dBTP itself,
/// a file measured −0.9999985. A ten-thousandth of a dB, far below anything heard or shown,
/// keeps the figure written at or under the ceiling.
pub const CEILING_MARGIN_DB: f64 = 1e-4;

/// What the render's output measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Loudness {
    /// Integrated loudness (LUFS), gated as EBU R128; −∞ for a render that is silent or has
    /// nothing above the absolute gate (−70 LUFS).
    pub integrated_lufs: f64,
    /// Loudness range (LU), EBU Tech 3342.
    pub range_lu: f64,
    /// True peak (dBTP), 4× oversampled (BS.1770-4 Annex 2).
    pub true_peak_dbtp: f64,
    /// Length measured (s).
    pub duration_s: f64,
}

impl Loudness {
    /// The same measurement after a gain of `gain_db` (a gain scales every figure but the
    /// range, which is a difference of loudnesses).
    pub fn after_gain(self, gain_db: f64) -> Self {
        Self {
            integrated_lufs: self.integrated_lufs + gain_db,
            true_peak_dbtp: self.true_peak_dbtp + gain_db,
            ..self
        }
    }
}

impl fmt::Display for Loudness {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let db = |value: f64| {
            if value.is_finite() {
                format!("{value:.1}")
            } else {
                "−∞".to_owned()
            }
        };
        write!(
            f,
            "{} LUFS, range {} LU, true peak {} dBTP",
            db(self.integrated_lufs),
            db(self.range_lu),
            db(self.true_peak_dbtp)
        )
    }
}

/// Measures a mono stream block by block.
pub struct LoudnessMeter {
    meter: EbuR128,
    sample_rate: u32,
    samples: u64,
}

impl LoudnessMeter {
    /// A meter of one channel at `sample_rate` (Hz).
    pub fn mono(sample_rate: u32) -> Self {
        Self::new(1, sample_rate)
    }

    /// A meter of `channels` interleaved channels at `sample_rate` (Hz), each weighted 1 as
    /// BS.1770 weights left, right and centre.
    pub fn new(channels: u32, sample_rate: u32) -> Self {
        let meter = EbuR128::new(channels, sample_rate, Mode::I | Mode::LRA | Mode::TRUE_PEAK)
            .expect("a render's channel count and rate are within the meter's limits");
        Self {
            meter,
            sample_rate,
            samples: 0,
        }
    }

    /// The next interleaved frames.
    pub fn add(&mut self, frames: &[f32]) {
        self.meter
            .add_frames_f32(frames)
            .expect("frames of the meter's channel count");
        self.samples += frames.len() as u64 / self.meter.channels() as u64;
    }

    /// What was heard.
    pub fn loudness(&self) -> Loudness {
        let to_db = |linear: f64| 20.0 * linear.log10();
        let true_peak = (0..self.meter.channels())
            .map(|channel| self.meter.true_peak(channel).unwrap_or(0.0))
            .fold(0.0, f64::max);
        Loudness {
            integrated_lufs: self.meter.loudness_global().unwrap_or(f64::NEG_INFINITY),
            range_lu: self.meter.loudness_range().unwrap_or(0.0),
            true_peak_dbtp: to_db(true_peak),
            duration_s: self.samples as f64 / self.sample_rate as f64,
        }
    }
}

/// The level asked of the waveform files: a loudness, a true-peak ceiling, or both.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LevelTarget {
    /// `--loudness`: the integrated loudness (LUFS) the render is brought to.
    pub loudness_lufs: Option<f64>,
    /// `--true-peak`: the ceiling (dBTP) its true peak is kept under. With a loudness too, the
    /// ceiling wins: the render then ends quieter than asked, and [`Levelled::held_by_peak`]
    /// says so.
    pub true_peak_dbtp: Option<f64>,
}

impl LevelTarget {
    /// Whether anything is asked (else the render is written as it comes).
    pub fn is_set(&self) -> bool {
        self.loudness_lufs.is_some() || self.true_peak_dbtp.is_some()
    }

    /// The gain that brings `measured` to this target, refused for a render that cannot be
    /// brought to a loudness (too short to gate, or silent).
    pub fn gain_for(&self, measured: &Loudness) -> Result<Levelled, LevelError> {
        let mut gain_db = 0.0;
        if let Some(target) = self.loudness_lufs {
            if measured.duration_s < GATING_BLOCK_S {
                return Err(LevelError::TooShort {
                    duration_s: measured.duration_s,
                });
            }
            if !measured.integrated_lufs.is_finite() {
                return Err(LevelError::Silent);
            }
            gain_db = target - measured.integrated_lufs;
        }
        let mut held_by_peak = false;
        let asked_db = gain_db;
        if let Some(ceiling) = self.true_peak_dbtp {
            let aim = ceiling - CEILING_MARGIN_DB;
            // A silent render has no peak to hold; nothing to lower.
            if measured.true_peak_dbtp.is_finite() && measured.true_peak_dbtp + gain_db > aim {
                gain_db = aim - measured.true_peak_dbtp;
                held_by_peak = self.loudness_lufs.is_some();
            }
        }
        Ok(Levelled {
            gain_db,
            held_by_peak,
            quieter_than_asked_lu: asked_db - gain_db,
            before: *measured,
            after: measured.after_gain(gain_db),
        })
    }
}

/// The gain a render's waveform files were given, and what they measure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Levelled {
    /// The gain (dB) applied to every sample.
    pub gain_db: f64,
    /// The true-peak ceiling lowered the gain below what the loudness asked: the files are
    /// quieter than the loudness target.
    pub held_by_peak: bool,
    /// How much quieter (LU) than the loudness asked the ceiling left the files (0 unless
    /// [`Levelled::held_by_peak`]).
    pub quieter_than_asked_lu: f64,
    /// The render as synthesised.
    pub before: Loudness,
    /// The files as written.
    pub after: Loudness,
}

impl Levelled {
    /// The gain as a factor of the samples.
    pub fn gain(&self) -> f32 {
        10f64.powf(self.gain_db / 20.0) as f32
    }
}

/// Why a render cannot be brought to a loudness.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LevelError {
    /// Shorter than one gating block: it has no integrated loudness.
    #[error(
        "--loudness: the render lasts {duration_s:.3} s, shorter than the {GATING_BLOCK_S} s \
         block EBU R128 gates loudness over, so it has no integrated loudness; give it a longer \
         duration_s, or level it with --true-peak alone"
    )]
    TooShort {
        /// Its length (s).
        duration_s: f64,
    },
    /// Nothing in it reaches the absolute gate (−70 LUFS): normalising it would need an
    /// unbounded gain.
    #[error(
        "--loudness: the render is silent (nothing above EBU R128's −70 LUFS gate), so no gain \
         brings it to a loudness; check that the scene pours"
    )]
    Silent,
}

/// `--loudness`'s value: a number of LUFS within [`LOUDNESS_RANGE_LUFS`].
pub fn parse_loudness(text: &str) -> Result<f64, String> {
    parse_level(text, LOUDNESS_UNIT)
}

/// `--true-peak`'s value: a number of dBTP within [`TRUE_PEAK_RANGE_DBTP`].
pub fn parse_true_peak(text: &str) -> Result<f64, String> {
    parse_level(text, TRUE_PEAK_UNIT)
}

/// A loudness given as a number (Python's `loudness=`), checked as `--loudness` checks its text.
pub fn check_loudness(value: f64) -> Result<f64, String> {
    check_level(value, &value.to_string(), LOUDNESS_UNIT)
}

/// A true-peak ceiling given as a number (Python's `true_peak=`), checked as `--true-peak`
/// checks its text.
pub fn check_true_peak(value: f64) -> Result<f64, String> {
    check_level(value, &value.to_string(), TRUE_PEAK_UNIT)
}

/// A level's unit and the range a target may ask for in it.
type LevelUnit = (&'static str, std::ops::RangeInclusive<f64>);
const LOUDNESS_UNIT: LevelUnit = ("LUFS", LOUDNESS_RANGE_LUFS);
const TRUE_PEAK_UNIT: LevelUnit = ("dBTP", TRUE_PEAK_RANGE_DBTP);

fn parse_level(text: &str, (unit, range): LevelUnit) -> Result<f64, String> {
    let number = text.trim();
    let number = number
        .strip_suffix(unit)
        .or_else(|| number.strip_suffix(&unit.to_lowercase()))
        .unwrap_or(number)
        .trim();
    // Text that is no number is refused as a number out of range is, with the same sentence.
    check_level(
        number.parse::<f64>().unwrap_or(f64::NAN),
        text,
        (unit, range),
    )
}

fn check_level(value: f64, text: &str, (unit, range): LevelUnit) -> Result<f64, String> {
    if range.contains(&value) {
        Ok(value)
    } else {
        Err(format!(
            "`{text}` is not a level from {} to {} {unit}",
            range.start(),
            range.end()
        ))
    }
}

/// The level stage of one render (MODEL.md §19), as every product applies it (the command
/// line's files through [`crate::render_to_files`], Python's samples): a first pass of the same
/// render measures it, once, for what was asked (the gain of a [`LevelTarget`], the sample peaks
/// `--haptic-peak` drives a haptic channel from); the second pass's samples go through
/// [`LevelStage::apply`] before anything hears them, and, with `measure`, are measured as
/// written.
pub struct LevelStage {
    levelled: Option<Levelled>,
    gain: Option<f32>,
    /// The samples as written, measured (with `measure`).
    meter: Option<LoudnessMeter>,
    /// Each rate asked for, with the peak |sample| of the render there, as synthesised.
    peaks: Vec<(u32, f64)>,
    scaled: Vec<f32>,
}

impl LevelStage {
    /// The stage for `scene` at `target`, measuring what is written if `measure`, and the
    /// render's sample peak at each of `peak_rates` (Hz; another rate than the scene's
    /// resampled, [`Resample`]). A first pass runs only if a target is set or a peak asked for;
    /// `observer` is asked on it whether to stop. A render that cannot be brought to the target
    /// is refused ([`LevelError`]).
    pub fn new<E: From<RenderError> + From<LevelError>>(
        scene: &Scene,
        target: &LevelTarget,
        measure: bool,
        peak_rates: &[u32],
        observer: &impl RenderObserver,
    ) -> Result<Self, E> {
        let mut stage = Self {
            levelled: None,
            gain: None,
            meter: measure.then(|| LoudnessMeter::mono(scene.sample_rate)),
            peaks: Vec::new(),
            scaled: Vec::new(),
        };
        if !target.is_set() && peak_rates.is_empty() {
            return Ok(stage);
        }
        let mut meter = target
            .is_set()
            .then(|| LoudnessMeter::mono(scene.sample_rate));
        let mut peaks: Vec<(u32, f64, Option<Resample>)> = Vec::new();
        for &rate in peak_rates {
            if !peaks.iter().any(|&(known, ..)| known == rate) {
                let resample =
                    (rate != scene.sample_rate).then(|| Resample::new(scene.sample_rate, rate));
                peaks.push((rate, 0.0, resample));
            }
        }
        let fold_peak = |peak: &mut f64, samples: &[f64]| {
            *peak = samples.iter().fold(*peak, |peak, y| peak.max(y.abs()));
            Ok::<(), RenderError>(())
        };
        render_scene(
            scene,
            |block: &[f32]| {
                if let Some(meter) = meter.as_mut() {
                    meter.add(block);
                }
                for (_, peak, resample) in &mut peaks {
                    match resample {
                        None => {
                            *peak = block
                                .iter()
                                .fold(*peak, |peak, &y| peak.max(y.abs().into()))
                        }
                        Some(resample) => {
                            resample.push(block, &mut |samples: &[f64]| fold_peak(peak, samples))?
                        }
                    }
                }
                Ok::<(), RenderError>(())
            },
            &mut Interruptible(observer),
        )?;
        for (rate, mut peak, resample) in peaks {
            if let Some(resample) = resample {
                resample.finish(&mut |samples: &[f64]| fold_peak(&mut peak, samples))?;
            }
            stage.peaks.push((rate, peak));
        }
        if let Some(meter) = meter {
            let levelled = target.gain_for(&meter.loudness())?;
            stage.gain = Some(levelled.gain());
            stage.levelled = Some(levelled);
        }
        Ok(stage)
    }

    /// The samples as the files are written from them: `block` at the stage's gain.
    pub fn apply<'a>(&'a mut self, block: &'a [f32]) -> &'a [f32] {
        let block = match self.gain {
            Some(gain) => {
                self.scaled.clear();
                self.scaled.extend(block.iter().map(|y| y * gain));
                &self.scaled[..]
            }
            None => block,
        };
        if let Some(meter) = self.meter.as_mut() {
            meter.add(block);
        }
        block
    }

    /// The gain (linear) [`LevelStage::apply`] gives every sample: 1 without a target.
    pub fn gain(&self) -> f64 {
        self.levelled
            .as_ref()
            .map_or(1.0, |levelled| 10f64.powf(levelled.gain_db / 20.0))
    }

    /// The render's sample peak at `rate` (Hz) as synthesised, before the gain, if it was asked
    /// for.
    pub fn peak_at(&self, rate: u32) -> Option<f64> {
        self.peaks
            .iter()
            .find(|&&(known, _)| known == rate)
            .map(|&(_, peak)| peak)
    }

    /// What the stage did, once the second pass has ended: the gain, and what the samples
    /// written measure (measured on them with `measure`, else as the first pass's figures after
    /// the gain); `None` if nothing was asked or measured.
    pub fn finish(self) -> Option<Levelled> {
        match (self.levelled, self.meter) {
            (Some(levelled), Some(meter)) => Some(Levelled {
                after: meter.loudness(),
                ..levelled
            }),
            (Some(levelled), None) => Some(levelled),
            (None, Some(meter)) => {
                let loudness = meter.loudness();
                Some(Levelled {
                    gain_db: 0.0,
                    held_by_peak: false,
                    quieter_than_asked_lu: 0.0,
                    before: loudness,
                    after: loudness,
                })
            }
            (None, None) => None,
        }
    }
}

/// An observer asked only whether to stop (the first pass reports no progress and no units).
struct Interruptible<'a, O>(&'a O);

impl<O: RenderObserver> RenderObserver for Interruptible<'_, O> {
    fn interrupted(&self) -> bool {
        self.0.interrupted()
    }
}

/// `--haptic-peak`: the drive the strongest moment of every haptic clip reaches, on the clips'
/// amplitude scale (0..1 of the motor's full drive; Android's 255, a rumble motor's 1.0, a
/// `.haptic` amplitude of 1.0, an `.ahap` intensity of √level, Core Haptics' intensity being
/// perceptual).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HapticPeak(f64);

impl HapticPeak {
    /// Full drive.
    pub const FULL: Self = Self(1.0);

    /// The level (0..1].
    pub fn level(self) -> f64 {
        self.0
    }
}

impl fmt::Display for HapticPeak {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.0} %", self.0 * 100.0)
    }
}

impl FromStr for HapticPeak {
    type Err = String;

    /// `100%`, `-3dB` or a level `0.8`: above 0, at most full drive.
    fn from_str(text: &str) -> Result<Self, String> {
        let trimmed = text.trim();
        let lower = trimmed.to_ascii_lowercase();
        let level = if let Some(percent) = lower.strip_suffix('%') {
            percent.trim().parse::<f64>().map(|p| p / 100.0)
        } else if let Some(db) = lower.strip_suffix("db") {
            db.trim().parse::<f64>().map(|db| 10f64.powf(db / 20.0))
        } else {
            lower.parse::<f64>()
        };
        level
            .ok()
            .and_then(|level| Self::of_level(level).ok())
            .ok_or_else(|| {
                format!(
                    "`{text}` is not a drive above 0 and at most full: give a percentage (100%), \
                     a level in dB (-3dB) or a fraction (0.8)"
                )
            })
    }
}

impl HapticPeak {
    /// The drive of `level`: above 0, at most full (a hair over, a percentage's or a level in
    /// dB's rounding, is full).
    pub fn of_level(level: f64) -> Result<Self, String> {
        if level > 0.0 && level <= 1.0 + 1e-12 {
            Ok(Self(level.min(1.0)))
        } else {
            Err(format!(
                "{level} is not a drive above 0 and at most full (1)"
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// EBU Tech 3341's signals, generated from their definitions: a 1 kHz sine, stereo, each
    /// channel at the given dBFS (the peak of the sine), for `seconds`, at 48 kHz.
    fn stereo_sine(dbfs: f64, seconds: f64) -> Vec<f32> {
        let rate = 48_000.0;
        let amplitude = 10f64.powf(dbfs / 20.0);
        (0..(seconds * rate) as usize)
            .flat_map(|n| {
                let y = (amplitude * (2.0 * std::f64::consts::PI * 1000.0 * n as f64 / rate).sin())
                    as f32;
                [y, y]
            })
            .collect()
    }

    fn measured(frames: &[f32]) -> Loudness {
        let mut meter = LoudnessMeter::new(2, 48_000);
        meter.add(frames);
        meter.loudness()
    }

    /// Tech 3341 case 1 and 2: 1 kHz at −23 dBFS reads −23.0 LUFS, at −33 dBFS −33.0, within
    /// the 0.1 LU the test allows.
    #[test]
    fn tech_3341_sines_read_their_loudness() {
        for dbfs in [-23.0, -33.0] {
            let loudness = measured(&stereo_sine(dbfs, 20.0));
            assert!(
                (loudness.integrated_lufs - dbfs).abs() <= 0.1,
                "{dbfs} dBFS: {loudness}"
            );
        }
    }

    /// Tech 3341 case 3's idea at its core: silence around a tone is gated out.
    #[test]
    fn silence_is_gated_out() {
        let mut frames = vec![0.0f32; 2 * 48_000 * 10];
        frames.extend(stereo_sine(-23.0, 10.0));
        frames.extend(vec![0.0f32; 2 * 48_000 * 10]);
        let loudness = measured(&frames);
        // The six blocks that straddle an edge of the tone pass both gates and pull it down a
        // little (measured −23.1): silence ten times as long as the tone moves it no more.
        assert!((loudness.integrated_lufs + 23.0).abs() <= 0.2, "{loudness}");
    }

    #[test]
    fn the_ceiling_wins_and_says_so() {
        let measured = Loudness {
            integrated_lufs: -30.0,
            range_lu: 3.0,
            true_peak_dbtp: -10.0,
            duration_s: 5.0,
        };
        let target = LevelTarget {
            loudness_lufs: Some(-16.0),
            true_peak_dbtp: Some(-1.0),
        };
        let levelled = target.gain_for(&measured).unwrap();
        let margin = CEILING_MARGIN_DB;
        let close =
            |value: f64, expected: f64| assert!((value - expected).abs() < 1e-12, "{value}");
        close(levelled.gain_db, 9.0 - margin);
        assert!(levelled.held_by_peak);
        close(levelled.quieter_than_asked_lu, 5.0 + margin);
        close(levelled.after.true_peak_dbtp, -1.0 - margin);
        close(levelled.after.integrated_lufs, -21.0 - margin);
        let alone = LevelTarget {
            loudness_lufs: Some(-23.0),
            true_peak_dbtp: Some(-1.0),
        };
        let levelled = alone.gain_for(&measured).unwrap();
        assert_eq!((levelled.gain_db, levelled.held_by_peak), (7.0, false));
    }

    #[test]
    fn short_or_silent_renders_are_refused() {
        let target = LevelTarget {
            loudness_lufs: Some(-23.0),
            true_peak_dbtp: None,
        };
        let short = measured(&stereo_sine(-20.0, 0.3));
        assert!(matches!(
            target.gain_for(&short),
            Err(LevelError::TooShort { .. })
        ));
        let silent = measured(&vec![0.0; 2 * 48_000 * 2]);
        assert_eq!(target.gain_for(&silent), Err(LevelError::Silent));
        // A true-peak ceiling alone leaves silence as it is.
        let ceiling = LevelTarget {
            loudness_lufs: None,
            true_peak_dbtp: Some(-1.0),
        };
        assert_eq!(ceiling.gain_for(&silent).unwrap().gain_db, 0.0);
    }

    #[test]
    fn haptic_peaks_parse() {
        let level = |text: &str| text.parse::<HapticPeak>().map(HapticPeak::level);
        assert_eq!(level("100%"), Ok(1.0));
        assert_eq!(level("0.8"), Ok(0.8));
        assert!((level("-6dB").unwrap() - 0.501).abs() < 1e-3);
        assert!(level("0").is_err());
        assert!(level("120%").is_err());
        assert!(level("3dB").is_err());
        assert!(level("NaN").is_err());
    }
}
