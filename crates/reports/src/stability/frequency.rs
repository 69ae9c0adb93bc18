//! Frequencies from 0 to above Nyquist: nothing is computed for 0 or at/above fs/2.

use super::checks::{
    ceiling, check, energy_not_growing, finite, outcome, time_ratio, Outcome, Property,
};
use super::harness::{follow, normal, pour_then_stop, run, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use sake_glug_engine::Constant;
use sake_glug_engine::{ModelConfig, Synthesis};

pub(super) struct FrequencySweep;

impl CaseGroup for FrequencySweep {
    const NAME: &'static str = "frequency";
    const DESCRIPTION: &'static str =
        "f1 = f2 ∈ {0, 1, 80, 0.4999·fs, fs/2, fs, 400 kHz, 10⁹} Hz; the same pour";
    const TIME_REFERENCE: &'static str = "continuous pouring (follow mode, 135°)";

    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let fs = 48_000.0;
        let seconds = scale.sweep_s();
        let normal = normal::<S>(fs, seconds, scale);
        [
            0.0,
            1.0,
            80.0,
            0.4999 * fs,
            0.5 * fs,
            fs,
            Constant::F1.range().max,
            1e9,
        ]
        .into_iter()
        .map(|frequency| {
            let config = ModelConfig {
                frequency_hz: [frequency; 2],
                ..follow().deterministic()
            };
            let run = run::<S>(
                &Setup::new(fs, config, seconds).repeats(scale.repeats()),
                &pour_then_stop(fs, 1.0),
            );
            let mut checks = vec![finite(&run), ceiling(&run)];
            if frequency > 0.0 && frequency < 0.5 * fs {
                checks.push(energy_not_growing(&run));
            } else {
                checks.push(check(
                    Property::NotComputed,
                    run.render.max_sounding == 0 && run.render.peak == 0.0,
                    format!(
                        "at most {} components sounded, peak {}",
                        run.render.max_sounding, run.render.peak
                    ),
                ));
            }
            checks.push(time_ratio(&run, &normal));
            outcome(
                StabilityCase::FrequencySweep,
                format!("f1 = f2 = {frequency} Hz"),
                checks,
                &run,
            )
        })
        .collect()
    }
}
