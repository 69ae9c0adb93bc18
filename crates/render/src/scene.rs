//! Scene files (MODEL.md §10): TOML in, a validated [`Scene`] out. Every key is optional; an
//! unknown key, a wrong type or an out-of-range value is refused with an error naming it.

use std::fs::{File, FileType};
use std::io::Read;
use std::path::{Path, PathBuf};

use super::automation::{Automation, CsvLaneRef, LaneSpec};
use sake_glug_device::axis::Axis;
use sake_glug_device::csv_lane::{read_csv_lane, CsvLaneError, CsvLaneSpec, MAX_CSV_LANE_BYTES};
use sake_glug_device::midi::{MidiMap, MidiSetting};
use sake_glug_device::midi_take::{read_midi_take, TakeError, TimedInput, MAX_TAKE_BYTES};
use sake_glug_engine::config;
use sake_glug_engine::{
    sample_time_s, Constant, Control, ControlSource, ControlValues, Controls, Curve, DrainMode,
    ModelConfig, PerControl, Preset, PresetValue, Quantity, Range, ValueError,
};
use sake_glug_io::text::printable;
use sake_glug_model_file::{curve_points, ModelFile};

/// The built-in default scene: a full 300 ml bottle of water tilted from 90° to 135° over half a
/// second and held until it stops pouring.
pub const DEFAULT_SCENE: &str = r#"
tilt_deg = [[0.0, 90.0], [0.5, 135.0]]
"#;

/// The largest scene file read (16 MiB): its automation points are written out in TOML, which
/// the parser holds several times over while it reads them; a longer recording belongs in a
/// CSV lane, which may be larger.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Longest render a scene may ask for (and the limit on one that never falls silent).
pub const MAX_DURATION_S: f64 = 86_400.0;

/// Why a scene was refused. Text from the scene or a file it names is shown with its control
/// characters escaped ([`printable`]).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read: missing, not a regular file, too large, not UTF-8.
    #[error("cannot read scene file {}: {source}", shown(path))]
    Read {
        /// The file's path.
        path: PathBuf,
        /// Why not.
        source: InputFileError,
    },
    /// The file of a CSV lane could not be read.
    #[error("cannot read CSV lane `{key}` file {}: {source}", shown(path))]
    CsvFile {
        /// The scene key.
        key: &'static str,
        /// The file's path.
        path: PathBuf,
        /// Why not.
        source: InputFileError,
    },
    /// The file of a MIDI take could not be read.
    #[error("cannot read MIDI take {}: {source}", shown(path))]
    TakeFile {
        /// The file's path.
        path: PathBuf,
        /// Why not.
        source: InputFileError,
    },
    /// Not valid TOML, an unknown key or a value of the wrong type: the parser's message, its
    /// control characters escaped.
    #[error("invalid scene: {0}")]
    Syntax(String),
    /// A value the model cannot take: out of range, V0 not below the capacity, or no curve.
    #[error(transparent)]
    Value(#[from] ValueError),
    /// A CSV lane could not be read: the error names the file, line and column.
    #[error("`{key}`: {source}")]
    Csv {
        /// The scene key.
        key: &'static str,
        /// What was wrong, and where.
        source: CsvLaneError,
    },
    /// A CSV lane's table is not one of the two forms.
    #[error("`{key}`: {}", printable(message))]
    CsvForm {
        /// The scene key.
        key: &'static str,
        /// What was wrong.
        message: String,
    },
    /// The MIDI take is not one the renderer reads.
    #[error("midi take {}: {source}", shown(path))]
    Take {
        /// The take's path.
        path: PathBuf,
        /// What was wrong.
        source: TakeError,
    },
    /// A value that must be a whole number (the sample rate) has a fraction.
    #[error("`{key}` = {value} is not a whole number: {what}")]
    NotWhole {
        /// The scene key (also for the command line's override of it).
        key: &'static str,
        /// The value given.
        value: f64,
        /// Why it must be whole, in the message.
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

/// Why a CSV lane's or a MIDI take's file was not read.
#[derive(Debug, thiserror::Error)]
pub enum InputFileError {
    /// Opening or reading it failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// A FIFO, a device, a folder: reading it could block, never end or mean nothing.
    #[error("it is {0}, not a regular file")]
    NotAFile(&'static str),
    /// Larger than the limit, by its size on disk.
    #[error("it is {size} bytes, over the limit of {limit} bytes ({} MiB)", limit >> 20)]
    TooLarge {
        /// Its size (bytes).
        size: u64,
        /// The limit (bytes).
        limit: u64,
    },
    /// More bytes than the limit came out of it, whatever its size said.
    #[error("it holds more than the limit of {limit} bytes ({} MiB)", limit >> 20)]
    OverLimit {
        /// The limit (bytes).
        limit: u64,
    },
    /// A scene or a CSV lane that is not UTF-8 text.
    #[error("line {line} is not UTF-8 text")]
    NotText {
        /// The line, from 1.
        line: u64,
    },
}

/// A file a scene read besides itself: a CSV lane or its MIDI take.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputFile {
    /// The scene key that names it (`midi_take` for the take).
    pub key: &'static str,
    /// The file, as read: the scene's folder joined with the path the scene gives.
    pub path: PathBuf,
    /// Whether the file lies outside the scene's folder (an absolute path, `..`, or a link out
    /// of it), for the summary to say so. `false` for a take given to
    /// [`Scene::with_midi_take`], which the user named.
    pub outside_folder: bool,
}

impl InputFile {
    /// `path`, read by the scene in `folder` for `key`.
    fn new(key: &'static str, path: PathBuf, folder: &Path) -> Self {
        // Canonical paths, so that a link counts where it leads; "" is the current folder.
        let folder = if folder.as_os_str().is_empty() {
            Path::new(".")
        } else {
            folder
        };
        let inside = match (path.canonicalize(), folder.canonicalize()) {
            (Ok(file), Ok(folder)) => file.starts_with(folder),
            _ => false,
        };
        Self {
            key,
            path,
            outside_folder: !inside,
        }
    }
}

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
        let bytes =
            read_input_file(path, MAX_TAKE_BYTES).map_err(|source| SceneError::TakeFile {
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

/// A scene file's text, read as a regular file within [`MAX_SCENE_BYTES`], in UTF-8.
fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    read_input_file(path, MAX_SCENE_BYTES)
        .and_then(utf8_text)
        .map_err(|source| SceneError::Read {
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
            let (section, name) = match quantity.scene_key.split_once('.') {
                Some((section, name)) => {
                    let section = table
                        .entry(section)
                        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
                    let section = section.as_table_mut().expect("a section is a table");
                    (section, name)
                }
                None => (&mut table, quantity.scene_key),
            };
            section.insert(name.to_owned(), toml::Value::Float(value));
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

// ---- The file as written: every key optional, nothing unknown. ----

/// The keys a scene has besides the controls' and the constants' (theirs come from their tables).
const SAMPLE_RATE: &str = "sample_rate";
const DURATION: &str = "duration_s";
const SEED: &str = config::SEED.scene_key;
const DETERMINISTIC: &str = "deterministic";
const MIDI_TAKE: &str = "midi_take";
const DRAIN: &str = config::DRAIN.scene_key;
/// The table of the plugin's saved MIDI settings, by their names in the state.
const MIDI_SECTION: &str = "midi";

/// A scene file's TOML, from which each key is taken as it is read: what is left at the end is
/// unknown, and refused.
struct SceneFile {
    table: toml::Table,
    /// Every key read or asked for, for the message that refuses an unknown one.
    known: Vec<String>,
}

impl SceneFile {
    fn parse(text: &str) -> Result<Self, SceneError> {
        let table = toml::from_str(text).map_err(|error| {
            // toml's message shows the line at fault over several lines: their layout is kept.
            let lines: Vec<_> = error
                .to_string()
                .split('\n')
                .map(|line| printable(line).into_owned())
                .collect();
            SceneError::Syntax(lines.join("\n"))
        })?;
        Ok(Self {
            table,
            known: Vec::new(),
        })
    }

    /// Adds each key of `model` that the scene does not set (a model gives nothing but bottle
    /// and liquid keys, so it adds no file, lane or setting). A section the scene writes as
    /// something other than a table is left for validation to refuse.
    fn layer_over(&mut self, model: &ModelFile) {
        for (key, value) in model.keys() {
            let (table, name) = match key.split_once('.') {
                None => (&mut self.table, key.as_str()),
                Some((section, name)) => {
                    let section = self
                        .table
                        .entry(section)
                        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
                    match section.as_table_mut() {
                        Some(table) => (table, name),
                        None => continue,
                    }
                }
            };
            table.entry(name).or_insert_with(|| value.clone());
        }
    }

    /// The value at `key` (`section.name` inside a table), taken out of the file.
    fn take<T: serde::de::DeserializeOwned>(&mut self, key: &str) -> Result<Option<T>, SceneError> {
        self.known.push(key.to_owned());
        let (section, name) = match key.split_once('.') {
            Some((section, name)) => (Some(section), name),
            None => (None, key),
        };
        let table = match section {
            None => &mut self.table,
            Some(section) => match self.table.get_mut(section) {
                None => return Ok(None),
                Some(toml::Value::Table(table)) => table,
                Some(other) => {
                    return Err(syntax(&format!(
                        "`{section}`: invalid type: {}, expected a table",
                        other.type_str()
                    )))
                }
            },
        };
        match table.remove(name) {
            None => Ok(None),
            Some(value) => value
                .try_into()
                .map(Some)
                // toml ends a message without a place in the file with a line break.
                .map_err(|error| syntax(&format!("`{key}`: {}", error.to_string().trim_end()))),
        }
    }

    /// Refuses whatever key is left: none of the scene's.
    fn refuse_unknown(self) -> Result<(), SceneError> {
        // The names known inside `section` (`None`: at the top, sections included).
        let names_in = |section: Option<&str>| {
            let mut names: Vec<&str> = Vec::new();
            for key in &self.known {
                let name = match (key.split_once('.'), section) {
                    (Some((outer, name)), Some(wanted)) if outer == wanted => name,
                    (Some((outer, _)), None) => outer,
                    (None, None) => key.as_str(),
                    _ => continue,
                };
                if !names.contains(&name) {
                    names.push(name);
                }
            }
            names
        };
        let unknown = |name: &str, place: String, known: Vec<&str>| {
            let known: Vec<String> = known.iter().map(|name| format!("`{name}`")).collect();
            syntax(&format!(
                "unknown field `{name}`{place}, expected one of {}",
                known.join(", ")
            ))
        };
        for (name, value) in &self.table {
            let inside = names_in(Some(name));
            if inside.is_empty() {
                if !self.known.contains(name) {
                    return Err(unknown(name, String::new(), names_in(None)));
                }
            } else if let Some(key) = value.as_table().and_then(|table| table.keys().next()) {
                return Err(unknown(key, format!(" in [{name}]"), inside));
            }
        }
        Ok(())
    }

    /// The `[midi]` table, each setting checked: a CC above 127 or a channel above 15 that is
    /// not [`OFF`](sake_glug_device::midi::OFF) is refused rather than silently unmapped.
    fn midi_map(&mut self) -> Result<MidiMap, SceneError> {
        let mut map = MidiMap::default();
        for setting in MidiSetting::all() {
            let key = format!("{MIDI_SECTION}.{}", setting.key());
            let Some(byte) = self.take::<u8>(&key)? else {
                continue;
            };
            if byte > setting.max() && byte != sake_glug_device::midi::OFF {
                return Err(ValueError::OutOfRange {
                    key: setting.key(),
                    value: byte as f64,
                    min: 0.0,
                    max: setting.max() as f64,
                }
                .into());
            }
            map.set_raw(setting, byte);
        }
        Ok(map)
    }

    fn validate(mut self, folder: &Path) -> Result<Scene, SceneError> {
        let sample_rate = match self.take::<f64>(SAMPLE_RATE)? {
            Some(rate) => check_sample_rate(rate)?,
            None => config::SAMPLE_RATE_HZ.default as u32,
        };
        let duration_s = self
            .take::<f64>(DURATION)?
            .map(|seconds| {
                let allowed = Range {
                    min: 1.0 / sample_rate as f64,
                    max: MAX_DURATION_S,
                    default: 0.0,
                };
                check(DURATION, seconds, allowed)
            })
            .transpose()?;
        let mut config = ModelConfig {
            seed: self
                .take::<u64>(SEED)?
                .unwrap_or(ModelConfig::default().seed),
            ..ModelConfig::default()
        };
        let mut lanes = PerControl::from_fn(|_| None);
        let mut inputs = Vec::new();
        for &control in Control::ALL {
            let key = control.quantity().scene_key;
            let spec = self.take::<LaneSpec>(key)?;
            lanes[control] = Some(automation(
                key,
                resolve(key, spec, folder, &mut inputs)?,
                control.range(),
            )?);
        }
        for &constant in Constant::ALL {
            let Quantity {
                scene_key, range, ..
            } = *constant.quantity();
            if let Some(value) = self.take::<f64>(scene_key)? {
                constant.set(&mut config, check(scene_key, value, range)?);
            }
        }
        config.check_silent_below()?;
        for curve in Curve::ALL {
            let key = curve.scene_key();
            if let Some(points) = self.take::<Vec<toml::Value>>(key)? {
                *curve.of_mut(&mut config.curves) = curve
                    .from_points(&curve_points_of(key, &points)?)
                    .map_err(|source| ValueError::Curve { key, source })?;
            }
        }
        config.drain = self.take::<DrainMode>(DRAIN)?.unwrap_or_default();
        if self.take::<bool>(DETERMINISTIC)?.unwrap_or(false) {
            config = config.deterministic();
        }
        let take = match self.take::<PathBuf>(MIDI_TAKE)? {
            None => None,
            Some(name) => {
                let path = folder.join(name);
                let take = MidiTake::load(&path, sample_rate)?;
                inputs.push(InputFile::new(MIDI_TAKE, path, folder));
                Some(take)
            }
        };
        let midi = self.midi_map()?;
        self.refuse_unknown()?;
        Ok(Scene {
            sample_rate,
            duration_s,
            lanes: lanes.into_map(|_, lane| lane.expect("every control was read above")),
            config,
            take,
            midi,
            inputs,
        })
    }
}

/// A lane as the scene wrote it, with a CSV take read into points (relative to `folder`) and
/// its file added to `inputs`.
fn resolve(
    key: &'static str,
    spec: Option<LaneSpec>,
    folder: &Path,
    inputs: &mut Vec<InputFile>,
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
            let axis: Axis = axis.as_deref().unwrap_or("+z").parse().map_err(
                |error: sake_glug_device::axis::AxisParseError| form(&error.to_string()),
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
    let file_error = |source| SceneError::CsvFile {
        key,
        path: path.clone(),
        source,
    };
    let text = read_input_file(&path, MAX_CSV_LANE_BYTES)
        .and_then(utf8_text)
        .map_err(file_error)?;
    let points =
        read_csv_lane(&text, &path, &spec).map_err(|source| SceneError::Csv { key, source })?;
    inputs.push(InputFile::new(key, path, folder));
    Ok(Some(Automation::Points(points)))
}

/// The bytes of the regular file at `path`, refused if larger than `limit` bytes.
fn read_input_file(path: &Path, limit: u64) -> Result<Vec<u8>, InputFileError> {
    let (file, size) = open_regular_file(path, limit)?;
    // A file may hold more than its size says (/proc) or grow while read.
    read_at_most(file, size, limit)
}

/// The regular file at `path`, opened, and its size, refused if over `limit` bytes. What is
/// checked is the opened file, not the path: a path checked and then opened can be replaced in
/// between. Opening never waits: a FIFO opened for reading without O_NONBLOCK waits for a
/// writer, and is refused as soon as it is open.
fn open_regular_file(path: &Path, limit: u64) -> Result<(File, u64), InputFileError> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let metadata = file.metadata()?;
    if !metadata.is_file() {
        return Err(InputFileError::NotAFile(kind(metadata.file_type())));
    }
    match metadata.len() {
        size if size > limit => Err(InputFileError::TooLarge { size, limit }),
        // O_NONBLOCK changes nothing for a regular file.
        size => Ok((file, size)),
    }
}

/// `bytes` as text, or the line (from 1) where they stop being UTF-8.
fn utf8_text(bytes: Vec<u8>) -> Result<String, InputFileError> {
    String::from_utf8(bytes).map_err(|error| {
        let bytes = &error.as_bytes()[..error.utf8_error().valid_up_to()];
        let line = 1 + bytes.iter().filter(|&&byte| byte == b'\n').count() as u64;
        InputFileError::NotText { line }
    })
}

/// Everything `reader` holds (`expected_size` bytes, it says), or an error once more than
/// `limit` bytes came out of it.
fn read_at_most(
    reader: impl Read,
    expected_size: u64,
    limit: u64,
) -> Result<Vec<u8>, InputFileError> {
    let mut bytes = Vec::with_capacity(expected_size.min(limit) as usize);
    reader.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(InputFileError::OverLimit { limit });
    }
    Ok(bytes)
}

/// What a file that is not a regular file is, for a message.
fn kind(file_type: FileType) -> &'static str {
    if file_type.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

/// A path for a message.
fn shown(path: &Path) -> String {
    printable(&path.to_string_lossy()).into_owned()
}

/// A curve's points as a scene writes them ([`curve_points`]).
fn curve_points_of(key: &str, points: &[toml::Value]) -> Result<Vec<(f64, f64)>, SceneError> {
    curve_points(points).ok_or_else(|| {
        syntax(&format!(
            "`{key}`: each point must be a [tilt_deg, value] pair of numbers"
        ))
    })
}

/// A [`SceneError::Syntax`] whose message may quote the scene.
fn syntax(message: &str) -> SceneError {
    SceneError::Syntax(printable(message).into_owned())
}

fn check(key: &'static str, value: f64, range: Range) -> Result<f64, SceneError> {
    Ok(range.check(key, value)?)
}

/// A sample rate in range and a whole number of Hz.
fn check_sample_rate(sample_rate: f64) -> Result<u32, SceneError> {
    let sample_rate = check("sample_rate", sample_rate, config::SAMPLE_RATE_HZ)?;
    if sample_rate.fract() != 0.0 {
        return Err(SceneError::NotWhole {
            key: "sample_rate",
            value: sample_rate,
            what: "a sample rate counts whole samples per second",
        });
    }
    Ok(sample_rate as u32)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_file_is_read_up_to_its_limit() {
        let folder = tempfile::tempdir().unwrap();
        let path = folder.path().join("take.csv");
        std::fs::write(&path, "0123456789").unwrap();
        assert_eq!(read_input_file(&path, 10).unwrap(), b"0123456789");
        assert!(matches!(
            read_input_file(&path, 9),
            Err(InputFileError::TooLarge { size: 10, limit: 9 })
        ));
    }

    #[test]
    fn reading_stops_past_the_limit() {
        let endless = std::io::repeat(b'x');
        assert!(matches!(
            read_at_most(endless, 0, 1000),
            Err(InputFileError::OverLimit { limit: 1000 })
        ));
        assert_eq!(read_at_most(&b"12345"[..], 5, 5).unwrap(), b"12345");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn the_limit_holds_while_reading_a_file_larger_than_its_size_says() {
        // Files of /proc say they hold 0 bytes.
        let status = Path::new("/proc/self/status");
        assert_eq!(std::fs::metadata(status).unwrap().len(), 0);
        assert!(matches!(
            read_input_file(status, 16),
            Err(InputFileError::OverLimit { limit: 16 })
        ));
    }
}
