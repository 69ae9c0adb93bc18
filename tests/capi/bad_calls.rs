//! Every call checks its arguments and answers with a status, never a crash: NULL handles and
//! buffers, NaN and infinity, values out of range, controls that do not exist, negative sizes
//! (cast to size_t) and sizes over the limits, a full queue; a bad sample rate or model text
//! gives NULL and a message; a panic inside process is caught, answered and leaves silence.

use std::ptr::null_mut;

use sake_glug::*;
use sake_glug_engine::Control;

use super::{last_error, Live};

const TILT: i32 = SakeGlugControl::Tilt as i32;

/// A size_t as a caller's negative int becomes.
const MINUS_ONE: usize = -1isize as usize;

#[test]
fn a_null_handle_is_answered_by_every_call() {
    let mut samples = [0.0f32; 4];
    let mut state = SakeGlugState::default();
    let mut units = [SakeGlugUnit::default(); 2];
    let mut count = 0;
    let null_handle = SakeGlugStatus::NullHandle;
    unsafe {
        assert_eq!(sake_glug_set(null_mut(), TILT, 90.0), null_handle);
        assert_eq!(sake_glug_ramp(null_mut(), TILT, 90.0, 10), null_handle);
        assert_eq!(sake_glug_refill(null_mut()), null_handle);
        assert_eq!(sake_glug_reset(null_mut()), null_handle);
        assert_eq!(
            sake_glug_process(null_mut(), samples.as_mut_ptr(), 4),
            null_handle
        );
        let status = sake_glug_process_interleaved(null_mut(), samples.as_mut_ptr(), 2, 2);
        assert_eq!(status, null_handle);
        assert_eq!(sake_glug_state(null_mut(), &mut state), null_handle);
        let status = sake_glug_units(null_mut(), units.as_mut_ptr(), 2, &mut count);
        assert_eq!(status, null_handle);
        sake_glug_destroy(null_mut());
    }
}

#[test]
fn null_buffers_and_out_pointers_are_refused() {
    let live = Live::paper(48_000.0);
    let mut units = [SakeGlugUnit::default(); 2];
    let mut count = 0;
    let null_pointer = SakeGlugStatus::NullPointer;
    unsafe {
        assert_eq!(sake_glug_process(live.raw(), null_mut(), 16), null_pointer);
        assert_eq!(sake_glug_process(live.raw(), null_mut(), 0), null_pointer);
        let status = sake_glug_process_interleaved(live.raw(), null_mut(), 16, 2);
        assert_eq!(status, null_pointer);
        assert_eq!(sake_glug_state(live.raw(), null_mut()), null_pointer);
        let status = sake_glug_units(live.raw(), null_mut(), 2, &mut count);
        assert_eq!(status, null_pointer);
        let status = sake_glug_units(live.raw(), units.as_mut_ptr(), 2, null_mut());
        assert_eq!(status, null_pointer);
        assert_eq!(sake_glug_control_range(TILT, null_mut()), null_pointer);
    }
}

#[test]
fn values_that_are_not_finite_or_out_of_range_and_unknown_controls_are_refused() {
    let live = Live::paper(48_000.0);
    let glug = live.raw();
    for &control in &SakeGlugControl::ALL {
        let range = Control::ALL[control as usize].range();
        for (value, expected) in [
            (f64::NAN, SakeGlugStatus::NotFinite),
            (f64::INFINITY, SakeGlugStatus::NotFinite),
            (f64::NEG_INFINITY, SakeGlugStatus::NotFinite),
            (
                range.min - 1e-9 * range.min.abs().max(1.0),
                SakeGlugStatus::OutOfRange,
            ),
            (
                range.max + 1e-9 * range.max.abs().max(1.0),
                SakeGlugStatus::OutOfRange,
            ),
            (range.min, SakeGlugStatus::Ok),
            (range.max, SakeGlugStatus::Ok),
        ] {
            unsafe {
                assert_eq!(
                    sake_glug_set(glug, control as i32, value),
                    expected,
                    "{control:?} {value}"
                );
                let status = sake_glug_ramp(glug, control as i32, value, 100);
                assert_eq!(status, expected, "{control:?} ramp to {value}");
            }
        }
    }
    for control in [-1, 5, i32::MAX, i32::MIN] {
        let mut range = SakeGlugRange {
            min: 0.0,
            max: 0.0,
            default_value: 0.0,
        };
        let invalid = SakeGlugStatus::InvalidControl;
        unsafe {
            assert_eq!(sake_glug_set(glug, control, 1.0), invalid);
            assert_eq!(sake_glug_ramp(glug, control, 1.0, 10), invalid);
            assert_eq!(sake_glug_control_range(control, &mut range), invalid);
        }
    }
    // Nothing refused reached the engine: the queued values are the in-range ones.
    let mut block = [0.0f32; 64];
    live.process(&mut block);
    assert!(block.iter().all(|y| y.is_finite()));
}

#[test]
fn negative_and_oversized_sizes_are_refused_and_nothing_is_written() {
    let live = Live::paper(48_000.0);
    let glug = live.raw();
    let mut samples = [7.0f32; 8];
    let mut units = [SakeGlugUnit::default(); 2];
    let mut count = 99;
    let invalid = SakeGlugStatus::InvalidSize;
    unsafe {
        for frames in [MINUS_ONE, SAKE_GLUG_MAX_FRAMES + 1, usize::MAX / 2] {
            assert_eq!(
                sake_glug_process(glug, samples.as_mut_ptr(), frames),
                invalid
            );
            let status = sake_glug_process_interleaved(glug, samples.as_mut_ptr(), frames, 2);
            assert_eq!(status, invalid);
        }
        for channels in [0, SAKE_GLUG_MAX_CHANNELS + 1, MINUS_ONE] {
            let status = sake_glug_process_interleaved(glug, samples.as_mut_ptr(), 4, channels);
            assert_eq!(status, invalid);
        }
        let status = sake_glug_units(glug, units.as_mut_ptr(), MINUS_ONE, &mut count);
        assert_eq!(status, invalid);
    }
    assert_eq!(samples, [7.0; 8], "a refused call writes nothing");
    assert_eq!(count, 99);
    // Zero frames is a call that renders nothing.
    assert_eq!(
        unsafe { sake_glug_process(glug, samples.as_mut_ptr(), 0) },
        SakeGlugStatus::Ok
    );
    assert_eq!(live.state().position, 0);
}

#[test]
fn a_full_queue_refuses_the_next_control_call_until_a_process_call_takes_them() {
    let live = Live::paper(48_000.0);
    for _ in 0..SAKE_GLUG_MAX_QUEUED_CONTROLS {
        live.set(SakeGlugControl::Tilt, 120.0);
    }
    assert_eq!(
        unsafe { sake_glug_set(live.raw(), TILT, 130.0) },
        SakeGlugStatus::QueueFull
    );
    let mut block = [0.0f32; 16];
    live.process(&mut block);
    live.set(SakeGlugControl::Tilt, 130.0);
}

#[test]
fn a_bad_sample_rate_or_model_gives_null_and_says_what_was_wrong() {
    for (rate, said) in [
        (f64::NAN, "`sample_rate` = NaN"),
        (0.0, "`sample_rate` = 0"),
        (-48_000.0, "`sample_rate` = -48000"),
        (999.0, "`sample_rate` = 999"),
        (1e9, "`sample_rate` = 1000000000"),
        (44_100.5, "not a whole number"),
    ] {
        let error = Live::create(rate, None, 1).err().unwrap();
        assert!(error.contains(said), "{rate}: {error}");
    }
    for (text, said) in [
        (
            "tilt_deg = [[0.0, 90.0]]",
            "`tilt_deg` does not belong in a model",
        ),
        ("[glug]\nf1_hz = -3.0", "`glug.f1_hz` = -3"),
        ("[glug\n", "invalid model"),
        (
            "duration_s = 3.0",
            "`duration_s` does not belong in a model",
        ),
        ("\u{1b}[31m = 1", "line 1, column "),
    ] {
        let error = Live::create(48_000.0, Some(text), 1).err().unwrap();
        assert!(error.starts_with("model text: "), "{error}");
        assert!(error.contains(said), "{text:?}: {error}");
        assert!(
            !error.contains('\u{1b}'),
            "control characters escaped: {error:?}"
        );
    }
    let huge = format!("# {}\n", "x".repeat(2 << 20));
    assert!(Live::create(48_000.0, Some(&huge), 1)
        .err()
        .unwrap()
        .contains("over the limit"));
    // Bytes that are not UTF-8, on the second line.
    let bytes = b"# a model\n\xff\xfe = 1\0";
    let glug = unsafe { sake_glug_create(48_000.0, bytes.as_ptr().cast(), 1) };
    assert!(glug.is_null());
    assert_eq!(last_error(), "model text: line 2 is not UTF-8 text");
    // A good create clears the message.
    drop(Live::paper(48_000.0));
    assert_eq!(last_error(), "");
}

#[test]
fn an_unknown_preset_gives_null_and_names_the_presets() {
    let error = Live::preset(48_000.0, "rum", 1).err().unwrap();
    assert!(
        error.starts_with("no preset `rum`: the presets are water, thin, "),
        "{error}"
    );
    assert!(error.contains("glass-bottle"), "{error}");
    // The name is the preset's id, as its file is named, not its menu name.
    assert!(Live::preset(48_000.0, "Water", 1).is_err());
    let glug = unsafe { sake_glug_create_preset(48_000.0, std::ptr::null(), 1) };
    assert!(glug.is_null());
    assert!(last_error().starts_with("the preset's name is NULL"));
    let error = Live::preset(999.0, "water", 1).err().unwrap();
    assert!(error.contains("`sample_rate` = 999"), "{error}");
    drop(Live::preset(48_000.0, "syrup", 1).unwrap());
    assert_eq!(last_error(), "");
}

#[test]
fn the_error_message_is_cut_to_the_buffer_at_a_character() {
    assert!(Live::create(48_000.0, Some("ä = 1"), 1).is_err());
    let full = last_error();
    let len = unsafe { sake_glug_last_error(null_mut(), 0) };
    assert_eq!(len, full.len());
    for capacity in 1..full.len() + 3 {
        let mut buffer = vec![0xAAu8; capacity];
        let said = unsafe { sake_glug_last_error(buffer.as_mut_ptr().cast(), capacity) };
        assert_eq!(said, full.len());
        let end = buffer.iter().position(|&byte| byte == 0).unwrap();
        let text = std::str::from_utf8(&buffer[..end]).unwrap();
        assert!(
            full.starts_with(text) && text.len() < capacity,
            "{capacity}: {text}"
        );
        assert!(
            text == full || text.len() + 4 >= capacity,
            "{capacity}: cut short"
        );
    }
}

#[test]
fn a_panic_inside_process_is_caught_answered_and_leaves_silence() {
    let live = Live::paper(48_000.0);
    live.set(SakeGlugControl::Tilt, 135.0);
    let mut block = vec![0.0f32; 48_000];
    live.process(&mut block);
    assert!(block.iter().any(|&y| y != 0.0), "it glugs before the fault");
    let glug: &SakeGlug = unsafe { &*live.raw() };
    glug.inject_fault();
    block.fill(1.0);
    let status = unsafe { sake_glug_process(live.raw(), block.as_mut_ptr(), block.len()) };
    assert_eq!(status, SakeGlugStatus::Panicked);
    assert!(block.iter().all(|&y| y == 0.0), "silence after the fault");
    // From then on every call answers that the handle failed, and process writes silence.
    block.fill(1.0);
    let failed = SakeGlugStatus::Failed;
    let mut state = SakeGlugState::default();
    unsafe {
        assert_eq!(
            sake_glug_process(live.raw(), block.as_mut_ptr(), 64),
            failed
        );
        let status = sake_glug_process_interleaved(live.raw(), block.as_mut_ptr(), 32, 2);
        assert_eq!(status, failed);
        assert_eq!(sake_glug_set(live.raw(), TILT, 90.0), failed);
        assert_eq!(sake_glug_ramp(live.raw(), TILT, 90.0, 9), failed);
        assert_eq!(sake_glug_refill(live.raw()), failed);
        assert_eq!(sake_glug_reset(live.raw()), failed);
        assert_eq!(sake_glug_state(live.raw(), &mut state), failed);
    }
    assert!(block[..64].iter().all(|&y| y == 0.0));
}

#[test]
fn every_status_has_its_text_and_the_version_is_the_headers() {
    for status in 0..=9 {
        let text = unsafe { std::ffi::CStr::from_ptr(sake_glug_status_text(status)) };
        assert!(
            !text.to_str().unwrap().starts_with("not a status"),
            "{status}"
        );
    }
    let unknown = unsafe { std::ffi::CStr::from_ptr(sake_glug_status_text(-3)) };
    assert_eq!(unknown.to_str().unwrap(), "not a status of SakeGlugStatus");
    assert_eq!(sake_glug_abi_version(), SAKE_GLUG_ABI_VERSION);
    let version = unsafe { std::ffi::CStr::from_ptr(sake_glug_version()) };
    assert_eq!(version.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
    assert_eq!(
        sake_glug_default_seed(),
        sake_glug_engine::ModelConfig::default().seed
    );
}
