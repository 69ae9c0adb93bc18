//! Doing only what a scene needs: cost follows the units a scene starts, not its length.
//!
//! - one hour whose bottle empties in the first seconds against one hour of continuous pouring
//!   (the project's target: at least 20× faster);
//! - the same short pour inside renders of 1 min, 10 min and 1 h (cost nearly flat);
//! - 5 s to 500 s of pouring inside a fixed 10 min render (cost grows with the units);
//! - an idle engine (bottle upright, nothing sounding) against `fill(0.0)` of the same buffer.
//!
//! Nothing is asserted here: each group ends with a line of ratios between benchmarks measured in
//! the same run (medians of criterion's own samples).

use std::cell::RefCell;
use std::collections::HashMap;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sake_glug_engine::{ControlValues, Controls, DrainMode, Engine, Lane, ModelConfig};

const FS: f64 = 48_000.0;
const BLOCK: usize = 4096;
const HOUR_S: f64 = 3600.0;

/// How the bottle is handled over a render.
#[derive(Clone, Copy)]
enum Handling {
    /// The default scene: tilt 90°→135° over 0.5 s, held; the bottle is empty after ~5 s.
    DefaultPour,
    /// Follow mode held full at 135° for `seconds`, then upright: 12 units per second of pouring.
    PourFor { seconds: f64 },
    /// Upright, nothing ever pours.
    Idle,
}

impl Handling {
    fn config(self) -> ModelConfig {
        match self {
            Handling::PourFor { .. } => ModelConfig {
                drain: DrainMode::Follow,
                ..ModelConfig::default()
            },
            _ => ModelConfig::default(),
        }
    }
}

/// Renders `seconds` from a reset, block by block as a host would; returns units started.
fn render_hours(
    engine: &mut Engine,
    handling: Handling,
    seconds: f64,
    ramp: &[f64],
    out: &mut [f32],
) -> u64 {
    engine.reset();
    let len = (seconds * FS) as usize;
    let mut done = 0;
    while done < len {
        let n = (len - done).min(BLOCK);
        let tilt = match handling {
            Handling::DefaultPour if done < ramp.len() => Lane::Samples(&ramp[done..]),
            Handling::DefaultPour => Lane::Constant(135.0),
            Handling::PourFor { seconds } if (done as f64) < seconds * FS => Lane::Constant(135.0),
            _ => Lane::Constant(0.0),
        };
        let controls = Controls {
            tilt_deg: tilt,
            ..Controls::constant(ControlValues {
                gain_db: -6.0,
                ..ControlValues::default()
            })
        };
        engine.process(&controls, &mut out[..n]);
        done += n;
    }
    engine.stats().units_started
}

/// Medians of each benchmark's per-iteration time, filled by [`timed`].
type Medians = RefCell<HashMap<String, Vec<Duration>>>;

/// Runs `body` `iters` times for criterion and keeps the per-iteration time for the ratios.
fn timed(medians: &Medians, key: &str, iters: u64, mut body: impl FnMut()) -> Duration {
    let start = Instant::now();
    for _ in 0..iters {
        body();
    }
    let elapsed = start.elapsed();
    medians
        .borrow_mut()
        .entry(key.to_string())
        .or_default()
        .push(elapsed / iters.max(1) as u32);
    elapsed
}

fn median(medians: &Medians, key: &str) -> Option<f64> {
    let map = medians.borrow();
    let mut times: Vec<f64> = map.get(key)?.iter().map(Duration::as_secs_f64).collect();
    times.sort_by(f64::total_cmp);
    Some(times[times.len() / 2])
}

fn ramp() -> Vec<f64> {
    let samples = (0.5 * FS) as usize;
    (0..samples)
        .map(|n| 90.0 + 45.0 * n as f64 / samples as f64)
        .collect()
}

fn one_hour(c: &mut Criterion) {
    let medians = Medians::default();
    let ramp = ramp();
    let mut out = vec![0.0f32; BLOCK];
    let mut group = c.benchmark_group("scaling: one hour");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    group.measurement_time(Duration::from_secs(5));
    group.throughput(Throughput::Elements((HOUR_S * FS) as u64));
    for (name, handling) in [
        ("bottle empty after 5 s", Handling::DefaultPour),
        ("continuous pouring", Handling::PourFor { seconds: HOUR_S }),
    ] {
        let mut engine = Engine::new(FS, handling.config());
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                timed(&medians, name, iters, || {
                    render_hours(&mut engine, handling, HOUR_S, &ramp, &mut out);
                })
            })
        });
    }
    group.finish();
    if let (Some(empty), Some(continuous)) = (
        median(&medians, "bottle empty after 5 s"),
        median(&medians, "continuous pouring"),
    ) {
        println!(
            "one hour: early-empty {:.0}× real time, continuous {:.0}× real time; \
             early-empty is {:.1}× faster (target ≥ 20×)",
            HOUR_S / empty,
            HOUR_S / continuous,
            continuous / empty
        );
    }
}

fn cost_follows_units(c: &mut Criterion) {
    let medians = Medians::default();
    let mut out = vec![0.0f32; BLOCK];
    let mut engine = Engine::new(FS, Handling::PourFor { seconds: 0.0 }.config());

    // The same 5 s of pouring (≈ 60 units) inside longer and longer renders.
    let mut group = c.benchmark_group("scaling: length, same units");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    group.measurement_time(Duration::from_secs(2));
    let lengths = [60.0, 600.0, HOUR_S];
    for seconds in lengths {
        let handling = Handling::PourFor { seconds: 5.0 };
        let key = format!("length {seconds} s");
        group.bench_function(BenchmarkId::new("5 s of pouring", seconds), |b| {
            b.iter_custom(|iters| {
                timed(&medians, &key, iters, || {
                    render_hours(&mut engine, handling, seconds, &[], &mut out);
                })
            })
        });
    }
    group.finish();

    // More and more pouring inside the same 10 min render.
    let mut group = c.benchmark_group("scaling: units, same length");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    group.measurement_time(Duration::from_secs(2));
    let pours = [5.0, 50.0, 500.0];
    let mut units = Vec::new();
    for pour_s in pours {
        let handling = Handling::PourFor { seconds: pour_s };
        units.push(render_hours(&mut engine, handling, 600.0, &[], &mut out));
        let key = format!("pour {pour_s} s");
        group.bench_function(
            BenchmarkId::new("10 min render, pouring for", pour_s),
            |b| {
                b.iter_custom(|iters| {
                    timed(&medians, &key, iters, || {
                        render_hours(&mut engine, handling, 600.0, &[], &mut out);
                    })
                })
            },
        );
    }
    group.finish();

    let by_length: Vec<Option<f64>> = lengths
        .iter()
        .map(|s| median(&medians, &format!("length {s} s")))
        .collect();
    if let [Some(minute), Some(ten), Some(hour)] = by_length[..] {
        println!(
            "same 5 s pour: a 10 min render costs {:.2}× a 1 min render, a 1 h render {:.2}× \
             (length grew 10× and 60×)",
            ten / minute,
            hour / minute
        );
    }
    let by_units: Vec<Option<f64>> = pours
        .iter()
        .map(|s| median(&medians, &format!("pour {s} s")))
        .collect();
    if let [Some(few), Some(more), Some(most)] = by_units[..] {
        println!(
            "10 min render: {} → {} → {} units cost 1 : {:.1} : {:.1}",
            units[0],
            units[1],
            units[2],
            more / few,
            most / few
        );
    }
}

fn idle_against_zeros(c: &mut Criterion) {
    let medians = Medians::default();
    let mut out = vec![0.0f32; BLOCK];
    let mut engine = Engine::new(FS, ModelConfig::default());
    let seconds = 600.0;
    let mut group = c.benchmark_group("scaling: silence");
    group.sample_size(20);
    group.warm_up_time(Duration::from_millis(200));
    group.throughput(Throughput::Elements((seconds * FS) as u64));
    group.bench_function("idle engine, 10 min", |b| {
        b.iter_custom(|iters| {
            timed(&medians, "idle", iters, || {
                render_hours(&mut engine, Handling::Idle, seconds, &[], &mut out);
            })
        })
    });
    group.bench_function("fill(0.0), 10 min", |b| {
        b.iter_custom(|iters| {
            timed(&medians, "zeros", iters, || {
                for _ in 0..(seconds * FS) as usize / BLOCK {
                    out.fill(0.0);
                    std::hint::black_box(&mut out);
                }
            })
        })
    });
    group.finish();
    if let (Some(idle), Some(zeros)) = (median(&medians, "idle"), median(&medians, "zeros")) {
        println!(
            "silence: the idle engine costs {:.2}× writing zeros ({:.0}× real time)",
            idle / zeros,
            seconds / idle
        );
    }
}

criterion_group!(benches, one_hour, cost_follows_units, idle_against_zeros);
criterion_main!(benches);
