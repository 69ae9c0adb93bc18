//! The C library (crates/capi) through its C functions: the renderer's samples bit for bit
//! (`same_samples`), the real-time rules under a counting allocator (`realtime`), every bad
//! argument and a forced panic answered with a status (`bad_calls`), and the committed header
//! (`header`). tests/host/test_capi.py runs the C, C++, C# and Python examples against the CLI.

mod allocations;
mod bad_calls;
mod header;
mod realtime;
mod same_samples;
#[path = "../support/mod.rs"]
mod support;

use std::ffi::CString;

use sake_glug::*;

/// A handle for the tests, destroyed when dropped.
pub struct Live(*mut SakeGlug);

impl Live {
    /// A handle, or the library's message.
    pub fn create(sample_rate: f64, model: Option<&str>, seed: u64) -> Result<Self, String> {
        let text = model.map(|text| CString::new(text).unwrap());
        let pointer = text.as_ref().map_or(std::ptr::null(), |text| text.as_ptr());
        let glug = unsafe { sake_glug_create(sample_rate, pointer, seed) };
        if glug.is_null() {
            Err(last_error())
        } else {
            Ok(Self(glug))
        }
    }

    /// A handle playing the shipped preset `name`, or the library's message.
    pub fn preset(sample_rate: f64, name: &str, seed: u64) -> Result<Self, String> {
        let name = CString::new(name).unwrap();
        let glug = unsafe { sake_glug_create_preset(sample_rate, name.as_ptr(), seed) };
        if glug.is_null() {
            Err(last_error())
        } else {
            Ok(Self(glug))
        }
    }

    /// The paper's bottle with the default seed.
    pub fn paper(sample_rate: f64) -> Self {
        Self::create(sample_rate, None, sake_glug_default_seed()).unwrap()
    }

    pub fn raw(&self) -> *mut SakeGlug {
        self.0
    }

    pub fn set(&self, control: SakeGlugControl, value: f64) {
        assert_eq!(
            unsafe { sake_glug_set(self.0, control as i32, value) },
            SakeGlugStatus::Ok
        );
    }

    pub fn ramp(&self, control: SakeGlugControl, target: f64, samples: u64) {
        let status = unsafe { sake_glug_ramp(self.0, control as i32, target, samples) };
        assert_eq!(status, SakeGlugStatus::Ok);
    }

    pub fn process(&self, out: &mut [f32]) {
        let status = unsafe { sake_glug_process(self.0, out.as_mut_ptr(), out.len()) };
        assert_eq!(status, SakeGlugStatus::Ok);
    }

    pub fn state(&self) -> SakeGlugState {
        let mut state = SakeGlugState::default();
        assert_eq!(
            unsafe { sake_glug_state(self.0, &mut state) },
            SakeGlugStatus::Ok
        );
        state
    }

    pub fn units(&self) -> Vec<SakeGlugUnit> {
        let mut units = vec![SakeGlugUnit::default(); SAKE_GLUG_MAX_UNITS];
        let mut count = 0;
        let status =
            unsafe { sake_glug_units(self.0, units.as_mut_ptr(), units.len(), &mut count) };
        assert_eq!(status, SakeGlugStatus::Ok);
        units.truncate(count);
        units
    }

    /// Renders in calls of `block` frames until the pour has settled (no ramp under way, nothing
    /// sounding or about to start), then cuts the samples where the last unit fell silent: a
    /// render of a scene without a duration. Returns the samples and every unit.
    pub fn until_settled(&self, block: usize) -> (Vec<f32>, Vec<SakeGlugUnit>) {
        let (mut samples, mut units) = (Vec::new(), Vec::new());
        let mut buffer = vec![0.0f32; block];
        loop {
            self.process(&mut buffer);
            samples.extend_from_slice(&buffer);
            units.extend(self.units());
            let state = self.state();
            if state.settled == 1 {
                samples.truncate(state.active_until as usize);
                return (samples, units);
            }
            assert!(samples.len() < 48_000 * 600, "no end within 10 minutes");
        }
    }
}

impl Drop for Live {
    fn drop(&mut self) {
        unsafe { sake_glug_destroy(self.0) };
    }
}

/// The message of the last failed create on this thread.
pub fn last_error() -> String {
    let len = unsafe { sake_glug_last_error(std::ptr::null_mut(), 0) };
    let mut buffer = vec![0u8; len + 1];
    unsafe { sake_glug_last_error(buffer.as_mut_ptr().cast(), buffer.len()) };
    String::from_utf8(buffer[..len].to_vec()).unwrap()
}

/// The default scene through the C library (MODEL.md §10's built-in pour): tilt 90° → 135° over
/// half a second, held until every unit has decayed.
pub fn builtin_pour(live: &Live, sample_rate: u32, block: usize) -> (Vec<f32>, Vec<SakeGlugUnit>) {
    live.set(SakeGlugControl::Tilt, 90.0);
    live.ramp(SakeGlugControl::Tilt, 135.0, u64::from(sample_rate / 2));
    live.until_settled(block)
}
