//! The f64 direct evaluator of MODEL.md §3–6: every unit's closed form summed at every sample, no
//! recursion, no dropping above −260 dB. Slow by design; the yardstick the fast paths are held to.
//!
//! It takes only the onset schedule from the engine: [`Pour`] gives the sample and the fraction
//! of it at which each unit starts, and its draws: f's spread 1 + j_f·u, B and the amplitude's
//! factor (MODEL.md §4, §7, §12; the schedule is checked on its own by `tests/engine/drain.rs` and `onsets.rs`).
//! Everything else it computes itself from the contract, with its own copies of the contract's
//! formulas and constants and none of the engine's: the drain of §3 and §8 through its own reading
//! of the bottle's curves r, s and h (§2, §12), and from it each unit's V_i; the headspace law of
//! §5.1 and each unit's f from it; the glide of §5.2, each phase from its closed form; the amplitude law
//! a(V) with its V0 (§5, §12); the c / (1 − c) split, the gain in dB, the ceiling, the ranges
//! inputs are brought into (§11), the onset cap and the start budget (§11). A unit the schedule
//! starts in a sample where its own drain has no glugging outflow it leaves silent. So a fault in
//! any of the engine's copies shows as a difference from this evaluator
//! (`tests/engine/reference_match.rs`).

use std::ops::Range;

use crate::glide::LOWEST_SOUNDING_HZ;
use crate::{ControlSource, ControlValues, DrainMode, ModelConfig, Pour, SilentBelow, UnitOnset};

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
const TILT_DEG: Allowed = Allowed {
    min: 0.0,
    max: 180.0,
    default: 0.0,
};
const FILL_PERCENT: Allowed = Allowed {
    min: 0.0,
    max: 100.0,
    default: 100.0,
};
const POUR_TIME_S: Allowed = Allowed {
    min: 0.01,
    max: 3_600.0,
    default: 5.0,
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
const FREQUENCY_HZ: [Allowed; 2] = [
    Allowed {
        min: 0.0,
        max: 400_000.0,
        default: 80.0,
    },
    Allowed {
        min: 0.0,
        max: 400_000.0,
        default: 300.0,
    },
];
const POCKET_ML: Allowed = Allowed {
    min: 0.001,
    max: 1_000.0,
    default: 5.0,
};
const HEADSPACE_ML: Allowed = Allowed {
    min: 0.001,
    max: 100_000.0,
    default: 30.0,
};
const HEADSPACE_EXPONENT: Allowed = Allowed {
    min: -3.0,
    max: 3.0,
    default: 0.0,
};
const GLIDE_RATIO: Allowed = Allowed {
    min: 0.25,
    max: 4.0,
    default: 1.0,
};
const GLIDE_MS: Allowed = Allowed {
    min: 0.5,
    max: 500.0,
    default: 20.0,
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
    /// Every unit the reference voiced (the caps of §11 passed, its sample glugging), in order,
    /// as it computed it.
    pub units: Vec<ReferenceUnit>,
}

/// A unit as the reference computes it from the contract.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceUnit {
    /// t_i (s).
    pub onset_s: f64,
    /// V_i from its own drain (ml).
    pub volume_ml: f64,
    /// A1 = c·Asum_i and A2 = (1 − c)·Asum_i, before the output gain.
    pub amplitudes: [f64; 2],
}

/// MODEL.md §2, §12: a curve of tilt at `tilt_deg`: linear between its points, constant outside
/// them (the points as the constants give them: data, not the engine's evaluation).
fn curve_at(points: &[(f64, f64)], tilt_deg: f64) -> f64 {
    let (first, last) = (points[0], points[points.len() - 1]);
    if tilt_deg <= first.0 {
        return first.1;
    }
    if tilt_deg > last.0 {
        return last.1;
    }
    // The first point at or beyond the tilt, and the one before it.
    let next = points.partition_point(|&(tilt, _)| tilt < tilt_deg);
    let ((t0, v0), (t1, v1)) = (points[next - 1], points[next]);
    v0 + (v1 - v0) * (tilt_deg - t0) / (t1 - t0)
}

/// MODEL.md §3 and §8, sample by sample: the residual volume, and what each sample poured.
struct Drain {
    volume_ml: f64,
    /// The fill level of the sample before (simulate mode refills when it changes).
    fill_percent: f64,
}

/// One sample of [`Drain`]: V at its start, its outflow, and whether it glugs.
struct Poured {
    volume_before_ml: f64,
    outflow_ml: f64,
    /// The mouth is submerged (V > s(θ)·C) and liquid flows: §4 counts this outflow.
    glugs: bool,
}

impl Drain {
    /// Sample `sample` under `values`, the first one after a reset at sample 0.
    fn step(
        &mut self,
        sample: u64,
        values: &ControlValues,
        config: &ModelConfig,
        capacity_ml: f64,
        sample_rate: f64,
    ) -> Poured {
        let tilt_deg = TILT_DEG.bring_in(values.tilt_deg);
        let fill_percent = FILL_PERCENT.bring_in(values.fill_percent);
        let pour_time_s = POUR_TIME_S.bring_in(values.pour_time_s);
        let curves = &config.curves;
        let simulate = config.drain == DrainMode::Simulate;
        // §8: a reset fills the bottle; in simulate mode so does any change of the fill level;
        // in follow mode V is the fill level at every sample.
        let refill = sample == 0 || (simulate && fill_percent != self.fill_percent);
        self.fill_percent = fill_percent;
        let volume_before_ml = if refill || !simulate {
            fill_percent / 100.0 * capacity_ml
        } else {
            self.volume_ml
        };
        // §3: k(θ) = (C/T)·h(θ); the outflow is min(k/fs, max(0, V − r(θ)·C)).
        let rate_ml_per_s = capacity_ml / pour_time_s * curve_at(curves.drain.points(), tilt_deg);
        let rest_ml = curve_at(curves.rest.points(), tilt_deg) * capacity_ml;
        let outflow_ml = (rate_ml_per_s / sample_rate).min((volume_before_ml - rest_ml).max(0.0));
        let submerged_ml = curve_at(curves.submerged.points(), tilt_deg) * capacity_ml;
        self.volume_ml = if simulate {
            volume_before_ml - outflow_ml
        } else {
            volume_before_ml
        };
        Poured {
            volume_before_ml,
            outflow_ml,
            glugs: volume_before_ml > submerged_ml && outflow_ml > 0.0,
        }
    }
}

/// One started unit: what §5 needs, computed here.
struct Unit {
    /// t_i in samples: n + x.
    onset: f64,
    onset_s: f64,
    volume_ml: f64,
    first_sample: u64,
    /// A1 = c·Asum_i, A2 = (1 − c)·Asum_i, Asum_i = a(V_i)·exp(σ_A·z_i); the gain G is applied
    /// per sample, on its ramp.
    amplitudes: [f64; 2],
    frequency_hz: [f64; 2],
    decay_per_s: [f64; 2],
    /// ρ_k and τ_k (s) of the glide of §5.2, as the model gave them at the onset.
    glide_ratio: [f64; 2],
    glide_s: [f64; 2],
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
    let mut drain = Drain {
        volume_ml: 0.0,
        fill_percent: f64::NAN,
    };
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
        let poured = drain.step(sample, &values, &config, capacity_ml, sample_rate);
        let mut this_sample = 0;
        pour.step(sample, values, |onset| {
            onsets.push(*onset);
            if !poured.glugs {
                return;
            }
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
            // §4: V_i = V at the sample's start less the part of its outflow before the onset.
            let volume_ml = poured.volume_before_ml - onset.fraction * poured.outflow_ml;
            let amplitude = amplitude_law(volume_ml, capacity_ml, config.silent_below)
                * onset.shape.amplitude_factor;
            units.push(Unit {
                onset: onset.sample as f64 + onset.fraction,
                onset_s,
                volume_ml,
                first_sample: onset.sample + 1,
                amplitudes: [viscosity * amplitude, (1.0 - viscosity) * amplitude],
                frequency_hz: unit_frequencies(
                    &config,
                    volume_ml,
                    capacity_ml,
                    onset.shape.frequency_spread,
                ),
                decay_per_s: onset.shape.decay_per_s,
                glide_ratio: config.glide.ratio.map(|ratio| GLIDE_RATIO.bring_in(ratio)),
                glide_s: config
                    .glide
                    .time_ms
                    .map(|ms| GLIDE_MS.bring_in(ms) / 1000.0),
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
    let units = units
        .iter()
        .map(|unit| ReferenceUnit {
            onset_s: unit.onset_s,
            volume_ml: unit.volume_ml,
            amplitudes: unit.amplitudes,
        })
        .collect();
    ReferenceWindow {
        samples,
        onsets,
        units,
    }
}

/// a(V) of MODEL.md §5 and §12: max(0, (V − V0)/(C − V0)). V0 is brought into 0 ≤ V0 < C (a NaN
/// is the default); the default, the paper's V0 scaled with C, is evaluated as the paper's line,
/// the same function in the arithmetic renders have always used.
fn amplitude_law(volume_ml: f64, capacity_ml: f64, silent_below: SilentBelow) -> f64 {
    let silent_ml = match silent_below {
        SilentBelow::Ml(ml) if !ml.is_nan() => ml.max(0.0).min(capacity_ml.next_down()),
        _ => {
            let in_papers_bottle_ml = FIT_BOTTLE_ML * volume_ml / capacity_ml;
            return (FIT_SLOPE_PER_ML * in_papers_bottle_ml - FIT_OFFSET).max(0.0)
                / FIT_FULL_BOTTLE;
        }
    };
    ((volume_ml - silent_ml) / (capacity_ml - silent_ml)).max(0.0)
}

/// f_k,i of MODEL.md §5.1 and §7: f_k · ((H + b)/(H + C − V_i))^γ_k · (1 + j_f·u), the law read from
/// the unit's own V_i and only the draw (1 + j_f·u) taken from the engine. An exponent of 0 is
/// the paper's constant frequency: the factor is exactly 1.
fn unit_frequencies(
    config: &ModelConfig,
    volume_ml: f64,
    capacity_ml: f64,
    spread: [f64; 2],
) -> [f64; 2] {
    let headspace_ml = HEADSPACE_ML.bring_in(config.headspace.headspace_ml);
    let pocket_ml = POCKET_ML.bring_in(config.pocket_ml);
    let air_ml = headspace_ml + capacity_ml - volume_ml;
    std::array::from_fn(|k| {
        let quoted_hz = FREQUENCY_HZ[k].bring_in(config.frequency_hz[k]);
        let exponent = HEADSPACE_EXPONENT.bring_in(config.headspace.exponent[k]);
        let law = if exponent == 0.0 {
            1.0
        } else {
            ((headspace_ml + pocket_ml) / air_ml).powf(exponent)
        };
        quoted_hz * law * spread[k]
    })
}

/// q_i(τ) of MODEL.md §5 (without G), added at every sample of `window` with τ ≥ 0. A component
/// at or above fs/2 (a glide's start frequency included, §5.2), below 20 Hz or of zero amplitude
/// is omitted (§6). A gliding component's phase is §5.2's closed form,
/// 2π·f·[τ + (ρ − 1)·τ_k·(1 − e^(−τ/τ_k))].
fn add_unit(unit: &Unit, sample_rate: f64, window: &Range<u64>, out: &mut [f64]) {
    for k in 0..2 {
        let (amplitude, frequency_hz) = (unit.amplitudes[k], unit.frequency_hz[k]);
        let (ratio, glide_s) = (unit.glide_ratio[k], unit.glide_s[k]);
        let highest_hz = frequency_hz * ratio.max(1.0);
        if amplitude == 0.0 || frequency_hz < LOWEST_SOUNDING_HZ || highest_hz >= 0.5 * sample_rate
        {
            continue;
        }
        let first = window.start.max(unit.first_sample);
        for sample in first..window.end {
            let tau = (sample as f64 - unit.onset) / sample_rate;
            let envelope = (-unit.decay_per_s[k] * tau).exp();
            if envelope < NEGLIGIBLE_ENVELOPE {
                break;
            }
            let phase = if ratio == 1.0 {
                std::f64::consts::TAU * frequency_hz * tau
            } else {
                std::f64::consts::TAU
                    * frequency_hz
                    * (tau + (ratio - 1.0) * glide_s * (1.0 - (-tau / glide_s).exp()))
            };
            out[(sample - window.start) as usize] += amplitude * envelope * phase.sin();
        }
    }
}
