"""sake_glug.render gives the samples of `sake-glug render` of the same scene, bit for bit, and
refuses what the command line refuses with the same message."""

import collections
import itertools
import threading
import time
import warnings
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


# A pour as long as a render may be (a day, no duration_s), at a low rate: it cannot end before
# the tests below stop it, and what it holds until then is small.
ENDLESS_POUR = {"tilt_deg": [[0.0, 90.0], [86400.0, 135.0]], "sample_rate": 1000}


class CallCount:
    """A progress callback made of C alone: `deque.insert`, which runs no Python code, so calling
    it never offers the GIL nor runs a pending signal's handler (as Python code would, and
    as C that prints does). Each call adds an entry; `stop()` fills the deque, and the next call
    raises IndexError (deque already at its maximum size)."""

    def __init__(self):
        self.calls = collections.deque(maxlen=1_000_000)
        self.callback = self.calls.insert

    def __len__(self):
        return len(self.calls)

    def stop(self):
        self.calls.extend(itertools.repeat(None, self.calls.maxlen - len(self.calls)))


def test_the_gil_is_released_while_rendering():
    # The render runs in a thread whose only Python is the C callback: this thread can run
    # while it renders only if the render released the GIL. Held, this loop would first run
    # once the render had ended (a day of pouring), and see the count stand still.
    calls = CallCount()
    outcome = []

    def render():
        try:
            sake_glug.render(ENDLESS_POUR, progress=calls.callback)
        except IndexError as error:
            outcome.append(str(error))

    worker = threading.Thread(target=render)
    worker.start()
    while len(calls) == 0 and worker.is_alive():
        time.sleep(0.001)
    seen = len(calls)
    while len(calls) == seen and worker.is_alive():
        time.sleep(0.001)
    # Seen rendering on while this thread ran: now stop it.
    calls.stop()
    worker.join()
    assert outcome == ["deque already at its maximum size"]


def test_ctrl_c_stops_a_render(ctrl_c):
    # Ctrl-C comes once the render has begun (its callback was called), from another thread.
    # The callback is C that looks for no signal, so only the render's own look can raise it,
    # and it must raise it before calling the callback again. A render that went on instead is
    # stopped through its callback (IndexError, not CtrlC): a failure, not a hang.
    calls = CallCount()
    rendering = threading.Event()
    interrupted_at = []

    def interrupt_once_rendering():
        while rendering.is_set() and len(calls) == 0:
            time.sleep(0.001)
        if not rendering.is_set():
            return
        _thread.interrupt_main()
        interrupted_at.append(len(calls))
        while rendering.is_set() and len(calls) == interrupted_at[0]:
            time.sleep(0.001)
        if rendering.is_set():
            calls.stop()

    rendering.set()
    interrupter = threading.Thread(target=interrupt_once_rendering)
    interrupter.start()
    try:
        with pytest.raises(ctrl_c):
            sake_glug.render(ENDLESS_POUR, progress=calls.callback)
    finally:
        rendering.clear()
        interrupter.join()
    assert len(calls) == interrupted_at[0], "the render called back after Ctrl-C"


class Stop(Exception):
    pass


def test_what_the_progress_callback_raises_stops_the_render_and_is_raised():
    calls = []

    def progress(done, total):
        calls.append((done, total))
        raise Stop

    with pytest.raises(Stop):
        sake_glug.render(ENDLESS_POUR, progress=progress)
    # Called once with the samples so far; a scene without duration_s has no total till its end.
    [(done, total)] = calls
    assert done > 0 and total is None
    day = dict(ENDLESS_POUR, duration_s=86400.0)
    with pytest.raises(Stop):
        sake_glug.render(day, progress=progress)
    assert calls[1][1] == 86400 * 1000 and 0 < calls[1][0] < calls[1][1]


def test_a_progress_callback_must_be_callable():
    with pytest.raises(TypeError, match="progress must be callable or None, not int"):
        sake_glug.render(progress=3)


def test_a_fitted_model_played_far_beyond_its_recordings_warns_as_the_cli_does():
    """A model fitted from glugs at 275–295 ml (`[fit] volumes_ml`), played as a whole pour,
    warns with the command line's sentence; played within them, it does not (issue 49)."""
    fitted = {"tilt_deg": 135.0, "fit": {"volumes_ml": [275.0, 295.0]}}
    with pytest.warns(UserWarning, match=r"its glugs come at .* fitted from glugs at 275–295 ml"):
        assert sake_glug.render(fitted).size > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sake_glug.render({**fitted, "duration_s": 0.9}).size > 0
