//! NaN, ±∞, negative and huge values for every control and every constant, each alone, through
//! the engine's API: output finite and under the sanitised ceiling.

use super::checks::{check, Outcome, Property};
use super::harness::{follow, run, steady, Run, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use sake_glug_engine::{Constant, Control, ModelConfig, Synthesis};

/// Values no input should ever carry.
const HOSTILE: [f64; 7] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    -1e300,
    1e300,
    -1.0,
    0.0,
];

pub(super) struct HostileInputs;

impl CaseGroup for HostileInputs {
    const NAME: &'static str = "hostile input";
    const DESCRIPTION: &'static str =
        "NaN, +∞, −∞, −10³⁰⁰, 10³⁰⁰, −1 and 0 for each control (every other sample, so \
         they arrive mid-pour), each model constant and the ceiling (at construction, and \
         again through `set_config` halfway through a pour) and the sample rate, by scene key";
    const TIME_REFERENCE: &'static str = "—";

    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let fs = 48_000.0;
        let seconds = match scale {
            Scale::Test => 0.5,
            Scale::Report => 5.0,
        };
        // Every constant of the table, by its scene key, then what a scene does not set.
        let constants = Constant::ALL
            .iter()
            .map(|&constant| Setting::Constant(constant))
            .chain([Setting::Ceiling, Setting::SampleRate]);
        let mut outcomes = Vec::new();
        for &control in Control::ALL {
            let name = control.quantity().scene_key;
            let runs = HOSTILE
                .iter()
                .map(|&value| {
                    // The bad value every other sample, so it also arrives mid-pour.
                    let inputs = move |sample: u64| {
                        let mut values = steady(sample);
                        if sample % 2 == 1 {
                            values[control] = value;
                        }
                        values
                    };
                    run::<S>(&Setup::new(fs, follow(), seconds), &inputs)
                })
                .collect();
            outcomes.push(judge(format!("control: {name}"), runs));
        }
        for setting in constants {
            let name = setting.name();
            let runs = HOSTILE
                .iter()
                .map(|&value| {
                    let mut config = follow();
                    setting.set(&mut config, value);
                    let sample_rate = match setting {
                        Setting::SampleRate => value,
                        _ => fs,
                    };
                    run::<S>(&Setup::new(sample_rate, config, seconds), &steady)
                })
                .chain(HOSTILE.iter().map(|&value| {
                    // The same value arriving mid-pour through `set_config`.
                    let mut config = follow();
                    setting.set(&mut config, value);
                    let setup = Setup::new(fs, follow(), seconds).switching_to(config);
                    run::<S>(&setup, &steady)
                }))
                .collect();
            outcomes.push(judge(format!("constant: {name}"), runs));
        }
        outcomes
    }
}

/// A constant of the model, or a setting that is not in the table of constants.
#[derive(Clone, Copy)]
enum Setting {
    Constant(Constant),
    Ceiling,
    SampleRate,
}

impl Setting {
    fn name(self) -> &'static str {
        match self {
            Setting::Constant(constant) => constant.quantity().scene_key,
            Setting::Ceiling => "ceiling",
            Setting::SampleRate => "sample rate",
        }
    }

    /// Puts `value` into `config` (the sample rate is not in it: the caller renders at it).
    fn set(self, config: &mut ModelConfig, value: f64) {
        match self {
            Setting::Constant(constant) => constant.set(config, value),
            Setting::Ceiling => config.ceiling = value,
            Setting::SampleRate => {}
        }
    }
}

/// One outcome for every render of one input: finite, and under each render's ceiling.
fn judge(name: String, runs: Vec<Run>) -> Outcome {
    let hidden: u64 = runs
        .iter()
        .map(|r| r.render.non_finite_before_limiter)
        .sum();
    let all_finite = runs.iter().all(|r| r.render.all_finite) && hidden == 0;
    let within = runs
        .iter()
        .all(|r| r.render.all_finite && r.render.peak <= r.ceiling as f32);
    let peak = runs.iter().map(|r| r.render.peak).fold(0.0f32, f32::max);
    let limited: u64 = runs.iter().map(|r| r.render.limiter_events).sum();
    Outcome {
        group: StabilityCase::HostileInputs,
        name,
        checks: vec![
            check(
                Property::Finite,
                all_finite,
                format!(
                    "{} renders, {hidden} samples not finite before the limiter",
                    runs.len()
                ),
            ),
            check(
                Property::Ceiling,
                within,
                format!("largest peak {peak:.3}, limiter acted on {limited} samples"),
            ),
        ],
        notes: "values: NaN, +∞, −∞, −1e300, 1e300, −1, 0 (constants: at construction and \
                again through set_config mid-pour)"
            .into(),
    }
}
