//! What a listener hears in a pour, measured the same way in a recording and in a model's render
//! (MODEL.md §13, "How close a model sounds"): its glugs by a plain onset detector of its own
//! (an energy envelope's rises, not the fit's detector, so that a render and a recording are read
//! alike), their rate, each glug's low pitch, and the share of its energy above a split between
//! the bottle's two modes. (The log-spectral distance between two pours is
//! [`super::compare::log_spectral_distance`].)

use rustfft::num_complex::Complex;

use super::spectrum::{forward, Spectrum};

/// The envelope's frame (s).
const FRAME_S: f64 = 0.005;
/// A glug's envelope rises by this factor (3 dB in energy) from the quietest frame since the last
/// glug's peak (a glug joining one that still rings may add little more)…
const RISE: f64 = 2.0;
/// …to at least this share of the loudest frame (−30 dB: what stands out of a pour, not the
/// small bubbles and the codec's noise between its glugs)…
const ABOVE_LOUDEST: f64 = 1e-3;
/// …and this many times the noise (12 dB, as the fit's onsets ask; the noise here the quietest
/// tenth of the frames that are not digital silence), a gate never set higher than
/// [`NOISE_GATE_CAP`] of the loudest frame, so that a pour whose glugs never fall quiet keeps
/// every glug…
const ABOVE_NOISE: f64 = 16.0;
const NOISE_GATE_CAP: f64 = 1e-2;
/// …above the loudest of the [`PRIOR_FRAMES`] frames before it by [`PRIOR_RISE`] (a decaying
/// ring whose modes beat swells back to where it just was, a new glug rises past it)…
const PRIOR_FRAMES: usize = 4;
const PRIOR_RISE: f64 = 1.5;
/// …and comes at least this long after the last (s): a bottle glugs at most about 25 times a
/// second, and a glug's own modes and bubbles start within this of each other.
const MIN_GLUG_S: f64 = 0.04;
/// A glug's attack is sought this many frames back from where its rise is seen, at most.
const ATTACK_FRAMES: usize = 4;
/// A glug's low pitch is read from its first this many seconds, at most.
const PITCH_SPAN_S: f64 = 0.06;
/// The lowest pitch read (Hz).
const LOWEST_PITCH_HZ: f64 = 30.0;
/// A glug's pitch is voiced (drawn in the comparison's pitch track) where its span's energy is at
/// least this share of the loudest glug's (−30 dB: a glug, not the bubbles between glugs)…
const VOICED_ENERGY: f64 = 1e-3;
/// …and the span holds this many periods of the pitch read (a span cut short by the next onset
/// or the clip's end reads no pitch).
const VOICED_PERIODS: f64 = 2.0;

/// What a listener hears of one pour.
#[derive(Debug, Clone, PartialEq)]
pub struct Heard {
    /// Each glug's onset (s).
    pub onsets_s: Vec<f64>,
    /// Glugs a second over the glugs heard (NaN with fewer than 2).
    pub rate_per_s: f64,
    /// Each glug's low pitch, below the split (Hz; NaN where none is heard).
    pub pitch_hz: Vec<f64>,
    /// Whether each glug's pitch is voiced: its span loud enough and long enough to read it
    /// ([`VOICED_ENERGY`], [`VOICED_PERIODS`]); what the comparison's pitch track draws.
    pub voiced: Vec<bool>,
    /// The share of the energy above the split.
    pub high_share: f64,
}

impl Heard {
    /// How far the low pitch falls over the first `glugs` glugs: the first's over the last's (NaN
    /// where either is not heard).
    pub fn fall_over(&self, glugs: usize) -> f64 {
        let heard: Vec<f64> = self.pitch_hz.iter().take(glugs).copied().collect();
        match (heard.first(), heard.last()) {
            (Some(first), Some(last)) if heard.len() >= 2 => first / last,
            _ => f64::NAN,
        }
    }
}

/// The glugs of `samples` at `sample_rate`, their low pitch below `split_hz` and the energy above.
pub fn hear(samples: &[f32], sample_rate: f64, split_hz: f64) -> Heard {
    let onsets = glug_onsets(samples, sample_rate);
    let onsets_s: Vec<f64> = onsets.iter().map(|&n| n as f64 / sample_rate).collect();
    let rate_per_s = match (onsets_s.first(), onsets_s.last()) {
        (Some(first), Some(last)) if onsets_s.len() >= 2 && last > first => {
            (onsets_s.len() - 1) as f64 / (last - first)
        }
        _ => f64::NAN,
    };
    let span = (PITCH_SPAN_S * sample_rate) as usize;
    let spans: Vec<&[f32]> = onsets
        .iter()
        .enumerate()
        .map(|(i, &from)| {
            let to = onsets
                .get(i + 1)
                .copied()
                .unwrap_or(samples.len())
                .min(from + span)
                .min(samples.len());
            &samples[from..to]
        })
        .collect();
    let pitch_hz: Vec<f64> = spans
        .iter()
        .map(|span| low_pitch(span, sample_rate, split_hz))
        .collect();
    let energy = |span: &[f32]| {
        span.iter().map(|&y| f64::from(y).powi(2)).sum::<f64>() / span.len().max(1) as f64
    };
    let loudest = spans.iter().map(|span| energy(span)).fold(0.0, f64::max);
    let voiced = spans
        .iter()
        .zip(&pitch_hz)
        .map(|(span, &hz)| {
            let periods = hz * span.len() as f64 / sample_rate;
            energy(span) >= VOICED_ENERGY * loudest && periods >= VOICED_PERIODS
        })
        .collect();
    Heard {
        onsets_s,
        rate_per_s,
        pitch_hz,
        voiced,
        high_share: high_share(samples, sample_rate, split_hz),
    }
}

/// Where glugs start: the frames where the energy envelope has risen [`RISE`]-fold from its
/// quietest since the last glug's peak, at least [`MIN_GLUG_S`] after it, each placed at the
/// frame where its attack began. Until a glug's envelope has peaked and begun to fall, no new glug
/// starts: its own attack and the modes that join it are part of it.
pub(crate) fn glug_onsets(samples: &[f32], sample_rate: f64) -> Vec<usize> {
    let frame = ((FRAME_S * sample_rate) as usize).max(1);
    let energy: Vec<f64> = samples
        .chunks(frame)
        .map(|chunk| chunk.iter().map(|&y| f64::from(y).powi(2)).sum::<f64>() / frame as f64)
        .collect();
    let loudest = energy.iter().copied().fold(0.0, f64::max);
    if loudest <= 0.0 {
        return Vec::new();
    }
    let mut sounding: Vec<f64> = energy.iter().copied().filter(|&e| e > 0.0).collect();
    sounding.sort_by(f64::total_cmp);
    let noise = sounding[sounding.len() / 10];
    let gate = (ABOVE_LOUDEST * loudest).max((ABOVE_NOISE * noise).min(NOISE_GATE_CAP * loudest));
    let gap = (MIN_GLUG_S / FRAME_S).ceil() as usize;
    let mut onsets = Vec::new();
    let mut quietest = energy[0];
    let mut quietest_at = 0;
    // The last glug's frame and its envelope's peak so far, while it still rises.
    let mut last: Option<usize> = None;
    let mut rising = false;
    let mut peak = 0.0;
    for (i, &e) in energy.iter().enumerate() {
        if rising {
            if e >= peak {
                peak = e;
                continue;
            }
            // Past the peak: the quietest point is searched afresh from here.
            rising = false;
            (quietest, quietest_at) = (e, i);
        }
        if e < quietest {
            (quietest, quietest_at) = (e, i);
        }
        let clear = last.is_none_or(|l| i >= l + gap);
        let prior = energy[i.saturating_sub(PRIOR_FRAMES)..i]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        if clear && e >= gate && e >= RISE * quietest.max(1e-30) && e >= PRIOR_RISE * prior {
            // The glug starts where its attack does: the frames rising into this one, back to the
            // quietest point at most.
            let mut at = i;
            while at > quietest_at + 1 && at + ATTACK_FRAMES > i && energy[at - 1] < energy[at] {
                at -= 1;
            }
            onsets.push(at * frame);
            last = Some(at);
            (rising, peak) = (true, e);
        }
    }
    onsets
}

/// The strongest peak below `split_hz` of a Hann-windowed, zero-padded spectrum of `samples`.
fn low_pitch(samples: &[f32], sample_rate: f64, split_hz: f64) -> f64 {
    if samples.len() < 8 {
        return f64::NAN;
    }
    let padded = (8 * samples.len()).next_power_of_two().max(8192);
    let mut buffer: Vec<Complex<f64>> = samples
        .iter()
        .enumerate()
        .map(|(n, &y)| {
            let hann = 0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / samples.len() as f64).cos();
            Complex::new(f64::from(y) * hann, 0.0)
        })
        .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
        .take(padded)
        .collect();
    forward(padded).process(&mut buffer);
    let bin_hz = sample_rate / padded as f64;
    let (first, last) = (
        (LOWEST_PITCH_HZ / bin_hz).ceil() as usize,
        ((split_hz.min(0.5 * sample_rate) / bin_hz) as usize).min(padded / 2 - 1),
    );
    if first + 2 > last {
        return f64::NAN;
    }
    let power = |k: usize| buffer[k].norm_sqr();
    let peak = (first..=last).max_by(|&a, &b| power(a).total_cmp(&power(b)));
    match peak {
        Some(k) if power(k) > 0.0 && k > first && k < last => {
            // A parabola through the peak's log powers places it between bins.
            let (a, b, c) = (power(k - 1).ln(), power(k).ln(), power(k + 1).ln());
            let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
            (k as f64 + if shift.is_finite() { shift } else { 0.0 }) * bin_hz
        }
        Some(k) if power(k) > 0.0 => k as f64 * bin_hz,
        _ => f64::NAN,
    }
}

/// The share of the energy of `samples` above `split_hz` (Welch's spectrum).
pub fn high_share(samples: &[f32], sample_rate: f64, split_hz: f64) -> f64 {
    Spectrum::of(samples, sample_rate).share_above(split_hz)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Glugs at `rate` whose low mode falls from 200 Hz by `fall` over `glugs`, each with a
    /// short 1.2 kHz mode.
    fn glugs(rate: f64, glugs: usize, fall: f64, fs: f64) -> Vec<f32> {
        let len = ((glugs as f64 / rate + 0.3) * fs) as usize;
        let mut samples = vec![0f32; len];
        for g in 0..glugs {
            let start = ((0.05 + g as f64 / rate) * fs) as usize;
            let low = 200.0 / fall.powf(g as f64 / (glugs - 1) as f64);
            for (n, y) in samples[start..].iter_mut().enumerate() {
                let t = n as f64 / fs;
                let v = (-30.0 * t).exp() * (std::f64::consts::TAU * low * t).sin()
                    + 0.5 * (-150.0 * t).exp() * (std::f64::consts::TAU * 1200.0 * t).sin();
                *y += v as f32;
            }
        }
        samples
    }

    #[test]
    fn hears_the_rate_the_fall_and_the_bright_mode() {
        let fs = 44_100.0;
        let heard = hear(&glugs(9.0, 8, 2.0, fs), fs, 600.0);
        assert_eq!(heard.onsets_s.len(), 8, "{:?}", heard.onsets_s);
        assert!(
            (heard.rate_per_s / 9.0 - 1.0).abs() < 0.03,
            "{}",
            heard.rate_per_s
        );
        assert!(
            (heard.fall_over(8) / 2.0 - 1.0).abs() < 0.1,
            "{:?}",
            heard.pitch_hz
        );
        assert!(
            (0.02..0.5).contains(&heard.high_share),
            "{}",
            heard.high_share
        );
        let dull = hear(&glugs(9.0, 8, 1.0, fs), fs, 600.0);
        assert!((dull.fall_over(8) - 1.0).abs() < 0.05);
    }

    /// A clip cut 7 ms into its last glug reads a nonsense pitch there (a few periods of 30 Hz
    /// do not fit): that glug is not voiced, every whole one is.
    #[test]
    fn a_glug_cut_short_is_not_voiced() {
        let fs = 44_100.0;
        let whole = glugs(9.0, 4, 1.0, fs);
        let last_onset = ((0.05 + 3.0 / 9.0) * fs) as usize;
        let cut = &whole[..last_onset + (0.007 * fs) as usize];
        let heard = hear(cut, fs, 600.0);
        assert_eq!(heard.onsets_s.len(), 4, "{:?}", heard.onsets_s);
        assert_eq!(
            heard.voiced,
            [true, true, true, false],
            "{:?}",
            heard.pitch_hz
        );
        assert!(heard.pitch_hz[..3]
            .iter()
            .all(|hz| (hz / 200.0 - 1.0).abs() < 0.05));
    }

    #[test]
    fn a_pour_is_at_no_distance_from_itself_and_at_some_from_another() {
        let fs = 22_050.0;
        let (a, b) = (glugs(9.0, 8, 2.0, fs), glugs(9.0, 8, 1.0, fs));
        let (sa, sb) = (Spectrum::of(&a, fs), Spectrum::of(&b, fs));
        let distance = crate::compare::log_spectral_distance;
        assert!(distance(&sa, &sa, fs) < 1e-9);
        assert!(distance(&sa, &sb, fs) > 1.0);
    }
}
