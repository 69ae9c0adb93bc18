//! The binding's core in plain Rust, built and tested natively as well as for WebAssembly: the C
//! library's handle ([`SakeGlug`]) with the buffers a block is rendered into, owned by the handle
//! and reused, and every argument checked before it reaches the handle.
//!
//! A panic in WebAssembly aborts the instance (there is no unwinding to catch it, as the C
//! library does), so nothing here may panic on what a caller passes: every value is checked
//! first and refused with a [`LiveError`], which lib.rs turns into a JavaScript `Error`.

use sake_glug::{Command, SakeGlug, SakeGlugState, SakeGlugUnit, SAKE_GLUG_MAX_QUEUED_CONTROLS};
use sake_glug_actuator::{ActuatorProfile, MAX_PROFILE_BYTES};
use sake_glug_device::axis::{tilt_from_gravity, Axis};
use sake_glug_engine::config::SEED;
use sake_glug_engine::{Control, ControlValues, Preset};
use sake_glug_model_file::ModelFile;

/// The most frames one process call renders into the handle's buffer (an AudioWorklet's block
/// is 128; an offline render may take larger blocks, which give the same samples).
pub const MAX_BLOCK_FRAMES: usize = 16_384;

/// The most units one process call keeps (the rest are counted in [`LiveGlug::units_lost`]).
/// A block of [`MAX_BLOCK_FRAMES`] holds far fewer glugs than this at any rate the engine takes.
pub const MAX_UNITS: usize = 1024;

/// The numbers of one unit in the handle's table of units, in this order (each a float64).
pub const UNIT_FIELDS: [&str; 13] = [
    "frame",
    "audible",
    "sample",
    "fraction",
    "tiltDeg",
    "volumeMl",
    "pocketMl",
    "amplitude",
    "viscosityC",
    "f1Hz",
    "f2Hz",
    "b1PerS",
    "b2PerS",
];

/// The largest whole number a float64 (a JavaScript number) holds exactly: the largest seed and
/// ramp length taken.
pub const MAX_SAFE_INTEGER: f64 = 9_007_199_254_740_991.0;

/// Why a call was refused: a message for a JavaScript `Error`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiveError(pub String);

impl std::fmt::Display for LiveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for LiveError {}

fn refuse<T>(message: String) -> Result<T, LiveError> {
    Err(LiveError(message))
}

/// One live glug: the C library's handle and the buffers its blocks and units are copied into.
pub struct LiveGlug {
    glug: SakeGlug,
    /// The last block's samples (the first `frames` of them).
    out: Box<[f32]>,
    frames: usize,
    /// The last block's units, [`UNIT_FIELDS`] numbers each, the first `unit_count` of them.
    units: Box<[f64]>,
    unit_count: usize,
    /// The bottle after the last block.
    state: SakeGlugState,
    /// Each control's value when the handle was made: the model's or the preset's, else its
    /// default.
    starting: ControlValues,
}

impl LiveGlug {
    /// A handle at `sample_rate` (Hz) playing `model_text` (a model file's text, MODEL.md §12.1)
    /// or the paper's bottle, seeded with `seed` (the products' default if `None`).
    pub fn new(
        sample_rate: f64,
        model_text: Option<&str>,
        seed: Option<f64>,
    ) -> Result<Self, LiveError> {
        let seed = checked_seed(seed)?;
        let glug = SakeGlug::new(sample_rate, model_text, seed).map_err(LiveError)?;
        // The handle parsed the text and took it: so does this, to know the values it starts
        // from (what a model gives, as the handle reads it; the defaults elsewhere).
        let model = model_text.and_then(|text| ModelFile::parse("model", text).ok());
        let starting = ControlValues::from_fn(|control| {
            model
                .as_ref()
                .and_then(|model| model.controls()[control])
                .unwrap_or(control.range().default)
        });
        Ok(Self::around(glug, starting))
    }

    /// A handle playing the shipped preset `name` (`syrup`, …; [`Preset::ids`]).
    pub fn preset(sample_rate: f64, name: &str, seed: Option<f64>) -> Result<Self, LiveError> {
        let seed = checked_seed(seed)?;
        let glug = SakeGlug::preset(sample_rate, name, seed).map_err(LiveError)?;
        let starting = Preset::find(name).map_or_else(ControlValues::default, |preset| {
            preset.controls(ControlValues::default())
        });
        Ok(Self::around(glug, starting))
    }

    fn around(glug: SakeGlug, starting: ControlValues) -> Self {
        Self {
            glug,
            out: vec![0.0; MAX_BLOCK_FRAMES].into_boxed_slice(),
            frames: 0,
            units: vec![0.0; MAX_UNITS * UNIT_FIELDS.len()].into_boxed_slice(),
            unit_count: 0,
            state: SakeGlugState::default(),
            starting,
        }
    }

    /// The value control number `control` had when the handle was made.
    pub fn starting_value(&self, control: u32) -> Result<f64, LiveError> {
        match Control::ALL.get(control as usize) {
            Some(&control) => Ok(self.starting[control]),
            None => refuse(no_control(control)),
        }
    }

    /// Sets `control` (its index in the engine's table of controls) to `value` from the first
    /// sample of the next block on.
    pub fn set(&mut self, control: u32, value: f64) -> Result<(), LiveError> {
        let control = checked_control(control, value, "value")?;
        self.queue(Command::Set(control, value))
    }

    /// Ramps `control` from its value at the first sample of the next block to `target`, reached
    /// `samples` samples later (a scene's two-point lane, MODEL.md §17).
    pub fn ramp(&mut self, control: u32, target: f64, samples: f64) -> Result<(), LiveError> {
        let control = checked_control(control, target, "target")?;
        let samples = checked_whole("a ramp's length in samples", samples)?;
        self.queue(Command::Ramp(control, target, samples))
    }

    /// MODEL.md §8 refill at the first sample of the next block.
    pub fn refill(&mut self) -> Result<(), LiveError> {
        self.queue(Command::Refill)
    }

    /// MODEL.md §8 reset at the first sample of the next block.
    pub fn reset(&mut self) -> Result<(), LiveError> {
        self.queue(Command::Reset)
    }

    /// Compensates the units that start from the next block on for the actuator whose profile is
    /// `profile_text` (MODEL.md §18), as `sake-glug render --actuator` does; `None` plays the
    /// model's drive as it is.
    pub fn set_actuator(&mut self, profile_text: Option<&str>) -> Result<(), LiveError> {
        let response = match profile_text {
            None => None,
            Some(text) if text.len() as u64 > MAX_PROFILE_BYTES => {
                return refuse(format!(
                    "actuator profile: {} bytes, over the limit of {MAX_PROFILE_BYTES} bytes",
                    text.len()
                ))
            }
            Some(text) => Some(
                ActuatorProfile::parse(text)
                    .map_err(|error| LiveError(format!("actuator profile: {error}")))?
                    .response(),
            ),
        };
        self.glug.set_actuator(response).map_err(|_| {
            LiveError(format!(
                "{SAKE_GLUG_MAX_QUEUED_CONTROLS} control calls already wait for the next block: \
                 render a block first"
            ))
        })
    }

    fn queue(&mut self, command: Command) -> Result<(), LiveError> {
        self.glug.queue(command).map_err(|_| {
            LiveError(format!(
                "{SAKE_GLUG_MAX_QUEUED_CONTROLS} control calls already wait for the next block: \
                 render a block first"
            ))
        })
    }

    /// Renders `frames` samples into the handle's buffer ([`LiveGlug::output`]) after taking the
    /// control calls queued since the last block, and keeps the units first heard in them and
    /// the bottle's state. Allocates nothing.
    pub fn process(&mut self, frames: f64) -> Result<(), LiveError> {
        if !(frames.fract() == 0.0 && (0.0..=MAX_BLOCK_FRAMES as f64).contains(&frames)) {
            return refuse(format!(
                "a block of {frames} frames: a block is a whole number of frames from 0 to \
                 {MAX_BLOCK_FRAMES}"
            ));
        }
        let frames = frames as usize;
        // The handle is this struct's alone, and `&mut self` makes this the only call on it: the
        // one audio thread the C library asks for.
        unsafe { self.glug.process(&mut self.out[..frames]) };
        self.frames = frames;
        let units = unsafe { self.glug.units() };
        let kept = units.len().min(MAX_UNITS);
        for (unit, numbers) in units[..kept]
            .iter()
            .zip(self.units.chunks_exact_mut(UNIT_FIELDS.len()))
        {
            numbers.copy_from_slice(&unit_numbers(unit));
        }
        self.unit_count = kept;
        self.state = unsafe { self.glug.state() };
        Ok(())
    }

    /// The samples of the last block.
    pub fn output(&self) -> &[f32] {
        &self.out[..self.frames]
    }

    /// The whole buffer the blocks are rendered into (its address is stable for the handle's
    /// life).
    pub fn output_buffer(&self) -> &[f32] {
        &self.out
    }

    /// The last block's units, [`UNIT_FIELDS`] numbers each.
    pub fn units(&self) -> &[f64] {
        &self.units[..self.unit_count * UNIT_FIELDS.len()]
    }

    /// The whole table the units are copied into (its address is stable).
    pub fn units_buffer(&self) -> &[f64] {
        &self.units
    }

    /// Units first heard in the last block.
    pub fn unit_count(&self) -> usize {
        self.unit_count
    }

    /// Units of the last block that were not kept (beyond [`MAX_UNITS`]).
    pub fn units_lost(&self) -> u32 {
        self.state.units_lost
    }

    /// The bottle after the last block.
    pub fn state(&self) -> &SakeGlugState {
        &self.state
    }
}

/// A unit as the numbers of [`UNIT_FIELDS`].
fn unit_numbers(unit: &SakeGlugUnit) -> [f64; UNIT_FIELDS.len()] {
    [
        unit.frame.into(),
        unit.audible.into(),
        unit.sample as f64,
        unit.fraction,
        unit.tilt_deg,
        unit.volume_ml,
        unit.pocket_ml,
        unit.amplitude,
        unit.viscosity_c,
        unit.f1_hz,
        unit.f2_hz,
        unit.b1_per_s,
        unit.b2_per_s,
    ]
}

/// The control with index `index` if `value` is finite and within its range.
fn checked_control(index: u32, value: f64, what: &str) -> Result<Control, LiveError> {
    let Some(&control) = Control::ALL.get(index as usize) else {
        return refuse(no_control(index));
    };
    let quantity = control.quantity();
    let range = quantity.range;
    if !value.is_finite() {
        return refuse(format!(
            "{} ({}): the {what} {value} is not a finite number; it takes {} to {} {}",
            quantity.name, quantity.param_id, range.min, range.max, quantity.unit
        ));
    }
    if !range.contains(value) {
        return refuse(format!(
            "{} ({}): the {what} {value} is outside its range, {} to {} {}",
            quantity.name, quantity.param_id, range.min, range.max, quantity.unit
        ));
    }
    Ok(control)
}

/// What a control number outside the table is told.
fn no_control(index: u32) -> String {
    format!(
        "no control {index}: the controls are 0 to {} ({})",
        Control::ALL.len() - 1,
        control_names()
    )
}

/// The controls' parameter ids, in order.
fn control_names() -> String {
    let names: Vec<&str> = Control::ALL
        .iter()
        .map(|control| control.quantity().param_id)
        .collect();
    names.join(", ")
}

/// A whole number from 0 to [`MAX_SAFE_INTEGER`].
fn checked_whole(what: &str, value: f64) -> Result<u64, LiveError> {
    if value.fract() == 0.0 && (0.0..=MAX_SAFE_INTEGER).contains(&value) {
        Ok(value as u64)
    } else {
        refuse(format!(
            "{what} is {value}: it must be a whole number from 0 to {MAX_SAFE_INTEGER}"
        ))
    }
}

/// The seed given, or the products' default.
fn checked_seed(seed: Option<f64>) -> Result<u64, LiveError> {
    match seed {
        None => Ok(SEED.range.default as u64),
        Some(seed) => checked_whole("the seed", seed),
    }
}

/// The bottle's tilt (°) from a gravity reading that points up, along the sensor axis `axis`
/// (`+y`: from the base to the mouth), as the plugin reads a phone's gravity over OSC; `None`
/// when the reading has no direction.
pub fn tilt_of(reading: [f64; 3], axis: &str) -> Result<Option<f64>, LiveError> {
    let axis: Axis = axis
        .parse()
        .map_err(|error| LiveError(format!("{error}")))?;
    Ok(tilt_from_gravity(reading, axis))
}

/// The numbers of one unit that [`clip`] reads, in this order: its onset (s from the start of the
/// clip), its amplitude as heard (G·a), c, f1, f2, B1 and B2.
pub const CLIP_UNIT_FIELDS: [&str; 7] = [
    "timeS",
    "amplitude",
    "viscosityC",
    "f1Hz",
    "f2Hz",
    "b1PerS",
    "b2PerS",
];

/// The clip formats [`clip`] writes, each by the renderer's own writer.
pub const CLIP_FORMATS: [&str; 6] = [
    "ahap",
    "haptic",
    "rumble",
    "android-waveform",
    "android-xml",
    "haps",
];

/// A haptic clip of `duration_s` seconds written by the renderer from `units` ([`CLIP_UNIT_FIELDS`]
/// numbers each, as a render's units give them): its `format`'s text (one of [`CLIP_FORMATS`];
/// `.haptic` with the default band, rumble at its default rate), at the output ceiling 1, without
/// an actuator's compensation; `name` and `seed` go into the clip's description. The renderer
/// computes each unit's amplitudes from its onset's and its gain's; these are the heard ones, so
/// a number may differ from the CLI's in its last bits.
pub fn clip(
    format: &str,
    units: &[f64],
    duration_s: f64,
    name: &str,
    seed: f64,
) -> Result<String, LiveError> {
    use sake_glug_render::clips::{ClipSource, Glug, HapticBand};
    use sake_glug_render::sinks;
    if !units.len().is_multiple_of(CLIP_UNIT_FIELDS.len()) {
        return refuse(format!(
            "a clip's units are {} numbers each ({}), not {} numbers",
            CLIP_UNIT_FIELDS.len(),
            CLIP_UNIT_FIELDS.join(", "),
            units.len()
        ));
    }
    if units.iter().any(|x| !x.is_finite()) {
        return refuse("a clip's units hold a number that is not finite".to_owned());
    }
    if !(duration_s.is_finite() && duration_s >= 0.0) {
        return refuse(format!(
            "a clip lasts a finite number of seconds from 0, not {duration_s}"
        ));
    }
    let seed = checked_whole("the seed", seed)?;
    let glugs: Vec<Glug> = units
        .chunks_exact(CLIP_UNIT_FIELDS.len())
        .map(|unit| {
            let &[onset_s, amplitude, c, f1, f2, b1, b2] = unit else {
                unreachable!("chunks of the fields' length")
            };
            Glug {
                onset_s,
                amplitudes: [c * amplitude, (1.0 - c) * amplitude],
                frequency_hz: [f1, f2],
                decay_per_s: [b1, b2],
                viscosity: c,
                actuator_gain: [1.0, 1.0],
            }
        })
        .collect();
    let source = ClipSource {
        duration_s,
        glugs: &glugs,
        ceiling: 1.0,
        scene_name: name,
        seed,
    };
    Ok(match format {
        "ahap" => sinks::ahap_json(&source),
        "haptic" => sinks::haptic_json(&source, &HapticBand::default()),
        "rumble" => sinks::rumble_json(&source, sinks::DEFAULT_RUMBLE_RATE_HZ),
        "android-waveform" => sinks::android_waveform_json(&source),
        "android-xml" => sinks::android_xml(&source),
        "haps" => sinks::haps_json(&source),
        _ => {
            return refuse(format!(
                "no clip format `{}`: the page writes {}",
                format.escape_debug(),
                CLIP_FORMATS.join(", ")
            ))
        }
    })
}
