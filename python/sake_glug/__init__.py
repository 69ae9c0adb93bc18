"""Sake Glug: the glug vibration of liquid poured from a Japanese sake bottle.

The offline renderer of the ``sake-glug`` command line, for Python::

    import sake_glug
    samples = sake_glug.render({"tilt_deg": 135.0, "duration_s": 2.0})

- :func:`render` renders a scene (a file, TOML text, a dict, or the built-in pour) to a NumPy
  ``float32`` array, bit for bit the samples ``sake-glug render`` writes to an f32 WAV;
- :func:`presets` lists the presets of the plugin's menu;
- :class:`SakeGlugError` (a ``ValueError``) carries the command line's message for whatever it
  refuses.
"""

from typing import List, NamedTuple

from ._sake_glug import SakeGlugError, render
from ._sake_glug import presets as _presets

__all__ = ["Preset", "SakeGlugError", "presets", "render"]


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
