"""The built VST3, loaded in a real host (pedalboard), renders exactly the samples of the offline
renderer for the same scene (every sample identical, as the guide says), at several host buffer
sizes.

Needs `cargo xtask bundle sake_glug --release` and `cargo build --release --bin sake-glug`.
"""

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from pedalboard import load_plugin
from pedalboard.io import AudioFile

REPO = Path(__file__).resolve().parents[2]
BUNDLE = REPO / "target" / "bundled" / "Sake Glug.vst3"
CLI = REPO / "target" / "release" / "sake-glug"

SAMPLE_RATE = 48000
DURATION_S = 3.0
BUFFER_SIZES = [32, 512, 4096]

# Each scene as (plugin parameter name, scene key, value). Values are decimals the parameters
# show exactly, so both renderers get the same numbers. Scene keys with a dot are in a table.
SCENES = {
    # MODEL.md's defaults with the bottle at 135°.
    "pour_at_135": [
        ("Seed", "seed", 7),
        ("Tilt", "tilt_deg", 135.0),
        ("Viscosity", "viscosity_c", 0.33),
        ("Fill level", "fill_percent", 100.0),
        ("Pour time", "pour_time_s", 5.0),
        ("Output gain", "output.gain_db", -6.0),
        ("f1", "glug.f1_hz", 80.0),
        ("f2", "glug.f2_hz", 300.0),
        ("B1", "glug.b1_per_s", 45.0),
        ("B2", "glug.b2_per_s", 40.0),
    ],
    # Off every plateau of the bottle's curves, with values that are not binary fractions:
    # any difference in how the two renderers read a value would move the glugs.
    "shallow_follow": [
        ("Seed", "seed", 11),
        ("Tilt", "tilt_deg", 97.35),
        ("Viscosity", "viscosity_c", 0.29),
        ("Fill level", "fill_percent", 87.3),
        ("Pour time", "pour_time_s", 4.2),
        ("Output gain", "output.gain_db", -3.5),
        ("Drain mode", "output.drain", "follow"),
        ("f1", "glug.f1_hz", 81.7),
        ("f2", "glug.f2_hz", 312.5),
        ("B1", "glug.b1_per_s", 52.3),
        ("B2", "glug.b2_per_s", 38.9),
        ("Pocket volume", "bottle.pocket_ml", 4.3),
    ],
}


def scene_toml(scene: str) -> str:
    top = [f"sample_rate = {SAMPLE_RATE}", f"duration_s = {DURATION_S}"]
    tables: dict[str, list[str]] = {}
    for _, key, value in SCENES[scene]:
        text = f'"{value}"' if isinstance(value, str) else str(value)
        table, _, name = key.rpartition(".")
        (tables.setdefault(table, []) if table else top).append(f"{name} = {text}")
    lines = top + [line for table, rows in tables.items() for line in ["", f"[{table}]", *rows]]
    return "\n".join(lines) + "\n"


def plugin_text(value) -> str:
    return value.capitalize() if isinstance(value, str) else str(value)


@pytest.fixture(scope="module")
def offline_renders(tmp_path_factory) -> dict:
    if not CLI.exists():
        pytest.fail(f"{CLI} is missing: run `cargo build --release --bin sake-glug`")
    renders = {}
    for scene in SCENES:
        directory = tmp_path_factory.mktemp(scene)
        scene_file = directory / "scene.toml"
        scene_file.write_text(scene_toml(scene))
        wav = directory / "offline.wav"
        subprocess.run([str(CLI), "render", str(scene_file), "-o", str(wav)], check=True, timeout=120)
        with AudioFile(str(wav)) as file:
            assert file.samplerate == SAMPLE_RATE
            samples = file.read(file.frames)
        assert samples.shape[0] == 1, "the offline renderer writes mono"
        renders[scene] = samples[0].astype(np.float64)
    return renders


@pytest.fixture(scope="module")
def plugin():
    if not BUNDLE.exists():
        pytest.fail(f"{BUNDLE} is missing: run `cargo xtask bundle sake_glug --release`")
    # A generator never passes pedalboard's instrument warm-up (it waits for a note to sound),
    # so keep the wait it spends on that short.
    return load_plugin(str(BUNDLE), initialization_timeout=0.2)


def set_by_text(parameter, text: str) -> None:
    """Sets a parameter as a host's text entry does: the plugin parses the text.

    pedalboard's `setattr` snaps a value to the nearest of 1000 probed raw values when the
    plugin's own parse falls outside that probe's interval, which moves fine-grained parameters
    (f2 = 300 Hz arrives as 301.5 Hz); asking the plugin directly avoids that.
    """
    parameter.raw_value = parameter.get_raw_value_for_text(text)


def load_scene(plugin, scene: str) -> None:
    by_name = {parameter.name: parameter for parameter in plugin.parameters.values()}
    defaults = {"Drain mode": "Simulate", "Pocket volume": "5.0"}
    for name, text in defaults.items():
        set_by_text(by_name[name], text)
    for name, _, value in SCENES[scene]:
        assert name in by_name, f"parameter {name!r} missing; the plugin has {sorted(by_name)}"
        set_by_text(by_name[name], plugin_text(value))
        shown = str(by_name[name].string_value).split()[0].rstrip("°%")
        expected = plugin_text(value)
        assert shown == expected or float(shown) == float(expected), (
            f"{name}: set {expected}, the plugin shows {by_name[name].string_value}"
        )


def render(plugin, buffer_size: int) -> np.ndarray:
    output = plugin(
        [],
        duration=DURATION_S,
        sample_rate=SAMPLE_RATE,
        num_channels=2,
        buffer_size=buffer_size,
        reset=True,
    )
    return np.asarray(output, dtype=np.float64)


def error_db(actual: np.ndarray, expected: np.ndarray) -> float:
    peak = np.max(np.abs(expected))
    error = np.max(np.abs(actual - expected))
    return -math.inf if error == 0 else 20 * math.log10(error / peak)


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("buffer_size", BUFFER_SIZES)
def test_plugin_equals_offline_renderer(plugin, offline_renders, scene, buffer_size):
    load_scene(plugin, scene)
    offline = offline_renders[scene]
    assert np.max(np.abs(offline)) > 0.01, "the scene must glug"
    output = render(plugin, buffer_size)
    assert output.shape == (2, offline.shape[0])
    # Both are f32 samples widened to f64: identical means bit for bit.
    different = np.flatnonzero(output[0] != offline)
    assert different.size == 0, (
        f"{scene}, buffer {buffer_size}: {different.size} samples differ, the first at "
        f"{different[0]} ({output[0][different[0]]!r} against {offline[different[0]]!r}); "
        f"max error {error_db(output[0], offline):.1f} dB relative to the peak"
    )


def test_stereo_channels_are_equal(plugin):
    load_scene(plugin, "pour_at_135")
    output = render(plugin, 512)
    assert np.array_equal(output[0], output[1])


def test_output_is_a_glugging_pour(plugin):
    load_scene(plugin, "pour_at_135")
    output = render(plugin, 512)[0]
    assert np.all(np.isfinite(output))
    assert np.max(np.abs(output)) > 0.05, "a full bottle at 135° must be clearly audible"
    assert np.max(np.abs(output)) <= 1.0
    spectrum = np.abs(np.fft.rfft(output * np.hanning(output.size)))
    frequencies = np.fft.rfftfreq(output.size, 1 / SAMPLE_RATE)
    for expected_hz in (80.0, 300.0):
        band = (frequencies > expected_hz * 0.8) & (frequencies < expected_hz * 1.2)
        # The band's peak stands well above the spectrum's median.
        assert spectrum[band].max() > 30 * np.median(spectrum), f"no peak near {expected_hz} Hz"
        peak_hz = frequencies[band][np.argmax(spectrum[band])]
        assert abs(peak_hz - expected_hz) < 0.1 * expected_hz, f"peak at {peak_hz:.1f} Hz"


def test_upright_bottle_is_silent(plugin):
    load_scene(plugin, "pour_at_135")
    set_by_text(next(p for p in plugin.parameters.values() if p.name == "Tilt"), "0")
    assert np.max(np.abs(render(plugin, 512))) == 0.0
