//! libsake_glug: the engine of MODEL.md behind a C interface, for a game, a VR scene or an app
//! that drives the pour at run time (its tilt from the player's hand) and plays or feels the
//! glugs. include/sake_glug.h is generated from this file and types.rs by cbindgen
//! (tests/capi/header.rs); include/sake_glug.hpp wraps it for C++.
//!
//! A handle's samples are those of `sake-glug render` of the equivalent scene, bit for bit: a
//! control set is a step of its lane, a ramp a two-point linear lane (MODEL.md §10, and the
//! rules of the C library in MODEL.md §17). Every function checks its arguments and answers with
//! a [`SakeGlugStatus`]; no panic crosses the boundary.

mod glug;
mod types;

use std::cell::RefCell;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

pub use glug::{Command, SakeGlug};
pub use types::*;

use sake_glug_engine::config::SEED;

/// Runs `body`, answering `on_panic` if it panics.
fn guarded<T>(on_panic: T, body: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(body)).unwrap_or(on_panic)
}

thread_local! {
    /// Why the last `sake_glug_create` or `sake_glug_create_preset` on this thread failed, or
    /// `sake_glug_set_actuator`.
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

fn set_last_error(message: &str) {
    LAST_ERROR.with(|last| {
        let mut last = last.borrow_mut();
        last.clear();
        last.push_str(message);
    });
}

/// The version of the interface this library implements; compare it with
/// `SAKE_GLUG_ABI_VERSION` of the header the caller was built with.
#[no_mangle]
pub extern "C" fn sake_glug_abi_version() -> u32 {
    SAKE_GLUG_ABI_VERSION
}

/// The library's version, as text (static; never NULL).
#[no_mangle]
pub extern "C" fn sake_glug_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The seed the products use when none is chosen (the plugin's and a scene's default).
#[no_mangle]
pub extern "C" fn sake_glug_default_seed() -> u64 {
    SEED.range.default as u64
}

/// What a status means, as text (static; never NULL).
#[no_mangle]
pub extern "C" fn sake_glug_status_text(status: i32) -> *const c_char {
    let text: &CStr = match status {
        0 => c"ok",
        1 => c"the handle is NULL",
        2 => c"a buffer or an out-pointer is NULL",
        3 => c"not a control of SakeGlugControl",
        4 => c"a value is NaN or infinite",
        5 => c"a value lies outside its control's range (sake_glug_control_range)",
        6 => c"a size is zero or over its limit",
        7 => c"too many control calls wait for the next process call",
        8 => c"the library failed inside this call; the handle renders silence from now on",
        9 => c"the handle failed earlier; destroy it and create another",
        10 => c"the actuator profile was refused (sake_glug_last_error says why)",
        _ => c"not a status of SakeGlugStatus",
    };
    text.as_ptr()
}

/// A control's range and default, from the engine's table of controls.
///
/// # Safety
/// `range` is NULL or points to a writable `SakeGlugRange`.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_control_range(
    control: i32,
    range: *mut SakeGlugRange,
) -> SakeGlugStatus {
    guarded(SakeGlugStatus::Panicked, || {
        let Some(control) = SakeGlugControl::engine_control(control) else {
            return SakeGlugStatus::InvalidControl;
        };
        if range.is_null() {
            return SakeGlugStatus::NullPointer;
        }
        let engine_range = control.range();
        unsafe {
            range.write(SakeGlugRange {
                min: engine_range.min,
                max: engine_range.max,
                default_value: engine_range.default,
            })
        };
        SakeGlugStatus::Ok
    })
}

/// A new handle at `sample_rate` (Hz: a whole number from 1000 to 768000, audio rates and the
/// rates haptic APIs take PCM at alike), playing the model file whose text is `model_text`
/// (MODEL.md §12.1), or the paper's bottle if it is NULL, with the random draws of §7 seeded by
/// `seed`. Every control starts at the model's value or its default. Allocates: not on the audio
/// thread. NULL if anything was wrong: `sake_glug_last_error` then says what.
///
/// # Safety
/// `model_text` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_create(
    sample_rate: f64,
    model_text: *const c_char,
    seed: u64,
) -> *mut SakeGlug {
    let created = catch_unwind(|| {
        let text = if model_text.is_null() {
            None
        } else {
            let bytes = unsafe { CStr::from_ptr(model_text) }.to_bytes();
            match std::str::from_utf8(bytes) {
                Ok(text) => Some(text),
                Err(error) => {
                    let line = 1 + bytes[..error.valid_up_to()]
                        .iter()
                        .filter(|&&byte| byte == b'\n')
                        .count();
                    return Err(format!("model text: line {line} is not UTF-8 text"));
                }
            }
        };
        SakeGlug::new(sample_rate, text, seed)
    });
    handle_or_null(created, "sake_glug_create")
}

/// A new handle at `sample_rate` (Hz, as `sake_glug_create` takes it) playing the shipped preset
/// named `name` (a file name of presets/ without `.toml`, such as "syrup": the presets of the
/// command line and the plugin's menu, from one table in the engine): its
/// bottle, its glug and its liquid's viscosity and pour time; tilt, fill and gain start at their
/// defaults (the preset file's tilt automation is a scene's, for the game to play). Seeded with
/// `seed`. Allocates: not on the audio thread. NULL if the name is unknown or anything else was
/// wrong: `sake_glug_last_error` then says what (an unknown name's message lists the presets).
///
/// # Safety
/// `name` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_create_preset(
    sample_rate: f64,
    name: *const c_char,
    seed: u64,
) -> *mut SakeGlug {
    let created = catch_unwind(|| {
        if name.is_null() {
            return Err(format!(
                "the preset's name is NULL: the presets are {}",
                sake_glug_engine::Preset::ids()
            ));
        }
        let name = unsafe { CStr::from_ptr(name) }.to_string_lossy();
        SakeGlug::preset(sample_rate, &name, seed)
    });
    handle_or_null(created, "sake_glug_create_preset")
}

/// The handle a create call made, or NULL with the reason kept for `sake_glug_last_error`.
fn handle_or_null(
    created: std::thread::Result<Result<SakeGlug, glug::CreateError>>,
    function: &str,
) -> *mut SakeGlug {
    match created {
        Ok(Ok(glug)) => {
            set_last_error("");
            Box::into_raw(Box::new(glug))
        }
        Ok(Err(message)) => {
            set_last_error(&message);
            std::ptr::null_mut()
        }
        Err(_) => {
            set_last_error(&format!("the library failed inside {function} (a bug)"));
            std::ptr::null_mut()
        }
    }
}

/// Why the last `sake_glug_create` or `sake_glug_create_preset` on this thread returned NULL, or the last
/// `sake_glug_set_actuator` refused its profile ("" after one that succeeded):
/// copied into `buffer` as NUL-terminated UTF-8, cut at a character to fit `capacity` bytes.
/// Returns the message's full length in bytes (without the NUL), as snprintf does; `buffer` may
/// be NULL when `capacity` is 0, to ask the length.
///
/// # Safety
/// `buffer` points to `capacity` writable bytes, or is NULL with `capacity` 0.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_last_error(buffer: *mut c_char, capacity: usize) -> usize {
    guarded(0, || {
        LAST_ERROR.with(|last| {
            let message = last.borrow();
            if !buffer.is_null() && capacity > 0 {
                let mut len = message.len().min(capacity - 1);
                while !message.is_char_boundary(len) {
                    len -= 1;
                }
                unsafe {
                    std::ptr::copy_nonoverlapping(message.as_ptr(), buffer.cast::<u8>(), len);
                    buffer.add(len).write(0);
                }
            }
            message.len()
        })
    })
}

/// Frees a handle (NULL is ignored). No other call may use it then or after. Not on the audio
/// thread.
///
/// # Safety
/// `glug` is NULL or a handle from `sake_glug_create` not yet destroyed.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_destroy(glug: *mut SakeGlug) {
    if !glug.is_null() {
        // A panic while dropping is not caught: dropping the engine's plain buffers cannot panic.
        drop(unsafe { Box::from_raw(glug) });
    }
}

/// The handle behind `glug`, or the status a NULL or failed one answers.
unsafe fn handle<'a>(glug: *const SakeGlug) -> Result<&'a SakeGlug, SakeGlugStatus> {
    match unsafe { glug.as_ref() } {
        None => Err(SakeGlugStatus::NullHandle),
        Some(glug) if glug.has_failed() => Err(SakeGlugStatus::Failed),
        Some(glug) => Ok(glug),
    }
}

/// A control value checked against its control: finite and within its range.
fn checked_control(control: i32, value: f64) -> Result<sake_glug_engine::Control, SakeGlugStatus> {
    let control = SakeGlugControl::engine_control(control).ok_or(SakeGlugStatus::InvalidControl)?;
    if !value.is_finite() {
        return Err(SakeGlugStatus::NotFinite);
    }
    if !control.range().contains(value) {
        return Err(SakeGlugStatus::OutOfRange);
    }
    Ok(control)
}

fn status(result: Result<(), SakeGlugStatus>) -> SakeGlugStatus {
    result.err().unwrap_or(SakeGlugStatus::Ok)
}

/// Queues a control call; any thread.
unsafe fn queue(
    glug: *const SakeGlug,
    command: impl FnOnce() -> Result<Command, SakeGlugStatus>,
) -> SakeGlugStatus {
    guarded(SakeGlugStatus::Panicked, || {
        status(unsafe { handle(glug) }.and_then(|glug| glug.queue(command()?)))
    })
}

/// Sets `control` to `value` from the first sample of the next process call on (a step of its
/// lane), ending any ramp of it. Any thread; real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_set(
    glug: *mut SakeGlug,
    control: i32,
    value: f64,
) -> SakeGlugStatus {
    unsafe {
        queue(glug, || {
            Ok(Command::Set(checked_control(control, value)?, value))
        })
    }
}

/// Ramps `control` from its value at the first sample of the next process call to `target`,
/// reached `samples` samples later and held from then on: the samples of a scene lane with the
/// two points (p/fs, value) and ((p + samples)/fs, target), p the position (MODEL.md §17). A
/// ramp over 0 samples is a set. Any thread; real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_ramp(
    glug: *mut SakeGlug,
    control: i32,
    target: f64,
    samples: u64,
) -> SakeGlugStatus {
    unsafe {
        queue(glug, || {
            Ok(Command::Ramp(
                checked_control(control, target)?,
                target,
                samples,
            ))
        })
    }
}

/// MODEL.md §8 refill at the first sample of the next process call: the bottle fills to the fill
/// level, sounding units ring on, the random draws go on. Any thread; real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_refill(glug: *mut SakeGlug) -> SakeGlugStatus {
    unsafe { queue(glug, || Ok(Command::Refill)) }
}

/// MODEL.md §8 reset at the first sample of the next process call: refill, silence every unit,
/// re-seed, count samples from 0 again. A ramp under way stops at the value it has reached. Any
/// thread; real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_reset(glug: *mut SakeGlug) -> SakeGlugStatus {
    unsafe { queue(glug, || Ok(Command::Reset)) }
}

/// Compensates the units that start from the first sample of the next process call on for the
/// actuator whose profile is `profile_text` (an actuator profile file's text, MODEL.md §18), as
/// `sake-glug render --actuator` does; NULL plays the model's drive as it is. A refused profile
/// answers `SAKE_GLUG_STATUS_INVALID_PROFILE` and changes nothing; `sake_glug_last_error` says
/// why. Parses the text, so it allocates: not on the audio thread.
///
/// # Safety
/// `glug` is NULL or a live handle; `profile_text` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_set_actuator(
    glug: *mut SakeGlug,
    profile_text: *const c_char,
) -> SakeGlugStatus {
    guarded(SakeGlugStatus::Panicked, || {
        let glug = match unsafe { handle(glug) } {
            Ok(glug) => glug,
            Err(status) => return status,
        };
        let response = if profile_text.is_null() {
            None
        } else {
            let bytes = unsafe { CStr::from_ptr(profile_text) }.to_bytes();
            let text = if bytes.len() as u64 > sake_glug_actuator::MAX_PROFILE_BYTES {
                Err(format!(
                    "{} bytes, over the limit of {} bytes",
                    bytes.len(),
                    sake_glug_actuator::MAX_PROFILE_BYTES
                ))
            } else {
                std::str::from_utf8(bytes).map_err(|_| "not UTF-8 text".to_owned())
            };
            let parsed = text.and_then(|text| {
                sake_glug_actuator::ActuatorProfile::parse(text).map_err(|error| error.to_string())
            });
            match parsed {
                Ok(profile) => Some(profile.response()),
                Err(error) => {
                    set_last_error(&format!("actuator profile: {error}"));
                    return SakeGlugStatus::InvalidProfile;
                }
            }
        };
        set_last_error("");
        status(glug.set_actuator(response))
    })
}

/// A frame count within [`SAKE_GLUG_MAX_FRAMES`] (a negative count cast to size_t is far above
/// it).
fn checked_frames(frames: usize) -> Result<(), SakeGlugStatus> {
    if frames > SAKE_GLUG_MAX_FRAMES {
        Err(SakeGlugStatus::InvalidSize)
    } else {
        Ok(())
    }
}

/// Runs a render call on the audio thread: a panic inside it fails the handle and leaves
/// silence in `out`. The checks before it cannot panic (comparisons, an atomic load, a fill),
/// so the render is the one part inside `catch_unwind`: a second guard around the whole cost
/// every call, small ones above all, an indirect call and nothing else.
unsafe fn render(
    glug: *mut SakeGlug,
    out: *mut f32,
    len: impl FnOnce() -> Result<usize, SakeGlugStatus>,
    body: impl FnOnce(&SakeGlug, &mut [f32]),
) -> SakeGlugStatus {
    let glug = match unsafe { glug.as_ref() } {
        Some(glug) => glug,
        None => return SakeGlugStatus::NullHandle,
    };
    if out.is_null() {
        return SakeGlugStatus::NullPointer;
    }
    let len = match len() {
        Ok(len) => len,
        Err(status) => return status,
    };
    let out = unsafe { std::slice::from_raw_parts_mut(out, len) };
    if glug.has_failed() {
        out.fill(0.0);
        return SakeGlugStatus::Failed;
    }
    match catch_unwind(AssertUnwindSafe(|| body(glug, out))) {
        Ok(()) => SakeGlugStatus::Ok,
        Err(_) => {
            glug.fail();
            out.fill(0.0);
            SakeGlugStatus::Panicked
        }
    }
}

/// Renders `frames` mono samples into `out`, after taking the control calls queued since the
/// last call. The audio thread; real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle; `out` is NULL or points to `frames` writable floats.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_process(
    glug: *mut SakeGlug,
    out: *mut f32,
    frames: usize,
) -> SakeGlugStatus {
    unsafe {
        render(
            glug,
            out,
            || checked_frames(frames).map(|()| frames),
            |glug, out| glug.process(out),
        )
    }
}

/// Renders `frames` frames of `channels` interleaved channels into `out`, each channel the mono
/// signal of `sake_glug_process`. The audio thread; real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle; `out` is NULL or points to `frames × channels` writable
/// floats.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_process_interleaved(
    glug: *mut SakeGlug,
    out: *mut f32,
    frames: usize,
    channels: usize,
) -> SakeGlugStatus {
    unsafe {
        render(
            glug,
            out,
            || {
                checked_frames(frames)?;
                if channels == 0 || channels > SAKE_GLUG_MAX_CHANNELS {
                    return Err(SakeGlugStatus::InvalidSize);
                }
                Ok(frames * channels)
            },
            |glug, out| glug.process_interleaved(out, channels),
        )
    }
}

/// Copies the bottle's state after the last process call into `state`. The audio thread;
/// real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle; `state` is NULL or points to a writable `SakeGlugState`.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_state(
    glug: *mut SakeGlug,
    state: *mut SakeGlugState,
) -> SakeGlugStatus {
    guarded(SakeGlugStatus::Panicked, || {
        let glug = match unsafe { handle(glug) } {
            Ok(glug) => glug,
            Err(status) => return status,
        };
        if state.is_null() {
            return SakeGlugStatus::NullPointer;
        }
        unsafe { state.write(glug.state()) };
        SakeGlugStatus::Ok
    })
}

/// Copies up to `capacity` of the units first heard in the last process call, in onset order,
/// into `units`, and their number into `*count` (the state says how many there were). The audio
/// thread; real-time safe.
///
/// # Safety
/// `glug` is NULL or a live handle; `units` is NULL or points to `capacity` writable
/// `SakeGlugUnit`s; `count` is NULL or points to a writable size_t.
#[no_mangle]
pub unsafe extern "C" fn sake_glug_units(
    glug: *mut SakeGlug,
    units: *mut SakeGlugUnit,
    capacity: usize,
    count: *mut usize,
) -> SakeGlugStatus {
    guarded(SakeGlugStatus::Panicked, || {
        let glug = match unsafe { handle(glug) } {
            Ok(glug) => glug,
            Err(status) => return status,
        };
        if units.is_null() || count.is_null() {
            return SakeGlugStatus::NullPointer;
        }
        if capacity > isize::MAX as usize / size_of::<SakeGlugUnit>() {
            return SakeGlugStatus::InvalidSize;
        }
        let kept = unsafe { glug.units() };
        let copied = kept.len().min(capacity);
        unsafe {
            std::ptr::copy_nonoverlapping(kept.as_ptr(), units, copied);
            count.write(copied);
        }
        SakeGlugStatus::Ok
    })
}
