"""Sake Glug: the glug vibration of liquid poured from a Japanese sake bottle.

The offline renderer of the ``sake-glug`` command line, for Python::

    import sake_glug
    samples = sake_glug.render({"tilt_deg": 135.0, "duration_s": 2.0})

- :func:`render` renders a scene (a file, TOML text, a dict, or the built-in pour) to a NumPy
  ``float32`` array, bit for bit the samples ``sake-glug render`` writes to an f32 WAV, and
  with ``actuator=`` (a shipped profile's name or a profile file) compensated for a device as
  ``--actuator`` does;
- :func:`render_variations` renders a set of takes of a scene, each drawing its seed and the
  values its ``[variations]`` table gives ranges for (``sake-glug render --variations``), with
  each take's row, which ``render(scene, take=row)`` renders again bit for bit;
- :func:`render_tables` renders the same samples with the glug data: one row per unit and the
  bottle's state at a fixed rate, the tables of ``sake-glug render --units/--state``;
- :func:`fit` fits a model to a session file or to WAV clips (``sake-glug fit``), and
  :func:`analyze_paired` / :func:`analyze_constant` / :func:`analyze_discrimination`
  analyse a study's trial logs
  (``sake-glug analyze … --json``), each returning its numbers as a dict;
- :func:`presets` lists the presets of the plugin's menu;
- :class:`SakeGlugError` (a ``ValueError``) carries the command line's message for whatever it
  refuses;
- ``__version__`` is the release's version, the one ``sake-glug --version`` prints.

No argument crashes the interpreter: a dict scene that contains itself or nests deeper than 32
levels is refused, a render that cannot fit in memory is refused with the figure, and Ctrl-C
stops every long call.
"""

from typing import Any, Dict, List, NamedTuple

import numpy as np

from ._sake_glug import (
    SakeGlugError,
    __version__,
    analyze_constant,
    analyze_discrimination,
    analyze_paired,
    fit,
    render,
    render_variations,
)
from ._sake_glug import presets as _presets
from ._sake_glug import render_tables as _render_tables

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


class Tables(NamedTuple):
    """A render's samples and its glug data (MODEL.md §14)."""

    samples: np.ndarray
    """The samples, as :func:`render` returns them."""
    units: Dict[str, np.ndarray]
    """One row per glug unit: a float64 array per column of ``--units`` (onset_s, tilt_deg, …)."""
    state: Dict[str, np.ndarray]
    """The bottle at ``state_rate``: a float64 array per column of ``--state`` (time_s, …)."""


def render_tables(scene: Any = None, **options: Any) -> Tables:
    """Renders a scene as :func:`render` does (same arguments but ``progress``, ``actuator``
    and ``felt`` included, plus ``state_rate`` in Hz, 1000 by default) and returns its samples with its units and state
    tables, the rows ``sake-glug render --units/--state`` writes. The scene renders twice: once
    keeping nothing, to refuse tables that cannot fit in memory with the figure, then into
    them."""
    return Tables(*_render_tables(scene, **options))


class Preset(NamedTuple):
    """A starting point of the plugin's preset menu."""

    id: str
    """What ``render(preset=...)`` and ``sake-glug render --preset`` take."""
    name: str
    """The name the plugin's menu shows."""
    description: str
    """What it is for."""
    scene: str
    """Its scene file (TOML), as ``sake-glug presets ID`` prints it."""


def presets() -> List[Preset]:
    """Every preset, in the order of the plugin's menu."""
    return [Preset(*preset) for preset in _presets()]
