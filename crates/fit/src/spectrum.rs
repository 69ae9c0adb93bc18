//! The recording's power spectrum (Welch's method, rustfft) and its two strongest peaks: the
//! starting guess of f1 and f2 for eq. 1, and panel (b) of the plot; and a unit's own spectrum
//! and its peaks, where a unit that eq. 1 does not describe is started.

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

/// Segment length (s) of Welch's average: fine enough to part 80 Hz from its neighbours (a
/// decaying component's peak is B/π wide, about 14 Hz at 45 /s).
const SEGMENT_S: f64 = 0.16;

/// The quantile of a bin's powers over a recording's segments that its noise is read from: the
/// glugs fill most segments, the quietest fifth holds little but noise.
const NOISE_QUANTILE: f64 = 0.2;

/// A bin's noise is the median of the quiet powers of the bins within this ratio of its
/// frequency (half an octave either side).
const NOISE_NEIGHBOURHOOD: f64 = std::f64::consts::SQRT_2;

/// A bin less its noise keeps at least this share of itself (a bin of noise alone has no
/// power of its own to keep, but a log-spectral distance needs some).
const KEPT_UNDER_NOISE: f64 = 0.03;

/// Lowest frequency searched for a peak (Hz): below it lie drift and handling noise.
const LOWEST_PEAK_HZ: f64 = 20.0;

/// A peak weaker than this fraction of the strongest (in power) is no component: 30 dB.
const WEAKEST_PEAK: f64 = 1e-3;

/// Two peaks closer than this ratio of frequencies are one component.
pub(crate) const PEAK_SEPARATION: f64 = 1.4;

/// A unit's second peak counts as a component if within this fraction of its strongest (in
/// power): 20 dB.
const WEAKEST_OWN_PEAK: f64 = 1e-2;

/// A unit's spectrum is zero-padded to at least this many times its length, and to a bin of at
/// most [`OWN_BIN_HZ`]: with a parabola through the peak's bins, fine enough to place a peak
/// within a few hertz.
const OWN_PADDING: usize = 2;
const OWN_BIN_HZ: f64 = 4.0;

thread_local! {
    /// rustfft's planner keeps the plans it made: a fit asks for the same few lengths again and
    /// again.
    static PLANNER: std::cell::RefCell<FftPlanner<f64>> = std::cell::RefCell::new(FftPlanner::new());
}

/// The forward FFT of `len` points, planned once per length and thread.
pub(crate) fn forward(len: usize) -> std::sync::Arc<dyn rustfft::Fft<f64>> {
    PLANNER.with(|planner| planner.borrow_mut().plan_fft_forward(len))
}

/// Welch's segments of `samples` (Hann windows, half overlapping, a power of two long, the
/// last zero-padded): each one's power per bin, from 0 Hz to Nyquist, to `each`; the bins'
/// spacing (Hz).
fn segment_powers(samples: &[f32], sample_rate: f64, mut each: impl FnMut(&[f64])) -> f64 {
    let len = ((SEGMENT_S * sample_rate) as usize)
        .next_power_of_two()
        .min(samples.len().next_power_of_two().max(16));
    let fft = forward(len);
    let window: Vec<f64> = (0..len)
        .map(|n| 0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / len as f64).cos())
        .collect();
    let mut power = vec![0.0; len / 2 + 1];
    let mut buffer = vec![Complex::new(0.0, 0.0); len];
    let mut start = 0;
    loop {
        for (n, slot) in buffer.iter_mut().enumerate() {
            let sample = samples.get(start + n).map_or(0.0, |&y| f64::from(y));
            *slot = Complex::new(sample * window[n], 0.0);
        }
        fft.process(&mut buffer);
        for (bin, slot) in power.iter_mut().enumerate() {
            *slot = buffer[bin].norm_sqr();
        }
        each(&power);
        start += len / 2;
        if start + len > samples.len() {
            break;
        }
    }
    sample_rate / len as f64
}

/// A held line stands at least this far above its neighbourhood in the quiet segments: 10 dB.
const HELD_LINE_ABOVE: f64 = 10.0;
/// A held line's loud segments ([`NOISE_QUANTILE`] from the top) hold at most this many times
/// its quiet ones: 3 dB (a bin of noise alone spreads 7.2 times between them, a glug's mode more).
const HELD_LINE_STEADY: f64 = 2.0;
/// A held line is as narrow as a steady sinusoid's: [`HELD_LINE_ABOVE`] down this many bins
/// either side (a Hann window's main lobe is 2 wide; a mode decaying at B is B/π Hz wide, 8 bins
/// at 140 /s).
const HELD_LINE_WIDTH_BINS: usize = 3;
/// A unit's peak within this many of the recording's bins of a held line is that line.
const HELD_LINE_REACH_BINS: f64 = 2.0;

/// The lines a recording holds throughout ([`Spectrum::held_lines`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HeldLines {
    /// Their frequencies (Hz).
    pub hz: Vec<f64>,
    /// A peak this near one (Hz) is that line.
    pub reach_hz: f64,
}

impl HeldLines {
    /// Whether a peak at `hz` is one of these lines.
    pub fn holds(&self, hz: f64) -> bool {
        self.hz
            .iter()
            .any(|&line| (hz - line).abs() <= self.reach_hz)
    }
}

/// Per bin of `samples`' Welch segments, the power at each of the `quantiles` of its segments'
/// powers; the bins' spacing (Hz) and the number of segments.
fn segment_quantiles<const N: usize>(
    samples: &[f32],
    sample_rate: f64,
    quantiles: [f64; N],
) -> (f64, usize, [Vec<f64>; N]) {
    let mut segments: Vec<Vec<f64>> = Vec::new();
    let bin_hz = segment_powers(samples, sample_rate, |segment| {
        segments.push(segment.to_vec())
    });
    let bins = segments.first().map_or(0, Vec::len);
    let mut at: [Vec<f64>; N] = std::array::from_fn(|_| Vec::with_capacity(bins));
    let mut powers = Vec::with_capacity(segments.len());
    for bin in 0..bins {
        powers.clear();
        powers.extend(segments.iter().map(|s| s[bin]));
        powers.sort_by(f64::total_cmp);
        for (values, q) in at.iter_mut().zip(quantiles) {
            values.push(powers[((q * powers.len() as f64) as usize).min(powers.len() - 1)]);
        }
    }
    (bin_hz, segments.len(), at)
}

/// The median of `values` over the bins within [`NOISE_NEIGHBOURHOOD`] of `bin`'s frequency.
fn neighbourhood_median(values: &[f64], bin: usize) -> f64 {
    let from = ((bin as f64 / NOISE_NEIGHBOURHOOD) as usize).max(1);
    let to = ((bin as f64 * NOISE_NEIGHBOURHOOD).ceil() as usize + 1).min(values.len());
    let mut near: Vec<f64> = values[from.min(bin)..to.max(bin + 1)].to_vec();
    near.sort_by(f64::total_cmp);
    near[near.len() / 2]
}

/// The averaged power spectrum of a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// Spacing of the bins (Hz).
    pub bin_hz: f64,
    /// Power per bin, from 0 Hz to Nyquist.
    pub power: Vec<f64>,
}

impl Spectrum {
    /// Welch's estimate of the power spectrum of `samples` at `sample_rate` (Hann windows, half
    /// overlapping, a power of two long).
    pub fn of(samples: &[f32], sample_rate: f64) -> Self {
        let mut power: Vec<f64> = Vec::new();
        let bin_hz = segment_powers(samples, sample_rate, |segment| {
            power.resize(segment.len(), 0.0);
            power.iter_mut().zip(segment).for_each(|(sum, p)| *sum += p);
        });
        Self { bin_hz, power }
    }

    /// The recording's noise in the same units as [`Spectrum::of`]'s: in each bin, the
    /// [`NOISE_QUANTILE`] of its segments' powers (the quiet ones, between and after the glugs)
    /// over that quantile of noise's own spread, times the segments; then the median of that over
    /// its neighbourhood ([`NOISE_NEIGHBOURHOOD`]).
    pub fn noise_of(samples: &[f32], sample_rate: f64) -> Self {
        let (bin_hz, count, [quiet]) = segment_quantiles(samples, sample_rate, [NOISE_QUANTILE]);
        // A noise periodogram's bin is exponential: its q-quantile is −ln(1 − q) times its mean.
        let quiet: Vec<f64> = quiet
            .iter()
            .map(|q| q / -(1.0 - NOISE_QUANTILE).ln() * count as f64)
            .collect();
        // A mode that rings in every segment (glugs faster than it decays) is no quieter in
        // the quiet ones: a bin's noise is the median over its neighbourhood, where such a peak
        // is a few bins of many (and noise is smooth, but for hum's few lines).
        let power = (0..quiet.len())
            .map(|bin| neighbourhood_median(&quiet, bin))
            .collect();
        Self { bin_hz, power }
    }

    /// The lines the recording holds between its glugs as during them (mains hum and its
    /// harmonics, a machine's whine): a bin that is a local maximum of its segments'
    /// [`NOISE_QUANTILE`] powers, stands [`HELD_LINE_ABOVE`] above its neighbourhood's, falls
    /// as far within [`HELD_LINE_WIDTH_BINS`] either side, and whose loud segments hold at most
    /// [`HELD_LINE_STEADY`] times its quiet ones. A glug's mode, even
    /// one ringing in every segment, comes and goes with its onsets; a held line does not.
    pub fn held_lines(samples: &[f32], sample_rate: f64) -> HeldLines {
        let (bin_hz, _, [quiet, loud]) =
            segment_quantiles(samples, sample_rate, [NOISE_QUANTILE, 1.0 - NOISE_QUANTILE]);
        let bins = quiet.len();
        let first_bin = ((LOWEST_PEAK_HZ / bin_hz).ceil() as usize).max(HELD_LINE_WIDTH_BINS);
        let hz = (first_bin..bins.saturating_sub(HELD_LINE_WIDTH_BINS))
            .filter(|&bin| {
                quiet[bin] > quiet[bin - 1]
                    && quiet[bin] >= quiet[bin + 1]
                    && quiet[bin] >= HELD_LINE_ABOVE * neighbourhood_median(&quiet, bin)
                    && loud[bin] <= HELD_LINE_STEADY * quiet[bin]
                    && quiet[bin - HELD_LINE_WIDTH_BINS].max(quiet[bin + HELD_LINE_WIDTH_BINS])
                        <= quiet[bin] / HELD_LINE_ABOVE
            })
            .map(|bin| bin as f64 * bin_hz)
            .collect();
        HeldLines {
            hz,
            reach_hz: HELD_LINE_REACH_BINS * bin_hz,
        }
    }

    /// This spectrum less `noise` (of the same recording), each bin kept at least
    /// [`KEPT_UNDER_NOISE`] of itself.
    pub fn less(&self, noise: &Spectrum) -> Self {
        Self {
            bin_hz: self.bin_hz,
            power: self
                .power
                .iter()
                .zip(&noise.power)
                .map(|(&p, &n)| (p - n).max(KEPT_UNDER_NOISE * p))
                .collect(),
        }
    }

    /// The share of the power at or above `split_hz`.
    pub fn share_above(&self, split_hz: f64) -> f64 {
        let total: f64 = self.power.iter().sum();
        let high: f64 = (0..self.power.len())
            .filter(|&bin| self.hz(bin) >= split_hz)
            .map(|bin| self.power[bin])
            .sum();
        if total > 0.0 {
            high / total
        } else {
            f64::NAN
        }
    }

    /// The frequencies (Hz, ascending) of the one or two strongest peaks at least
    /// [`PEAK_SEPARATION`] apart, a peak's frequency refined by a parabola through its bin and
    /// its neighbours' log powers.
    /// No peak is taken at one of the recording's `held` lines: they ring no glug.
    pub fn peaks(&self, held: &HeldLines) -> Vec<f64> {
        let mut peaks: Vec<f64> = self
            .peaks_within(WEAKEST_PEAK, held)
            .into_iter()
            .map(|(hz, _)| hz)
            .collect();
        peaks.sort_by(f64::total_cmp);
        peaks
    }

    /// The one or two strongest peaks `(Hz, power)`, strongest first, the second at least
    /// [`PEAK_SEPARATION`] from the first and within `weakest` of its power.
    fn peaks_within(&self, weakest: f64, held: &HeldLines) -> Vec<(f64, f64)> {
        let mut maxima: Vec<(f64, f64)> = self.maxima_above(LOWEST_PEAK_HZ, held).collect();
        maxima.sort_by(|a, b| b.1.total_cmp(&a.1));
        let Some(&(strongest_hz, strongest)) = maxima.first() else {
            return Vec::new();
        };
        let second = maxima.iter().find(|&&(hz, power)| {
            power >= weakest * strongest
                && (hz / strongest_hz).max(strongest_hz / hz) >= PEAK_SEPARATION
        });
        let mut peaks = vec![(strongest_hz, strongest)];
        peaks.extend(second.copied());
        peaks
    }

    /// Its local maxima `(Hz, power)` at or above `lowest_hz` (and [`LOWEST_PEAK_HZ`]), in
    /// order, a maximum's frequency refined; none at one of `held`'s lines.
    fn maxima_above<'a>(
        &'a self,
        lowest_hz: f64,
        held: &'a HeldLines,
    ) -> impl Iterator<Item = (f64, f64)> + 'a {
        let first_bin = ((lowest_hz.max(LOWEST_PEAK_HZ) / self.bin_hz).ceil() as usize).max(1);
        (first_bin..self.power.len().saturating_sub(1))
            .filter(|&bin| {
                self.power[bin] > self.power[bin - 1] && self.power[bin] >= self.power[bin + 1]
            })
            .map(|bin| (self.refined_hz(bin), self.power[bin]))
            .filter(|&(hz, _)| !held.holds(hz))
    }

    /// The spectrum of one stretch of samples: a Hann window, zero-padded.
    pub fn of_span(samples: &[f64], sample_rate: f64) -> Self {
        let width = samples.len() as f64;
        Self::of_windowed(samples, sample_rate, |n| {
            0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / width).cos()
        })
    }

    /// The spectrum of the stretch from a ring's start, where a mode decaying at about
    /// `decay_per_s` is sought: weighted by that decay, zero-padded. The weight is the matched
    /// filter of such a mode in white noise (its energy lies in the first few milliseconds, which
    /// a Hann window over 40 ms tapers away: against the noise it weighs a mode decaying at
    /// 60 /s 4 dB, at 150 /s 12 dB and at 400 /s 27 dB less than this weight does); a mode decaying
    /// at 60 or 400 /s loses about 1 dB against its own matched weight, 4B·β/(B + β)².
    pub fn of_ring(samples: &[f64], sample_rate: f64, decay_per_s: f64) -> Self {
        Self::of_windowed(samples, sample_rate, |n| {
            (-decay_per_s * n as f64 / sample_rate).exp()
        })
    }

    /// The spectrum of `samples` weighted by `window` (of the sample's index), zero-padded to
    /// [`OWN_PADDING`] times their length and a bin of at most [`OWN_BIN_HZ`].
    fn of_windowed(samples: &[f64], sample_rate: f64, window: impl Fn(usize) -> f64) -> Self {
        let len = (OWN_PADDING * samples.len())
            .max((sample_rate / OWN_BIN_HZ) as usize)
            .next_power_of_two();
        let fft = forward(len);
        let mut buffer: Vec<Complex<f64>> = (0..len)
            .map(|n| Complex::new(samples.get(n).map_or(0.0, |y| y * window(n)), 0.0))
            .collect();
        fft.process(&mut buffer);
        Self {
            bin_hz: sample_rate / len as f64,
            power: buffer[..=len / 2].iter().map(|z| z.norm_sqr()).collect(),
        }
    }

    /// The spectra of rings' starts ([`Spectrum::of_ring`]) summed, of those as long as the
    /// longest (zero-padded alike, so their bins agree); none of no stretches.
    fn summed(spans: &[Vec<f64>], sample_rate: f64, decay_per_s: f64) -> Option<Self> {
        let longest = spans.iter().map(Vec::len).max()?;
        let mut sum: Option<Spectrum> = None;
        for span in spans.iter().filter(|span| span.len() == longest) {
            let one = Spectrum::of_ring(span, sample_rate, decay_per_s);
            match sum.as_mut() {
                Some(sum) => sum
                    .power
                    .iter_mut()
                    .zip(&one.power)
                    .for_each(|(s, p)| *s += p),
                None => sum = Some(one),
            }
        }
        sum
    }

    /// The frequency (Hz) at which a bin lies.
    pub fn hz(&self, bin: usize) -> f64 {
        bin as f64 * self.bin_hz
    }
}

/// The peaks of a unit's own span `(Hz, power)`, strongest first: its strongest, and a second
/// [`PEAK_SEPARATION`] from it within 20 dB if there is one; none at one of the recording's
/// `held` lines, which ring no glug.
pub fn own_peaks(samples: &[f64], sample_rate: f64, held: &HeldLines) -> Vec<(f64, f64)> {
    Spectrum::of_span(samples, sample_rate).peaks_within(WEAKEST_OWN_PEAK, held)
}

/// The strongest peak `(Hz, power)` at or above `lowest_hz` of the start of a unit's ring, where
/// a mode decaying at about `decay_per_s` is sought ([`Spectrum::of_ring`]), if any, none at one
/// of the recording's `held` lines.
pub fn own_peak_above(
    samples: &[f64],
    sample_rate: f64,
    lowest_hz: f64,
    decay_per_s: f64,
    held: &HeldLines,
) -> Option<(f64, f64)> {
    Spectrum::of_ring(samples, sample_rate, decay_per_s)
        .maxima_above(lowest_hz, held)
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// The peak at or above `lowest_hz` of many short stretches' spectra summed
/// ([`Spectrum::summed`]) that stands furthest above the sum's own median within
/// [`NOISE_NEIGHBOURHOOD`] of it (Hz), none at one of `held`'s lines. A mode too weak to stand out
/// of any one stretch's noise stands out of the sum where it rings near one pitch in each, as
/// noise does not; the sum's strongest peak may still be a broad hump of noise that is not white
/// (a room, a microphone), which stands less far above what lies near it.
pub fn pooled_peak_above(
    spans: &[Vec<f64>],
    sample_rate: f64,
    lowest_hz: f64,
    decay_per_s: f64,
    held: &HeldLines,
) -> Option<f64> {
    let pooled = Spectrum::summed(spans, sample_rate, decay_per_s)?;
    pooled
        .maxima_above(lowest_hz, held)
        .map(|(hz, power)| {
            let bin = ((hz / pooled.bin_hz).round() as usize).min(pooled.power.len() - 1);
            (
                hz,
                power / neighbourhood_median(&pooled.power, bin).max(1e-300),
            )
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(hz, _)| hz)
}

impl Spectrum {
    fn refined_hz(&self, bin: usize) -> f64 {
        let log = |bin: usize| self.power[bin].max(1e-300).ln();
        let (left, centre, right) = (log(bin - 1), log(bin), log(bin + 1));
        let curvature = left - 2.0 * centre + right;
        let offset = if curvature < 0.0 {
            (0.5 * (left - right) / curvature).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        (bin as f64 + offset) * self.bin_hz
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Glugs 10 a second (a 300 Hz mode decaying at 20 /s, ringing on into the next glug, and
    /// a 760 Hz one at 140 /s, at the same pitch in every glug) over 50 Hz mains hum with its
    /// third harmonic (26 dB under the glugs' peak: a span's strongest peak where a glug is weak)
    /// and white noise, at 16 kHz: the hum is held, neither mode is.
    #[test]
    fn mains_hum_is_a_held_line_and_a_glugs_modes_are_not() {
        let fs = 16_000.0;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let mut samples = vec![0.0f64; (3.0 * fs) as usize];
        let mut onset = 0.01;
        while onset < 3.0 {
            let level = 0.6 + 0.8 * rng.random::<f64>();
            for (n, y) in samples.iter_mut().enumerate().skip((onset * fs) as usize) {
                let tau = n as f64 / fs - onset;
                *y += level
                    * ((-20.0 * tau).exp() * (std::f64::consts::TAU * 300.0 * tau).sin()
                        + 0.6 * (-140.0 * tau).exp() * (std::f64::consts::TAU * 760.0 * tau).sin());
            }
            onset += 0.07 + 0.06 * rng.random::<f64>();
        }
        let recording: Vec<f32> = samples
            .iter()
            .enumerate()
            .map(|(n, y)| {
                let t = n as f64 / fs;
                let hum = (std::f64::consts::TAU * 50.0 * t).sin()
                    + (std::f64::consts::TAU * 150.0 * t).sin() / 3.0;
                (y + 0.05 * hum + 0.002 * (2.0 * rng.random::<f64>() - 1.0)) as f32
            })
            .collect();
        let held = Spectrum::held_lines(&recording, fs);
        assert!(held.holds(50.0), "50 Hz hum not held: {held:?}");
        for mode_hz in [300.0, 760.0] {
            assert!(
                held.hz
                    .iter()
                    .all(|&line| (line / mode_hz - 1.0).abs() > 0.1),
                "the {mode_hz} Hz mode taken for a held line: {held:?}"
            );
        }
    }

    /// Thirty glugs' first 40 ms at 16 kHz, each with a mode near 900 Hz (within 3 %) decaying
    /// at 150 /s, under white noise and a broad hump of noise about 5 kHz (a two-pole resonance):
    /// in no glug is the mode the strongest peak above 400 Hz, and the hump is the sum's
    /// strongest, but the mode stands furthest above its surroundings in the sum.
    #[test]
    fn a_weak_mode_every_stretch_rings_is_the_peak_of_their_sum() {
        let fs = 16_000.0;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let mut noise = || 2.0 * rng.random::<f64>() - 1.0;
        let held = HeldLines {
            hz: Vec::new(),
            reach_hz: 0.0,
        };
        let (radius, theta) = (0.5, std::f64::consts::TAU * 5000.0 / fs);
        let spans: Vec<Vec<f64>> = (0..30)
            .map(|glug| {
                let mode_hz = 900.0 * (1.0 + 0.03 * ((glug % 3) as f64 - 1.0));
                let (mut y1, mut y2) = (0.0, 0.0);
                (0..640)
                    .map(|n| {
                        let tau = n as f64 / fs;
                        let hump = noise() + 2.0 * radius * theta.cos() * y1 - radius * radius * y2;
                        (y2, y1) = (y1, hump);
                        0.03 * (-150.0 * tau).exp() * (std::f64::consts::TAU * mode_hz * tau).sin()
                            + 0.1 * noise()
                            + 0.13 * hump
                    })
                    .collect()
            })
            .collect();
        let near_mode = |hz: f64| (hz / 900.0 - 1.0).abs() < 0.05;
        let found_alone = spans
            .iter()
            .filter(|span| {
                own_peak_above(span, fs, 400.0, 150.0, &held).is_some_and(|p| near_mode(p.0))
            })
            .count();
        assert_eq!(
            found_alone, 0,
            "the mode stood out in {found_alone} glugs alone"
        );
        let pooled = pooled_peak_above(&spans, fs, 400.0, 150.0, &held).unwrap();
        // The premise: the sum's strongest peak is the hump, so a peak taken by its height alone
        // would be the hump's.
        let sum = Spectrum::summed(&spans, fs, 150.0).unwrap();
        let strongest = sum
            .maxima_above(400.0, &held)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        assert!(
            strongest.is_some_and(|(hz, _)| hz > 4000.0),
            "{strongest:?}"
        );
        assert!(near_mode(pooled), "the sum's peak at {pooled} Hz");
    }

    /// The first 40 ms of rings at 16 kHz, each a 1.2 kHz mode decaying at 250 /s under white
    /// noise, its RMS over the stretch some 7 dB under the noise's: weighted by the decay sought,
    /// the mode is the strongest peak above 400 Hz in most rings; under a Hann window over the
    /// stretch, which tapers away the milliseconds the mode rings in, in few.
    #[test]
    fn a_short_mode_stands_out_of_a_ring_weighted_by_its_decay() {
        let fs = 16_000.0;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let held = HeldLines {
            hz: Vec::new(),
            reach_hz: 0.0,
        };
        let rings: Vec<Vec<f64>> = (0..40)
            .map(|_| {
                (0..640)
                    .map(|n| {
                        let tau = n as f64 / fs;
                        0.5 * (-250.0 * tau).exp() * (std::f64::consts::TAU * 1200.0 * tau).sin()
                            + 0.3 * (2.0 * rng.random::<f64>() - 1.0)
                    })
                    .collect()
            })
            .collect();
        let at_mode = |spectrum: Spectrum| {
            spectrum
                .maxima_above(400.0, &held)
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .is_some_and(|(hz, _)| (hz / 1200.0 - 1.0).abs() < 0.03)
        };
        let weighted = rings
            .iter()
            .filter(|ring| at_mode(Spectrum::of_ring(ring, fs, 150.0)))
            .count();
        let hann = rings
            .iter()
            .filter(|ring| at_mode(Spectrum::of_span(ring, fs)))
            .count();
        assert!(weighted >= 30, "found in {weighted} of 40 rings weighted");
        assert!(hann <= 10, "found in {hann} of 40 rings under Hann");
    }

    /// Glugs (a 200 Hz mode, decaying at 30 /s, 6 a second) with white noise 10 dB below their
    /// RMS, at 16 kHz: the noise read from the quiet segments, and the glugs' bright share once
    /// it is taken away.
    #[test]
    fn a_recordings_noise_is_read_and_taken_away() {
        let fs = 16_000.0;
        let glugs: Vec<f32> = (0..(3.0 * fs) as usize)
            .map(|n| {
                let tau = (n as f64 / fs) % (1.0 / 6.0);
                ((-30.0 * tau).exp() * (std::f64::consts::TAU * 200.0 * tau).sin()) as f32
            })
            .collect();
        let rms =
            (glugs.iter().map(|y| f64::from(*y).powi(2)).sum::<f64>() / glugs.len() as f64).sqrt();
        // Uniform noise of this half-width has the RMS sought.
        let half_width = 10f64.powf(-0.5) * rms * 3f64.sqrt();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let noise: Vec<f32> = glugs
            .iter()
            .map(|_| (half_width * (2.0 * rng.random::<f64>() - 1.0)) as f32)
            .collect();
        let noisy: Vec<f32> = glugs.iter().zip(&noise).map(|(g, n)| g + n).collect();
        let floor = Spectrum::noise_of(&noisy, fs);
        let truth = Spectrum::of(&noise, fs);
        // Above the glugs' band, the floor is the noise's own level, within 25 %.
        let band = |s: &Spectrum| -> f64 {
            (0..s.power.len())
                .filter(|&bin| s.hz(bin) >= 2000.0)
                .map(|bin| s.power[bin])
                .sum()
        };
        let ratio = band(&floor) / band(&truth);
        assert!(
            (0.75..1.25).contains(&ratio),
            "noise read at {ratio} of its level"
        );
        // The noise lends the recording a bright share the glugs do not have; less it, the share
        // comes most of the way back to the glugs' (a bin of noise alone keeps a little).
        let glugs_share = Spectrum::of(&glugs, fs).share_above(700.0);
        let noisy_spectrum = Spectrum::of(&noisy, fs);
        let less_share = noisy_spectrum.less(&floor).share_above(700.0);
        let noisy_share = noisy_spectrum.share_above(700.0);
        assert!(
            noisy_share > glugs_share + 0.05,
            "{noisy_share}, the glugs' {glugs_share}"
        );
        assert!(
            (less_share - glugs_share).abs() < 0.2 * (noisy_share - glugs_share),
            "{less_share} less the noise, {noisy_share} with it, {glugs_share} the glugs alone"
        );
    }
}
