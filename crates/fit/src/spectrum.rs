//! The recording's power spectrum (Welch's method, rustfft) and its two strongest peaks: the
//! starting guess of f1 and f2 for eq. 1, and panel (b) of the plot; and a unit's own spectrum
//! and its peaks, where a unit that eq. 1 does not describe is started.

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

/// Segment length (s) of Welch's average: fine enough to part 80 Hz from its neighbours (a
/// decaying component's peak is B/π wide, about 14 Hz at 45 /s).
const SEGMENT_S: f64 = 0.16;

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
                *slot += buffer[bin].norm_sqr();
            }
            start += len / 2;
            if start + len > samples.len() {
                break;
            }
        }
        Self {
            bin_hz: sample_rate / len as f64,
            power,
        }
    }

    /// The frequencies (Hz, ascending) of the one or two strongest peaks at least
    /// [`PEAK_SEPARATION`] apart, a peak's frequency refined by a parabola through its bin and
    /// its neighbours' log powers.
    pub fn peaks(&self) -> Vec<f64> {
        let mut peaks: Vec<f64> = self
            .peaks_within(WEAKEST_PEAK)
            .into_iter()
            .map(|(hz, _)| hz)
            .collect();
        peaks.sort_by(f64::total_cmp);
        peaks
    }

    /// The one or two strongest peaks `(Hz, power)`, strongest first, the second at least
    /// [`PEAK_SEPARATION`] from the first and within `weakest` of its power.
    fn peaks_within(&self, weakest: f64) -> Vec<(f64, f64)> {
        let first_bin = ((LOWEST_PEAK_HZ / self.bin_hz).ceil() as usize).max(1);
        let mut maxima: Vec<(f64, f64)> = (first_bin..self.power.len().saturating_sub(1))
            .filter(|&bin| {
                self.power[bin] > self.power[bin - 1] && self.power[bin] >= self.power[bin + 1]
            })
            .map(|bin| (self.refined_hz(bin), self.power[bin]))
            .collect();
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

    /// The spectrum of one stretch of samples: a Hann window, zero-padded.
    pub fn of_span(samples: &[f64], sample_rate: f64) -> Self {
        let len = (OWN_PADDING * samples.len())
            .max((sample_rate / OWN_BIN_HZ) as usize)
            .next_power_of_two();
        let fft = forward(len);
        let width = samples.len() as f64;
        let mut buffer: Vec<Complex<f64>> = (0..len)
            .map(|n| {
                let sample = samples.get(n).copied().unwrap_or(0.0);
                let hann = 0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / width).cos();
                Complex::new(sample * hann, 0.0)
            })
            .collect();
        fft.process(&mut buffer);
        Self {
            bin_hz: sample_rate / len as f64,
            power: buffer[..=len / 2].iter().map(|z| z.norm_sqr()).collect(),
        }
    }

    /// The frequency (Hz) at which a bin lies.
    pub fn hz(&self, bin: usize) -> f64 {
        bin as f64 * self.bin_hz
    }
}

/// The peaks of a unit's own span `(Hz, power)`, strongest first: its strongest, and a second
/// [`PEAK_SEPARATION`] from it within 20 dB if there is one.
pub fn own_peaks(samples: &[f64], sample_rate: f64) -> Vec<(f64, f64)> {
    Spectrum::of_span(samples, sample_rate).peaks_within(WEAKEST_OWN_PEAK)
}

/// The strongest peak `(Hz, power)` of a unit's own span at or above `lowest_hz`, if any.
pub fn own_peak_above(samples: &[f64], sample_rate: f64, lowest_hz: f64) -> Option<(f64, f64)> {
    let spectrum = Spectrum::of_span(samples, sample_rate);
    let first_bin = ((lowest_hz.max(LOWEST_PEAK_HZ) / spectrum.bin_hz).ceil() as usize).max(1);
    (first_bin..spectrum.power.len().saturating_sub(1))
        .filter(|&bin| {
            spectrum.power[bin] > spectrum.power[bin - 1]
                && spectrum.power[bin] >= spectrum.power[bin + 1]
        })
        .max_by(|&a, &b| spectrum.power[a].total_cmp(&spectrum.power[b]))
        .map(|bin| (spectrum.refined_hz(bin), spectrum.power[bin]))
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
