//! Trimming a render's silent tail (`--trim`, MODEL.md §10.2): the file ends once its last unit
//! has decayed below a level re the render's peak, with a short fade after that point.
//!
//! The end is found from the units themselves (each unit's two components decay as
//! A·e^(−Bτ), MODEL.md §5), by a first render that keeps only the units and the peak; the
//! trimmed scene is then the same scene with that duration and the fade, rendered as any other.
//! The engine's samples do not depend on where a render ends, so every sample before the fade is
//! the untrimmed render's, bit for bit.

use super::render::{render_scene, RenderError, RenderObserver};
use super::scene::{FadeOut, Scene};
use super::tables::UnitRow;
use sake_glug_engine::{Glide, UnitOnset, Voicing};

/// The level of `--trim` without a value (dB re the render's peak).
pub const DEFAULT_TRIM_DB: f64 = -60.0;

/// How long the fade after the trim point lasts (s): short enough to add nothing audible, long
/// enough that the end does not click (the 80 Hz component turns by most of a period in it).
pub const TRIM_FADE_S: f64 = 0.010;

/// A `--trim` level that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("--trim {0}: the level is in dB below the peak: a finite number below 0, such as -60")]
pub struct TrimLevelError(pub f64);

/// Checks a trim level: finite and below 0 dB.
pub fn check_trim_db(level_db: f64) -> Result<f64, TrimLevelError> {
    if level_db.is_finite() && level_db < 0.0 {
        Ok(level_db)
    } else {
        Err(TrimLevelError(level_db))
    }
}

/// When a unit of the units table has decayed below `threshold` (in output units) for good:
/// its onset plus the time its two components' sum A1·e^(−B1·τ) + A2·e^(−B2·τ) takes to fall to
/// the threshold; a component the engine omits (reaching Nyquist, its `glide`'s start included,
/// or below 20 Hz: [`Glide::sounds`]) counts for nothing. `None` for a unit that starts at or below the threshold (it
/// keeps nothing audible); infinity for one that never falls below it (a decay rate of 0).
pub fn unit_decayed_s(
    unit: &UnitRow,
    threshold: f64,
    sample_rate: f64,
    glide: &Glide,
) -> Option<f64> {
    let sounds = |index: usize, frequency_hz: f64| {
        unit.audible && glide.sounds(index, frequency_hz, sample_rate)
    };
    let components: Vec<(f64, f64)> = [
        (unit.f1_hz, unit.a1.abs(), unit.b1_per_s),
        (unit.f2_hz, unit.a2.abs(), unit.b2_per_s),
    ]
    .into_iter()
    .enumerate()
    .filter(|&(index, (frequency_hz, amplitude, _))| sounds(index, frequency_hz) && amplitude > 0.0)
    .map(|(_, (_, amplitude, decay))| (amplitude, decay))
    .collect();
    let level = |tau: f64| -> f64 {
        components
            .iter()
            .map(|&(amplitude, decay)| amplitude * (-decay * tau).exp())
            .sum()
    };
    if level(0.0) <= threshold {
        return None;
    }
    if components.iter().any(|&(_, decay)| decay <= 0.0) {
        return Some(f64::INFINITY);
    }
    // Each component below half the threshold by then: the sum is below it.
    let mut high = components
        .iter()
        .map(|&(amplitude, decay)| (2.0 * amplitude / threshold).ln().max(0.0) / decay)
        .fold(0.0, f64::max);
    let mut low = 0.0;
    // The sum falls monotonically: bisect to well below a sample.
    for _ in 0..80 {
        let middle = 0.5 * (low + high);
        if level(middle) > threshold {
            low = middle;
        } else {
            high = middle;
        }
    }
    Some(unit.onset_s + high)
}

/// What a first render tells the trim: its units, its peak and its length.
struct UnitsAndPeak {
    sample_rate: f64,
    units: Vec<UnitRow>,
}

impl RenderObserver for UnitsAndPeak {
    fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
        self.units
            .push(UnitRow::of(onset, voicing, self.sample_rate));
    }
}

/// The sample at which every unit of a render with these `units` and this `peak` has decayed
/// below `level_db` re the peak (rounded up), or `None` if one never does; `glide` is the
/// model's (MODEL.md §5.2).
pub fn trim_point(
    units: &[UnitRow],
    peak: f64,
    sample_rate: f64,
    level_db: f64,
    glide: &Glide,
) -> Option<u64> {
    let threshold = peak * 10f64.powf(level_db / 20.0);
    let last_s = units
        .iter()
        .filter_map(|unit| unit_decayed_s(unit, threshold, sample_rate, glide))
        .fold(0.0, f64::max);
    last_s
        .is_finite()
        .then(|| (last_s * sample_rate).ceil() as u64)
}

/// `scene` ending where its last unit has decayed below `level_db` re its peak, with a fade of
/// [`TRIM_FADE_S`] after that point; the scene as it is if its render ends sooner (then it is
/// already silent there). Renders the scene once to find the point.
pub fn trimmed(scene: Scene, level_db: f64) -> Result<Scene, RenderError> {
    let mut observer = UnitsAndPeak {
        sample_rate: scene.sample_rate as f64,
        units: Vec::new(),
    };
    let summary = render_scene(&scene, |_: &[f32]| Ok::<(), RenderError>(()), &mut observer)?;
    let sample_rate = scene.sample_rate as f64;
    let Some(point) = trim_point(
        &observer.units,
        summary.peak as f64,
        sample_rate,
        level_db,
        &scene.config.glide,
    ) else {
        return Ok(scene);
    };
    let fade_samples = (TRIM_FADE_S * sample_rate).round().max(1.0) as u64;
    let end = (point + fade_samples).min(summary.samples);
    if end >= summary.samples {
        return Ok(scene);
    }
    Ok(Scene {
        duration_s: Some(end as f64 / sample_rate),
        fade_out: Some(FadeOut { start: point, end }),
        ..scene
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fade_falls_from_one_to_zero() {
        let fade = FadeOut { start: 10, end: 20 };
        assert_eq!(fade.gain(9), 1.0);
        assert!(fade.gain(10) < 1.0 && fade.gain(10) > 0.9);
        assert_eq!(fade.gain(19), 0.0);
        let mut block = [1.0f32; 32];
        fade.apply(0, &mut block);
        assert!(block.windows(2).all(|pair| pair[1] <= pair[0]));
        assert_eq!(block[19..], [0.0; 13]);
    }

    #[test]
    fn a_level_must_be_below_zero_and_finite() {
        assert!(check_trim_db(-60.0).is_ok());
        for bad in [0.0, 6.0, f64::NAN, f64::NEG_INFINITY] {
            assert!(check_trim_db(bad).is_err(), "{bad}");
        }
    }
}
