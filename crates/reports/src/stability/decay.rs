//! Decay rates from 0 to 10⁹ s⁻¹: a second of pouring, then the units ring out.

use super::checks::{ceiling, energy_not_growing, finite, outcome, time_ratio, Outcome};
use super::harness::{follow, pour_then_stop_at, run, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use sake_glug_engine::{ModelConfig, Synthesis};

/// The output gain of the decay sweep: twelve never-decaying units in phase at 300 Hz sum to
/// 4 before the gain, and must stay under the ceiling so that their energy can be judged.
const DECAY_SWEEP_GAIN_DB: f64 = -20.0;

pub(super) struct DecaySweep;

impl CaseGroup for DecaySweep {
    const NAME: &'static str = "decay";
    const DESCRIPTION: &'static str =
        "B1 = B2 ∈ {0, 10⁻⁶, 1, 45, 10³, 10⁵, 10⁷, 10⁹} s⁻¹; 1 s of steady pouring then \
         upright, at −20 dB (twelve undecaying units in phase stay under the ceiling)";
    const TIME_REFERENCE: &'static str = "the same pour with B = 0 (most work, no small values)";

    /// Times are compared with B = 0, the same pour with the most work (every component rings to
    /// the end) and no small values, so a slower decay case means time lost to denormals or
    /// wasted work.
    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let fs = 48_000.0;
        let seconds = scale.sweep_s();
        // Deterministic: equal frequencies, so ringing units add without beats.
        let setup = |decay: f64| {
            let config = ModelConfig {
                decay_per_s: [decay; 2],
                ..follow().deterministic()
            };
            Setup::new(fs, config, seconds).repeats(scale.repeats())
        };
        let inputs = pour_then_stop_at(fs, 1.0, DECAY_SWEEP_GAIN_DB);
        let normal = run::<S>(&setup(0.0), &inputs);
        [0.0, 1e-6, 1.0, 45.0, 1e3, 1e5, 1e7, 1e9]
            .into_iter()
            .map(|decay| {
                let run = run::<S>(&setup(decay), &inputs);
                let checks = vec![
                    finite(&run),
                    ceiling(&run),
                    energy_not_growing(&run),
                    time_ratio(&run, &normal),
                ];
                outcome(
                    StabilityCase::DecaySweep,
                    format!("B1 = B2 = {decay:e} /s"),
                    checks,
                    &run,
                )
            })
            .collect()
    }
}
