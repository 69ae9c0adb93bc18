//! NaN, ±∞, negative and huge values for every control and every constant, each alone, through
//! the engine's API: output finite and under the sanitised ceiling.

use super::checks::{check, Outcome, Property};
use super::harness::{follow, run, steady, Run, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use crate::engine::config::ControlValues;
use crate::engine::{ModelConfig, Synthesis};

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
        "NaN, +∞, −∞, −10³⁰⁰, 10³⁰⁰, −1 and 0 for each of the five controls (every \
         other sample, so they arrive mid-pour) and each constant of `ModelConfig` (at \
         construction, and again through `set_config` halfway through a pour) and the \
         sample rate";
    const TIME_REFERENCE: &'static str = "—";

    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let fs = 48_000.0;
        let seconds = match scale {
            Scale::Test => 0.5,
            Scale::Report => 5.0,
        };
        type SetControl = fn(&mut ControlValues, &mut f64, f64);
        let controls: [(&str, SetControl); 5] = [
            ("tilt", |c, _, v| c.tilt_deg = v),
            ("viscosity", |c, _, v| c.viscosity = v),
            ("fill", |c, _, v| c.fill_percent = v),
            ("pour time", |c, _, v| c.pour_time_s = v),
            ("gain", |_, g, v| *g = v),
        ];
        type SetConfig = fn(&mut ModelConfig, f64);
        let constants: [(&str, SetConfig); 11] = [
            ("capacity", |c, v| c.capacity_ml = v),
            ("pocket", |c, v| c.pocket_ml = v),
            ("f1", |c, v| c.frequency_hz[0] = v),
            ("f2", |c, v| c.frequency_hz[1] = v),
            ("B1", |c, v| c.decay_per_s[0] = v),
            ("B2", |c, v| c.decay_per_s[1] = v),
            ("timing jitter", |c, v| c.timing_jitter = v),
            ("frequency jitter", |c, v| c.freq_jitter = v),
            ("decay sigma", |c, v| c.decay_sigma = v),
            ("ceiling", |c, v| c.ceiling = v),
            ("sample rate", |_, _| {}),
        ];
        let mut outcomes = Vec::new();
        for (name, set) in controls {
            let runs = HOSTILE
                .iter()
                .map(|&value| {
                    // The bad value every other sample, so it also arrives mid-pour.
                    let inputs = move |sample: u64| {
                        let (mut values, mut gain) = steady(sample);
                        if sample % 2 == 1 {
                            set(&mut values, &mut gain, value);
                        }
                        (values, gain)
                    };
                    run::<S>(&Setup::new(fs, follow(), seconds), &inputs)
                })
                .collect();
            outcomes.push(judge(format!("control: {name}"), runs));
        }
        for (name, set) in constants {
            let runs = HOSTILE
                .iter()
                .map(|&value| {
                    let mut config = follow();
                    set(&mut config, value);
                    let sample_rate = if name == "sample rate" { value } else { fs };
                    run::<S>(&Setup::new(sample_rate, config, seconds), &steady)
                })
                .chain(HOSTILE.iter().map(|&value| {
                    // The same value arriving mid-pour through `set_config`.
                    let mut config = follow();
                    set(&mut config, value);
                    let setup = Setup::new(fs, follow(), seconds).switching_to(config);
                    run::<S>(&setup, &steady)
                }))
                .collect();
            outcomes.push(judge(format!("constant: {name}"), runs));
        }
        outcomes
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
