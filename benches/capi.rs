//! The C library in small blocks: the cost per sample of `sake_glug_process` called with 16
//! frames (a game engine's or a haptics API's small buffers) against 4096, over the same second
//! of pouring (the bottle refilled at each second's start, so units start and ring throughout).
//! Goal: 16-frame calls cost at most 1.5× per sample. Nothing is asserted here: the group ends
//! with the ratio of the medians measured in the same run.

use std::cell::RefCell;
use std::collections::HashMap;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use sake_glug::*;

const FS: u32 = 48_000;

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
    // 48 000 is a multiple of 16 but not of 4096: the larger calls render 46 × 4096 samples.
    for block in [16usize, 4096] {
        let samples = (FS as usize / block * block) as u64;
        group.throughput(Throughput::Elements(samples));
        let glug = unsafe { sake_glug_create(FS as f64, std::ptr::null(), 1) };
        unsafe { sake_glug_set(glug, SakeGlugControl::Tilt as i32, 135.0) };
        group.bench_function(format!("calls of {block} frames"), |b| {
            b.iter_custom(|iters| {
                let start = Instant::now();
                for _ in 0..iters {
                    second_of_pouring(glug, block, &mut out);
                }
                let elapsed = start.elapsed();
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
    if let (Some(small), Some(large)) = (median(&times, 16), median(&times, 4096)) {
        println!(
            "capi: {:.1} ns a sample in calls of 16 frames, {:.1} ns in calls of 4096: {:.2}× \
             (goal ≤ 1.5×)",
            small * 1e9,
            large * 1e9,
            small / large
        );
    }
}

criterion_group!(benches, small_blocks);
criterion_main!(benches);
