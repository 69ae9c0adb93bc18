//! The native half of the Python package `sake_glug` (`sake_glug._sake_glug`): the offline
//! renderer of the main crate, scene in, samples out, as `sake-glug render` renders them. The
//! package's `__init__.py` re-exports it; `__init__.pyi` types it.

use std::cell::{Cell, RefCell};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use numpy::PyArray1;
use pyo3::create_exception;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use sake_glug_analysis::{
    analyze_constant_logs, analyze_paired_logs, constant_json, paired_json, PsychometricOptions,
};
use sake_glug_engine::{Preset, PRESETS};
use sake_glug_fit::{fit_json, fit_session, FitSession};
use sake_glug_render::{
    render_scene, render_tables_until, Column, RenderError, RenderObserver, Scene, SceneError,
    StateRate, StateRow, TablesError, UnitRow,
};

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
            let table: toml::Table = pythonize::depythonize(dict.as_any()).map_err(|error| {
                SakeGlugError::new_err(format!("invalid scene: the dict is no TOML table: {error}"))
            })?;
            let text = toml::to_string(&table).map_err(|error| {
                SakeGlugError::new_err(format!("invalid scene: the dict is no TOML table: {error}"))
            })?;
            return Ok(Self::Toml(text));
        }
        if let Ok(text) = scene.cast::<PyString>() {
            let text = text.to_cow()?;
            if text.contains(['\n', '=']) {
                return Ok(Self::Toml(text.into_owned()));
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

    /// The scene, read and validated as the command line reads it (`render_job` of
    /// `sake-glug render`): the preset only without a scene, then the sample rate's override.
    fn load(self, preset: Option<&str>, sample_rate: Option<f64>) -> Result<Scene, Refused> {
        let preset = match preset {
            None => None,
            Some(name) => Some(Preset::find(name).ok_or_else(|| {
                Refused::Message(format!(
                    "no preset `{name}`: choose one of {}",
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
        Ok(match sample_rate {
            Some(sample_rate) => scene.with_sample_rate(sample_rate)?,
            None => scene,
        })
    }
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
    #[error("{0}")]
    Message(String),
    /// Python raised an exception (KeyboardInterrupt) while the render ran: it stopped there.
    #[error(transparent)]
    Signal(PyErr),
}

/// How often a render looks for Ctrl-C (it runs without the GIL, so Python cannot see it).
const SIGNAL_CHECK_EVERY: Duration = Duration::from_millis(20);

/// Stops a render when Python has a signal to raise (KeyboardInterrupt), keeping the exception.
struct PythonSignals {
    last_check: Cell<Instant>,
    raised: RefCell<Option<PyErr>>,
}

impl RenderObserver for PythonSignals {
    fn interrupted(&self) -> bool {
        if self.last_check.get().elapsed() < SIGNAL_CHECK_EVERY {
            return false;
        }
        self.last_check.set(Instant::now());
        if let Err(error) = Python::attach(|py| py.check_signals()) {
            *self.raised.borrow_mut() = Some(error);
            return true;
        }
        false
    }
}

/// Renders a scene and returns its samples (mono, NumPy float32), the samples
/// `sake-glug render` writes to an f32 WAV for the same scene, bit for bit.
///
/// scene: a scene file's path (str or os.PathLike), scene TOML text (a str with a
///     newline or `=` in it), a dict of the same keys (tables as nested dicts), or None
///     for the built-in pour. MODEL.md §10 lists the keys.
/// sample_rate: overrides the scene's sample rate (Hz), as --sample-rate does.
/// preset: renders a preset (see presets()) instead of a scene, as --preset does.
///
/// The sample rate of the result is the scene's (or sample_rate if given). The GIL is
/// released while rendering; Ctrl-C stops it. Raises SakeGlugError with the command
/// line's message for a scene, preset or sample rate it refuses.
#[pyfunction]
#[pyo3(signature = (scene=None, *, sample_rate=None, preset=None))]
fn render<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    sample_rate: Option<f64>,
    preset: Option<&str>,
) -> PyResult<Bound<'py, PyArray1<f32>>> {
    let source = SceneSource::of(scene)?;
    let rendered = py.detach(|| {
        let scene = source.load(preset, sample_rate)?;
        let mut signals = PythonSignals {
            last_check: Cell::new(Instant::now()),
            raised: RefCell::new(None),
        };
        let mut samples = Vec::new();
        let sink = |block: &[f32]| {
            samples.extend_from_slice(block);
            Ok::<(), RenderError>(())
        };
        match render_scene(&scene, sink, &mut signals) {
            Ok(_) => Ok(samples),
            Err(RenderError::Interrupted) => Err(signals
                .raised
                .into_inner()
                .map_or(Refused::Render(RenderError::Interrupted), Refused::Signal)),
            Err(error) => Err(error.into()),
        }
    });
    match rendered {
        Ok(samples) => Ok(PyArray1::from_vec(py, samples)),
        Err(Refused::Signal(error)) => Err(error),
        Err(refused) => Err(SakeGlugError::new_err(refused.to_string())),
    }
}

/// Renders a scene as render() does and returns its samples with its glug data:
/// (samples, units, state), the tables `sake-glug render --units/--state` write, each a dict
/// of float64 NumPy arrays keyed by the files' column names (units: onset_s, tilt_deg, …,
/// audible as 1.0/0.0; state: time_s, tilt_deg, …, one row at the first sample at or after
/// each k/state_rate). MODEL.md §14 says what each column is.
///
/// state_rate: rows a second of the state table (Hz, above 0 and at most the sample rate).
#[pyfunction]
#[pyo3(signature = (scene=None, *, sample_rate=None, preset=None, state_rate=1000.0))]
fn render_tables<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    sample_rate: Option<f64>,
    preset: Option<&str>,
    state_rate: f64,
) -> PyResult<TablesTuple<'py>> {
    let source = SceneSource::of(scene)?;
    let state_rate = StateRate::new(state_rate)
        .map_err(|error| SakeGlugError::new_err(format!("state_rate: {error}")))?;
    let rendered = py.detach(|| {
        let scene = source.load(preset, sample_rate)?;
        let signals = PythonSignals {
            last_check: Cell::new(Instant::now()),
            raised: RefCell::new(None),
        };
        match render_tables_until(&scene, state_rate, || signals.interrupted()) {
            Ok(tables) => Ok(tables),
            Err(TablesError::Render(RenderError::Interrupted)) => Err(signals
                .raised
                .into_inner()
                .map_or(Refused::Render(RenderError::Interrupted), Refused::Signal)),
            Err(error) => Err(error.into()),
        }
    });
    let tables = match rendered {
        Ok(tables) => tables,
        Err(Refused::Signal(error)) => return Err(error),
        Err(refused) => return Err(SakeGlugError::new_err(refused.to_string())),
    };
    Ok((
        PyArray1::from_vec(py, tables.samples),
        columns(py, UnitRow::COLUMNS, &tables.units)?,
        columns(py, StateRow::COLUMNS, &tables.states)?,
    ))
}

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

/// Fits a model to the recordings of a session file (`sake-glug fit`, MODEL.md §13) and returns
/// what `sake-glug fit --json` prints (`sake_glug_fit::fit_json`, the same numbers): {"units":
/// {"detected", "used"}, "explained": {recording: share}, "estimates": {key: {"value", "low",
/// "high", "n", "in_model", "note"}}, "liquids": {name: {...}}, "warnings": [...]}. Nothing is
/// written. Raises SakeGlugError with the command line's message.
#[pyfunction]
fn fit(py: Python<'_>, session: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let fitted = py
        .detach(|| FitSession::load(&session).and_then(|session| fit_session(&session)))
        .map_err(|error| SakeGlugError::new_err(error.to_string()))?;
    Ok(pythonize::pythonize(py, &fit_json(&fitted))?)
}

/// The paired-comparison analysis of trial logs (`sake-glug analyze paired --json`): the
/// count matrix, proportions, Thurstone Case V "scale" by stimulus, predicted proportions,
/// Mosteller's "fit" test and the participants' "agreement" test, as a dict.
#[pyfunction]
fn analyze_paired(py: Python<'_>, logs: Vec<PathBuf>) -> PyResult<Bound<'_, PyAny>> {
    let analysis = py
        .detach(|| analyze_paired_logs(&logs))
        .map_err(|error| SakeGlugError::new_err(error.to_string()))?;
    Ok(pythonize::pythonize(py, &paired_json(&analysis))?)
}

/// The constant-stimuli analysis of trial logs (`sake-glug analyze constant --json`): the
/// logistic fit pooled and per participant, its 25/50/75 % "points" with 95 % intervals
/// ("value", "low", "high"), as a dict. resamples, seed and lapse as the command line's options.
#[pyfunction]
#[pyo3(signature = (logs, *, resamples=None, seed=None, lapse=None))]
fn analyze_constant(
    py: Python<'_>,
    logs: Vec<PathBuf>,
    resamples: Option<usize>,
    seed: Option<u64>,
    lapse: Option<f64>,
) -> PyResult<Bound<'_, PyAny>> {
    let defaults = PsychometricOptions::default();
    let options = PsychometricOptions {
        resamples: resamples.unwrap_or(defaults.resamples),
        seed: seed.unwrap_or(defaults.seed),
        max_lapse: lapse.unwrap_or(defaults.max_lapse),
    };
    let analysis = py
        .detach(|| analyze_constant_logs(&logs, &options))
        .map_err(|error| SakeGlugError::new_err(error.to_string()))?;
    Ok(pythonize::pythonize(py, &constant_json(&analysis))?)
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
    module.add_function(wrap_pyfunction!(render, module)?)?;
    module.add_function(wrap_pyfunction!(render_tables, module)?)?;
    module.add_function(wrap_pyfunction!(fit, module)?)?;
    module.add_function(wrap_pyfunction!(analyze_paired, module)?)?;
    module.add_function(wrap_pyfunction!(analyze_constant, module)?)?;
    module.add_function(wrap_pyfunction!(presets, module)?)?;
    module.add("SakeGlugError", module.py().get_type::<SakeGlugError>())?;
    Ok(())
}
