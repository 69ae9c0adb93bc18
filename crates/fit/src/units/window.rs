//! The samples a unit is fitted to: its span of the recording (from just before its onset to just
//! before the next unit's) and, within it, every k-th sample that a fit reads.

use std::f64::consts::TAU;

use num_complex::Complex;

use crate::spectrum::HeldLines;

/// One unit's span of the recording (less the units fitted before it), at the full rate.
pub(crate) struct Span {
    /// The samples `[first, end)` of the recording.
    pub samples: Vec<f64>,
    /// Where the span starts in the recording.
    pub first: usize,
    /// Where it ends (exclusive).
    pub end: usize,
    /// The detected onset (a sample of the recording).
    pub onset: usize,
    /// The sample rate (Hz).
    pub fs: f64,
    /// The lines the whole recording holds (hum), which no unit's peak is taken at.
    pub held: HeldLines,
}

impl Span {
    /// The span `[first, end)` of `signal` with its unit detected at `onset`.
    pub fn of(
        signal: &[f32],
        (first, end): (usize, usize),
        onset: usize,
        fs: f64,
        held: &HeldLines,
    ) -> Self {
        Self {
            samples: signal[first..end].iter().map(|&y| f64::from(y)).collect(),
            first,
            end,
            onset,
            fs,
            held: held.clone(),
        }
    }

    /// The detected onset (s).
    pub fn onset_s(&self) -> f64 {
        self.onset as f64 / self.fs
    }

    /// Its samples from the detected onset on, at most `seconds` of them.
    pub fn after_onset(&self, seconds: f64) -> &[f64] {
        let from = (self.onset - self.first).min(self.samples.len());
        let to = (from + (seconds * self.fs) as usize).min(self.samples.len());
        &self.samples[from..to]
    }

    /// Every `stride`-th sample from its first on.
    pub fn window(&self, stride: usize) -> Window {
        self.window_until(stride, self.end)
    }

    /// Every `stride`-th sample from its first up to the recording's sample `end`.
    pub fn window_until(&self, stride: usize, end: usize) -> Window {
        let len = end.clamp(self.first, self.end) - self.first;
        Window {
            data: self.samples[..len]
                .iter()
                .step_by(stride)
                .copied()
                .collect(),
            first: self.first,
            stride,
            fs: self.fs,
        }
    }
}

/// Every `stride`-th sample of the recording from `first` on: what a fit reads.
pub(crate) struct Window {
    /// The samples read.
    pub data: Vec<f64>,
    /// The recording's sample of `data[0]`.
    pub first: usize,
    /// Samples of the recording between two read.
    pub stride: usize,
    /// The sample rate (Hz).
    pub fs: f64,
}

impl Window {
    /// The recording's sample index of `data[n]`.
    pub fn index(&self, n: usize) -> usize {
        self.first + n * self.stride
    }

    /// The first n whose sample lies at or after `onset_s`, at most `data.len()`.
    pub fn first_after(&self, onset_s: f64) -> usize {
        let onset = (onset_s * self.fs).ceil().max(self.first as f64) - self.first as f64;
        ((onset / self.stride as f64).ceil() as usize).min(self.data.len())
    }

    /// For each n from the onset on, `each(n, z, τ)` with z = e^((−B + i2πf)τ) and τ the time of
    /// sample n after `onset_s`: one complex rotation per sample.
    pub fn rotate(
        &self,
        onset_s: f64,
        frequency_hz: f64,
        decay_per_s: f64,
        mut each: impl FnMut(usize, Complex<f64>, f64),
    ) {
        let rate = Complex::new(-decay_per_s, TAU * frequency_hz);
        let period = self.stride as f64 / self.fs;
        let step = (rate * period).exp();
        let start = self.first_after(onset_s);
        let tau0 = self.index(start) as f64 / self.fs - onset_s;
        let mut z = (rate * tau0).exp();
        for n in start..self.data.len() {
            each(n, z, tau0 + (n - start) as f64 * period);
            z *= step;
        }
    }
}

impl Window {
    /// The sum of the squares of its samples.
    pub fn energy(&self) -> f64 {
        self.data.iter().map(|y| y * y).sum()
    }

    /// The time of `data[n]` (s).
    pub fn time_s(&self, n: usize) -> f64 {
        self.index(n) as f64 / self.fs
    }
}
