"""sake_glug.render gives the samples of `sake-glug render` of the same scene, bit for bit, and
refuses what the command line refuses with the same message."""

import os
import threading
import time
import _thread
from pathlib import Path

import numpy as np
import pytest

import sake_glug
from conftest import cli_render, run_cli

# A scene off every default: a ramp, a seed, a drain mode, a table of glug constants.
SCENE_TOML = """\
seed = 3
duration_s = 1.5
tilt_deg = [[0.0, 90.0], [0.4, 121.5]]
viscosity_c = 0.42

[output]
drain = "follow"

[glug]
f1_hz = 91.5
"""
SCENE_DICT = {
    "seed": 3,
    "duration_s": 1.5,
    "tilt_deg": [[0.0, 90.0], [0.4, 121.5]],
    "viscosity_c": 0.42,
    "output": {"drain": "follow"},
    "glug": {"f1_hz": 91.5},
}


def assert_identical(ours: np.ndarray, theirs: np.ndarray) -> None:
    assert ours.dtype == np.float32 and ours.ndim == 1
    assert ours.shape == theirs.shape
    assert np.any(ours != 0), "a silent render proves nothing"
    # Bit for bit: as integers, so that no two NaNs or ±0 could pass for equal.
    assert np.array_equal(ours.view(np.uint32), theirs.view(np.uint32))


@pytest.fixture
def scene_file(tmp_path: Path) -> Path:
    path = tmp_path / "ramp.toml"
    path.write_text(SCENE_TOML)
    return path


def test_the_default_pour_equals_the_cli(cli, tmp_path):
    assert_identical(sake_glug.render(), cli_render(cli, tmp_path))


def test_a_preset_equals_the_cli(cli, tmp_path):
    assert_identical(sake_glug.render(preset="syrup"), cli_render(cli, tmp_path, "--preset", "syrup"))


def test_a_scene_file_equals_the_cli_whether_named_by_str_path_or_given_as_text(cli, tmp_path, scene_file):
    theirs = cli_render(cli, tmp_path, str(scene_file))
    assert_identical(sake_glug.render(scene_file), theirs)
    assert_identical(sake_glug.render(str(scene_file)), theirs)
    assert_identical(sake_glug.render(SCENE_TOML), theirs)


def test_a_dict_equals_the_cli_of_the_same_toml(cli, tmp_path, scene_file):
    tomllib = pytest.importorskip("tomllib")
    assert tomllib.loads(SCENE_TOML) == SCENE_DICT
    assert_identical(sake_glug.render(SCENE_DICT), cli_render(cli, tmp_path, str(scene_file)))


def test_the_sample_rate_override_equals_the_cli(cli, tmp_path, scene_file):
    ours = sake_glug.render(scene_file, sample_rate=44100)
    assert_identical(ours, cli_render(cli, tmp_path, str(scene_file), "--sample-rate", "44100"))
    assert len(ours) == round(1.5 * 44100)
    assert_identical(sake_glug.render(preset="water", sample_rate=96000.0),
                     cli_render(cli, tmp_path, "--preset", "water", "--sample-rate", "96000"))


def test_a_bad_value_raises_the_clis_message_naming_the_key(cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("tilt_deg = 500.0\n")
    with pytest.raises(sake_glug.SakeGlugError) as raised:
        sake_glug.render(bad)
    assert isinstance(raised.value, ValueError)
    assert "`tilt_deg`" in str(raised.value)
    done = run_cli(cli, "render", str(bad), "-o", str(tmp_path / "bad.wav"))
    assert done.returncode != 0
    assert done.stderr.strip() == f"error: bad: {raised.value}"
    with pytest.raises(sake_glug.SakeGlugError, match="`tilt_deg`"):
        sake_glug.render({"tilt_deg": 500.0})


def test_an_unknown_key_is_named(cli, tmp_path):
    with pytest.raises(sake_glug.SakeGlugError, match="unknown field `tilt_degrees`"):
        sake_glug.render({"tilt_degrees": 135.0})
    with pytest.raises(sake_glug.SakeGlugError, match="unknown field `gain`"):
        sake_glug.render("[output]\ngain = 1.0\n")


def test_a_missing_file_an_unknown_preset_and_a_bad_sample_rate_are_refused(cli, tmp_path):
    with pytest.raises(sake_glug.SakeGlugError, match="cannot read scene file .*missing.toml"):
        sake_glug.render(tmp_path / "missing.toml")
    with pytest.raises(sake_glug.SakeGlugError) as raised:
        sake_glug.render(preset="vodka")
    done = run_cli(cli, "render", "--preset", "vodka", "-o", str(tmp_path / "x.wav"))
    assert done.stderr.strip() == f"error: {raised.value}"
    with pytest.raises(sake_glug.SakeGlugError, match="`sample_rate` = 44100.5 is not a whole number"):
        sake_glug.render(sample_rate=44100.5)
    with pytest.raises(sake_glug.SakeGlugError, match="not both"):
        sake_glug.render(SCENE_DICT, preset="water")


def test_a_scene_of_another_type_is_a_type_error():
    with pytest.raises(TypeError, match="not int"):
        sake_glug.render(135)


# Five minutes of glugs (the bottle tilted slowly): a render of about half a second, far longer
# than Python's thread switch interval (5 ms) and the render's look for Ctrl-C (20 ms).
LONG_POUR = {"tilt_deg": [[0.0, 90.0], [300.0, 135.0]], "duration_s": 300.0}


def test_the_gil_is_released_while_rendering():
    started, spans, ticks = threading.Event(), [], []

    def render():
        started.set()
        begin = time.perf_counter()
        sake_glug.render(LONG_POUR)
        spans.append((begin, time.perf_counter()))

    worker = threading.Thread(target=render)
    worker.start()
    started.wait()
    while worker.is_alive():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    worker.join()
    (begin, end) = spans[0]
    # Holding the GIL, the render would let this thread run only about its start (a switch
    # interval, or longer if the system took the CPU away) and after its end.
    assert sum(begin + (end - begin) / 4 < tick < end for tick in ticks) >= 3


def test_ctrl_c_stops_a_render():
    began = time.perf_counter()
    sake_glug.render(LONG_POUR)
    whole = time.perf_counter() - began
    timer = threading.Timer(whole / 10, _thread.interrupt_main)
    began = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sake_glug.render(LONG_POUR)
    finally:
        timer.cancel()
    # Not a speed: a render that ignored Ctrl-C would raise it too, once it had finished; this
    # one stopped within a check interval (20 ms) of it, long before the same render's end.
    assert time.perf_counter() - began < whole * 0.6
