"""Arguments that once crashed or misled the interpreter (issue #31): a scene that contains
itself or nests too deep, a scene too long for memory, control characters in a preset's name,
an empty scene, a bootstrap of ten million resamples, an analysis waiting on a FIFO. What could
kill the interpreter runs in a child one, so that a crash is a failed test, not a dead run."""

import os
import subprocess
import sys
import textwrap
import threading
import time
import _thread
import unicodedata
import warnings

import numpy as np
import pytest

import sake_glug
from conftest import REPO, cli_render, run_cli
from test_fit_and_analyses import write_constant_log, write_paired_log


def run_child(code: str) -> str:
    """Runs `code` in a fresh interpreter with sake_glug imported; its output, once it has ended
    normally (a segfault or an abort fails the test with what it printed)."""
    done = subprocess.run(
        [sys.executable, "-c", "import sake_glug\n" + textwrap.dedent(code)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, f"the interpreter died ({done.returncode}): {done.stderr[-2000:]}"
    return done.stdout


REFUSED = """
try:
    {call}
except sake_glug.SakeGlugError as error:
    print(error)
else:
    print("accepted")
"""

CYCLES = {
    "a dict in itself": ('scene = {}\nscene["glug"] = scene', "`glug`", "dict"),
    "a list in itself": (
        'points = []\npoints.append(points)\nscene = {"tilt_deg": points}',
        "`tilt_deg[0]`",
        "list",
    ),
    "a cycle of two": ('a, b = {}, {}\na["b"] = b\nb["a"] = a\nscene = {"glug": a}', "`glug.b.a`", "dict"),
}


@pytest.mark.parametrize("name", CYCLES)
def test_a_scene_that_contains_itself_is_refused(name):
    build, key, kind = CYCLES[name]
    message = run_child(build + REFUSED.format(call="sake_glug.render(scene)"))
    assert message.strip() == (
        f"invalid scene: {key} refers back to a {kind} it is inside of: a scene cannot contain itself"
    )


DEEP = """
scene = inner = {{}}
for _ in range({depth}):
    inner["glug"] = {{}}
    inner = inner["glug"]
lists = inner = []
for _ in range({depth}):
    inner.append([])
    inner = inner[0]
"""


@pytest.mark.parametrize("in_a_thread", [False, True], ids=["main thread", "in a thread"])
def test_a_scene_nested_deeper_than_the_limit_is_refused(in_a_thread):
    code = DEEP.format(depth=20_000) + textwrap.dedent(
        """
        def refuse():
            for scene in (scene_of_dicts, {"tilt_deg": lists}):
                try:
                    sake_glug.render(scene)
                except sake_glug.SakeGlugError as error:
                    print(error)
        scene_of_dicts = scene
        """
    )
    code += "import threading\nt = threading.Thread(target=refuse)\nt.start()\nt.join()\n" if in_a_thread else "refuse()\n"
    first, second = run_child(code).splitlines()
    assert first == (
        "invalid scene: `glug.glug.glug.glug.glug.glug.gl…` nests deeper than the 32 levels a scene may"
    )
    assert second.startswith("invalid scene: `tilt_deg[0][0][0]") and "32 levels" in second


def test_the_depth_limit_is_32_levels():
    nested = {}
    inner = nested
    for _ in range(31):  # 32 dicts in all: read, then refused as no scene key
        inner["glug"] = {}
        inner = inner["glug"]
    with pytest.raises(sake_glug.SakeGlugError) as raised:
        sake_glug.render(nested)
    assert "32 levels" not in str(raised.value)
    inner["glug"] = {}
    with pytest.raises(sake_glug.SakeGlugError, match="nests deeper than the 32 levels"):
        sake_glug.render(nested)


def test_a_value_a_scene_cannot_hold_is_named_with_its_key():
    with pytest.raises(sake_glug.SakeGlugError, match=r"^invalid scene: `seed` = 1000000000000000000000: beyond"):
        sake_glug.render({"seed": 10**21})
    with pytest.raises(sake_glug.SakeGlugError, match=r"`glug.f1_hz` is of type set"):
        sake_glug.render({"glug": {"f1_hz": {80.0}}})
    with pytest.raises(sake_glug.SakeGlugError, match=r"the dict has a key of type int"):
        sake_glug.render({1: 2.0})


# A day of pouring at 48 kHz: 4,147,200,000 samples, 16.6 GB as float32.
DAY = '{"duration_s": 86400.0, "tilt_deg": 135.0}'

# An address-space limit the interpreter's own use plus `room` bytes: a render beyond it fails
# to allocate whatever memory the machine has, as under `ulimit -v`.
LIMITED = """
import resource
with open("/proc/self/status") as status:
    used = next(int(line.split()[1]) * 1024 for line in status if line.startswith("VmSize:"))
resource.setrlimit(resource.RLIMIT_AS, (used + {room}, used + {room}))
"""


def test_a_render_that_cannot_fit_in_memory_is_refused_with_the_figure():
    # It aborted the interpreter ("memory allocation of … bytes failed"): now refused up front,
    # by the memory the machine has available or, past that, by the process's limit.
    code = LIMITED.format(room=1 << 30) + REFUSED.format(call=f"sake_glug.render({DAY})")
    message = run_child(code).strip()
    assert message.startswith(
        "the render's 4147200000 samples (86400.0 s at 48000 Hz) need 16.6 GB of memory, more than "
    ), message
    assert message.endswith("; `sake-glug render` writes a render of any length to a file")


def test_tables_that_cannot_fit_in_memory_are_refused_with_the_figure():
    code = LIMITED.format(room=1 << 30) + REFUSED.format(call=f"sake_glug.render_tables({DAY})")
    message = run_child(code).strip()
    assert message.startswith(
        "the render's tables (4147200000 samples, 86400002 state rows, its units not yet counted) "
        "need at least "
    ), message


def test_a_render_without_duration_that_outgrows_memory_is_refused_with_the_figure():
    # No length to check before it starts: it grows only as far as memory allows.
    scene = '{"tilt_deg": [[0.0, 90.0], [86400.0, 135.0]], "output": {"drain": "follow"}}'
    code = LIMITED.format(room=256 << 20) + REFUSED.format(call=f"sake_glug.render({scene})")
    message = run_child(code).strip()
    assert message.startswith("the render reached ") and "give the scene a duration_s" in message, message


def test_an_unknown_preset_is_named_with_its_control_characters_escaped_and_cut():
    with pytest.raises(sake_glug.SakeGlugError) as raised:
        sake_glug.render(preset="x\x1b[31m\x07" + "y" * 10_000)
    message = str(raised.value)
    assert message.startswith("no preset `x\\u{1b}[31m\\u{7}yyyy")
    assert not [c for c in message if unicodedata.category(c) == "Cc"]
    assert len(message) < 200


def test_an_empty_scene_renders_as_an_empty_scene_file_does_and_says_so(cli, tmp_path):
    empty = REPO / "tests" / "fixtures" / "scenes" / "valid" / "empty.toml"
    assert cli_render(cli, tmp_path, str(empty)).size == 0
    for scene in ({}, empty, "# nothing = here\n"):
        with pytest.warns(UserWarning, match=r"nothing sounds: the bottle never tilts past where it pours"):
            samples = sake_glug.render(scene)
        assert samples.dtype == np.float32 and samples.size == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sake_glug.render(None).size > 0


def test_resamples_are_bounded_as_the_command_line_bounds_them(cli, tmp_path):
    log = tmp_path / "constant.csv"
    write_constant_log(log)
    for count in [10**7, 2**64 - 1, 10**30, 0, -1]:
        with pytest.raises(sake_glug.SakeGlugError, match=r"resamples: from 1 to 100000 are drawn$"):
            sake_glug.analyze_constant([log], resamples=count)
    with pytest.raises(sake_glug.SakeGlugError) as raised:
        sake_glug.analyze_constant([log], resamples=18446744073709551615)
    assert str(raised.value) == "18446744073709551615 resamples: from 1 to 100000 are drawn"
    done = run_cli(cli, "analyze", "constant", str(log), "--resamples", "18446744073709551615")
    assert done.returncode == 2
    assert "'18446744073709551615'" in done.stderr and "1..=100000" in done.stderr, done.stderr
    assert sake_glug.analyze_constant([log], resamples=100, seed=2)["points"]


def _fit(path):
    return sake_glug.fit(path)


CALLS = {
    "fit": _fit,
    "analyze_paired": lambda path: sake_glug.analyze_paired([path]),
    "analyze_constant": lambda path: sake_glug.analyze_constant([path]),
}


@pytest.mark.parametrize("name", CALLS)
def test_a_fifo_is_refused_at_once(name, tmp_path):
    # A FIFO opened for reading waits for a writer; the package's one reader opens it without
    # waiting and refuses it: with no writer at all, the call returns at once with why.
    fifo = tmp_path / "log.csv"
    os.mkfifo(fifo)
    with pytest.raises(sake_glug.SakeGlugError, match="not a regular file"):
        CALLS[name](fifo)


def _working():
    """Whether the package's worker thread (named `sake_glug`) is running."""
    tasks = "/proc/self/task"
    for task in os.listdir(tasks):
        try:
            with open(f"{tasks}/{task}/comm") as comm:
                if comm.read().strip() == "sake_glug":
                    return True
        except FileNotFoundError:
            pass
    return False


def test_ctrl_c_stops_a_long_analysis(tmp_path, ctrl_c):
    # The analysis runs on a thread of its own while the caller waits and looks for Ctrl-C. The
    # interrupt is sent once that thread runs; the call must then return while the work goes on
    # (its result dropped). A caller that only saw Ctrl-C once the work was done would raise it
    # too, so the test looks for the work a tenth of a second after the call returned: twenty
    # participants' 100,000 resamples take seconds, more on a busier machine, never less.
    log = tmp_path / "constant.csv"
    write_constant_log(log, participants=20)
    # An earlier call's worker may still be ending after handing its result over.
    deadline = time.monotonic() + 60
    while _working():
        assert time.monotonic() < deadline, "an earlier call's worker never ended"
        time.sleep(0.01)
    returned, gave_up = threading.Event(), []

    def interrupt_once_working():
        while not _working():
            if returned.wait(timeout=0.001):
                gave_up.append("the call returned before its thread was seen")
                return
        _thread.interrupt_main()

    interrupter = threading.Thread(target=interrupt_once_working)
    interrupter.start()
    try:
        with pytest.raises(ctrl_c):
            sake_glug.analyze_constant([log], resamples=100_000)
    finally:
        returned.set()
        interrupter.join()
    assert not gave_up, gave_up
    returned.wait(0.1)
    assert _working(), "Ctrl-C was seen only once the work was done"
