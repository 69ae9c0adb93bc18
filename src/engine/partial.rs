//! One decaying sinusoid of a wave unit (one term of MODEL.md §5), rendered as
//! `anchor · z^j` over a grid period of [`GRID`] samples.
//!
//! The anchor (the component's complex state at the period's first sample) advances in f64 once
//! per period, and the powers z^j are tabled once per component in f32. Each output sample is then
//! one f32 complex product: independent across samples (so it vectorises), about two f32 ulps from
//! the exact value, and free of the drift of a per-sample recursion. Periods sit on an absolute
//! sample grid, so how a host cuts time into blocks never changes a sample.

use super::pour::UnitOnset;

/// Samples per grid period; the anchor advances in f64 once per period.
pub const GRID: usize = 64;
/// A component is dropped once e^(−Bτ) < 10⁻⁶ (MODEL.md §6): Bτ > ln 10⁶.
const SILENT_DECAY_EXPONENT: f64 = 13.815_510_557_964_274;
/// Powers below this are stored as zero: it is inside the error budget and keeps f32 denormals
/// out of the render loop for very fast decays.
const NEGLIGIBLE_POWER: f64 = 1e-7;
/// A component this weak (−240 dB) is never audible; skipping it keeps denormals out of f32.
const NEGLIGIBLE_AMPLITUDE: f64 = 1e-12;
/// The f64 anchor recursion is re-evaluated from the closed form this often, so nothing can
/// drift however long a component rings (B = 0 rings for ever).
const PERIODS_PER_DIRECT_ANCHOR: u32 = 1024;

#[derive(Clone)]
pub struct Partial {
    powers_re: [f32; GRID],
    powers_im: [f32; GRID],
    /// State at `anchor_sample`, the first sample of the period being rendered.
    anchor: [f32; 2],
    anchor_sample: u64,
    /// State at the first sample of the next period.
    next_anchor: [f64; 2],
    /// z^GRID in f64.
    period_step: [f64; 2],
    onset_sample: u64,
    onset_fraction: f64,
    amplitude: f64,
    decay_per_sample: f64,
    radians_per_sample: f64,
    periods_since_direct: u32,
    /// |anchor|², for choosing which component to give up when the bank is full (squared: only
    /// the order matters, and it saves a hypot per component per period).
    level: f32,
}

impl Partial {
    /// Component `index` (0: f1/B1, 1: f2/B2) of `onset`, or `None` if it would be silent:
    /// zero amplitude, a frequency of 0 or at/above Nyquist (MODEL.md §6), or already decayed.
    pub fn start(onset: &UnitOnset, index: usize, sample_rate: f64) -> Option<Self> {
        let amplitude = onset.component_amplitudes()[index];
        let frequency_hz = onset.shape.frequency_hz[index];
        let audible_amplitude = amplitude >= NEGLIGIBLE_AMPLITUDE;
        let below_nyquist = frequency_hz > 0.0 && frequency_hz < 0.5 * sample_rate;
        if !audible_amplitude || !below_nyquist {
            return None;
        }
        let decay_per_sample = onset.shape.decay_per_s[index] / sample_rate;
        let radians_per_sample = std::f64::consts::TAU * frequency_hz / sample_rate;
        // The first sample at or after the onset time (n + x) is n + 1; a sample at exactly the
        // onset would contribute sin(0) = 0.
        let first_sample = onset.sample + 1;
        let mut partial = Self {
            powers_re: [0.0; GRID],
            powers_im: [0.0; GRID],
            anchor: [0.0; 2],
            anchor_sample: first_sample,
            next_anchor: [0.0; 2],
            period_step: complex_exp(-decay_per_sample * GRID as f64, radians_per_sample * GRID as f64),
            onset_sample: onset.sample,
            onset_fraction: onset.fraction,
            amplitude,
            decay_per_sample,
            radians_per_sample,
            periods_since_direct: 0,
            level: 0.0,
        };
        if partial.is_silent_at(first_sample) {
            return None;
        }
        partial.set_anchor(partial.state_at(first_sample));
        let next_period = (first_sample / GRID as u64 + 1) * GRID as u64;
        partial.next_anchor = partial.state_at(next_period);
        partial.fill_powers();
        Some(partial)
    }

    pub fn level(&self) -> f32 {
        self.level
    }

    /// Adds this component's samples for `out`, which starts at absolute sample `span_start` and
    /// lies within one grid period.
    #[inline]
    pub fn render(&self, span_start: u64, out: &mut [f32]) {
        let first = self.anchor_sample.max(span_start);
        let offset = (first - span_start) as usize;
        if offset >= out.len() {
            return;
        }
        let out = &mut out[offset..];
        let power = (first - self.anchor_sample) as usize;
        let re = &self.powers_re[power..power + out.len()];
        let im = &self.powers_im[power..power + out.len()];
        let [anchor_re, anchor_im] = self.anchor;
        for ((y, &z_re), &z_im) in out.iter_mut().zip(re).zip(im) {
            *y += anchor_re * z_im + anchor_im * z_re;
        }
    }

    /// Moves to the period starting at `period_start`; returns false once the component is silent.
    pub fn advance(&mut self, period_start: u64) -> bool {
        if self.anchor_sample >= period_start {
            // Started on this very boundary: its anchor already belongs to the new period.
            return true;
        }
        if self.is_silent_at(period_start) {
            return false;
        }
        self.set_anchor(self.next_anchor);
        self.anchor_sample = period_start;
        let following = period_start + GRID as u64;
        self.periods_since_direct += 1;
        self.next_anchor = if self.periods_since_direct == PERIODS_PER_DIRECT_ANCHOR {
            self.periods_since_direct = 0;
            self.state_at(following)
        } else {
            complex_mul(self.next_anchor, self.period_step)
        };
        true
    }

    fn is_silent_at(&self, sample: u64) -> bool {
        self.decay_per_sample * self.samples_since_onset(sample) > SILENT_DECAY_EXPONENT
    }

    fn samples_since_onset(&self, sample: u64) -> f64 {
        (sample - self.onset_sample) as f64 - self.onset_fraction
    }

    /// The exact complex state A·e^((−B + iω)τ) at `sample`; its imaginary part is the output.
    fn state_at(&self, sample: u64) -> [f64; 2] {
        let elapsed = self.samples_since_onset(sample);
        let [re, im] = complex_exp(
            -self.decay_per_sample * elapsed,
            self.radians_per_sample * elapsed,
        );
        [self.amplitude * re, self.amplitude * im]
    }

    fn set_anchor(&mut self, state: [f64; 2]) {
        self.anchor = [state[0] as f32, state[1] as f32];
        self.level = (state[0] * state[0] + state[1] * state[1]) as f32;
    }

    fn fill_powers(&mut self) {
        let step = complex_exp(-self.decay_per_sample, self.radians_per_sample);
        // |z^j| = e^(−dj) falls below NEGLIGIBLE_POWER from j = ln(1/NEGLIGIBLE_POWER)/d on;
        // counted up front rather than with a hypot per power, which made starts costly.
        let audible = (-NEGLIGIBLE_POWER.ln() / self.decay_per_sample).ceil();
        let count = if audible < GRID as f64 { audible as usize } else { GRID };
        let mut power: [f64; 2] = [1.0, 0.0];
        for j in 0..count {
            self.powers_re[j] = power[0] as f32;
            self.powers_im[j] = power[1] as f32;
            power = complex_mul(power, step);
        }
    }
}

#[inline]
fn complex_exp(log_magnitude: f64, phase: f64) -> [f64; 2] {
    let magnitude = log_magnitude.exp();
    let (sin, cos) = phase.sin_cos();
    [magnitude * cos, magnitude * sin]
}

#[inline]
fn complex_mul(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
}
