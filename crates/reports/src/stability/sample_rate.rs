//! Sample rates from 1 kHz to 768 kHz, and out-of-range ones (sanitised to the nearest bound or
//! the default): the same glugs at every rate, per-sample cost like 48 kHz's.

use super::checks::{
    ceiling, check, energy_not_growing, finite, outcome, time_ratio, Outcome, Property,
};
use super::harness::{follow, normal, pour_then_stop, run, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use sake_glug_engine::config;
use sake_glug_engine::Synthesis;

pub(super) struct SampleRateSweep;

impl CaseGroup for SampleRateSweep {
    const NAME: &'static str = "sample rate";
    const DESCRIPTION: &'static str =
        "fs ∈ {1, 8, 44.1, 96, 192, 384, 768} kHz and out-of-range {0, −48 kHz, NaN, ∞, \
         10¹²} (sanitised to the nearest bound, NaN to 48 kHz); the same pour";
    const TIME_REFERENCE: &'static str = "continuous pouring at 48 kHz, per sample";

    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let seconds = scale.sweep_s();
        let normal = normal::<S>(48_000.0, seconds, scale);
        let at_48k = run::<S>(
            &Setup::new(48_000.0, follow(), seconds),
            &pour_then_stop(48_000.0, 1.0),
        )
        .units_started;
        [
            1_000.0,
            8_000.0,
            44_100.0,
            96_000.0,
            192_000.0,
            384_000.0,
            768_000.0,
            0.0,
            -48_000.0,
            f64::NAN,
            f64::INFINITY,
            1e12,
        ]
        .into_iter()
        .map(|requested| {
            let fs = config::SAMPLE_RATE_HZ.sanitize(requested);
            let run = run::<S>(
                &Setup::new(requested, follow(), seconds).repeats(scale.repeats()),
                &pour_then_stop(fs, 1.0),
            );
            let checks = vec![
                finite(&run),
                ceiling(&run),
                energy_not_growing(&run),
                check(
                    Property::SameGlugs,
                    run.units_started.abs_diff(at_48k) <= 1,
                    format!("{} units, {} at 48 kHz", run.units_started, at_48k),
                ),
                time_ratio(&run, &normal),
            ];
            outcome(
                StabilityCase::SampleRateSweep,
                format!("fs = {requested} Hz (runs at {fs} Hz)"),
                checks,
                &run,
            )
        })
        .collect()
    }
}
