//! The f64 direct evaluator of MODEL.md §3–6: every unit's closed form summed at every sample, no
//! recursion, no dropping above −260 dB. Slow by design; the yardstick the fast paths are held to.
//!
//! It shares the pour (drain, onsets, draws: exact f64 procedures in the model itself) with the
//! engine, and shares none of the synthesis.

use std::ops::Range;

use crate::engine::amplitude::db_to_gain;
use crate::engine::config::{GAIN_DB, SAMPLE_RATE_HZ};
use crate::engine::{ControlSource, ModelConfig, Pour, UnitOnset};

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

/// Evaluates samples `window` of a render that starts from a reset at sample 0.
pub fn evaluate(
    sample_rate: f64,
    config: ModelConfig,
    controls: &impl ControlSource,
    window: Range<u64>,
) -> ReferenceWindow {
    let sample_rate = SAMPLE_RATE_HZ.sanitize(sample_rate);
    let mut pour = Pour::new(sample_rate, config);
    pour.reset();
    let mut onsets = Vec::new();
    let mut gains = Vec::with_capacity((window.end - window.start) as usize);
    for sample in 0..window.end {
        let (values, gain_db) = controls.at(sample);
        pour.step(sample, values, |onset| onsets.push(*onset));
        if sample >= window.start {
            gains.push(db_to_gain(GAIN_DB.sanitize(gain_db)));
        }
    }

    let mut samples = vec![0.0; gains.len()];
    for onset in &onsets {
        add_unit(onset, sample_rate, &window, &mut samples);
    }
    let ceiling = pour.config().ceiling;
    for (y, gain) in samples.iter_mut().zip(&gains) {
        *y = (*y * gain).clamp(-ceiling, ceiling);
    }
    ReferenceWindow { samples, onsets }
}

/// q_i(τ) of MODEL.md §5 (without G), added at every sample of `window` with τ ≥ 0.
fn add_unit(onset: &UnitOnset, sample_rate: f64, window: &Range<u64>, out: &mut [f64]) {
    let onset_time = onset.sample as f64 + onset.fraction;
    let components = onset
        .component_amplitudes()
        .into_iter()
        .zip(onset.shape.frequency_hz)
        .zip(onset.shape.decay_per_s);
    for ((amplitude, frequency_hz), decay_per_s) in components {
        if amplitude == 0.0 || frequency_hz >= 0.5 * sample_rate {
            continue;
        }
        let first = window.start.max(onset.sample + 1);
        for sample in first..window.end {
            let tau = (sample as f64 - onset_time) / sample_rate;
            let envelope = (-decay_per_s * tau).exp();
            if envelope < NEGLIGIBLE_ENVELOPE {
                break;
            }
            let phase = std::f64::consts::TAU * frequency_hz * tau;
            out[(sample - window.start) as usize] += amplitude * envelope * phase.sin();
        }
    }
}
