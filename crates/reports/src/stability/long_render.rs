//! Hours of rendering: continuous pouring stays stationary, a never-decaying unit neither grows
//! nor fades nor drifts from the reference, and the cost per second does not grow with length.

use super::checks::{
    ceiling, check, finite, limiter_events_in_spans, outcome, Check, Outcome, Property,
    ENERGY_TOLERANCE, MAX_TIME_RATIO,
};
use super::harness::{follow, run, steady, Run, Setup};
use super::{CaseGroup, Scale, StabilityCase};
use crate::accuracy;
use sake_glug_engine::synthesis::reference;
use sake_glug_engine::Synthesis;

/// Energies and run times are taken per minute.
const SPAN_S: f64 = 60.0;

pub(super) struct LongRender;

impl CaseGroup for LongRender {
    const NAME: &'static str = "long render";
    const DESCRIPTION: &'static str =
        "continuous pouring; one unit with B = 0 ringing for the whole render";
    const TIME_REFERENCE: &'static str =
        "the render's own early minutes: a late minute may cost at most the time ratio \
         times an early one (medians of the first and last thirds)";

    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome> {
        let fs = 48_000.0;
        let seconds = scale.long_s();
        let mut outcomes = Vec::new();

        let steady_config = follow().deterministic();
        let setup = Setup::new(fs, steady_config, seconds).energy_span_s(SPAN_S);
        let run_steady = run::<S>(&setup, &steady);
        let checks = vec![
            finite(&run_steady),
            ceiling(&run_steady),
            stationary(&run_steady),
            cost_flat(&run_steady),
        ];
        outcomes.push(outcome(
            StabilityCase::LongRender,
            format!("continuous pouring for {}", accuracy::length_label(seconds)),
            checks,
            &run_steady,
        ));

        let ring = accuracy::cases()
            .into_iter()
            .find(|s| s.name == "ring")
            .expect("the accuracy set has the ring scene");
        let controls = ring.controls(fs);
        let len = (seconds * fs) as u64;
        let last_second = len - fs as u64..len;
        let setup = Setup::new(fs, ring.config, seconds)
            .energy_span_s(SPAN_S)
            .keep(last_second.clone());
        let run_ring = run::<S>(&setup, &controls);
        let exact = reference::evaluate(fs, ring.config, &controls, last_second).samples;
        let (max_db, _) = accuracy::error_db(&run_ring.render.kept, &exact);
        let checks = vec![
            finite(&run_ring),
            ceiling(&run_ring),
            stationary(&run_ring),
            check(
                Property::NoDrift,
                max_db < -100.0,
                format!("last second vs reference: {max_db:.1} dB"),
            ),
        ];
        outcomes.push(outcome(
            StabilityCase::LongRender,
            format!(
                "a unit with B = 0 ringing for {}",
                accuracy::length_label(seconds)
            ),
            checks,
            &run_ring,
        ));
        outcomes
    }
}

/// The last minute's energy equals the second minute's within the tolerance, and the limiter did
/// not act after the first minute.
fn stationary(run: &Run) -> Check {
    let energies = &run.render.energies;
    // The first minute holds the onset transients of the ring scene; compare from the second.
    let (first, last) = (energies[1], energies[energies.len() - 1]);
    let ratio = last / first;
    let limited = limiter_events_in_spans(&run.render, 1);
    check(
        Property::Energy,
        (1.0 - ENERGY_TOLERANCE..=1.0 + ENERGY_TOLERANCE).contains(&ratio) && limited == 0,
        format!(
            "last minute's energy / second minute's = {ratio:.6}, limiter acted on \
             {limited} samples after the first minute"
        ),
    )
}

/// A late minute costs at most the time ratio times an early one.
fn cost_flat(run: &Run) -> Check {
    let times = &run.render.span_times;
    let minute = |k: usize| {
        times[k].as_secs_f64()
            - if k == 0 {
                0.0
            } else {
                times[k - 1].as_secs_f64()
            }
    };
    // Medians of the first and of the last third (the first minute aside: start-up), so one
    // busy moment of the machine does not count.
    let median = |range: std::ops::Range<usize>| {
        let mut v: Vec<f64> = range.map(minute).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let n = times.len();
    let third = (n - 1) / 3;
    let ratio = median(n - third..n) / median(1..1 + third);
    check(
        Property::Time,
        ratio <= MAX_TIME_RATIO,
        format!("a late minute costs {ratio:.2}× an early one"),
    )
}
