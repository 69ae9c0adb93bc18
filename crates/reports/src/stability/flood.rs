//! Pour time down to 10 ms and pockets down to 0.001 ml: hundreds of units due per sample.
//! The pour starts at most 8 units per sample and counts the rest as skipped, the start budget admits
//! a burst of 8 units and then 6000 units per second, and the bank holds at most 256
//! components (MODEL.md §11); the run time is compared with a busy but ordinary pour whose bank
//! is also full (0.02 ml pockets).

use super::checks::{
    ceiling, check, energy_not_growing, finite, outcome, time_ratio, Outcome, Property,
};
use super::harness::{follow, run, steady, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use sake_glug_engine::synthesis::MAX_COMPONENTS;
use sake_glug_engine::{Constant, Control, ControlValues};
use sake_glug_engine::{DrainMode, ModelConfig, Synthesis};

pub(super) struct Flood;

impl CaseGroup for Flood {
    const NAME: &'static str = "flood";
    const DESCRIPTION: &'static str =
        "pour time 10 ms, pocket 0.001 ml (≈ 600 units due per sample): once in simulate \
         mode (the bottle empties in 10 ms), once in follow mode (the flood lasts the \
         whole render)";
    const TIME_REFERENCE: &'static str =
        "a busy ordinary pour whose bank is also full (0.02 ml pockets, 3000 units/s)";

    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let fs = 48_000.0;
        let seconds = scale.sweep_s();
        let busy_config = ModelConfig {
            pocket_ml: 0.02,
            ..follow()
        };
        let busy = run::<S>(
            &Setup::new(fs, busy_config, seconds).repeats(scale.repeats()),
            &steady,
        );
        let fastest = |_: u64| ControlValues {
            tilt_deg: 135.0,
            pour_time_s: Control::PourTime.range().min,
            gain_db: -6.0,
            ..ControlValues::default()
        };
        let mut outcomes = Vec::new();
        for (name, drain) in [
            (
                "flood, bottle empties in 10 ms (simulate)",
                DrainMode::Simulate,
            ),
            ("flood for the whole render (follow)", DrainMode::Follow),
        ] {
            let config = ModelConfig {
                pocket_ml: Constant::Pocket.range().min,
                drain,
                ..ModelConfig::default()
            };
            let run = run::<S>(
                &Setup::new(fs, config, seconds).repeats(scale.repeats()),
                &fastest,
            );
            let mut checks = vec![
                finite(&run),
                ceiling(&run),
                check(
                    Property::ComponentsCapped,
                    run.render.max_sounding <= MAX_COMPONENTS && run.units_skipped > 0,
                    format!(
                        "at most {} sounding (cap {MAX_COMPONENTS}), {} of {} units skipped",
                        run.render.max_sounding, run.units_skipped, run.units_started
                    ),
                ),
                time_ratio(&run, &busy),
            ];
            if drain == DrainMode::Simulate {
                checks.push(energy_not_growing(&run));
            }
            outcomes.push(outcome(
                StabilityCase::Flood,
                name.to_string(),
                checks,
                &run,
            ));
        }
        outcomes
    }
}
