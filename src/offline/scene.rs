//! Scene files (MODEL.md §10): TOML in, a validated [`Scene`] out. Every key is optional; an
//! unknown key, a wrong type or an out-of-range value is refused with an error naming it.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::automation::{Automation, CsvLaneRef, LaneSpec};
use crate::device::axis::Axis;
use crate::device::csv_lane::{read_csv_lane, CsvLaneError, CsvLaneSpec};
use crate::device::midi::MidiMap;
use crate::device::midi_take::{read_midi_take, TakeError, TimedInput};
use crate::engine::config::{self, ControlValues, Range};
use crate::engine::{ControlSource, Controls, DrainMode, ModelConfig, Preset};

/// The built-in default scene: a full 300 ml bottle of water tilted from 90° to 135° over half a
/// second and held until it stops pouring.
pub const DEFAULT_SCENE: &str = r#"
tilt_deg = [[0.0, 90.0], [0.5, 135.0]]
"#;

/// Longest render a scene may ask for (and the limit on one that never falls silent).
pub const MAX_DURATION_S: f64 = 86_400.0;

/// Why a scene was refused.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read.
    #[error("cannot read scene file {}: {source}", path.display())]
    Read {
        /// The file's path.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Not valid TOML, an unknown key or a value of the wrong type: the parser's message.
    #[error("invalid scene: {0}")]
    Syntax(String),
    /// A value outside its allowed range.
    #[error("`{key}` = {value} is out of range: allowed {min} to {max}")]
    OutOfRange {
        /// The scene key.
        key: &'static str,
        /// The value given.
        value: f64,
        /// Lowest allowed value.
        min: f64,
        /// Highest allowed value.
        max: f64,
    },
    /// A CSV lane could not be read: the error names the file, line and column.
    #[error("`{key}`: {source}")]
    Csv {
        /// The scene key.
        key: &'static str,
        /// What was wrong, and where.
        source: CsvLaneError,
    },
    /// A CSV lane's table is not one of the two forms.
    #[error("`{key}`: {message}")]
    CsvForm {
        /// The scene key.
        key: &'static str,
        /// What was wrong.
        message: String,
    },
    /// The MIDI take could not be read.
    #[error("midi take {}: {source}", path.display())]
    Take {
        /// The take's path.
        path: PathBuf,
        /// What was wrong.
        source: TakeError,
    },
    /// A value that must be a whole number (the sample rate) has a fraction.
    #[error("`{key}` = {value} is not a whole number: {what} must be whole")]
    NotWhole {
        /// The scene key (also for the command line's override of it).
        key: &'static str,
        /// The value given.
        value: f64,
        /// What the value is, in the message.
        what: &'static str,
    },
    /// An automation point whose time is not finite, is negative or comes before the previous
    /// point's.
    #[error("`{key}`: point {index} is at {time_s} s; point times must be finite, at least 0 and in order")]
    PointTime {
        /// The scene key.
        key: &'static str,
        /// Index of the point in the list, from 0.
        index: usize,
        /// The point's time (s).
        time_s: f64,
    },
}

/// A validated scene, ready to render.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Sample rate fs (Hz).
    pub sample_rate: u32,
    /// `None`: until pouring stops and every unit has decayed.
    pub duration_s: Option<f64>,
    /// Tilt θ (degrees) over time.
    pub tilt_deg: Automation,
    /// Viscosity ratio c over time.
    pub viscosity: Automation,
    /// Fill level φ (percent of capacity) over time.
    pub fill_percent: Automation,
    /// Pour time T (s) over time.
    pub pour_time_s: Automation,
    /// Output gain (dB) over time.
    pub gain_db: Automation,
    /// Seed, spreads (zero if `deterministic`), drain mode and the other constants.
    pub config: ModelConfig,
    /// A recorded MIDI take from the tilt device, if the scene names one.
    pub take: Option<MidiTake>,
    /// How the take's messages map to controls (the plugin's MIDI settings).
    pub midi: MidiMap,
}

/// A recorded Standard MIDI File take: its bytes, and its messages at the scene's sample rate.
#[derive(Debug, Clone, PartialEq)]
pub struct MidiTake {
    /// Where it was read from.
    pub path: PathBuf,
    bytes: Vec<u8>,
    /// Every note-on and CC, at the first sample at or after its time.
    pub events: Vec<TimedInput>,
}

impl MidiTake {
    /// Reads the take at `path` for a render at `sample_rate` (Hz).
    pub fn load(path: &Path, sample_rate: u32) -> Result<Self, SceneError> {
        let bytes = std::fs::read(path).map_err(|source| SceneError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::from_bytes(path, bytes, sample_rate)
    }

    fn from_bytes(path: &Path, bytes: Vec<u8>, sample_rate: u32) -> Result<Self, SceneError> {
        let events = read_midi_take(&bytes, sample_rate).map_err(|source| SceneError::Take {
            path: path.to_owned(),
            source,
        })?;
        Ok(Self {
            path: path.to_owned(),
            bytes,
            events,
        })
    }
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
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read {
            path: path.to_owned(),
            source,
        })?;
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
        let file: SceneFile =
            toml::from_str(text).map_err(|error| SceneError::Syntax(error.to_string()))?;
        file.validate(folder)
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

    /// The scene file of a preset: the default pour (tilted from 90° to 135° over half a
    /// second) with the preset's liquid and bottle. `cargo xtask docs` writes these to
    /// `presets/<id>.toml`.
    pub fn preset_toml(preset: &Preset) -> String {
        let [f1, f2] = preset.frequency_hz;
        let [b1, b2] = preset.decay_per_s;
        format!(
            "# {name}: {description}.\n\
             # Written by `cargo xtask docs` from src/engine/presets.rs: edit the preset there.\n\
             tilt_deg = [[0.0, 90.0], [0.5, 135.0]]\n\
             viscosity_c = {viscosity:?}\n\
             pour_time_s = {pour_time:?}\n\
             \n[bottle]\ncapacity_ml = {capacity:?}\npocket_ml = {pocket:?}\n\
             \n[glug]\nf1_hz = {f1:?}\nf2_hz = {f2:?}\nb1_per_s = {b1:?}\nb2_per_s = {b2:?}\n",
            name = preset.name,
            description = preset.description,
            viscosity = preset.viscosity,
            pour_time = preset.pour_time_s,
            capacity = preset.capacity_ml,
            pocket = preset.pocket_ml,
        )
    }

    /// The same scene driven by the MIDI take at `path` (which replaces the scene's own).
    pub fn with_midi_take(self, path: &Path) -> Result<Self, SceneError> {
        let take = Some(MidiTake::load(path, self.sample_rate)?);
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
        self.lanes()
            .iter()
            .map(|lane| lane.last_time_s())
            .fold(last_message_s, f64::max)
    }

    /// The inputs at one sample.
    pub fn values_at(&self, sample: u64) -> (ControlValues, f64) {
        let time_s = sample as f64 / self.sample_rate as f64;
        let values = ControlValues {
            tilt_deg: self.tilt_deg.value_at(time_s),
            viscosity: self.viscosity.value_at(time_s),
            fill_percent: self.fill_percent.value_at(time_s),
            pour_time_s: self.pour_time_s.value_at(time_s),
        };
        (values, self.gain_db.value_at(time_s))
    }

    /// The engine's controls for `len` samples from `first_sample`, using `buffers` as storage.
    pub fn controls<'a>(
        &self,
        first_sample: u64,
        buffers: &'a mut LaneBuffers,
        len: usize,
    ) -> Controls<'a> {
        let fs = self.sample_rate as f64;
        let [tilt, viscosity, fill, pour_time, gain] = &mut buffers.0;
        for buffer in [
            &mut *tilt,
            &mut *viscosity,
            &mut *fill,
            &mut *pour_time,
            &mut *gain,
        ] {
            buffer.resize(len, 0.0);
        }
        Controls {
            tilt_deg: self.tilt_deg.lane(first_sample, fs, tilt),
            viscosity: self.viscosity.lane(first_sample, fs, viscosity),
            fill_percent: self.fill_percent.lane(first_sample, fs, fill),
            pour_time_s: self.pour_time_s.lane(first_sample, fs, pour_time),
            gain_db: self.gain_db.lane(first_sample, fs, gain),
        }
    }

    fn lanes(&self) -> [&Automation; 5] {
        [
            &self.tilt_deg,
            &self.viscosity,
            &self.fill_percent,
            &self.pour_time_s,
            &self.gain_db,
        ]
    }
}

impl ControlSource for Scene {
    fn at(&self, sample: u64) -> (ControlValues, f64) {
        self.values_at(sample)
    }
}

/// Storage for the per-sample lanes of one block, reused from block to block.
#[derive(Debug, Default)]
pub struct LaneBuffers([Vec<f64>; 5]);

// ---- The file as written: every key optional, nothing unknown. ----

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    /// Read as a number of either type, so that a fraction is refused by [`check_sample_rate`]
    /// with the same message as the command line's `--sample-rate`.
    sample_rate: Option<f64>,
    duration_s: Option<f64>,
    seed: Option<u64>,
    deterministic: Option<bool>,
    tilt_deg: Option<LaneSpec>,
    viscosity_c: Option<LaneSpec>,
    fill_percent: Option<LaneSpec>,
    pour_time_s: Option<LaneSpec>,
    midi_take: Option<PathBuf>,
    #[serde(default)]
    midi: MidiSection,
    #[serde(default)]
    bottle: BottleSection,
    #[serde(default)]
    glug: GlugSection,
    #[serde(default)]
    output: OutputSection,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct BottleSection {
    capacity_ml: Option<f64>,
    pocket_ml: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct GlugSection {
    f1_hz: Option<f64>,
    f2_hz: Option<f64>,
    b1_per_s: Option<f64>,
    b2_per_s: Option<f64>,
    timing_jitter: Option<f64>,
    freq_jitter: Option<f64>,
    decay_sigma: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct OutputSection {
    gain_db: Option<LaneSpec>,
    drain: Option<DrainMode>,
}

/// The `[midi]` table: the plugin's saved MIDI settings, by the same names and values (0–127,
/// a channel 0–15; 255 for "not mapped" or "any channel").
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct MidiSection {
    midi_channel: Option<u8>,
    midi_cc_tilt: Option<u8>,
    midi_cc_tilt_lsb: Option<u8>,
    midi_cc_viscosity: Option<u8>,
    midi_cc_fill: Option<u8>,
}

impl MidiSection {
    /// The map, each field checked: a CC above 127 or a channel above 15 that is not 255 is
    /// refused rather than silently unmapped.
    fn map(&self) -> Result<MidiMap, SceneError> {
        let defaults = MidiMap::default().to_raw();
        let field = |key: &'static str, value: Option<u8>, default: u8, max: u8| {
            let value = value.unwrap_or(default);
            if value <= max || value == crate::device::midi::OFF {
                Ok(value)
            } else {
                Err(SceneError::OutOfRange {
                    key,
                    value: value as f64,
                    min: 0.0,
                    max: max as f64,
                })
            }
        };
        Ok(MidiMap::from_raw([
            field("midi.midi_channel", self.midi_channel, defaults[0], 15)?,
            field("midi.midi_cc_tilt", self.midi_cc_tilt, defaults[1], 127)?,
            field(
                "midi.midi_cc_tilt_lsb",
                self.midi_cc_tilt_lsb,
                defaults[2],
                127,
            )?,
            field(
                "midi.midi_cc_viscosity",
                self.midi_cc_viscosity,
                defaults[3],
                127,
            )?,
            field("midi.midi_cc_fill", self.midi_cc_fill, defaults[4], 127)?,
        ]))
    }
}

impl SceneFile {
    fn validate(self, folder: &Path) -> Result<Scene, SceneError> {
        let sample_rate = match self.sample_rate {
            Some(rate) => check_sample_rate(rate)?,
            None => config::SAMPLE_RATE_HZ.default as u32,
        };
        let duration_s = self
            .duration_s
            .map(|seconds| {
                let allowed = Range {
                    min: 1.0 / sample_rate as f64,
                    max: MAX_DURATION_S,
                    default: 0.0,
                };
                check("duration_s", seconds, allowed)
            })
            .transpose()?;
        let glug = &self.glug;
        let mut config = ModelConfig {
            capacity_ml: constant(
                "bottle.capacity_ml",
                self.bottle.capacity_ml,
                config::CAPACITY_ML,
            )?,
            pocket_ml: constant("bottle.pocket_ml", self.bottle.pocket_ml, config::POCKET_ML)?,
            frequency_hz: [
                constant("glug.f1_hz", glug.f1_hz, config::F1_HZ)?,
                constant("glug.f2_hz", glug.f2_hz, config::F2_HZ)?,
            ],
            decay_per_s: [
                constant("glug.b1_per_s", glug.b1_per_s, config::B1_PER_S)?,
                constant("glug.b2_per_s", glug.b2_per_s, config::B2_PER_S)?,
            ],
            timing_jitter: constant(
                "glug.timing_jitter",
                glug.timing_jitter,
                config::TIMING_JITTER,
            )?,
            freq_jitter: constant("glug.freq_jitter", glug.freq_jitter, config::FREQ_JITTER)?,
            decay_sigma: constant("glug.decay_sigma", glug.decay_sigma, config::DECAY_SIGMA)?,
            seed: self.seed.unwrap_or(ModelConfig::default().seed),
            drain: self.output.drain.unwrap_or_default(),
            ceiling: config::CEILING.default,
        };
        if self.deterministic.unwrap_or(false) {
            config = config.deterministic();
        }
        let lane = |key, spec, range| automation(key, resolve(key, spec, folder)?, range);
        let take = self
            .midi_take
            .map(|path| MidiTake::load(&folder.join(path), sample_rate))
            .transpose()?;
        Ok(Scene {
            sample_rate,
            duration_s,
            tilt_deg: lane("tilt_deg", self.tilt_deg, config::TILT_DEG)?,
            viscosity: lane("viscosity_c", self.viscosity_c, config::VISCOSITY)?,
            fill_percent: lane("fill_percent", self.fill_percent, config::FILL_PERCENT)?,
            pour_time_s: lane("pour_time_s", self.pour_time_s, config::POUR_TIME_S)?,
            gain_db: lane("output.gain_db", self.output.gain_db, config::GAIN_DB)?,
            config,
            take,
            midi: self.midi.map()?,
        })
    }
}

/// A lane as the scene wrote it, with a CSV take read into points (relative to `folder`).
fn resolve(
    key: &'static str,
    spec: Option<LaneSpec>,
    folder: &Path,
) -> Result<Option<Automation>, SceneError> {
    let reference = match spec {
        None => return Ok(None),
        Some(LaneSpec::Inline(automation)) => return Ok(Some(automation)),
        Some(LaneSpec::Csv(reference)) => reference,
    };
    let form = |message: &str| SceneError::CsvForm {
        key,
        message: message.to_string(),
    };
    let CsvLaneRef {
        csv,
        column,
        accel,
        axis,
    } = reference;
    let spec = match (column, accel) {
        (Some(column), None) if axis.is_none() => CsvLaneSpec::Column(column),
        (None, Some(columns)) if key == "tilt_deg" => {
            let axis: Axis =
                axis.as_deref().unwrap_or("+z").parse().map_err(
                    |error: crate::device::axis::AxisParseError| form(&error.to_string()),
                )?;
            CsvLaneSpec::Gravity { columns, axis }
        }
        (None, Some(_)) => return Err(form("`accel` gives a tilt: only tilt_deg takes it")),
        (Some(_), None) => return Err(form("`axis` goes with `accel`, not with `column`")),
        _ => {
            return Err(form(
                "give either `column` or `accel` (with `axis`), not both",
            ))
        }
    };
    let path = folder.join(&csv);
    let text = std::fs::read_to_string(&path).map_err(|source| SceneError::Read {
        path: path.clone(),
        source,
    })?;
    let points =
        read_csv_lane(&text, &path, &spec).map_err(|source| SceneError::Csv { key, source })?;
    Ok(Some(Automation::Points(points)))
}

fn check(key: &'static str, value: f64, range: Range) -> Result<f64, SceneError> {
    if range.contains(value) {
        Ok(value)
    } else {
        Err(SceneError::OutOfRange {
            key,
            value,
            min: range.min,
            max: range.max,
        })
    }
}

/// A sample rate in range and a whole number of Hz.
fn check_sample_rate(sample_rate: f64) -> Result<u32, SceneError> {
    let sample_rate = check("sample_rate", sample_rate, config::SAMPLE_RATE_HZ)?;
    if sample_rate.fract() != 0.0 {
        return Err(SceneError::NotWhole {
            key: "sample_rate",
            value: sample_rate,
            what: "a sample rate is a number of samples per second",
        });
    }
    Ok(sample_rate as u32)
}

fn constant(key: &'static str, value: Option<f64>, range: Range) -> Result<f64, SceneError> {
    check(key, value.unwrap_or(range.default), range)
}

fn automation(
    key: &'static str,
    value: Option<Automation>,
    range: Range,
) -> Result<Automation, SceneError> {
    let automation = value.unwrap_or(Automation::Constant(range.default));
    for value in automation.values() {
        check(key, value, range)?;
    }
    if let Automation::Points(points) = &automation {
        let mut previous = 0.0;
        for (index, &(time_s, _)) in points.iter().enumerate() {
            if !(time_s.is_finite() && time_s >= previous) {
                return Err(SceneError::PointTime { key, index, time_s });
            }
            previous = time_s;
        }
    }
    Ok(automation)
}
