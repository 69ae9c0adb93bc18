//! The f64 direct evaluator of MODEL.md §3–6: every unit's closed form summed at every sample, no
//! recursion, no dropping above −260 dB. Slow by design; the yardstick the fast paths are held to.
//!
//! It takes only the onset schedule from the engine: [`Pour`] gives each unit's onset time, V_i
//! and drawn f/B (MODEL.md §3, §4, §7; checked on their own by `tests/engine/drain.rs` and
//! `onsets.rs`). Everything after that it computes itself from the contract, with its own copies
//! of the contract's formulas and constants and none of the engine's: the amplitude law a(V), the
//! c / (1 − c) split, the gain in dB, the ceiling, the ranges inputs are brought into (§11), the
//! onset cap and the start budget (§11). So a fault in any of the engine's copies shows as a
//! difference from this evaluator (`tests/engine/reference_match.rs`).

use std::ops::Range;

use crate::engine::{ControlSource, ModelConfig, Pour, UnitOnset};

/// MODEL.md §5: Asum = 0.0027·V − 0.2277, V in ml of the paper's 300 ml bottle, normalised by
/// its value for a full bottle, 0.5823.
const FIT_SLOPE_PER_ML: f64 = 0.0027;
const FIT_OFFSET: f64 = 0.2277;
const FIT_BOTTLE_ML: f64 = 300.0;
const FIT_FULL_BOTTLE: f64 = 0.5823;

/// MODEL.md §11: an input's range and default, copied from the contract's table.
struct Allowed {
    min: f64,
    max: f64,
    default: f64,
}

impl Allowed {
    /// NaN takes the default; anything else is brought to the nearest bound (MODEL.md §11).
    fn bring_in(&self, value: f64) -> f64 {
        if value.is_nan() {
            self.default
        } else {
            value.max(self.min).min(self.max)
        }
    }
}

const SAMPLE_RATE_HZ: Allowed = Allowed {
    min: 1_000.0,
    max: 768_000.0,
    default: 48_000.0,
};
const VISCOSITY: Allowed = Allowed {
    min: 0.0,
    max: 1.0,
    default: 0.33,
};
const GAIN_DB: Allowed = Allowed {
    min: -120.0,
    max: 24.0,
    default: -6.0,
};
const CAPACITY_ML: Allowed = Allowed {
    min: 1.0,
    max: 100_000.0,
    default: 300.0,
};
const CEILING: Allowed = Allowed {
    min: 0.001,
    max: 1.0,
    default: 1.0,
};

/// MODEL.md §6: gain and ceiling reach a new value in a straight line over 10 ms.
const OUTPUT_RAMP_S: f64 = 0.010;

/// MODEL.md §6 as the contract words it: the value at sample n, where the target asked for
/// last changed at sample `since` (from the value the sample before had, `from`), is
/// from + (to − from)·min(1, (n − since + 1)/R).
struct Ramped {
    samples: f64,
    from: f64,
    to: f64,
    since: u64,
    now: f64,
}

impl Ramped {
    fn new(sample_rate: f64) -> Self {
        Self {
            samples: (sample_rate * OUTPUT_RAMP_S).round().max(1.0),
            from: f64::NAN,
            to: f64::NAN,
            since: 0,
            now: f64::NAN,
        }
    }

    /// The value at `sample` whose target is `to`; called for every sample from 0 on.
    fn at(&mut self, sample: u64, to: f64) -> f64 {
        if sample == 0 {
            // A reset: the first sample takes its target as it is.
            (self.from, self.to, self.since) = (to, to, 0);
        } else if to.to_bits() != self.to.to_bits() {
            (self.from, self.to, self.since) = (self.now, to, sample);
        }
        let done = (sample - self.since + 1) as f64 / self.samples;
        self.now = if done >= 1.0 {
            self.to
        } else {
            self.from + (self.to - self.from) * done
        };
        self.now
    }
}

/// MODEL.md §11: units started per sample at most.
const ONSETS_PER_SAMPLE: usize = 8;
/// MODEL.md §11: the start budget holds at most 8 units and refills at 6000 units per second.
const BUDGET_UNITS: f64 = 8.0;
const BUDGET_UNITS_PER_S: f64 = 6000.0;

/// A component's envelope e^(−Bτ) below which the reference stops adding it (−260 dB): far below
/// any error budget, and keeps the evaluation finite in time.
const NEGLIGIBLE_ENVELOPE: f64 = 1e-13;

/// What [`evaluate`] returns: the reference's samples of one window, and the onsets behind them.
pub struct ReferenceWindow {
    /// The samples of the window, in order.
    pub samples: Vec<f64>,
    /// Every unit that started from sample 0 to the window's end.
    pub onsets: Vec<UnitOnset>,
}

/// One started unit: what §5 needs, computed here.
struct Unit {
    /// t_i in samples: n + x.
    onset: f64,
    first_sample: u64,
    /// A1 = c·a(V_i), A2 = (1 − c)·a(V_i); the gain G is applied per sample, on its ramp.
    amplitudes: [f64; 2],
    frequency_hz: [f64; 2],
    decay_per_s: [f64; 2],
}

/// Evaluates samples `window` of a render that starts from a reset at sample 0.
pub fn evaluate(
    sample_rate: f64,
    config: ModelConfig,
    controls: &impl ControlSource,
    window: Range<u64>,
) -> ReferenceWindow {
    let sample_rate = SAMPLE_RATE_HZ.bring_in(sample_rate);
    let capacity_ml = CAPACITY_ML.bring_in(config.capacity_ml);
    let ceiling = CEILING.bring_in(config.ceiling);
    let mut pour = Pour::new(sample_rate, config);
    pour.reset();
    let mut onsets = Vec::new();
    let mut units = Vec::new();
    let mut budget = (BUDGET_UNITS, 0.0f64);
    let mut gains = Vec::with_capacity((window.end - window.start) as usize);
    let mut gain = Ramped::new(sample_rate);
    for sample in 0..window.end {
        let values = controls.at(sample);
        let gain_db = values.gain_db;
        // §5: c is taken at the onset's sample, brought into [0, 1].
        let viscosity = VISCOSITY.bring_in(values.viscosity);
        let mut this_sample = 0;
        pour.step(sample, values, |onset| {
            onsets.push(*onset);
            this_sample += 1;
            if this_sample > ONSETS_PER_SAMPLE {
                return;
            }
            let onset_s = (onset.sample as f64 + onset.fraction) / sample_rate;
            let (units_left, as_of_s) = &mut budget;
            *units_left = (*units_left + BUDGET_UNITS_PER_S * (onset_s - *as_of_s).max(0.0))
                .min(BUDGET_UNITS);
            *as_of_s = as_of_s.max(onset_s);
            if *units_left < 1.0 {
                return;
            }
            *units_left -= 1.0;
            let amplitude = amplitude_law(onset.volume_ml, capacity_ml);
            units.push(Unit {
                onset: onset.sample as f64 + onset.fraction,
                first_sample: onset.sample + 1,
                amplitudes: [viscosity * amplitude, (1.0 - viscosity) * amplitude],
                frequency_hz: onset.shape.frequency_hz,
                decay_per_s: onset.shape.decay_per_s,
            });
        });
        let gain = gain.at(sample, 10f64.powf(GAIN_DB.bring_in(gain_db) / 20.0));
        if sample >= window.start {
            gains.push(gain);
        }
    }

    let mut samples = vec![0.0; gains.len()];
    for unit in &units {
        add_unit(unit, sample_rate, &window, &mut samples);
    }
    for (y, gain) in samples.iter_mut().zip(&gains) {
        *y = (*y * gain).max(-ceiling).min(ceiling);
    }
    ReferenceWindow { samples, onsets }
}

/// a(V) of MODEL.md §5.
fn amplitude_law(volume_ml: f64, capacity_ml: f64) -> f64 {
    let in_papers_bottle_ml = FIT_BOTTLE_ML * volume_ml / capacity_ml;
    (FIT_SLOPE_PER_ML * in_papers_bottle_ml - FIT_OFFSET).max(0.0) / FIT_FULL_BOTTLE
}

/// q_i(τ) of MODEL.md §5 (without G), added at every sample of `window` with τ ≥ 0. A component
/// at or above fs/2, at 0 Hz or of zero amplitude is omitted (§6).
fn add_unit(unit: &Unit, sample_rate: f64, window: &Range<u64>, out: &mut [f64]) {
    for k in 0..2 {
        let (amplitude, frequency_hz) = (unit.amplitudes[k], unit.frequency_hz[k]);
        if amplitude == 0.0 || frequency_hz <= 0.0 || frequency_hz >= 0.5 * sample_rate {
            continue;
        }
        let first = window.start.max(unit.first_sample);
        for sample in first..window.end {
            let tau = (sample as f64 - unit.onset) / sample_rate;
            let envelope = (-unit.decay_per_s[k] * tau).exp();
            if envelope < NEGLIGIBLE_ENVELOPE {
                break;
            }
            let phase = std::f64::consts::TAU * frequency_hz * tau;
            out[(sample - window.start) as usize] += amplitude * envelope * phase.sin();
        }
    }
}
