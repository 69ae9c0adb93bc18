//! Scene files (MODEL.md §10): TOML in, a validated [`Scene`] out. Every key is optional; an
//! unknown key, a wrong type or an out-of-range value is refused with an error naming it.
//!
//! One job a file: [`error`] why a scene was refused, [`inputs`] the files it read besides
//! itself, [`take`] its MIDI take, [`validate`] the file as written checked key by key into a
//! scene, [`lanes`] its automation lanes (inline or from CSV); here, the scene and what the
//! renderer asks of it.

mod duration;
mod error;
mod fade_out;
mod inputs;
mod lanes;
mod take;
mod validate;
pub(crate) mod variations_table;

use std::path::Path;

use super::automation::Automation;
use sake_glug_device::midi::MidiMap;
use sake_glug_engine::{
    sample_time_s, ActuatorResponse, Control, ControlSource, ControlValues, Controls, ModelConfig,
    PerControl, Preset, PresetValue,
};
use sake_glug_io::keys;
use sake_glug_io::read::{self, InputKind};
use sake_glug_model_file::{FittedVolumes, ModelFile};

pub use duration::MAX_DURATION_S;
pub use error::SceneError;
pub use fade_out::FadeOut;
pub use inputs::InputFile;
pub use take::MidiTake;
use validate::{check_sample_rate, SceneFile, MIDI_TAKE};
use variations_table::VariationSpec;

/// The built-in default scene: a full 300 ml bottle of water tilted from 90° to 135° over half a
/// second and held until it stops pouring.
pub const DEFAULT_SCENE: &str = r#"
tilt_deg = [[0.0, 90.0], [0.5, 135.0]]
"#;

/// The largest scene file read ([`InputKind::SCENE`]).
pub const MAX_SCENE_BYTES: u64 = InputKind::SCENE.max_bytes;

/// A validated scene, ready to render.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Sample rate fs (Hz).
    pub sample_rate: u32,
    /// `None`: until pouring stops and every unit has decayed.
    pub duration_s: Option<f64>,
    /// Every control over time.
    pub lanes: PerControl<Automation>,
    /// Seed, spreads (zero if `deterministic`), drain mode and the other constants.
    pub config: ModelConfig,
    /// A recorded MIDI take from the tilt device, if the scene names one.
    pub take: Option<MidiTake>,
    /// How the take's messages map to controls (the plugin's MIDI settings).
    pub midi: MidiMap,
    /// The files read for the CSV lanes and the take, in the order read.
    pub inputs: Vec<InputFile>,
    /// The actuator the render is compensated for (MODEL.md §18): no scene key, set by the
    /// caller (`--actuator`); `None` plays the model's drive as it is.
    pub actuator: Option<ActuatorResponse>,
    /// The fade a trimmed render ends with ([`crate::trim`]): no scene key, set by
    /// [`crate::trim::trimmed`].
    pub fade_out: Option<FadeOut>,
    /// The scene's `[variations]` table (MODEL.md §10.2), if it has one: what a set of takes of
    /// it draws.
    pub variations: Option<VariationSpec>,
    /// The volumes the model's glugs were recorded at (`[fit] volumes_ml`, MODEL.md §13), if a
    /// fitted model gives them: they play nothing; the renderer warns of a pour far beyond them.
    pub fitted_volumes: Option<FittedVolumes>,
}

/// A scene file's text, read as a regular file within [`MAX_SCENE_BYTES`], in UTF-8.
fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    read::text_within(path, MAX_SCENE_BYTES).map_err(|source| SceneError::Read {
        path: path.to_owned(),
        source,
    })
}

impl Default for Scene {
    fn default() -> Self {
        Scene::parse(DEFAULT_SCENE).expect("the built-in scene is valid")
    }
}

impl Scene {
    /// Reads and validates the scene file at `path`; the files it names (CSV lanes, a MIDI
    /// take) are found relative to its folder.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let text = read_scene_text(path)?;
        let folder = path.parent().unwrap_or(Path::new(""));
        Self::parse_in(&text, folder)
    }

    /// Parses and validates a scene from TOML `text`; files it names are relative to the
    /// current folder.
    pub fn parse(text: &str) -> Result<Self, SceneError> {
        Self::parse_in(text, Path::new(""))
    }

    /// Parses and validates a scene from TOML `text` whose files are relative to `folder`.
    pub fn parse_in(text: &str, folder: &Path) -> Result<Self, SceneError> {
        SceneFile::parse(text)?.validate(folder)
    }

    /// The scene file at `path` played on `model`'s bottle (MODEL.md §12.1): every key the scene
    /// leaves out that the model gives comes from the model; what the scene sets, it keeps.
    pub fn load_with_model(path: &Path, model: &ModelFile) -> Result<Self, SceneError> {
        let text = read_scene_text(path)?;
        let folder = path.parent().unwrap_or(Path::new(""));
        Self::parse_with_model(&text, folder, model)
    }

    /// The scene of TOML `text` (its files relative to `folder`) played on `model`'s bottle, as
    /// [`Scene::load_with_model`].
    pub fn parse_with_model(
        text: &str,
        folder: &Path,
        model: &ModelFile,
    ) -> Result<Self, SceneError> {
        let mut file = SceneFile::parse(text)?;
        file.layer_over(model);
        file.validate(folder)
    }

    /// The output's ceiling (linear): the scene's, and at most the actuator's largest drive, as
    /// the engine holds it.
    pub fn output_ceiling(&self) -> f64 {
        match &self.actuator {
            Some(actuator) => self.config.ceiling.min(actuator.max_amplitude()),
            None => self.config.ceiling,
        }
    }

    /// The same scene at another sample rate, refused as a scene's `sample_rate` would be: out
    /// of range or not a whole number of Hz. A take's messages move to their new samples.
    pub fn with_sample_rate(self, sample_rate: f64) -> Result<Self, SceneError> {
        let sample_rate = check_sample_rate(sample_rate)?;
        let take = match self.take {
            Some(take) => Some(MidiTake::from_bytes(&take.path, take.bytes, sample_rate)?),
            None => None,
        };
        Ok(Self {
            sample_rate,
            take,
            ..self
        })
    }

    /// The scene file of a preset: the default pour ([`DEFAULT_SCENE`]) with the preset's
    /// values, each at its scene key. `cargo xtask docs` writes these to `presets/<id>.toml`.
    pub fn preset_toml(preset: &Preset) -> String {
        let mut table: toml::Table =
            toml::from_str(DEFAULT_SCENE).expect("the built-in scene is valid TOML");
        for value in preset.values {
            let (quantity, value) = match *value {
                PresetValue::Control(control, value) => (control.quantity(), value),
                PresetValue::Constant(constant, value) => (constant.quantity(), value),
            };
            keys::insert(&mut table, quantity.scene_key, toml::Value::Float(value));
        }
        format!(
            "# {}: {}.\n# Written by `cargo xtask docs` from crates/engine/src/presets.rs: edit the preset \
             there.\n{}",
            preset.name,
            preset.description,
            toml::to_string(&table).expect("a table of numbers is valid TOML")
        )
    }

    /// The same scene driven by the MIDI take at `path` (which replaces the scene's own).
    pub fn with_midi_take(mut self, path: &Path) -> Result<Self, SceneError> {
        let take = Some(MidiTake::load(path, self.sample_rate)?);
        self.inputs.retain(|input| input.key != MIDI_TAKE);
        self.inputs.push(InputFile {
            key: MIDI_TAKE,
            path: path.to_owned(),
            outside_folder: false,
        });
        Ok(Self { take, ..self })
    }

    /// Samples to render, if the scene fixes its duration.
    pub fn duration_samples(&self) -> Option<u64> {
        self.duration_s
            .map(|seconds| (seconds * self.sample_rate as f64).round() as u64)
    }

    /// Time of the last automation point or take message: the controls hold still after it.
    pub fn last_automation_s(&self) -> f64 {
        let last_message_s = self
            .take
            .as_ref()
            .and_then(|take| take.events.last())
            .map_or(0.0, |event| event.sample as f64 / self.sample_rate as f64);
        Control::ALL
            .iter()
            .map(|&control| self.lanes[control].last_time_s())
            .fold(last_message_s, f64::max)
    }

    /// The inputs at one sample.
    pub fn values_at(&self, sample: u64) -> ControlValues {
        let time_s = sample_time_s(sample, self.sample_rate as f64);
        ControlValues::from_fn(|control| self.lanes[control].value_at(time_s))
    }

    /// The engine's controls for `len` samples from `first_sample`, using `buffers` as storage.
    pub fn controls<'a>(
        &self,
        first_sample: u64,
        buffers: &'a mut LaneBuffers,
        len: usize,
    ) -> Controls<'a> {
        let fs = self.sample_rate as f64;
        buffers.0.each_mut().into_map(|control, buffer| {
            buffer.resize(len, 0.0);
            self.lanes[control].lane(first_sample, fs, buffer)
        })
    }
}

impl ControlSource for Scene {
    fn at(&self, sample: u64) -> ControlValues {
        self.values_at(sample)
    }
}

/// Storage for the per-sample lanes of one block, reused from block to block.
#[derive(Debug)]
pub struct LaneBuffers(PerControl<Vec<f64>>);

impl Default for LaneBuffers {
    fn default() -> Self {
        Self(PerControl::from_fn(|_| Vec::new()))
    }
}
