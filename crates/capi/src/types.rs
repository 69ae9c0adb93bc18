//! The C types of the interface: what include/sake_glug.h declares besides the functions.

use sake_glug_engine::Control;

/// The version of the interface that this library implements: a caller built against another
/// header compares it with `sake_glug_abi_version()` and refuses to run on a mismatch. Raised
/// whenever a function, a type or a value of the header changes.
pub const SAKE_GLUG_ABI_VERSION: u32 = 1;

/// The most frames one process call renders.
pub const SAKE_GLUG_MAX_FRAMES: usize = 1 << 24;

/// The most channels an interleaved process call fills.
pub const SAKE_GLUG_MAX_CHANNELS: usize = 64;

/// The most units one process call keeps for `sake_glug_units`; the state counts any beyond.
pub const SAKE_GLUG_MAX_UNITS: usize = 1024;

/// The most control calls queued before a process call takes them; one more is refused with
/// `SAKE_GLUG_STATUS_QUEUE_FULL`.
pub const SAKE_GLUG_MAX_QUEUED_CONTROLS: usize = 1024;

/// What a call did.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SakeGlugStatus {
    /// Done.
    Ok = 0,
    /// The handle is NULL.
    NullHandle = 1,
    /// A buffer or an out-pointer is NULL.
    NullPointer = 2,
    /// The control is not one of `SakeGlugControl`.
    InvalidControl = 3,
    /// A value is NaN or infinite.
    NotFinite = 4,
    /// A value lies outside its control's range (`sake_glug_control_range`).
    OutOfRange = 5,
    /// A size is zero where one is needed, or over its limit (`SAKE_GLUG_MAX_FRAMES`,
    /// `SAKE_GLUG_MAX_CHANNELS`).
    InvalidSize = 6,
    /// `SAKE_GLUG_MAX_QUEUED_CONTROLS` control calls wait for the next process call already.
    QueueFull = 7,
    /// The library failed inside this call (a bug): the call wrote silence, and the handle is
    /// failed from now on.
    Panicked = 8,
    /// The handle failed in an earlier call: it renders silence; destroy it and create another.
    Failed = 9,
    /// The actuator profile's text was refused: `sake_glug_last_error` says why.
    InvalidProfile = 10,
}

/// The controls (MODEL.md §1, §6), in the order of the engine's table of controls. Their ranges
/// and defaults come from `sake_glug_control_range`.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SakeGlugControl {
    /// Tilt θ (degrees): 0 upright, 90 horizontal, 180 upside down.
    Tilt = 0,
    /// Viscosity ratio c: the share of the f1 component; water 0.33.
    Viscosity = 1,
    /// Fill level φ (percent of capacity) that a refill or a reset fills to.
    Fill = 2,
    /// Pour time T (s): how long a full bottle takes to empty at 135°.
    PourTime = 3,
    /// Output gain (dB).
    Gain = 4,
}

impl SakeGlugControl {
    /// Every control, in the engine's order. (Rust's only: cbindgen wrote it into the header as
    /// a macro naming the variants by their Rust names, which C does not know.)
    ///
    /// cbindgen:ignore
    pub const ALL: [SakeGlugControl; 5] = [
        SakeGlugControl::Tilt,
        SakeGlugControl::Viscosity,
        SakeGlugControl::Fill,
        SakeGlugControl::PourTime,
        SakeGlugControl::Gain,
    ];

    /// The engine's control with this number, if there is one.
    pub fn engine_control(number: i32) -> Option<Control> {
        let index = usize::try_from(number).ok()?;
        Control::ALL.get(index).copied()
    }
}

// The header's controls are the engine's, one for one (the order is checked by name in
// tests/capi/header.rs).
const _: () = assert!(SakeGlugControl::ALL.len() == Control::ALL.len());

/// A control's range and default, as the engine declares them.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SakeGlugRange {
    /// The lowest value taken.
    pub min: f64,
    /// The highest value taken.
    pub max: f64,
    /// The value a handle starts with (unless its model file gives another).
    pub default_value: f64,
}

/// The bottle after the last process call (MODEL.md §3, §4, §8, §14's state table).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SakeGlugState {
    /// Samples rendered since the handle was created or last reset.
    pub position: u64,
    /// The sample after the last one during which liquid flowed or a component sounded: where a
    /// render that runs "until pouring stops and every unit has decayed" ends.
    pub active_until: u64,
    /// V (ml): what the bottle holds now, at the start of the next sample.
    pub volume_ml: f64,
    /// The last sample's outflow times the sample rate (ml/s).
    pub outflow_ml_per_s: f64,
    /// The tilt of the last sample, brought into range (°).
    pub tilt_deg: f64,
    /// The output gain G of the last sample (linear, on its ramp: MODEL.md §6).
    pub output_gain: f64,
    /// 1 if the mouth was under the liquid at the last sample's start, else 0.
    pub submerged: u32,
    /// 1 if nothing sounds and, under the controls now (no ramp under way), nothing will start:
    /// the rest is silence until a control changes. Else 0.
    pub settled: u32,
    /// Units kept from the last process call (at most `SAKE_GLUG_MAX_UNITS`).
    pub units: u32,
    /// Units of the last process call beyond `SAKE_GLUG_MAX_UNITS`, not kept.
    pub units_lost: u32,
}

/// One glug unit as it started (MODEL.md §5, §7; §14's units table), heard first in the last
/// process call: what a game needs to drive its platform's haptics live.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SakeGlugUnit {
    /// The frame of the last process call's buffer at which the unit is first heard (its
    /// sample n + 1): 0 for a unit that started in the previous call's last sample.
    pub frame: u32,
    /// 1 if any of its components sounds, 0 if none does (§14's `audible`).
    pub audible: u32,
    /// n: the sample, counted since the last reset, during which the unit starts.
    pub sample: u64,
    /// x: the onset lies at (n + x) / fs.
    pub fraction: f64,
    /// θ of the onset's sample (°).
    pub tilt_deg: f64,
    /// V_i (ml).
    pub volume_ml: f64,
    /// b_i: the pocket whose filling started it (ml).
    pub pocket_ml: f64,
    /// G·Asum_i: the unit's peak amplitude as heard, both components (a1 + a2 of §14).
    pub amplitude: f64,
    /// c_i: the share of the f1 component (a1 = c·amplitude, a2 = (1 − c)·amplitude).
    pub viscosity_c: f64,
    /// f1_i (Hz).
    pub f1_hz: f64,
    /// f2_i (Hz).
    pub f2_hz: f64,
    /// B1_i (1/s).
    pub b1_per_s: f64,
    /// B2_i (1/s).
    pub b2_per_s: f64,
}
