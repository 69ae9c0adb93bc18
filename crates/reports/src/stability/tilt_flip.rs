//! Tilt jumping 0° ↔ 180° every sample, in both drain modes.

use super::checks::{ceiling, check, finite, outcome, time_ratio, Outcome, Property};
use super::harness::{follow, run, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use sake_glug_engine::ControlValues;
use sake_glug_engine::{ModelConfig, Synthesis};

pub(super) struct TiltFlip;

impl CaseGroup for TiltFlip {
    const NAME: &'static str = "tilt flip";
    const DESCRIPTION: &'static str = "tilt 0° ↔ 180° every sample, simulate and follow modes";
    const TIME_REFERENCE: &'static str =
        "continuous pouring with the tilt moving at every sample (follow mode, a slow \
         sweep from 100° to 170°): under constant controls the pour takes a period at \
         once, under a moving tilt sample by sample, like the flip";

    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let fs = 48_000.0;
        let seconds = scale.sweep_s();
        let sweep_samples = seconds * fs;
        let sweep = move |sample: u64| ControlValues {
            tilt_deg: 100.0 + 70.0 * (sample as f64 / sweep_samples),
            gain_db: -6.0,
            ..ControlValues::default()
        };
        let setup = |config| Setup::new(fs, config, seconds).repeats(scale.repeats());
        let normal = run::<S>(&setup(follow()), &sweep);
        let flip = |sample: u64| ControlValues {
            tilt_deg: if sample.is_multiple_of(2) { 0.0 } else { 180.0 },
            gain_db: -6.0,
            ..ControlValues::default()
        };
        [("simulate", ModelConfig::default()), ("follow", follow())]
            .into_iter()
            .map(|(mode, config)| {
                let run = run::<S>(&setup(config), &flip);
                let checks = vec![
                    finite(&run),
                    ceiling(&run),
                    check(
                        Property::Glugs,
                        run.units_started > 0,
                        format!("{} units started", run.units_started),
                    ),
                    time_ratio(&run, &normal),
                ];
                outcome(
                    StabilityCase::TiltFlip,
                    format!("0° ↔ 180° every sample ({mode})"),
                    checks,
                    &run,
                )
            })
            .collect()
    }
}
