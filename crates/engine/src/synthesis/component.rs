//! One decaying sinusoid of a wave unit (one term of MODEL.md §5) as every synthesis path sees
//! it, and the rule for which components are computed at all (MODEL.md §6).

use crate::pour::UnitOnset;

/// A component is silent once e^(−Bτ) < 10⁻⁶ (MODEL.md §6): Bτ > ln 10⁶.
pub const SILENT_DECAY_EXPONENT: f64 = 13.815_510_557_964_274;
/// A component this weak (−240 dB) is never audible; skipping it keeps denormals out of f32.
const NEGLIGIBLE_AMPLITUDE: f64 = 1e-12;

/// A·e^(−d·τ + i·(ω·τ + glide(τ))) at sample n, τ = n − n_i − x: the closed form, in per-sample
/// units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    pub onset_sample: u64,
    pub onset_fraction: f64,
    pub amplitude: f64,
    pub decay_per_sample: f64,
    pub radians_per_sample: f64,
    /// `None` for a component that does not glide (MODEL.md §5.2: ρ = 1).
    pub glide: Option<ComponentGlide>,
}

/// A component's glide (MODEL.md §5.2) in per-sample units: its phase runs ahead of the plain
/// ω·τ by K·(1 − e^(−τ/T)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComponentGlide {
    /// K = ω·(ρ − 1)·T: all the phase the glide adds over its course (rad).
    pub excess_radians: f64,
    /// T: the time constant τ_k in samples.
    pub time_samples: f64,
}

impl ComponentGlide {
    /// The phase the glide has added by `elapsed` samples since the onset.
    #[inline]
    pub fn phase_at(&self, elapsed: f64) -> f64 {
        -self.excess_radians * (-elapsed / self.time_samples).exp_m1()
    }

    /// The phase it has yet to add after `elapsed` samples: K·e^(−τ/T).
    #[inline]
    pub fn phase_left_at(&self, elapsed: f64) -> f64 {
        self.excess_radians * (-elapsed / self.time_samples).exp()
    }
}

impl Component {
    /// Component `index` (0: f1/B1, 1: f2/B2) of `onset`, or `None` if it is never computed:
    /// zero amplitude, a frequency below 20 Hz or one that reaches Nyquist (its glide's start
    /// included, MODEL.md §5.2, §6), or already below −120 dB.
    pub fn of(onset: &UnitOnset, index: usize, sample_rate: f64) -> Option<Self> {
        let amplitude = onset.component_amplitudes()[index];
        let frequency_hz = onset.shape.frequency_hz[index];
        let glide = &onset.shape.glide;
        let audible_amplitude = amplitude >= NEGLIGIBLE_AMPLITUDE;
        if !audible_amplitude || !glide.sounds(index, frequency_hz, sample_rate) {
            return None;
        }
        let radians_per_sample = std::f64::consts::TAU * frequency_hz / sample_rate;
        let component = Self {
            onset_sample: onset.sample,
            onset_fraction: onset.fraction,
            amplitude,
            decay_per_sample: onset.shape.decay_per_s[index] / sample_rate,
            radians_per_sample,
            glide: glide.glides(index).then(|| {
                let time_samples = glide.time_ms[index] / 1000.0 * sample_rate;
                ComponentGlide {
                    excess_radians: radians_per_sample * (glide.ratio[index] - 1.0) * time_samples,
                    time_samples,
                }
            }),
        };
        (!component.is_silent_at(component.first_sample())).then_some(component)
    }

    /// The first sample at or after the onset time (n + x): n + 1. A sample at exactly the onset
    /// would contribute sin(0) = 0.
    pub fn first_sample(&self) -> u64 {
        self.onset_sample + 1
    }

    /// Whether e^(−Bτ) has fallen below 10⁻⁶ by `sample`.
    pub fn is_silent_at(&self, sample: u64) -> bool {
        self.decay_per_sample * self.samples_since_onset(sample) > SILENT_DECAY_EXPONENT
    }

    /// The first sample from which [`Component::is_silent_at`] holds (it then holds for good), or
    /// `u64::MAX` if it never does: found once, so that a sounding component compares integers.
    pub fn silent_from(&self) -> u64 {
        if self.decay_per_sample.is_nan() || self.decay_per_sample <= 0.0 {
            return u64::MAX;
        }
        let guess = self.onset_sample as f64
            + self.onset_fraction
            + SILENT_DECAY_EXPONENT / self.decay_per_sample;
        // Beyond any render (and any u64).
        if guess.is_nan() || guess >= 1e19 {
            return u64::MAX;
        }
        // The guess is off by a sample at most; the test itself decides.
        let mut sample = (guess as u64).max(self.onset_sample);
        while sample > self.onset_sample && self.is_silent_at(sample - 1) {
            sample -= 1;
        }
        while !self.is_silent_at(sample) {
            sample += 1;
        }
        sample
    }

    /// The exact complex state at `sample`; its imaginary part is the output.
    pub fn state_at(&self, sample: u64) -> [f64; 2] {
        let elapsed = self.samples_since_onset(sample);
        let phase = match self.glide {
            None => self.radians_per_sample * elapsed,
            Some(glide) => self.radians_per_sample * elapsed + glide.phase_at(elapsed),
        };
        let [re, im] = complex_exp(-self.decay_per_sample * elapsed, phase);
        [self.amplitude * re, self.amplitude * im]
    }

    /// z = e^(−d + iω): the state's rotation per sample, without the glide.
    pub fn step(&self) -> [f64; 2] {
        complex_exp(-self.decay_per_sample, self.radians_per_sample)
    }

    /// τ in samples: `sample` − n_i − x.
    pub fn samples_since_onset(&self, sample: u64) -> f64 {
        (sample - self.onset_sample) as f64 - self.onset_fraction
    }
}

#[inline]
pub fn complex_exp(log_magnitude: f64, phase: f64) -> [f64; 2] {
    let magnitude = log_magnitude.exp();
    let (sin, cos) = phase.sin_cos();
    [magnitude * cos, magnitude * sin]
}

#[inline]
pub fn complex_mul(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
}
