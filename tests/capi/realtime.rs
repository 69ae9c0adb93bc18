//! The real-time rules: once a handle exists, the process, control, state and units calls make
//! no allocator call at all (so they cannot block in it either), through a whole pour with ramps,
//! steps, a refill, a reset, interleaved channels, queued calls from another thread, and more
//! units in one call than are kept.

use std::sync::atomic::{AtomicBool, Ordering};

use sake_glug::*;

use super::allocations::counted;
use super::Live;

/// A raw handle that another thread may queue control calls on (the header allows it).
#[derive(Clone, Copy)]
struct Shared(*mut SakeGlug);
unsafe impl Send for Shared {}

#[test]
fn process_and_the_control_calls_never_allocate() {
    let live = Live::paper(48_000.0);
    let glug = live.raw();
    let mut mono = vec![0.0f32; 4096];
    let mut stereo = vec![0.0f32; 2 * 4096];
    let mut units = vec![SakeGlugUnit::default(); 64];
    let (glugs, calls) = counted(|| {
        let mut glugs = 0;
        let mut state = SakeGlugState::default();
        let mut count = 0;
        unsafe {
            sake_glug_set(glug, SakeGlugControl::Tilt as i32, 90.0);
            sake_glug_ramp(glug, SakeGlugControl::Tilt as i32, 150.0, 24_000);
            sake_glug_ramp(glug, SakeGlugControl::Gain as i32, -3.0, 2_000);
            for call in 0..200usize {
                match call {
                    40 => {
                        sake_glug_refill(glug);
                    }
                    90 => {
                        sake_glug_reset(glug);
                        sake_glug_ramp(glug, SakeGlugControl::Tilt as i32, 135.0, 100);
                    }
                    120 => {
                        sake_glug_set(glug, SakeGlugControl::Viscosity as i32, 0.7);
                    }
                    _ => {}
                }
                let frames = [1, 16, 64, 4096][call % 4];
                if call % 3 == 0 {
                    sake_glug_process_interleaved(glug, stereo.as_mut_ptr(), frames, 2);
                } else {
                    sake_glug_process(glug, mono.as_mut_ptr(), frames);
                }
                sake_glug_state(glug, &mut state);
                sake_glug_units(glug, units.as_mut_ptr(), units.len(), &mut count);
                glugs += count;
            }
        }
        glugs
    });
    assert!(glugs > 20, "the pour glugged ({glugs} units)");
    assert_eq!(
        calls, 0,
        "allocator calls during process and the control calls"
    );
}

#[test]
fn more_units_than_are_kept_are_counted_without_allocating() {
    // Thousands of tiny glugs in one call of ten seconds.
    let live = Live::create(48_000.0, Some("[bottle]\npocket_ml = 0.05\n"), 1).unwrap();
    live.set(SakeGlugControl::Tilt, 135.0);
    let mut call = vec![0.0f32; 48_000 * 10];
    let (state, calls) = counted(|| {
        live.process(&mut call);
        live.state()
    });
    assert_eq!(calls, 0);
    assert_eq!(state.units as usize, SAKE_GLUG_MAX_UNITS);
    assert!(
        state.units_lost > 0,
        "{} units beyond the kept ones",
        state.units_lost
    );
    assert_eq!(live.units().len(), SAKE_GLUG_MAX_UNITS);
}

#[test]
fn control_calls_from_another_thread_meet_process_without_allocating() {
    // The game's thread queues ten times what the queue holds, waiting whenever it is full; the
    // audio thread renders until the game is done. Neither makes an allocator call.
    const CALLS: u64 = 10 * SAKE_GLUG_MAX_QUEUED_CONTROLS as u64;
    let live = Live::paper(48_000.0);
    let shared = Shared(live.raw());
    let done = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let done = &done;
        let game = scope.spawn(move || {
            // The whole wrapper, not its field (closures capture fields one by one).
            let shared = shared;
            let (full, calls) = counted(|| {
                let (mut queued, mut full) = (0u64, 0u64);
                while queued < CALLS {
                    let tilt = (queued % 180) as f64;
                    let status = unsafe {
                        sake_glug_ramp(shared.0, SakeGlugControl::Tilt as i32, tilt, 480)
                    };
                    match status {
                        SakeGlugStatus::Ok => queued += 1,
                        SakeGlugStatus::QueueFull => {
                            full += 1;
                            std::thread::yield_now();
                        }
                        other => panic!("{other:?}"),
                    }
                }
                full
            });
            done.store(true, Ordering::Release);
            assert_eq!(calls, 0, "allocator calls on the game's thread");
            full
        });
        let mut block = vec![0.0f32; 64];
        let (rendered, calls) = counted(|| {
            let mut rendered = 0u64;
            while !done.load(Ordering::Acquire) {
                live.process(&mut block);
                rendered += 1;
            }
            live.process(&mut block);
            rendered
        });
        let full = game.join().unwrap();
        assert_eq!(calls, 0, "allocator calls on the audio thread");
        assert!(block.iter().all(|y| y.is_finite()));
        eprintln!("{rendered} calls of 64 frames; the queue was found full {full} times");
    });
}
