//! The C library in small blocks: the cost per sample of `sake_glug_process` called with 16, 64
//! and 256 frames (a game engine's or a haptics API's small buffers) against 4096, over the same
//! second of pouring (the bottle refilled at each second's start, so units start and ring
//! throughout). Goals (issue 40): 16-frame calls cost at most 1.5× per sample, 64-frame calls
//! 1.1×. Nothing is asserted here: the group ends with the ratios of the medians measured in the
//! same run. Times are the thread's CPU time, as the build machine is shared.

use std::cell::RefCell;
use std::collections::HashMap;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use sake_glug::*;

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

fn small_blocks(c: &mut Criterion) {
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
    let Some(large) = median(&times, LARGE) else {
        return;
    };
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
    println!(
        "capi, per sample against calls of {LARGE} frames: {} (goals: 16 ≤ 1.5×, 64 ≤ 1.1×)",
        ratios.join(", ")
    );
}

criterion_group!(benches, small_blocks);
criterion_main!(benches);
