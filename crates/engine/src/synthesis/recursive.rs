//! The recursive synthesis paths: each component is a complex oscillator stepped by one rotation
//! z = e^(−d + iω) per sample ([`RecursiveComponent`]), in f64 ([`RecursiveF64`]) or in f32
//! ([`RecursiveF32`]).
//!
//! A bare recursion drifts: the rounding of z compounds, so phase and magnitude errors grow
//! linearly with the samples rung. Both paths therefore re-anchor every component from the closed
//! form at fixed points of the absolute sample grid ([`REANCHOR_SAMPLES`]), so the error is
//! bounded by what one anchor interval can accumulate, whatever the render length. In f64 that is
//! far below the budget; in f32 it is not, which is why the default path ([`super::AnchoredF32`])
//! anchors every 64 samples instead of recursing.
//!
//! Which components are computed ([`Component::of`]) and admitted ([`Bank`]) is shared with the
//! default path; a component stops below −120 dB here too.

use num_complex::Complex;
use num_traits::Float;

use super::anchored::GRID;
use super::bank::{Bank, BankComponent};
use super::component::{Component, SILENT_DECAY_EXPONENT};

/// Components are re-evaluated from the closed form on every multiple of this many samples
/// (1024 grid periods, ≈ 1.4 s at 48 kHz): the longest a recursion runs unchecked.
pub const REANCHOR_SAMPLES: u64 = 1024 * GRID as u64;

/// The f64 recursive path: the precise one.
pub type RecursiveF64 = Bank<RecursiveComponent<f64>>;
/// The f32 recursive path: shows what a recursion in the output's precision costs in accuracy.
pub type RecursiveF32 = Bank<RecursiveComponent<f32>>;

/// One component on a recursive path, in precision `T`.
pub struct RecursiveComponent<T> {
    /// The complex state A·e^((−B + iω)τ) at `next_sample`; its imaginary part is the output.
    state: Complex<T>,
    /// z, the per-sample rotation.
    step: Complex<T>,
    next_sample: u64,
    /// The first sample at which the component is below −120 dB; never rendered.
    silent_from: u64,
    component: Component,
    /// A glide's second rotation (MODEL.md §5.2): the phase it adds from `next_sample` to the
    /// sample after, and r = e^(−1/T), by which that angle shrinks each sample. Kept in f64 on
    /// both paths: in f32, r^n's rounding would pile up over a long glide into radians of phase.
    glide: Option<(f64, f64)>,
}

impl<T: Float> BankComponent for RecursiveComponent<T> {
    fn start(component: Component) -> Self {
        // Bτ ≤ ln 10⁶ ⇔ sample ≤ onset + x + ln 10⁶ / d; `as` saturates for d = 0 (rings for ever).
        let audible_until = component.onset_sample as f64
            + component.onset_fraction
            + SILENT_DECAY_EXPONENT / component.decay_per_sample;
        let first_sample = component.first_sample();
        let mut recursive = Self {
            state: Complex::new(T::zero(), T::zero()),
            step: to_complex(component.step()),
            next_sample: first_sample,
            silent_from: (audible_until.floor() as u64).saturating_add(1),
            component,
            glide: None,
        };
        recursive.anchor_at(first_sample);
        recursive
    }

    fn level(&self) -> f64 {
        self.state.norm().to_f64().unwrap_or(0.0)
    }

    type Shared = ();

    fn advance_all(components: &mut Vec<Self>, _: &mut (), period_start: u64) {
        components.retain_mut(|component| component.advance(period_start));
    }

    fn write_all(components: &mut [Self], _: &mut (), span_start: u64, out: &mut [f32]) {
        // The span's sum in the path's own precision, before it meets the f32 output.
        let mut sum = [T::zero(); GRID];
        let sum = &mut sum[..out.len()];
        for component in components {
            component.synthesize(span_start, sum);
        }
        // From +0, as the bank writes every path's sum: −0 becomes +0.
        for (y, &value) in out.iter_mut().zip(sum.iter()) {
            *y = 0.0 + value.to_f32().unwrap_or(0.0);
        }
    }
}

impl<T: Float> RecursiveComponent<T> {
    /// Moves to the grid period starting at `period_start`; false once the component is silent.
    fn advance(&mut self, period_start: u64) -> bool {
        if period_start >= self.silent_from {
            return false;
        }
        if period_start.is_multiple_of(REANCHOR_SAMPLES) && self.next_sample == period_start {
            self.anchor_at(period_start);
        }
        true
    }

    /// Sets the state from the closed form at `sample`.
    fn anchor_at(&mut self, sample: u64) {
        self.state = to_complex(self.component.state_at(sample));
        self.next_sample = sample;
        self.glide = self.component.glide.map(|glide| {
            // K·e^(−τ/T)·(1 − e^(−1/T)): what the glide adds over this sample.
            let elapsed = self.component.samples_since_onset(sample);
            let angle = -glide.phase_left_at(elapsed) * (-1.0 / glide.time_samples).exp_m1();
            (angle, (-1.0 / glide.time_samples).exp())
        });
    }

    /// Adds samples to `out`, which starts at `span_start` and lies within one grid period.
    #[inline]
    fn synthesize(&mut self, span_start: u64, out: &mut [T]) {
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
        match &mut self.glide {
            None => {
                for y in &mut out[offset..offset + count] {
                    *y = *y + state.im;
                    state = state * self.step;
                }
            }
            Some((angle, shrink)) => {
                for y in &mut out[offset..offset + count] {
                    *y = *y + state.im;
                    let (sin, cos) = angle.sin_cos();
                    let turn = Complex::new(
                        T::from(cos).unwrap_or(T::one()),
                        T::from(sin).unwrap_or(T::zero()),
                    );
                    state = state * self.step * turn;
                    *angle *= *shrink;
                }
            }
        }
        self.state = state;
        self.next_sample = end;
    }
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
    use crate::pour::{UnitOnset, UnitShape};
    use crate::Synthesis;

    fn onset(decay_per_s: f64) -> UnitOnset {
        UnitOnset {
            sample: 10,
            fraction: 0.25,
            volume_ml: 300.0,
            tilt_deg: 135.0,
            pocket_ml: 5.0,
            amplitude: 1.0,
            viscosity: 0.5,
            shape: UnitShape {
                frequency_hz: [80.0, 300.0],
                frequency_spread: [1.0, 1.0],
                decay_per_s: [decay_per_s; 2],
                amplitude_factor: 1.0,
                glide: crate::Glide {
                    ratio: [1.0; 2],
                    time_ms: [20.0; 2],
                },
            },
            actuator_gain: [1.0, 1.0],
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
        let mut bank = Bank::<RecursiveComponent<T>>::new(fs);
        bank.start_unit(onset);
        let mut out = vec![0.0f32; len as usize];
        let mut sample = 0u64;
        while sample < len {
            let end = ((sample / GRID as u64 + 1) * GRID as u64).min(len);
            bank.synthesize(sample, &mut out[sample as usize..end as usize]);
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
            bank.synthesize(period * GRID as u64, &mut out);
            bank.advance((period + 1) * GRID as u64);
        }
        assert_eq!(bank.len(), 0);
    }
}
