//! The recursive synthesis paths: each component is a complex oscillator stepped by one rotation
//! z = e^(−d + iω) per sample, in f64 ([`RecursiveF64`]) or in f32 ([`RecursiveF32`]).
//!
//! A bare recursion drifts: the rounding of z compounds, so phase and magnitude errors grow
//! linearly with the samples rung. Both paths therefore re-anchor every component from the closed
//! form at fixed points of the absolute sample grid ([`REANCHOR_SAMPLES`]), so the error is
//! bounded by what one anchor interval can accumulate, whatever the render length. In f64 that is
//! far below the budget; in f32 it is not, which is why the default path ([`super::VoiceBank`])
//! anchors every 64 samples instead of recursing.
//!
//! Drop rules are the default path's: no component with zero amplitude, a frequency of 0 or at
//! or above Nyquist, or already below −120 dB; a component stops below −120 dB; at most
//! [`MAX_PARTIALS`] sound at once, the weakest giving way; at most [`MAX_STARTS_PER_PERIOD`]
//! start per grid period.

use num_complex::Complex;
use num_traits::Float;

use super::partial::GRID;
use super::pour::UnitOnset;
use super::synthesis::Synthesis;
use super::voices::{MAX_PARTIALS, MAX_STARTS_PER_PERIOD};

/// Components are re-evaluated from the closed form on every multiple of this many samples
/// (1024 grid periods, ≈ 1.4 s at 48 kHz): the longest a recursion runs unchecked.
pub const REANCHOR_SAMPLES: u64 = 1024 * GRID as u64;
/// ln 10⁶: a component is silent once e^(−Bτ) < 10⁻⁶ (−120 dB, MODEL.md §6).
const SILENT_DECAY_EXPONENT: f64 = 13.815_510_557_964_274;
/// Below −240 dB nothing is audible; skipping it keeps the recursion out of denormals.
const NEGLIGIBLE_AMPLITUDE: f64 = 1e-12;

/// The f64 recursive path: the precise one.
pub type RecursiveF64 = RecursiveBank<f64>;
/// The f32 recursive path: shows what a recursion in the output's precision costs in accuracy.
pub type RecursiveF32 = RecursiveBank<f32>;

struct Oscillator<T> {
    /// The complex state A·e^((−B + iω)τ) at `next_sample`; its imaginary part is the output.
    state: Complex<T>,
    /// z, the per-sample rotation.
    step: Complex<T>,
    next_sample: u64,
    /// The first sample at which the component is below −120 dB; never rendered.
    silent_from: u64,
    onset_sample: u64,
    onset_fraction: f64,
    amplitude: f64,
    decay_per_sample: f64,
    radians_per_sample: f64,
}

impl<T: Float> Oscillator<T> {
    fn start(onset: &UnitOnset, index: usize, sample_rate: f64) -> Option<Self> {
        let amplitude = onset.component_amplitudes()[index];
        let frequency_hz = onset.shape.frequency_hz[index];
        let audible_amplitude = amplitude >= NEGLIGIBLE_AMPLITUDE;
        let below_nyquist = frequency_hz > 0.0 && frequency_hz < 0.5 * sample_rate;
        if !audible_amplitude || !below_nyquist {
            return None;
        }
        let decay_per_sample = onset.shape.decay_per_s[index] / sample_rate;
        let radians_per_sample = std::f64::consts::TAU * frequency_hz / sample_rate;
        // Bτ ≤ ln 10⁶ ⇔ sample ≤ onset + x + ln 10⁶ / d; `as` saturates for d = 0 (rings for ever).
        let audible_until =
            onset.sample as f64 + onset.fraction + SILENT_DECAY_EXPONENT / decay_per_sample;
        let silent_from = (audible_until.floor() as u64).saturating_add(1);
        // As on the default path, the first sample at or after the onset time is n + 1.
        let first_sample = onset.sample + 1;
        if first_sample >= silent_from {
            return None;
        }
        let mut oscillator = Self {
            state: Complex::new(T::zero(), T::zero()),
            step: to_complex(complex_exp(-decay_per_sample, radians_per_sample)),
            next_sample: first_sample,
            silent_from,
            onset_sample: onset.sample,
            onset_fraction: onset.fraction,
            amplitude,
            decay_per_sample,
            radians_per_sample,
        };
        oscillator.anchor_at(first_sample);
        Some(oscillator)
    }

    /// Sets the state from the closed form at `sample`.
    fn anchor_at(&mut self, sample: u64) {
        let elapsed = (sample - self.onset_sample) as f64 - self.onset_fraction;
        let [re, im] = complex_exp(
            -self.decay_per_sample * elapsed,
            self.radians_per_sample * elapsed,
        );
        self.state = to_complex([self.amplitude * re, self.amplitude * im]);
        self.next_sample = sample;
    }

    /// Adds samples to `out`, which starts at `span_start` and lies within one grid period.
    #[inline]
    fn render(&mut self, span_start: u64, out: &mut [T]) {
        if self.next_sample < span_start {
            // Not rendered for a while (cannot happen under the engine): resume exactly.
            self.anchor_at(span_start);
        }
        let span_end = span_start + out.len() as u64;
        let end = span_end.min(self.silent_from);
        if self.next_sample >= end {
            return;
        }
        let offset = (self.next_sample - span_start) as usize;
        let count = (end - self.next_sample) as usize;
        let mut state = self.state;
        for y in &mut out[offset..offset + count] {
            *y = *y + state.im;
            state = state * self.step;
        }
        self.state = state;
        self.next_sample = end;
    }

    /// Moves to the period starting at `period_start`; returns false once the component is silent.
    fn advance(&mut self, period_start: u64) -> bool {
        if period_start >= self.silent_from {
            return false;
        }
        if period_start.is_multiple_of(REANCHOR_SAMPLES) && self.next_sample == period_start {
            self.anchor_at(period_start);
        }
        true
    }

    fn level(&self) -> f64 {
        self.state.norm().to_f64().unwrap_or(0.0)
    }
}

/// The sounding components of a recursive path, in a bank of fixed capacity allocated once.
pub struct RecursiveBank<T> {
    oscillators: Vec<Oscillator<T>>,
    /// Sums the components of a span in the path's own precision before it meets the f32 output.
    scratch: [T; GRID],
    sample_rate: f64,
    given_up: u64,
    starts_left: u32,
}

impl<T: Float> RecursiveBank<T> {
    fn insert(&mut self, oscillator: Oscillator<T>) {
        if self.oscillators.len() < MAX_PARTIALS {
            self.oscillators.push(oscillator);
            return;
        }
        self.given_up += 1;
        let weakest = self
            .oscillators
            .iter_mut()
            .min_by(|a, b| a.level().total_cmp(&b.level()))
            .expect("a full bank is not empty");
        if weakest.level() < oscillator.level() {
            *weakest = oscillator;
        }
    }
}

impl<T: Float> Synthesis for RecursiveBank<T> {
    fn new(sample_rate: f64) -> Self {
        Self {
            oscillators: Vec::with_capacity(MAX_PARTIALS),
            scratch: [T::zero(); GRID],
            sample_rate,
            given_up: 0,
            starts_left: MAX_STARTS_PER_PERIOD,
        }
    }

    fn clear(&mut self) {
        self.oscillators.clear();
        self.given_up = 0;
        self.starts_left = MAX_STARTS_PER_PERIOD;
    }

    fn is_empty(&self) -> bool {
        self.oscillators.is_empty()
    }

    fn len(&self) -> usize {
        self.oscillators.len()
    }

    fn given_up(&self) -> u64 {
        self.given_up
    }

    fn start_unit(&mut self, onset: &UnitOnset) {
        for index in 0..2 {
            if self.starts_left == 0 {
                self.given_up += 1;
                continue;
            }
            self.starts_left -= 1;
            if let Some(oscillator) = Oscillator::start(onset, index, self.sample_rate) {
                self.insert(oscillator);
            }
        }
    }

    fn render(&mut self, span_start: u64, out: &mut [f32]) {
        let scratch = &mut self.scratch[..out.len()];
        scratch.fill(T::zero());
        for oscillator in &mut self.oscillators {
            oscillator.render(span_start, scratch);
        }
        for (y, &sum) in out.iter_mut().zip(scratch.iter()) {
            *y += sum.to_f32().unwrap_or(0.0);
        }
    }

    fn advance(&mut self, period_start: u64) {
        self.starts_left = MAX_STARTS_PER_PERIOD;
        self.oscillators
            .retain_mut(|oscillator| oscillator.advance(period_start));
    }
}

fn complex_exp(log_magnitude: f64, phase: f64) -> [f64; 2] {
    let magnitude = log_magnitude.exp();
    let (sin, cos) = phase.sin_cos();
    [magnitude * cos, magnitude * sin]
}

fn to_complex<T: Float>([re, im]: [f64; 2]) -> Complex<T> {
    Complex::new(
        T::from(re).unwrap_or(T::zero()),
        T::from(im).unwrap_or(T::zero()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::randomness::UnitShape;

    fn onset(decay_per_s: f64) -> UnitOnset {
        UnitOnset {
            sample: 10,
            fraction: 0.25,
            volume_ml: 300.0,
            amplitude: 1.0,
            viscosity: 0.5,
            shape: UnitShape {
                frequency_hz: [80.0, 300.0],
                decay_per_s: [decay_per_s; 2],
            },
        }
    }

    fn exact(onset: &UnitOnset, sample: u64, fs: f64) -> f64 {
        if sample <= onset.sample {
            return 0.0;
        }
        let tau = (sample as f64 - onset.sample as f64 - onset.fraction) / fs;
        (0..2)
            .map(|k| {
                onset.component_amplitudes()[k]
                    * (-onset.shape.decay_per_s[k] * tau).exp()
                    * (std::f64::consts::TAU * onset.shape.frequency_hz[k] * tau).sin()
            })
            .sum()
    }

    /// Renders like the engine does: spans within grid periods, advance at each period start.
    fn render<T: Float>(onset: &UnitOnset, fs: f64, len: u64) -> Vec<f32> {
        let mut bank = RecursiveBank::<T>::new(fs);
        bank.start_unit(onset);
        let mut out = vec![0.0f32; len as usize];
        let mut sample = 0u64;
        while sample < len {
            let end = ((sample / GRID as u64 + 1) * GRID as u64).min(len);
            bank.render(sample, &mut out[sample as usize..end as usize]);
            sample = end;
            if sample.is_multiple_of(GRID as u64) {
                bank.advance(sample);
            }
        }
        out
    }

    #[test]
    fn f64_recursion_matches_the_closed_form_and_does_not_drift() {
        let fs = 48_000.0;
        let unit = onset(0.0);
        let len = 4 * REANCHOR_SAMPLES;
        let out = render::<f64>(&unit, fs, len);
        let worst = (0..len)
            .map(|n| (out[n as usize] as f64 - exact(&unit, n, fs)).abs())
            .fold(0.0, f64::max);
        // The f32 output itself rounds at 2⁻²⁴ of the peak (≈ 1).
        assert!(worst < 1e-7, "error {worst}");
    }

    #[test]
    fn f32_recursion_error_stays_bounded_by_one_anchor_interval() {
        let fs = 48_000.0;
        let unit = onset(0.0);
        let len = 6 * REANCHOR_SAMPLES;
        let out = render::<f32>(&unit, fs, len);
        let error_in = |range: std::ops::Range<u64>| {
            range
                .map(|n| (out[n as usize] as f64 - exact(&unit, n, fs)).abs())
                .fold(0.0, f64::max)
        };
        let first = error_in(0..REANCHOR_SAMPLES);
        let last = error_in(5 * REANCHOR_SAMPLES..6 * REANCHOR_SAMPLES);
        assert!(
            first > 1e-6,
            "an f32 recursion should show its rounding: {first}"
        );
        assert!(
            last < 2.0 * first,
            "drift: first interval {first}, last {last}"
        );
    }

    #[test]
    fn silent_and_unhearable_components_are_never_started() {
        let fs = 48_000.0;
        let mut bank = RecursiveF64::new(fs);
        let mut above_nyquist = onset(40.0);
        above_nyquist.shape.frequency_hz = [24_000.0, 30_000.0];
        bank.start_unit(&above_nyquist);
        let mut one_sided = onset(40.0);
        one_sided.viscosity = 1.0;
        bank.start_unit(&one_sided);
        bank.start_unit(&onset(1e9));
        assert_eq!(bank.len(), 1, "only the c = 1 unit's f1 component sounds");
    }

    #[test]
    fn a_component_stops_at_minus_120_db() {
        let fs = 48_000.0;
        let mut bank = RecursiveF64::new(fs);
        bank.start_unit(&onset(40.0));
        // −120 dB after ln(10⁶)/40 s ≈ 16 579 samples.
        let mut out = [0.0f32; GRID];
        for period in 0..300u64 {
            bank.render(period * GRID as u64, &mut out);
            bank.advance((period + 1) * GRID as u64);
        }
        assert_eq!(bank.len(), 0);
    }
}
