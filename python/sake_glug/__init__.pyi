import os
from typing import Any, Callable, Dict, List, Mapping, NamedTuple, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__all__ = [
    "Preset",
    "SakeGlugError",
    "Tables",
    "__version__",
    "analyze_constant",
    "analyze_discrimination",
    "analyze_paired",
    "fit",
    "presets",
    "render",
    "render_tables",
    "render_variations",
]

_Scene = Union[str, "os.PathLike[str]", Mapping[str, Any], None]
_Actuator = Union[str, "os.PathLike[str]", None]

__version__: str
"""The release's version, the one ``sake-glug --version`` prints."""

class SakeGlugError(ValueError):
    """A scene, preset or sample rate that Sake Glug refuses, with the command line's message."""

class Preset(NamedTuple):
    """A starting point of the plugin's preset menu."""

    id: str
    name: str
    description: str
    scene: str

def render(
    scene: _Scene = None,
    *,
    sample_rate: Optional[float] = None,
    preset: Optional[str] = None,
    progress: Optional[Callable[[int, Optional[int]], object]] = None,
    actuator: _Actuator = None,
    felt: bool = False,
    seed: Optional[int] = None,
    take: Optional[Mapping[str, Union[int, float, str]]] = None,
    trim: Union[bool, float, None] = None,
    loudness: Optional[float] = None,
    true_peak: Optional[float] = None,
) -> npt.NDArray[np.float32]:
    """Renders a scene and returns its samples (mono, float32), bit for bit those of
    `sake-glug render` of the same scene.

    scene: a scene file's path, scene TOML text (a str with a newline or `=`), a dict of the
    same keys (nested at most 32 deep; values bool, int, float, str, list, tuple or dict; one
    that contains itself is refused), or None for the built-in pour (90° to 135° in 0.5 s).
    An empty scene ({}) is every key's default, an upright bottle that never pours: 0 samples,
    as `sake-glug render` renders an empty scene file, with a UserWarning. sample_rate
    overrides the scene's (Hz); preset renders a preset instead of a scene. progress is called
    as progress(done, total) about every 20 ms with the samples rendered and the render's
    length (None without duration_s); what it raises stops the render and is raised.
    actuator compensates every unit for a device (MODEL.md §18) as --actuator does: a shipped
    profile's name (flat, haptuator-mark2, lra, phone, dualsense, vr-controller; a str names a
    shipped one first) or a profile file's path; felt (with actuator) equalises over the
    skin's threshold instead, as --felt does. A refused profile raises SakeGlugError naming
    the file and the key. seed overrides the scene's seed (--seed); take renders one take of a
    set again, bit for bit, from its row of the set's manifest (a row of render_variations(),
    or of NAME.variations.json), as --take-from does, with the set's trim and level options
    the row records (one given that differs raises SakeGlugError); trim ends the samples once the last glug
    has decayed below a level re their peak, with a 10 ms fade (--trim): True for -60 dB, or a
    level in dB below 0. loudness brings the samples to an integrated loudness (LUFS, -70 to
    0; BS.1770-4 gated as EBU R128) and true_peak keeps their true peak (dBTP, -60 to 0, 4x
    oversampled) under a ceiling, as --loudness and --true-peak do (the ceiling wins; a render
    under 0.4 s or silent is refused with the command line's message; MODEL.md §19). A render
    in which nothing sounds warns (UserWarning) with the command line's reason.

    The samples are held in memory: a render that cannot fit (a day at 48 kHz is 16.6 GB) is
    refused before it starts, or, without duration_s, as soon as it outgrows the memory
    available, with the figure. Ctrl-C stops it. Raises SakeGlugError for what it refuses."""

def render_variations(
    scene: _Scene = None,
    *,
    count: Optional[int] = None,
    seed: Optional[int] = None,
    sample_rate: Optional[float] = None,
    preset: Optional[str] = None,
    trim: Union[bool, float, None] = None,
    actuator: _Actuator = None,
    felt: bool = False,
    loudness: Optional[float] = None,
    true_peak: Optional[float] = None,
) -> List[Tuple[Dict[str, Union[int, float]], npt.NDArray[np.float32]]]:
    """Renders a set of takes of a scene, as `sake-glug render --variations COUNT` does, and
    returns [(row, samples)] in take order: row is the take's row of the set's manifest
    ({"take": k, "seed": ..., each drawn value by its key, the set's options trim_db,
    loudness_target_lufs, true_peak_ceiling_dbtp and haptic_peak (None where not given), then
    loudness_lufs and true_peak_dbtp, measured on the samples returned}), samples those of the
    command line's take k, bit for bit; render(scene, take=row) renders it again with the
    set's options (the measured columns are ignored). count defaults to the scene's [variations] count; seed is the master seed
    (default: the scene's seed); the other arguments are render()'s, for every take (loudness
    and true_peak level each take on its own)."""

def presets() -> List[Preset]:
    """Every preset, in the order of the plugin's menu."""

class Tables(NamedTuple):
    """A render's samples and its glug data (MODEL.md §14)."""

    samples: npt.NDArray[np.float32]
    units: Dict[str, npt.NDArray[np.float64]]
    state: Dict[str, npt.NDArray[np.float64]]

def render_tables(
    scene: _Scene = None,
    *,
    sample_rate: Optional[float] = None,
    preset: Optional[str] = None,
    state_rate: float = 1000.0,
    actuator: _Actuator = None,
    felt: bool = False,
    seed: Optional[int] = None,
    take: Optional[Mapping[str, Union[int, float, str]]] = None,
    trim: Union[bool, float, None] = None,
) -> Tables:
    """Renders a scene as render() does and returns its samples with its units and state
    tables (a float64 array per column, named as the columns of `sake-glug render --units` and
    `--state`); actuator, felt, seed, take and trim as render()'s. The scene renders twice: once keeping nothing, to count the tables' rows and
    refuse them with the figure if they cannot fit in memory, then into the tables. Ctrl-C
    stops it. Raises SakeGlugError for what it refuses."""

def fit(
    inputs: Union[str, "os.PathLike[str]", List[Union[str, "os.PathLike[str]"]]],
    *,
    capacity_ml: Optional[float] = None,
    tilt_deg: Optional[float] = None,
) -> Dict[str, Any]:
    """Fits a model (`sake-glug fit`, MODEL.md §13) to a session file (`.toml`), or to WAV clips
    of one bottle as the command line takes them: `fit("glugs.wav")` or a list of clips, a
    bottle of capacity_ml (default the model's) held at tilt_deg (default 135), full at each
    clip's first sample (`--capacity-ml`, `--tilt-deg`; a session file gives its own). Returns
    what `sake-glug fit --json` prints: {"units": {"detected", "used"}, "explained":
    {recording: share}, "estimates": {key: {"value", "low", "high", "n", "in_model", "note"}},
    "liquids": {name: {"estimates", "units", "detected", "kept_default", "model"}},
    "compared": {recording: {"rendered", "glugs", "rate_per_s", "pitch_fall", "pitch_hz",
    "high_share", "spectral_correlation", "log_spectral_distance_db"}}, "warnings": [...]}:
    "compared" holds what a listener hears in each recording, in its model and in the default
    bottle, each rendered as the recording was made (MODEL.md §13). Writes nothing. Ctrl-C
    returns at once (the fit, which cannot be stopped, runs on in the background and its
    result is dropped)."""

def analyze_paired(
    logs: List[Union[str, "os.PathLike[str]"]], *, dry_run_logs: bool = False
) -> Dict[str, Any]:
    """The paired-comparison analysis of trial logs, as `sake-glug analyze paired --json`.
    A dry run's trials (the log's `dry_run` column 1: answered while nothing played) raise
    SakeGlugError unless dry_run_logs=True (`--dry-run-logs`); "dry_run_trials" counts them.
    Ctrl-C returns at once (the analysis runs on in the background, its result dropped)."""

def analyze_discrimination(
    logs: List[Union[str, "os.PathLike[str]"]], *, dry_run_logs: bool = False
) -> Dict[str, Any]:
    """The discrimination analysis of trial logs (triangle, 2AFC or ABX), as `sake-glug analyze
    discrimination --json` (dry_run_logs and "dry_run_trials" as analyze_paired's): "trials", "correct", "proportion" with its exact interval
    ("proportion_low", "proportion_high"), the one-sided "p_value" against chance, "d_prime"
    with its profile-likelihood interval ("d_prime_low", "d_prime_high": None where infinite or
    the interval is empty) and the plain "sentence", pooled and under "participants". Ctrl-C
    returns at once (the analysis runs on in the background, its result dropped)."""

def analyze_constant(
    logs: List[Union[str, "os.PathLike[str]"]],
    *,
    resamples: Optional[int] = None,
    seed: Optional[int] = None,
    lapse: Optional[float] = None,
    dry_run_logs: bool = False,
) -> Dict[str, Any]:
    """The constant-stimuli analysis of trial logs, as `sake-glug analyze constant --json`
    (dry_run_logs and "dry_run_trials" as analyze_paired's):
    resamples from 1 to 100,000 (default 2000), seed and lapse as its options. Each point
    ("25", "50", "75") has "value", "low", "high" and "placement" ("within", "below_levels",
    "above_levels"): only a point within the levels tested is an estimate, so outside them its
    value and interval are None, and an interval's end beyond them is None. Ctrl-C returns at
    once (the analysis runs on in the background, its result dropped)."""
