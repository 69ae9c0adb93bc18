//! The C library in small blocks: the cost per sample of `sake_glug_process` called with 16, 64
//! and 256 frames (a game engine's or a haptics API's small buffers) against 4096, over the same
//! second of pouring (the bottle refilled at each second's start, so units start and ring
//! throughout). Goals (issue 40): 16-frame calls cost at most 1.5× per sample, 64-frame calls
//! 1.1×. Then many bottles at once (issue 47): a thousand handles processed in turn, each on its
//! own pour and refill schedule, in calls of 64 and 256 frames, and how many bottles one core
//! plays in real time, and what the goal (20,000) leaves each bottle against what one bottle alone
//! costs at its cheapest. Nothing is asserted here: each group ends with figures from the medians
//! measured in the same run, and the whole report is written to `<target>/bench-capi.md`, which
//! `cargo xtask docs scaling` copies into docs/scaling.md. Times are the thread's CPU time, as
//! the build machine is shared.

use std::cell::RefCell;
use std::collections::HashMap;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use sake_glug::*;

mod report;

const FS: u32 = 48_000;

/// The sizes of call measured; the last is the yardstick of the ratios.
const BLOCKS: [usize; 4] = [16, 64, 256, LARGE];
const LARGE: usize = 4096;

/// Seconds per sample of each block size's batches, for the ratio.
type Times = RefCell<HashMap<usize, Vec<f64>>>;

/// One second of pouring at 135° from a refill, in calls of `block` frames.
fn second_of_pouring(glug: *mut SakeGlug, block: usize, out: &mut [f32]) {
    unsafe {
        sake_glug_refill(glug);
        for _ in 0..FS as usize / block {
            sake_glug_process(glug, out.as_mut_ptr(), block);
        }
    }
}

/// This thread's CPU time: on a machine shared with other work, the time the calls took and not
/// the time other processes held the core.
fn thread_cpu_time() -> Duration {
    let mut now = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `now` is a valid timespec for the call to write.
    let status = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut now) };
    assert_eq!(status, 0, "CLOCK_THREAD_CPUTIME_ID is there on Linux");
    Duration::new(now.tv_sec as u64, now.tv_nsec as u32)
}

fn median(times: &Times, block: usize) -> Option<f64> {
    let mut seconds = times.borrow().get(&block)?.clone();
    seconds.sort_by(f64::total_cmp);
    Some(seconds[seconds.len() / 2])
}

/// Returns the seconds a sample costs in calls of [`LARGE`] frames: one bottle at its cheapest.
fn small_blocks(c: &mut Criterion, report: &mut Vec<String>) -> Option<f64> {
    let times = Times::default();
    let mut out = vec![0.0f32; 4096];
    let mut group = c.benchmark_group("capi: one second of pouring");
    group.sample_size(20);
    group.measurement_time(Duration::from_secs(5));
    // 48 000 is a multiple of 16, 64 and 256 but not of 4096: the larger calls render 11 × 4096
    // samples.
    for block in BLOCKS {
        let samples = (FS as usize / block * block) as u64;
        group.throughput(Throughput::Elements(samples));
        let glug = unsafe { sake_glug_create(FS as f64, std::ptr::null(), 1) };
        unsafe { sake_glug_set(glug, SakeGlugControl::Tilt as i32, 135.0) };
        group.bench_function(format!("calls of {block} frames"), |b| {
            b.iter_custom(|iters| {
                let start = thread_cpu_time();
                for _ in 0..iters {
                    second_of_pouring(glug, block, &mut out);
                }
                let elapsed = thread_cpu_time() - start;
                let per_sample = elapsed.as_secs_f64() / (iters.max(1) * samples) as f64;
                times
                    .borrow_mut()
                    .entry(block)
                    .or_default()
                    .push(per_sample);
                elapsed
            })
        });
        unsafe { sake_glug_destroy(glug) };
    }
    group.finish();
    let large = median(&times, LARGE)?;
    let ratios: Vec<String> = BLOCKS
        .iter()
        .filter_map(|&block| {
            let small = median(&times, block)?;
            Some(format!(
                "{block} frames {:.2} ns a sample ({:.2}×)",
                small * 1e9,
                small / large
            ))
        })
        .collect();
    report.push(format!(
        "capi, per sample against calls of {LARGE} frames: {} (goals: 16 ≤ 1.5×, 64 ≤ 1.1×)",
        ratios.join(", ")
    ));
    Some(large)
}

/// How many bottles play at once in the many-bottles group.
const BOTTLES: usize = 1000;
/// The goal for the many-bottles group: bottles one core plays in real time.
const GOAL_BOTTLES: f64 = 20_000.0;
/// The call sizes of the many-bottles group.
const BOTTLE_BLOCKS: [usize; 2] = [64, 256];
/// The seconds of sound each bottle makes in one batch.
const BOTTLE_BATCH_S: f64 = 1.0;

/// One bottle of a crate: its handle, and its own schedule (a tilt, and a refill every so many
/// samples, so that the bottles neither start nor refill together).
struct Bottle {
    glug: *mut SakeGlug,
    refill_every: u64,
    played: u64,
}

impl Bottle {
    fn new(index: usize) -> Self {
        let glug = unsafe { sake_glug_create(FS as f64, std::ptr::null(), index as u64 + 1) };
        assert!(!glug.is_null(), "the default model opens");
        // Tilts from 110° to 150°, refills every 0.6 to 1.55 s, each from its own offset.
        let tilt = 110.0 + (index % 9) as f64 * 5.0;
        let refill_every = FS as u64 * (60 + (index as u64 % 20) * 5) / 100;
        unsafe {
            sake_glug_ramp(glug, SakeGlugControl::Tilt as i32, tilt, FS as u64 / 5);
        }
        Self {
            glug,
            refill_every,
            played: (index as u64 * 7919) % refill_every,
        }
    }

    fn process(&mut self, out: &mut [f32]) {
        if self.played >= self.refill_every {
            self.played -= self.refill_every;
            unsafe { sake_glug_refill(self.glug) };
        }
        unsafe { sake_glug_process(self.glug, out.as_mut_ptr(), out.len()) };
        self.played += out.len() as u64;
    }
}

impl Drop for Bottle {
    fn drop(&mut self) {
        unsafe { sake_glug_destroy(self.glug) };
    }
}

/// `lone_s`: the seconds a sample costs one bottle alone in calls of [`LARGE`] frames, if measured.
fn many_bottles(c: &mut Criterion, report: &mut Vec<String>, lone_s: Option<f64>) {
    let mut group = c.benchmark_group(format!("capi: {BOTTLES} bottles in turn"));
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    let mut figures = Vec::new();
    for block in BOTTLE_BLOCKS {
        let mut bottles: Vec<Bottle> = (0..BOTTLES).map(Bottle::new).collect();
        let mut out = vec![0.0f32; block];
        let rounds = (BOTTLE_BATCH_S * FS as f64) as usize / block;
        let sound_s = (rounds * block) as f64 / FS as f64;
        // Every bottle glugs before the clock starts: the figure is of a crate in full flow.
        for _ in 0..rounds {
            bottles
                .iter_mut()
                .for_each(|bottle| bottle.process(&mut out));
        }
        let seconds = RefCell::new(Vec::new());
        group.throughput(Throughput::Elements((BOTTLES * rounds * block) as u64));
        group.bench_function(format!("calls of {block} frames"), |b| {
            b.iter_custom(|iters| {
                let start = thread_cpu_time();
                for _ in 0..iters {
                    for _ in 0..rounds {
                        bottles
                            .iter_mut()
                            .for_each(|bottle| bottle.process(&mut out));
                    }
                }
                let elapsed = thread_cpu_time() - start;
                seconds
                    .borrow_mut()
                    .push(elapsed.as_secs_f64() / iters.max(1) as f64);
                elapsed
            })
        });
        let mut seconds = seconds.into_inner();
        seconds.sort_by(f64::total_cmp);
        if let Some(&median) = seconds.get(seconds.len() / 2) {
            let per_sample_ns = median / (BOTTLES as f64 * sound_s * FS as f64) * 1e9;
            figures.push(format!(
                "calls of {block} frames: {:.0} bottles in real time ({per_sample_ns:.2} ns a \
                 sample a bottle)",
                BOTTLES as f64 * sound_s / median
            ));
        }
    }
    group.finish();
    report.push(format!(
        "capi, {BOTTLES} bottles at {} kHz processed in turn on one core, each on its own pour \
         and refill schedule: {}",
        FS / 1000,
        figures.join("; ")
    ));
    // What the goal asks of one voice, against what one voice costs at its cheapest: no way of
    // calling the library plays more bottles than that allows.
    let budget_s = 1.0 / (GOAL_BOTTLES * FS as f64);
    if let Some(lone_s) = lone_s {
        report.push(format!(
            "capi, the goal of {GOAL_BOTTLES:.0} bottles in real time at {} kHz leaves {:.2} ns a \
             sample a bottle; one bottle alone in calls of {LARGE} frames costs {:.2} ns ({:.2}× \
             that), so this core plays at most {:.0} bottles, a handle each, however large their calls",
            FS / 1000,
            budget_s * 1e9,
            lone_s * 1e9,
            lone_s / budget_s,
            1.0 / (lone_s * FS as f64)
        ));
    }
}

fn benches(c: &mut Criterion) {
    let mut report = Vec::new();
    let lone_s = small_blocks(c, &mut report);
    many_bottles(c, &mut report, lone_s);
    let lines: String = report.iter().map(|line| format!("{line}\n")).collect();
    print!("{lines}");
    report::save("capi", &lines);
}

criterion_group!(capi, benches);
criterion_main!(capi);
