import os
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Union

import numpy as np
import numpy.typing as npt

__all__ = [
    "Preset",
    "SakeGlugError",
    "Tables",
    "analyze_constant",
    "analyze_paired",
    "fit",
    "presets",
    "render",
    "render_tables",
]

_Scene = Union[str, "os.PathLike[str]", Mapping[str, Any], None]

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
) -> npt.NDArray[np.float32]:
    """Renders a scene and returns its samples (mono, float32), bit for bit those of
    `sake-glug render` of the same scene.

    scene: a scene file's path, scene TOML text (a str with a newline or `=`), a dict of the
    same keys, or None for the built-in pour. sample_rate overrides the scene's (Hz); preset
    renders a preset instead of a scene. Raises SakeGlugError for what it refuses."""

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
) -> Tables:
    """Renders a scene as render() does and returns its samples with its units and state
    tables (a float64 array per column, named as the columns of `sake-glug render --units` and
    `--state`). Raises SakeGlugError for what it refuses."""

def fit(session: Union[str, "os.PathLike[str]"]) -> Dict[str, Any]:
    """Fits a model to the recordings of a session file (`sake-glug fit`, MODEL.md §13) and
    returns what `sake-glug fit --json` prints: {"units": {"detected", "used"}, "explained":
    {recording: share}, "estimates": {key: {"value", "low", "high", "n", "in_model", "note"}},
    "liquids": {name: {"estimates", "units", "detected", "kept_default", "model"}},
    "warnings": [...]}. Writes nothing."""

def analyze_paired(logs: List[Union[str, "os.PathLike[str]"]]) -> Dict[str, Any]:
    """The paired-comparison analysis of trial logs, as `sake-glug analyze paired --json`."""

def analyze_constant(
    logs: List[Union[str, "os.PathLike[str]"]],
    *,
    resamples: Optional[int] = None,
    seed: Optional[int] = None,
    lapse: Optional[float] = None,
) -> Dict[str, Any]:
    """The constant-stimuli analysis of trial logs, as `sake-glug analyze constant --json`."""
