//! The native half of the Python package `sake_glug` (`sake_glug._sake_glug`): the offline
//! renderer of the main crate, scene in, samples out, as `sake-glug render` renders them, and the
//! fit and the analyses. The package's `__init__.py` re-exports it; `__init__.pyi` types it.
//!
//! No argument may crash the interpreter: a dict scene is read with its depth and cycles checked
//! (scene_dict.rs), what a render holds in memory is checked before it is taken (memory.rs), and
//! every long call can be stopped with Ctrl-C (interrupt.rs).

mod interrupt;
mod memory;
mod scene_dict;

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::create_exception;
use pyo3::exceptions::{PyTypeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyInt, PyString};

use sake_glug_actuator::ActuatorProfile;
use sake_glug_analysis::{
    analyze_constant_logs, analyze_discrimination_logs, analyze_paired_logs, constant_json,
    discrimination_json, paired_json, DryRuns, PsychometricOptions, MAX_RESAMPLES,
};
use sake_glug_engine::{Preset, UnitOnset, Voicing, PRESETS};
use sake_glug_fit::{fit_json, fit_session, FitError, FitSession};
use sake_glug_render::beyond_fit::beyond_fit;
use sake_glug_render::loudness::{
    check_loudness, check_true_peak, LevelError, LevelStage, LevelTarget, Loudness,
};
use sake_glug_render::silence::why_silent;
use sake_glug_render::trim::{check_trim_db, trimmed, DEFAULT_TRIM_DB};
use sake_glug_render::variations::{
    draw_takes, is_measured_column, manifest_row, Cell, Take, TakeOptions, VariationError,
    MAX_TAKES, NAME_COLUMN, OPTION_COLUMNS, SEED_COLUMN, TAKE_COLUMN,
};
use sake_glug_render::{
    render_scene, render_tables_until, Column, RenderError, RenderObserver, Scene, SceneError,
    StateRate, StateRow, TablesError, UnitRow, MAX_SCENE_BYTES,
};

use interrupt::{interruptible, Ticks};
use memory::{Samples, TableSizes};
use scene_dict::shown;

create_exception!(
    _sake_glug,
    SakeGlugError,
    PyValueError,
    "A scene, preset or sample rate that Sake Glug refuses; the message is the one \
     `sake-glug render` prints for it, naming the key, file, line or column."
);

/// Where a scene comes from, as `render`'s first argument says.
enum SceneSource {
    /// The built-in pour, or a preset's.
    BuiltIn,
    File(PathBuf),
    Toml(String),
}

impl SceneSource {
    /// A str holding a newline or `=` is scene text (no scene key is without one); any other
    /// str, or an `os.PathLike`, is a path; a dict is the TOML table it stands for.
    fn of(scene: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let Some(scene) = scene.filter(|scene| !scene.is_none()) else {
            return Ok(Self::BuiltIn);
        };
        if let Ok(dict) = scene.cast::<PyDict>() {
            let table = scene_dict::toml_table(dict).map_err(SakeGlugError::new_err)?;
            let text = toml::to_string(&table).map_err(|error| {
                SakeGlugError::new_err(format!("invalid scene: the dict is no TOML table: {error}"))
            })?;
            return Self::text(text);
        }
        if let Ok(text) = scene.cast::<PyString>() {
            let text = text.to_cow()?;
            if text.contains(['\n', '=']) {
                return Self::text(text.into_owned());
            }
        }
        match scene.extract::<PathBuf>() {
            Ok(path) => Ok(Self::File(path)),
            Err(_) => Err(PyTypeError::new_err(format!(
                "scene must be a path, TOML text, a dict or None, not {}",
                scene.get_type().name()?
            ))),
        }
    }

    /// Scene text, held to the size of the largest scene file read (the parser holds it several
    /// times over).
    fn text(text: String) -> PyResult<Self> {
        let size = text.len() as u64;
        if size > MAX_SCENE_BYTES {
            let too_large = sake_glug_io::ReadFailure::TooLarge {
                size,
                limit: MAX_SCENE_BYTES,
            };
            return Err(SakeGlugError::new_err(format!(
                "invalid scene: the scene text is too long: {too_large}"
            )));
        }
        Ok(Self::Toml(text))
    }

    /// The scene, read and validated as the command line reads it (`render_job` of
    /// `sake-glug render`): the preset only without a scene, then the sample rate's override,
    /// then the actuator's response.
    fn load(
        self,
        preset: Option<&str>,
        sample_rate: Option<f64>,
        actuator: Option<&ActuatorProfile>,
    ) -> Result<Scene, Refused> {
        let preset = match preset {
            None => None,
            Some(name) => Some(Preset::find(name).ok_or_else(|| {
                Refused::Message(format!(
                    "no preset `{}`: choose one of {}",
                    shown(name),
                    Preset::ids()
                ))
            })?),
        };
        let scene = match (self, preset) {
            (Self::BuiltIn, None) => Scene::default(),
            (Self::BuiltIn, Some(preset)) => Scene::parse(&Scene::preset_toml(preset))?,
            (_, Some(_)) => return Err(Refused::Message(NOT_BOTH.into())),
            (Self::File(path), None) => Scene::load(&path)?,
            (Self::Toml(text), None) => Scene::parse(&text)?,
        };
        let mut scene = match sample_rate {
            Some(sample_rate) => scene.with_sample_rate(sample_rate)?,
            None => scene,
        };
        scene.actuator = actuator.map(ActuatorProfile::response);
        Ok(scene)
    }
}

/// The actuator profile of `actuator=` and `felt=`, as `sake-glug render --actuator` and
/// `--felt` read it: a str is a shipped profile's name or else a file's path, an `os.PathLike`
/// a file's path. A refused profile raises SakeGlugError naming the file and the key.
fn actuator_profile(
    actuator: Option<&Bound<'_, PyAny>>,
    felt: bool,
) -> PyResult<Option<ActuatorProfile>> {
    let found = match actuator.filter(|actuator| !actuator.is_none()) {
        None if felt => {
            return Err(SakeGlugError::new_err(
                "felt=True needs an actuator (as --felt needs --actuator): the skin's \
                 sensitivity is equalised on a device's response",
            ))
        }
        None => return Ok(None),
        Some(actuator) => {
            if let Ok(name) = actuator.cast::<PyString>() {
                ActuatorProfile::find(&name.to_cow()?)
            } else if let Ok(path) = actuator.extract::<PathBuf>() {
                ActuatorProfile::load(&path)
            } else {
                return Err(PyTypeError::new_err(format!(
                    "actuator must be a shipped profile's name, a path or None, not {}",
                    actuator.get_type().name()?
                )));
            }
        }
    };
    let profile = found.map_err(|error| SakeGlugError::new_err(format!("actuator: {error}")))?;
    Ok(Some(profile.felt_if(felt)))
}

/// What `render` and `render_tables` change in a scene once it is read, in the command line's
/// order: `seed=` (--seed), `take=` (--take-from, a manifest's row as a dict), `trim=` (--trim).
struct Shaping {
    seed: Option<u64>,
    take: Option<Take>,
    trim_db: Option<f64>,
}

impl Shaping {
    fn of(
        seed: Option<u64>,
        take: Option<&Bound<'_, PyAny>>,
        trim: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(Self {
            seed,
            take: take_of(take)?,
            trim_db: trim_of(trim)?,
        })
    }

    /// A take's row records the options its set was rendered with (MODEL.md §10.2): they are
    /// applied (its trim, and the level returned for `level`), and one given that differs is
    /// refused, as --take-from refuses it. The haptic peak is a haptic clip's, which Python does
    /// not write.
    fn take_options(&mut self, level: LevelTarget) -> PyResult<LevelTarget> {
        let typed = TakeOptions {
            trim_db: self.trim_db,
            loudness_lufs: level.loudness_lufs,
            true_peak_dbtp: level.true_peak_dbtp,
            haptic_peak: None,
        };
        let recorded = self.take.as_ref().and_then(|take| take.recorded);
        let options = TakeOptions::resolve(
            typed,
            recorded.map(|recorded| TakeOptions {
                haptic_peak: None,
                ..recorded
            }),
        )
        .map_err(|error| SakeGlugError::new_err(format!("take: {error}")))?;
        self.trim_db = options.trim_db;
        Ok(LevelTarget {
            loudness_lufs: options.loudness_lufs,
            true_peak_dbtp: options.true_peak_dbtp,
        })
    }

    fn apply(&self, mut scene: Scene) -> Result<Scene, Refused> {
        if let Some(seed) = self.seed {
            scene.config.seed = seed;
        }
        if let Some(take) = &self.take {
            scene = take
                .apply(scene)
                .map_err(|error| Refused::Message(format!("take: {error}")))?;
        }
        trim_scene(scene, self.trim_db)
    }
}

/// `scene` trimmed at `trim_db`, if given.
fn trim_scene(scene: Scene, trim_db: Option<f64>) -> Result<Scene, Refused> {
    Ok(match trim_db {
        Some(level) => trimmed(scene, level)?,
        None => scene,
    })
}

/// `trim=`: None or False for no trim, True for --trim's default level, or a level in dB
/// below 0, as --trim takes it.
fn trim_of(trim: Option<&Bound<'_, PyAny>>) -> PyResult<Option<f64>> {
    let Some(trim) = trim.filter(|trim| !trim.is_none()) else {
        return Ok(None);
    };
    // A bool is an int to Python: it is read first.
    if let Ok(on) = trim.cast::<pyo3::types::PyBool>() {
        return Ok(on.is_true().then_some(DEFAULT_TRIM_DB));
    }
    let level: f64 = trim.extract().map_err(|_| {
        PyTypeError::new_err("trim must be None, a bool or a level in dB (a float below 0)")
    })?;
    check_trim_db(level)
        .map(Some)
        .map_err(|error| SakeGlugError::new_err(format!("trim: {error}")))
}

/// `take=`: a row of a set's manifest as a dict (a row of `render_variations`, or of
/// NAME.variations.json), read as --take-from reads one.
fn take_of(take: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Take>> {
    let Some(take) = take.filter(|take| !take.is_none()) else {
        return Ok(None);
    };
    let row = take.cast::<PyDict>().map_err(|_| {
        PyTypeError::new_err("take must be a dict (a row of a set's manifest) or None")
    })?;
    let mut number = 1;
    let mut fields = Vec::new();
    for (key, value) in row.iter() {
        let key: String = key
            .extract()
            .map_err(|_| PyTypeError::new_err("take: its keys are str"))?;
        let text = match key.as_str() {
            NAME_COLUMN => continue,
            // What the take measured (its loudness), not what it drew.
            column if is_measured_column(column) => continue,
            TAKE_COLUMN => {
                number = value.extract::<u32>().map_err(|_| {
                    SakeGlugError::new_err("take: `take` is the take's number, an int from 1")
                })?;
                continue;
            }
            // An option the set was rendered without.
            column
                if value.is_none() && OPTION_COLUMNS.iter().any(|(name, ..)| *name == column) =>
            {
                String::new()
            }
            SEED_COLUMN => value
                .extract::<u64>()
                .map_err(|_| {
                    SakeGlugError::new_err(format!(
                        "take: `seed` is a whole number from 0 to {}",
                        u64::MAX
                    ))
                })?
                .to_string(),
            _ => value
                .extract::<f64>()
                .map_err(|_| {
                    SakeGlugError::new_err(format!("take: `{}` is no number", shown(&key)))
                })?
                .to_string(),
        };
        fields.push((key, text));
    }
    Take::from_fields(
        number,
        fields
            .iter()
            .map(|(key, text)| (key.as_str(), text.as_str())),
    )
    .map(Some)
    .map_err(|error| SakeGlugError::new_err(format!("take: {error}")))
}

/// `loudness=` and `true_peak=`: the level the samples are brought to, checked as
/// --loudness and --true-peak check theirs (the same ranges, the same sentence).
fn level_target(loudness: Option<f64>, true_peak: Option<f64>) -> PyResult<LevelTarget> {
    fn refused(name: &'static str) -> impl Fn(String) -> PyErr {
        move |message| SakeGlugError::new_err(format!("{name}: {message}"))
    }
    Ok(LevelTarget {
        loudness_lufs: loudness
            .map(check_loudness)
            .transpose()
            .map_err(refused("loudness"))?,
        true_peak_dbtp: true_peak
            .map(check_true_peak)
            .transpose()
            .map_err(refused("true_peak"))?,
    })
}

/// Warns of a render (silent, or a fitted model played beyond its recordings), with the command
/// line's sentence.
fn warn_user(py: Python<'_>, reason: &str) -> PyResult<()> {
    let message = std::ffi::CString::new(reason.replace('\0', " ")).expect("no NUL is left");
    PyErr::warn(py, &py.get_type::<PyUserWarning>(), &message, 1)
}

/// A scene and a preset given together (`sake-glug render` refuses `--preset` with a scene).
const NOT_BOTH: &str =
    "give a scene or a preset, not both: a preset is the default pour with its liquid and bottle";

/// Why a render gave no samples.
#[derive(Debug, thiserror::Error)]
enum Refused {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error(transparent)]
    Tables(#[from] TablesError),
    #[error(transparent)]
    Variation(#[from] VariationError),
    #[error(transparent)]
    Level(#[from] LevelError),
    #[error("{0}")]
    Message(String),
    /// Python raised an exception while the render ran (KeyboardInterrupt, or the progress
    /// callback's own): it stopped there.
    #[error(transparent)]
    Raised(PyErr),
}

impl Refused {
    /// A render stopped by `ticks` ends with what Python raised there.
    fn stopped_by(self, ticks: Ticks) -> Self {
        match self {
            Self::Render(RenderError::Interrupted)
            | Self::Tables(TablesError::Render(RenderError::Interrupted)) => {
                ticks.raised().map_or(self, Self::Raised)
            }
            other => other,
        }
    }

    fn into_py(self) -> PyErr {
        match self {
            Self::Raised(error) => error,
            refused => SakeGlugError::new_err(refused.to_string()),
        }
    }
}

/// Renders a scene and returns its samples (mono, NumPy float32), the samples
/// `sake-glug render` writes to an f32 WAV for the same scene, bit for bit.
///
/// scene: a scene file's path (str or os.PathLike), scene TOML text (a str with a
///     newline or `=` in it), a dict of the same keys (tables as nested dicts, nested at
///     most 32 deep, values bool, int, float, str, list or tuple), or None for the built-in
///     pour. MODEL.md §10 lists the keys. An empty scene ({}, or text of comments alone) is
///     every key's default, an upright bottle that never pours: 0 samples, as
///     `sake-glug render` renders an empty scene file (with a UserWarning); None is the
///     built-in pour, 90° to 135° in 0.5 s.
/// sample_rate: overrides the scene's sample rate (Hz), as --sample-rate does.
/// preset: renders a preset (see presets()) instead of a scene, as --preset does.
/// progress: called as progress(done, total) about every 20 ms while rendering, with the
///     samples rendered and the render's length (None for a scene without duration_s, whose
///     end is known only when it comes); what it raises stops the render and is raised.
/// actuator: compensates every unit for a device (MODEL.md §18), as --actuator does: a
///     shipped profile's name (flat, haptuator-mark2, lra, phone, dualsense, vr-controller)
///     or a profile file's path (str or os.PathLike); a str names a shipped profile first.
/// felt: with actuator, equalises over the skin's threshold instead of the acceleration, as
///     --felt does.
/// seed: overrides the scene's seed, as --seed does.
/// take: renders one take of a set again, bit for bit, as --take-from does: its row of the
///     set's manifest as a dict (a row of render_variations(), or of NAME.variations.json),
///     with the set's trim, loudness and true peak the row records (one given that differs is
///     refused).
/// trim: ends the samples once the last glug has decayed below a level re their peak, with a
///     10 ms fade, as --trim does: True for -60 dB, or a level in dB below 0.
/// loudness: brings the samples to this integrated loudness (LUFS, -70 to 0; ITU-R BS.1770-4
///     gated as EBU R128), as --loudness does: one gain for the whole render, found on a first
///     pass (after the trim). A render shorter than 0.4 s, or silent, is refused.
/// true_peak: keeps the true peak (dBTP, -60 to 0, 4x oversampled) at or under this ceiling,
///     as --true-peak does; with loudness, the ceiling wins (MODEL.md §19).
///
/// A render in which nothing sounds warns (UserWarning) with the command line's reason (the
/// bottle never tilts past where it pours, the bottle is empty, …).
///
/// The sample rate of the result is the scene's (or sample_rate if given). The GIL is
/// released while rendering; Ctrl-C stops it. The samples are held in memory: a render
/// that cannot fit (a day at 48 kHz is 16.6 GB) is refused before it starts, or for a scene
/// without duration_s as soon as it outgrows the memory available, with the figure. Raises
/// SakeGlugError with the command line's message for a scene, preset or sample rate it
/// refuses.
#[pyfunction]
#[pyo3(signature = (
    scene=None, *, sample_rate=None, preset=None, progress=None, actuator=None, felt=false,
    seed=None, take=None, trim=None, loudness=None, true_peak=None
))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    sample_rate: Option<f64>,
    preset: Option<&str>,
    progress: Option<&Bound<'py, PyAny>>,
    actuator: Option<&Bound<'py, PyAny>>,
    felt: bool,
    seed: Option<u64>,
    take: Option<&Bound<'py, PyAny>>,
    trim: Option<&Bound<'py, PyAny>>,
    loudness: Option<f64>,
    true_peak: Option<f64>,
) -> PyResult<Bound<'py, PyArray1<f32>>> {
    let source = SceneSource::of(scene)?;
    let progress = callback("progress", progress)?;
    let actuator = actuator_profile(actuator, felt)?;
    let mut shaping = Shaping::of(seed, take, trim)?;
    let level = shaping.take_options(level_target(loudness, true_peak)?)?;
    let rendered = py.detach(|| {
        let scene = shaping.apply(source.load(preset, sample_rate, actuator.as_ref())?)?;
        let total = scene.duration_samples();
        let mut ticks = Ticks::new(progress, total);
        let rendered = render_levelled(&scene, &level, false, &mut ticks);
        rendered
            .map(|in_memory| (in_memory.samples, in_memory.warnings))
            .map_err(|refused| refused.stopped_by(ticks))
    });
    let (samples, warnings) = rendered.map_err(Refused::into_py)?;
    for reason in warnings {
        warn_user(py, &reason)?;
    }
    Ok(PyArray1::from_vec(py, samples))
}

/// Renders a set of takes of a scene, as `sake-glug render --variations COUNT` does, and returns
/// [(row, samples)] in the order of the takes: row is the take's row of the set's manifest
/// ({"take": k, "seed": …, and each value drawn, by its key}), samples those of
/// `sake-glug render` of take k, bit for bit; render(scene, take=row) renders it again.
///
/// count: takes in the set (1 to 9999); default: the count of the scene's [variations]
///     table, which gives the ranges drawn from (MODEL.md §10.2).
/// seed: the master seed (default: the scene's seed), as --seed with --variations.
/// trim, sample_rate, preset, actuator, felt, loudness, true_peak: as render()'s, for every
///     take (each take brought to the level on its own, as the command line's files are).
///
/// Each row records the set's options (trim_db, loudness_target_lufs, true_peak_ceiling_dbtp,
/// haptic_peak; None where not given), which render(scene, take=row) applies, and ends with the
/// take's loudness_lufs and true_peak_dbtp, measured on its samples as returned, as the
/// manifest's last columns are; render(scene, take=row) ignores those.
#[pyfunction]
#[pyo3(signature = (
    scene=None, *, count=None, seed=None, sample_rate=None, preset=None, trim=None,
    actuator=None, felt=false, loudness=None, true_peak=None
))]
#[allow(clippy::too_many_arguments)]
fn render_variations<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    count: Option<u32>,
    seed: Option<u64>,
    sample_rate: Option<f64>,
    preset: Option<&str>,
    trim: Option<&Bound<'py, PyAny>>,
    actuator: Option<&Bound<'py, PyAny>>,
    felt: bool,
    loudness: Option<f64>,
    true_peak: Option<f64>,
) -> PyResult<TakeRows<'py>> {
    let source = SceneSource::of(scene)?;
    let actuator = actuator_profile(actuator, felt)?;
    let trim_db = trim_of(trim)?;
    let level = level_target(loudness, true_peak)?;
    // What the command line's manifest records of the same call.
    let options = TakeOptions {
        trim_db,
        loudness_lufs: level.loudness_lufs,
        true_peak_dbtp: level.true_peak_dbtp,
        haptic_peak: None,
    };
    if let Some(count) = count.filter(|count| !(1..=MAX_TAKES).contains(count)) {
        return Err(SakeGlugError::new_err(format!(
            "count = {count}: a set has 1 to {MAX_TAKES} takes"
        )));
    }
    let rendered = py.detach(|| {
        let mut scene = source.load(preset, sample_rate, actuator.as_ref())?;
        if let Some(seed) = seed {
            scene.config.seed = seed;
        }
        let spec = scene.variations.clone();
        let count = count.or_else(|| spec.as_ref()?.count).ok_or_else(|| {
            Refused::Message(
                "how many takes? give count=, or a count in the scene's [variations] table".into(),
            )
        })?;
        let ranges = spec.map_or(Vec::new(), |spec| spec.ranges);
        let takes = draw_takes(&ranges, count, scene.config.seed);
        let scenes = takes
            .iter()
            .map(|take| take.apply(scene.clone()))
            .collect::<Result<Vec<_>, _>>()?;
        let mut rendered = Vec::with_capacity(takes.len());
        for (take, take_scene) in takes.into_iter().zip(scenes) {
            let take_scene = trim_scene(take_scene, trim_db)?;
            let mut ticks = Ticks::new(None, take_scene.duration_samples());
            let in_memory = match render_levelled(&take_scene, &level, true, &mut ticks) {
                Ok(in_memory) => in_memory,
                Err(refused) => return Err(refused.stopped_by(ticks)),
            };
            rendered.push((take, in_memory));
        }
        Ok((rendered, count))
    });
    let (rendered, count) = rendered.map_err(Refused::into_py)?;
    let mut set = Vec::with_capacity(rendered.len());
    for (
        take,
        InMemory {
            samples,
            warnings,
            measured,
        },
    ) in rendered
    {
        for reason in warnings {
            warn_user(py, &format!("take {}: {reason}", take.number))?;
        }
        let measured = measured.expect("render_levelled measures every take");
        // The manifest's row, but for the file name a set of samples has not.
        let row = PyDict::new(py);
        for (column, cell) in manifest_row(&take, "", count, &options, &measured) {
            match cell {
                _ if column == NAME_COLUMN => {}
                Cell::Empty => row.set_item(column, py.None())?,
                Cell::Whole(value) => row.set_item(column, value)?,
                Cell::Number(value) => row.set_item(column, value)?,
                Cell::Text(text) => row.set_item(column, text)?,
            }
        }
        set.push((row, PyArray1::from_vec(py, samples)));
    }
    Ok(set)
}

/// Renders `scene` into memory through the level stage of `level` (the command line's
/// [`LevelStage`]: a first pass finds the gain, the samples are written at it): its samples,
/// why it is silent if it is, and with `measure` their loudness and true peak as returned.
fn render_levelled(
    scene: &Scene,
    level: &LevelTarget,
    measure: bool,
    ticks: &mut Ticks,
) -> Result<InMemory, Refused> {
    let total = scene.duration_samples();
    let mut samples = match total {
        Some(total) => Samples::with_room(total, scene.sample_rate),
        None => Ok(Samples::growing(scene.sample_rate)),
    }
    .map_err(Refused::Message)?;
    let mut stage = LevelStage::new::<Refused>(scene, level, measure, &[], &*ticks)?;
    let sink = |block: &[f32]| samples.push(stage.apply(block)).map_err(Refused::Message);
    let summary = render_scene(scene, sink, ticks)?;
    let measured = stage.finish().filter(|_| measure).map(|level| level.after);
    Ok(InMemory {
        samples: samples.into_vec(),
        warnings: why_silent(scene, &summary)
            .into_iter()
            .chain(beyond_fit(scene, &summary))
            .collect(),
        measured,
    })
}

/// A render held in memory: its samples, its warnings (why it is silent if it is, a fitted model
/// played beyond its recordings), what they measure if asked.
struct InMemory {
    samples: Vec<f32>,
    warnings: Vec<String>,
    measured: Option<Loudness>,
}

/// `value` if it is None or callable, for `name`.
fn callback(name: &str, value: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Py<PyAny>>> {
    match value.filter(|value| !value.is_none()) {
        None => Ok(None),
        Some(value) if value.is_callable() => Ok(Some(value.clone().unbind())),
        Some(value) => Err(PyTypeError::new_err(format!(
            "{name} must be callable or None, not {}",
            value.get_type().name()?
        ))),
    }
}

/// Counts the units of a render that keeps nothing, for the tables it would make.
struct CountingUnits {
    ticks: Ticks,
    units: u64,
}

impl RenderObserver for CountingUnits {
    fn progress(&mut self, rendered: u64) {
        self.ticks.progress(rendered)
    }

    fn unit_started(&mut self, _onset: &UnitOnset, _voicing: Voicing) {
        self.units += 1;
    }

    fn interrupted(&self) -> bool {
        self.ticks.stop()
    }
}

/// Renders a scene as render() does and returns its samples with its glug data:
/// (samples, units, state), the tables `sake-glug render --units/--state` write, each a dict
/// of float64 NumPy arrays keyed by the files' column names (units: onset_s, tilt_deg, …,
/// audible as 1.0/0.0; state: time_s, tilt_deg, …, one row at the first sample at or after
/// each k/state_rate). MODEL.md §14 says what each column is.
///
/// state_rate: rows a second of the state table (Hz, above 0 and at most the sample rate).
/// actuator, felt: as render()'s; the tables are then those `sake-glug render --actuator` writes.
/// seed, take, trim: as render()'s.
///
/// The scene renders twice: once keeping nothing, to count what the tables will hold and
/// refuse them with the figure if they cannot fit in memory, then into the tables.
#[pyfunction]
#[pyo3(signature = (
    scene=None, *, sample_rate=None, preset=None, state_rate=1000.0, actuator=None, felt=false,
    seed=None, take=None, trim=None
))]
#[allow(clippy::too_many_arguments)]
fn render_tables<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    sample_rate: Option<f64>,
    preset: Option<&str>,
    state_rate: f64,
    actuator: Option<&Bound<'py, PyAny>>,
    felt: bool,
    seed: Option<u64>,
    take: Option<&Bound<'py, PyAny>>,
    trim: Option<&Bound<'py, PyAny>>,
) -> PyResult<TablesTuple<'py>> {
    let source = SceneSource::of(scene)?;
    let state_rate = StateRate::new(state_rate)
        .map_err(|error| SakeGlugError::new_err(format!("state_rate: {error}")))?;
    let actuator = actuator_profile(actuator, felt)?;
    let mut shaping = Shaping::of(seed, take, trim)?;
    // A take's row gives its set's trim; the tables' samples are never levelled.
    shaping.take_options(LevelTarget::default())?;
    let rendered = py.detach(|| {
        let scene = shaping.apply(source.load(preset, sample_rate, actuator.as_ref())?)?;
        // A bound: row k is at sample ⌈k·fs/R⌉, before the end.
        let state_rows =
            |samples: u64| (samples as f64 * state_rate.hz() / scene.sample_rate as f64) as u64 + 2;
        let fits = |samples: u64, units: Option<u64>| {
            let sizes = TableSizes {
                samples,
                units,
                state_rows: state_rows(samples),
            };
            sizes
                .check(
                    std::mem::size_of::<UnitRow>() as u64,
                    std::mem::size_of::<(u64, StateRow)>() as u64,
                    [
                        UnitRow::COLUMNS.len() as u64,
                        StateRow::COLUMNS.len() as u64,
                    ],
                )
                .map_err(Refused::Message)
        };
        // The state rate against the scene's sample rate, refused before a whole pass: the
        // tables' render checks it first and stops after its first block.
        match render_tables_until(&scene, state_rate, || true) {
            Err(TablesError::Render(RenderError::Interrupted)) => {}
            Err(error) => return Err(error.into()),
            Ok(_) => {}
        }
        // What a duration tells before anything renders: a day at 48 kHz is refused at once.
        if let Some(samples) = scene.duration_samples() {
            fits(samples, None)?;
        }
        let mut counting = CountingUnits {
            ticks: Ticks::new(None, None),
            units: 0,
        };
        let discard = |_: &[f32]| Ok::<(), Refused>(());
        let summary = match render_scene(&scene, discard, &mut counting) {
            Ok(summary) => summary,
            Err(refused) => return Err(refused.stopped_by(counting.ticks)),
        };
        fits(summary.samples, Some(counting.units))?;
        let ticks = Ticks::new(None, None);
        match render_tables_until(&scene, state_rate, || ticks.stop()) {
            Ok(tables) => Ok(tables),
            Err(error) => Err(Refused::from(error).stopped_by(ticks)),
        }
    });
    let mut tables = rendered.map_err(Refused::into_py)?;
    tables.samples.shrink_to_fit();
    Ok((
        PyArray1::from_vec(py, tables.samples),
        columns(py, UnitRow::COLUMNS, &tables.units)?,
        columns(py, StateRow::COLUMNS, &tables.states)?,
    ))
}

/// A set's takes: each one's row of the manifest and its samples.
type TakeRows<'py> = Vec<(Bound<'py, PyDict>, Bound<'py, PyArray1<f32>>)>;

/// (samples, units, state), as `__init__.py` makes its `Tables` of them.
type TablesTuple<'py> = (
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyDict>,
    Bound<'py, PyDict>,
);

/// A table as a dict of one NumPy array per column, named as the table's file names them.
fn columns<'py, R>(
    py: Python<'py>,
    columns: &[Column<R>],
    rows: &[R],
) -> PyResult<Bound<'py, PyDict>> {
    let table = PyDict::new(py);
    for column in columns {
        let values: Vec<f64> = rows.iter().map(column.value).collect();
        table.set_item(column.name, PyArray1::from_vec(py, values))?;
    }
    Ok(table)
}

/// Fits a model (`sake-glug fit`, MODEL.md §13) to a session file, or to WAV clips of one bottle
/// as the command line takes them (`fit("glugs.wav")`, or a list of clips, with `capacity_ml`
/// and `tilt_deg` as its --capacity-ml and --tilt-deg), and returns what `sake-glug fit --json`
/// prints (`sake_glug_fit::fit_json`, the same numbers): {"units": {"detected", "used"},
/// "explained": {recording: share}, "estimates": {key: {"value", "low", "high", "n",
/// "in_model", "note"}}, "liquids": {name: {...}}, "warnings": [...]}. Nothing is written.
/// Raises SakeGlugError with the command line's message (a clip option named as the argument
/// is). Ctrl-C returns at once; the fit, which cannot be stopped, runs on in the background and
/// its result is dropped.
#[pyfunction]
#[pyo3(signature = (inputs, *, capacity_ml=None, tilt_deg=None))]
fn fit<'py>(
    py: Python<'py>,
    inputs: &Bound<'py, PyAny>,
    capacity_ml: Option<f64>,
    tilt_deg: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    // One path (str or os.PathLike), or a list of them; a str is never read as a list of letters.
    let inputs: Vec<PathBuf> = match inputs.extract::<PathBuf>() {
        Ok(path) => vec![path],
        Err(_) => inputs.extract().map_err(|_| {
            PyTypeError::new_err(
                "fit() takes a session file or a WAV clip (str or os.PathLike), or a list of clips",
            )
        })?,
    };
    let fitted = interruptible(py, move || {
        FitSession::from_inputs(&inputs, capacity_ml, tilt_deg)
            .and_then(|session| fit_session(&session))
    })?
    .map_err(|error| match error {
        FitError::ClipOption { key, value, why } => {
            SakeGlugError::new_err(format!("{key}={value}: {why}"))
        }
        error => SakeGlugError::new_err(error.to_string()),
    })?;
    Ok(pythonize::pythonize(py, &fit_json(&fitted))?)
}

/// The paired-comparison analysis of trial logs (`sake-glug analyze paired --json`): the
/// count matrix, proportions, Thurstone Case V "scale" by stimulus, predicted proportions,
/// Mosteller's "fit" test and the participants' "agreement" test, as a dict. Ctrl-C returns at
/// once (the analysis runs on in the background, its result dropped).
#[pyfunction]
#[pyo3(signature = (logs, *, dry_run_logs=false))]
fn analyze_paired(
    py: Python<'_>,
    logs: Vec<PathBuf>,
    dry_run_logs: bool,
) -> PyResult<Bound<'_, PyAny>> {
    let dry_runs = dry_runs(dry_run_logs);
    let analysis = interruptible(py, move || analyze_paired_logs(&logs, dry_runs))?
        .map_err(|error| SakeGlugError::new_err(error.to_string()))?;
    Ok(pythonize::pythonize(py, &paired_json(&analysis))?)
}

/// The constant-stimuli analysis of trial logs (`sake-glug analyze constant --json`): the
/// logistic fit pooled and per participant, its 25/50/75 % "points" with 95 % intervals
/// ("value", "low", "high"; None beyond the levels tested, "placement" says where), as a dict.
/// resamples (1 to 100,000), seed and lapse as the command
/// line's options. Ctrl-C returns at once (the analysis runs on in the background, its result
/// dropped).
#[pyfunction]
#[pyo3(signature = (logs, *, resamples=None, seed=None, lapse=None, dry_run_logs=false))]
fn analyze_constant<'py>(
    py: Python<'py>,
    logs: Vec<PathBuf>,
    resamples: Option<&Bound<'py, PyInt>>,
    seed: Option<u64>,
    lapse: Option<f64>,
    dry_run_logs: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let dry_runs = dry_runs(dry_run_logs);
    let defaults = PsychometricOptions::default();
    let resamples = match resamples {
        None => defaults.resamples,
        // Past what a usize holds (the analysis refuses the rest with the same words).
        Some(count) => count.extract::<usize>().map_err(|_| {
            SakeGlugError::new_err(format!(
                "{} resamples: from 1 to {MAX_RESAMPLES} are drawn",
                shown(&count.to_string())
            ))
        })?,
    };
    let options = PsychometricOptions {
        resamples,
        seed: seed.unwrap_or(defaults.seed),
        max_lapse: lapse.unwrap_or(defaults.max_lapse),
    };
    let analysis = interruptible(py, move || analyze_constant_logs(&logs, &options, dry_runs))?
        .map_err(|error| SakeGlugError::new_err(error.to_string()))?;
    Ok(pythonize::pythonize(py, &constant_json(&analysis))?)
}

/// The discrimination analysis of trial logs (`sake-glug analyze discrimination --json`):
/// triangle, 2AFC or ABX; the proportion correct with its exact interval, the one-sided test
/// against chance, d′ under the design's decision model with its profile-likelihood interval
/// (None where infinite or empty) and the plain "sentence", pooled and per participant, as a
/// dict. Ctrl-C returns at once.
#[pyfunction]
#[pyo3(signature = (logs, *, dry_run_logs=false))]
fn analyze_discrimination(
    py: Python<'_>,
    logs: Vec<PathBuf>,
    dry_run_logs: bool,
) -> PyResult<Bound<'_, PyAny>> {
    let dry_runs = dry_runs(dry_run_logs);
    let analysis = interruptible(py, move || analyze_discrimination_logs(&logs, dry_runs))?
        .map_err(|error| SakeGlugError::new_err(error.to_string()))?;
    Ok(pythonize::pythonize(py, &discrimination_json(&analysis))?)
}

/// `dry_run_logs=`: whether an analysis reads a dry run's trials (`--dry-run-logs`); they are
/// refused by default, and counted in the result's "dry_run_trials".
fn dry_runs(read: bool) -> DryRuns {
    match read {
        true => DryRuns::Read,
        false => DryRuns::Refused,
    }
}

/// Every preset as (id, name, description, scene): the id that render(preset=...) and
/// `sake-glug render --preset` take, the name the plugin's menu shows, what it is for,
/// and its scene file (TOML), in menu order.
#[pyfunction]
fn presets() -> Vec<(&'static str, &'static str, &'static str, String)> {
    PRESETS
        .iter()
        .map(|preset| {
            (
                preset.id,
                preset.name,
                preset.description,
                Scene::preset_toml(preset),
            )
        })
        .collect()
}

#[pymodule]
fn _sake_glug(module: &Bound<'_, PyModule>) -> PyResult<()> {
    // rust-numpy fetches NumPy's API on first use, running Python (an import): done here, so that
    // a Ctrl-C pending as a render returns is raised as KeyboardInterrupt, not met by that
    // import and turned into a panic.
    PyArray1::<f32>::zeros(module.py(), 0, false);
    module.add_function(wrap_pyfunction!(render, module)?)?;
    module.add_function(wrap_pyfunction!(render_tables, module)?)?;
    module.add_function(wrap_pyfunction!(render_variations, module)?)?;
    module.add_function(wrap_pyfunction!(fit, module)?)?;
    module.add_function(wrap_pyfunction!(analyze_paired, module)?)?;
    module.add_function(wrap_pyfunction!(analyze_constant, module)?)?;
    module.add_function(wrap_pyfunction!(analyze_discrimination, module)?)?;
    module.add_function(wrap_pyfunction!(presets, module)?)?;
    module.add("SakeGlugError", module.py().get_type::<SakeGlugError>())?;
    // The workspace's version, which every product reports.
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
