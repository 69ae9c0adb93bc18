//! Sake Glug in WebAssembly: what the C library exposes (crates/capi), as a JavaScript class
//! through wasm-bindgen. web/src/ wraps it in the npm package's API: an AudioWorklet processor,
//! an `AudioNode`, offline renders and haptics.
//!
//! A [`Glug`] is the C library's handle: created at a sample rate from a model file's text or a
//! preset's name, its controls set or ramped, refilled and reset, each call taken at the first
//! sample of the next block, so that its samples are those of `sake-glug render` of the same
//! scene (MODEL.md §17). A block is rendered into a buffer the handle owns and reuses (nothing is
//! allocated per block); JavaScript reads it, and the units first heard in it, as views of the
//! WebAssembly memory at [`Glug::output_ptr`] and [`Glug::units_ptr`].
//!
//! Every argument is checked in [`live`] and refused with a JavaScript `Error` that says what was
//! wrong: nothing a caller passes can abort the WebAssembly instance.

pub mod live;

use wasm_bindgen::prelude::*;

pub use live::{LiveError, LiveGlug, MAX_BLOCK_FRAMES, MAX_UNITS, UNIT_FIELDS};

fn js(error: LiveError) -> JsError {
    JsError::new(&error.0)
}

/// One live glug.
#[wasm_bindgen]
pub struct Glug {
    live: LiveGlug,
}

#[wasm_bindgen]
impl Glug {
    /// A glug at `sampleRate` (Hz, a whole number from 1000 to 768000) playing the model file
    /// whose text is `modelText` (MODEL.md §12.1), or the paper's bottle if it is null or
    /// undefined, seeded with `seed` (a whole number; the products' default if left out).
    #[wasm_bindgen(constructor)]
    pub fn new(
        sample_rate: f64,
        model_text: Option<String>,
        seed: Option<f64>,
    ) -> Result<Glug, JsError> {
        LiveGlug::new(sample_rate, model_text.as_deref(), seed)
            .map(|live| Glug { live })
            .map_err(js)
    }

    /// A glug at `sampleRate` playing the shipped preset `name` (`water`, `syrup`, …).
    #[wasm_bindgen(js_name = fromPreset)]
    pub fn from_preset(sample_rate: f64, name: &str, seed: Option<f64>) -> Result<Glug, JsError> {
        LiveGlug::preset(sample_rate, name, seed)
            .map(|live| Glug { live })
            .map_err(js)
    }

    /// Sets control number `control` (the order of the engine's table: tilt, visc, fill, pour,
    /// gain) to `value` from the first sample of the next block on.
    pub fn set(&mut self, control: u32, value: f64) -> Result<(), JsError> {
        self.live.set(control, value).map_err(js)
    }

    /// Ramps control number `control` from its value at the first sample of the next block to
    /// `target`, reached `samples` samples later and held from then on.
    pub fn ramp(&mut self, control: u32, target: f64, samples: f64) -> Result<(), JsError> {
        self.live.ramp(control, target, samples).map_err(js)
    }

    /// The value control number `control` had when the glug was made (the model's or the
    /// preset's, else its default).
    #[wasm_bindgen(js_name = startingValue)]
    pub fn starting_value(&self, control: u32) -> Result<f64, JsError> {
        self.live.starting_value(control).map_err(js)
    }

    /// Refills the bottle to the fill level at the first sample of the next block.
    pub fn refill(&mut self) -> Result<(), JsError> {
        self.live.refill().map_err(js)
    }

    /// Resets at the first sample of the next block: refill, silence, re-seed, count from 0.
    pub fn reset(&mut self) -> Result<(), JsError> {
        self.live.reset().map_err(js)
    }

    /// Compensates the units that start from the next block on for the actuator whose profile
    /// file's text is `profileText` (MODEL.md §18); null plays the model's drive as it is.
    #[wasm_bindgen(js_name = setActuator)]
    pub fn set_actuator(&mut self, profile_text: Option<String>) -> Result<(), JsError> {
        self.live.set_actuator(profile_text.as_deref()).map_err(js)
    }

    /// Renders `frames` samples (0 to `maxBlockFrames()`) into the handle's buffer, at
    /// `outputPtr()` in the WebAssembly memory.
    pub fn process(&mut self, frames: f64) -> Result<(), JsError> {
        self.live.process(frames).map_err(js)
    }

    /// The address of the buffer blocks are rendered into (`maxBlockFrames()` float32s; stable
    /// for the handle's life).
    #[wasm_bindgen(js_name = outputPtr)]
    pub fn output_ptr(&self) -> usize {
        self.live.output_buffer().as_ptr() as usize
    }

    /// The address of the table the last block's units are copied into (`maxUnits()` rows of
    /// `unitFields()` float64s; stable for the handle's life).
    #[wasm_bindgen(js_name = unitsPtr)]
    pub fn units_ptr(&self) -> usize {
        self.live.units_buffer().as_ptr() as usize
    }

    /// Units first heard in the last block.
    #[wasm_bindgen(js_name = unitCount)]
    pub fn unit_count(&self) -> usize {
        self.live.unit_count()
    }

    /// Units of the last block beyond `maxUnits()`, not kept.
    #[wasm_bindgen(js_name = unitsLost)]
    pub fn units_lost(&self) -> u32 {
        self.live.units_lost()
    }

    /// Samples rendered since the glug was made or last reset.
    pub fn position(&self) -> f64 {
        self.live.state().position as f64
    }

    /// The sample after the last one in which liquid flowed or a unit sounded.
    #[wasm_bindgen(js_name = activeUntil)]
    pub fn active_until(&self) -> f64 {
        self.live.state().active_until as f64
    }

    /// What the bottle holds now (ml).
    #[wasm_bindgen(js_name = volumeMl)]
    pub fn volume_ml(&self) -> f64 {
        self.live.state().volume_ml
    }

    /// The last sample's outflow (ml/s).
    #[wasm_bindgen(js_name = outflowMlPerS)]
    pub fn outflow_ml_per_s(&self) -> f64 {
        self.live.state().outflow_ml_per_s
    }

    /// The tilt of the last sample (°).
    #[wasm_bindgen(js_name = tiltDeg)]
    pub fn tilt_deg(&self) -> f64 {
        self.live.state().tilt_deg
    }

    /// The output gain of the last sample (linear).
    #[wasm_bindgen(js_name = outputGain)]
    pub fn output_gain(&self) -> f64 {
        self.live.state().output_gain
    }

    /// Whether the mouth was under the liquid at the last sample.
    pub fn submerged(&self) -> bool {
        self.live.state().submerged != 0
    }

    /// Whether nothing sounds and nothing will start under the controls now: silence until a
    /// control changes.
    pub fn settled(&self) -> bool {
        self.live.state().settled != 0
    }
}

/// The most frames one `process` call renders.
#[wasm_bindgen(js_name = maxBlockFrames)]
pub fn max_block_frames() -> usize {
    MAX_BLOCK_FRAMES
}

/// The most units one block keeps.
#[wasm_bindgen(js_name = maxUnits)]
pub fn max_units() -> usize {
    MAX_UNITS
}

/// The names of a unit's numbers, in the order of the units' table.
#[wasm_bindgen(js_name = unitFields)]
pub fn unit_fields() -> Vec<String> {
    UNIT_FIELDS.iter().map(|&field| field.to_owned()).collect()
}

/// The bottle's tilt (°) from a gravity reading `x, y, z` that points up (the sensor at rest
/// reads +1 g away from the earth), `axis` the sensor axis from the bottle's base to its mouth
/// (`+x`, `-y`, …): the plugin's reading of a phone's gravity. Undefined if the reading has no
/// direction.
#[wasm_bindgen(js_name = tiltFromGravity)]
pub fn tilt_from_gravity(x: f64, y: f64, z: f64, axis: &str) -> Result<Option<f64>, JsError> {
    live::tilt_of([x, y, z], axis).map_err(js)
}

/// A haptic clip's text written by the renderer's own writer: `format` one of `clipFormats()`,
/// `units` a Float64Array of `clipUnitFields()` numbers a unit (a render's units), the clip
/// `durationS` long, `name` and `seed` in its description.
#[wasm_bindgen]
pub fn clip(
    format: &str,
    units: &[f64],
    duration_s: f64,
    name: &str,
    seed: f64,
) -> Result<String, JsError> {
    live::clip(format, units, duration_s, name, seed).map_err(js)
}

/// The clip formats `clip` writes.
#[wasm_bindgen(js_name = clipFormats)]
pub fn clip_formats() -> Vec<String> {
    live::CLIP_FORMATS.iter().map(|&f| f.to_owned()).collect()
}

/// The numbers of a unit that `clip` reads, in order.
#[wasm_bindgen(js_name = clipUnitFields)]
pub fn clip_unit_fields() -> Vec<String> {
    live::CLIP_UNIT_FIELDS
        .iter()
        .map(|&f| f.to_owned())
        .collect()
}

/// The version of the engine inside (the release's).
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_owned()
}
