"""The built VST3 in Ardour 7, a real DAW, run headless (`ardour7-lua` on its dummy backend):
Tilt automation bounced from a MIDI track and compared with the offline renderer.

- A stepped Tilt bounces to exactly the samples of `sake-glug render` of the same steps.
- A ramped Tilt bounces to exactly the samples of `sake-glug render` of the automation as Ardour
  delivered it: once per cycle, a parameter queue of the value at the cycle's start, the list's
  points inside it, and the value at its end (ardour_bounce.lua logs each queue and says where
  Ardour builds it). nice-plug applies each point as a step at its offset (the end one, an
  offset past the cycle, at its last sample), the value normalised in f32 and snapped to the
  knob's step, and the engine plays the decimal the knob shows.
- Against the offline render of the ramp itself the bounce differs: glugs move. The test
  measures how much and checks the guide's figures are these (docs/guide/sound-designer.md) (SAKE_GLUG_WRITE_DOCS=1 rewrites
  them).

Needs Ardour 7 (Debian `ardour`), `cargo xtask bundle sake_glug --release` and the release CLI.
"""

import math
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from pedalboard.io import AudioFile

REPO = Path(__file__).resolve().parents[2]
BUNDLE = REPO / "target" / "bundled" / "Sake Glug.vst3"
CLI = REPO / "target" / "release" / "sake-glug"
LUA = Path(__file__).with_name("ardour_bounce.lua")
SCANNER = Path("/usr/lib/ardour7/ardour-vst3-scanner")
ARDOUR = shutil.which("ardour7-lua")

SAMPLE_RATE = 48000
LENGTH = 5 * SAMPLE_RATE
# A float-WAV export preset of our own (Ardour ships none that writes 32-bit float at the
# session's rate), on Ardour's "BWAV 32float" format.
PRESET_ID = "5a4e9c1e-6b1f-4c0e-9d52-5ac3e61a0001"
PRESET = f"""<?xml version="1.0" encoding="UTF-8"?>
<ExportPreset id="{PRESET_ID}" name="Sake Glug float WAV">
  <ExportFormat id="20b4ab09-6452-4cb3-bd66-b921cdbd2942"/>
  <ExportFilename>
    <Folder relative="1" path="export"/>
    <Field name="label" enabled="1"/>
  </ExportFilename>
</ExportPreset>
"""
# Points on the MIDI track's beat grid (1/1920 beat = 12.5 samples at 120 bpm), so Ardour keeps
# them where they are. The bottle stands upright before either change: Ardour runs the plugin
# before the export starts, so it must not be pouring then.
STEP = [(0, 0.0), (47975, 0.0)]
# The tilts a step goes to: 135°, and 97.5°, a value off the grid of 1000 steps that JUCE hosts
# such as pedalboard probe (0.18° apart), which must land as typed: the VST3 declares every float
# parameter continuous (stepCount 0), and a host's value reaches the engine as the knob shows it.
STEP_TILTS = [135.0, 97.5]
# How many times a bounce is run when Ardour dies of a signal before it finishes (see bounce).
ARDOUR_ATTEMPTS = 4
RAMP = [(0, 0.0), (23975, 0.0), (24000, 90.0), (48000, 135.0)]

pytestmark = pytest.mark.skipif(ARDOUR is None, reason="Ardour 7 is not installed")


@pytest.fixture(scope="module")
def ardour_home(tmp_path_factory):
    """A home of its own for Ardour: its plugin cache (the scanned bundle) and our preset."""
    home = tmp_path_factory.mktemp("ardour-home")
    vst3 = home / "vst3"
    vst3.mkdir()
    shutil.copytree(BUNDLE, vst3 / BUNDLE.name)
    env = dict(
        os.environ,
        HOME=str(home),
        XDG_CONFIG_HOME=str(home / ".config"),
        XDG_CACHE_HOME=str(home / ".cache"),
        VST3_PATH=str(vst3),
        LD_LIBRARY_PATH="/usr/lib/ardour7",
    )
    scan = subprocess.run(
        [SCANNER, "-f", vst3 / BUNDLE.name], env=env, capture_output=True, text=True, timeout=60
    )
    assert "Found Plugin: Sake Glug" in scan.stdout + scan.stderr, scan.stdout + scan.stderr
    presets = home / ".config" / "ardour7" / "export"
    presets.mkdir(parents=True)
    (presets / "sake-glug-float.preset").write_text(PRESET)
    del env["LD_LIBRARY_PATH"]  # ardour7-lua finds its own libraries
    return env


def bounce(env, tmp_path, points):
    """Ardour's export of the plugin under `points`, and what Ardour says it delivered: the
    list's points as it kept them, its cycle, and each cycle's queue (start, offset, value)."""
    (tmp_path / "points.txt").write_text("".join(f"{at} {value}\n" for at, value in points))
    # Ardour 7.3 corrupts its heap now and then and dies of a signal (SIGSEGV, or glibc's abort:
    # "malloc assertion failure", "corrupted size vs. prev_size"), before or after the export,
    # with or without this plugin (seen with only its own synth on the track; here about one run
    # of ardour7-lua in 20). Such a death says nothing of the bounce: run it again, a few times.
    # Any other failure, an error it prints, or a run that finishes, is taken as it is.
    for attempt in range(1, ARDOUR_ATTEMPTS + 1):
        out = tmp_path / f"out-{attempt}"
        out.mkdir()
        run = subprocess.run(
            [ARDOUR, LUA],
            env=dict(
                env,
                GLUG_POINTS=str(tmp_path / "points.txt"),
                GLUG_LENGTH=str(LENGTH),
                GLUG_OUT=str(out),
                GLUG_SESSION=str(tmp_path / f"session-{attempt}"),
                GLUG_PRESET=PRESET_ID,
            ),
            capture_output=True,
            text=True,
            timeout=300,
        )
        finished = "bounced" in run.stdout.splitlines()
        if finished or run.returncode >= 0:
            break
    # A crash in Ardour's teardown after the export has finished is Ardour's, not the bounce's.
    assert "Error" not in run.stdout and (run.returncode == 0 or finished), (
        f"ardour7-lua exited {run.returncode} (attempt {attempt}):\n" + run.stdout + run.stderr
    )
    (wav,) = out.glob("*.wav")
    with AudioFile(str(wav)) as file:
        assert file.samplerate == SAMPLE_RATE
        samples = file.read(file.frames)
    assert np.array_equal(samples[0], samples[-1]), "the channels differ"
    points, cycle, queues = [], None, []
    for line in (out / "delivered.txt").read_text().splitlines():
        kind, *fields = line.split()
        if kind == "point":
            points.append((int(fields[0]), float(fields[1])))
        elif kind == "cycle":
            cycle = int(fields[0])
        else:
            queues.append((int(fields[0]), int(fields[1]), float(fields[2])))
    return samples[0], points, cycle, queues


def steps_lane(steps):
    """A Tilt lane that holds each (sample, degrees) from that sample on: two points at a time."""
    lane, previous = [], None
    for at, value in steps:
        time_s = at / SAMPLE_RATE
        if previous is not None:
            lane.append(f"[{time_s!r}, {previous!r}]")
        lane.append(f"[{time_s!r}, {value!r}]")
        previous = value
    return f"[{', '.join(lane)}]"


def offline(tmp_path, name, tilt_lane):
    """`sake-glug render` of the default scene with this Tilt lane, as long as the bounces."""
    scene = tmp_path / f"{name}.toml"
    scene.write_text(f"duration_s = {LENGTH / SAMPLE_RATE}\ntilt_deg = {tilt_lane}\n")
    wav = tmp_path / f"{name}.wav"
    subprocess.run([CLI, "render", scene, "-o", wav], check=True, capture_output=True)
    with AudioFile(str(wav)) as file:
        return file.read(file.frames)[0]


def tilt_knob():
    """Tilt's range and step as `sake-glug parameters` shows them: (min, max, step text)."""
    table = subprocess.run([CLI, "parameters"], check=True, capture_output=True, text=True).stdout
    rows = [[cell.strip() for cell in line.strip("|").split("|")] for line in table.splitlines()]
    header = rows[0]
    (tilt,) = [row for row in rows if row[header.index("ID")] == "`tilt`"]
    number = r"-?[0-9.]+"
    low, high = re.match(rf"({number})–({number})", tilt[header.index("range")]).groups()
    step = re.match(number, tilt[header.index("step")]).group(0)
    return float(low), float(high), step


def round_half_away(x):
    """Rust's `round`: halves away from zero (Python's `round` takes halves to even)."""
    whole = math.floor(abs(x))
    return math.copysign(whole + (abs(x) - whole >= 0.5), x)


def as_the_plugin_plays(degrees, knob):
    """A value of Ardour's queue as the engine plays it. Ardour keeps it as a float and has the
    plugin normalise it (nice-plug's linear range, in f32); nice-plug turns the normalised value
    back into degrees in f32 and snaps it to the knob's step (in f32, Rust's rounding); the
    engine plays the decimal the knob shows (crates/plugin/src/params.rs, `exact`)."""
    f32 = np.float32
    low, high, step_text = knob
    plain = np.clip(f32(degrees), f32(low), f32(high))
    normalised = f32((plain - f32(low)) / (f32(high) - f32(low)))
    plain = f32(np.clip(normalised, f32(0), f32(1)) * (f32(high) - f32(low)) + f32(low))
    step = f32(float(step_text))
    snapped = np.clip(f32(f32(round_half_away(float(f32(plain / step)))) * step), low, high)
    scale = 10.0 ** len(step_text.partition(".")[2])
    return round_half_away(float(snapped) * scale) / scale + 0.0  # -0.0 shows as 0


def delivered_steps(cycle, queues, knob):
    """Ardour's queues as the steps the plugin plays: each value from its offset in its cycle on,
    an offset past the cycle's end on its last sample (nice-plug's VST3 wrapper clamps an event
    into the buffer); at one sample the later value is the one played."""
    return [
        (start + min(offset, cycle - 1), as_the_plugin_plays(value, knob))
        for start, offset, value in queues
    ]


def first_sound(samples):
    return int(np.flatnonzero(samples)[0])


def difference_db(a, b):
    """The largest difference, in dB of the offline render's peak."""
    return 20 * np.log10(np.abs(a - b).max() / np.abs(b).max())


@pytest.mark.parametrize("tilt", STEP_TILTS)
def test_a_stepped_tilt_bounces_to_the_offline_render_to_the_sample(ardour_home, tmp_path, tilt):
    step = STEP + [(48000, tilt)]
    bounced, points, _, _ = bounce(ardour_home, tmp_path, step)
    assert points == [(at, value) for at, value in step]
    # A step is two points at one time offline; in Ardour a point 25 samples before, which the
    # plugin is handed as a step at the later point's sample.
    rendered = offline(tmp_path, "step", steps_lane([(0, 0.0), (48000, tilt)]))
    assert len(bounced) == len(rendered) == LENGTH
    assert np.abs(rendered).max() > 0, f"the bottle pours at {tilt}°"
    assert np.array_equal(bounced, rendered)


def ramp_figures(bounced, true_ramp, cycle, steps):
    ms = lambda samples: f"{samples * 1000 / SAMPLE_RATE:.1f} ms"  # noqa: E731
    late = first_sound(true_ramp) - first_sound(bounced)
    changes = sum(after != before for (_, before), (_, after) in zip(steps, steps[1:]))
    return (
        "<!-- generated:vst3-ramps:begin -->\n"
        f"Measured in Ardour 7 ({cycle}-sample cycles, {SAMPLE_RATE // 1000} kHz), Tilt ramped "
        f"90°→135° over 0.5 s: the plugin plays it as {changes} steps, and the bounce is, to "
        f"the sample, the offline render of those steps. Against the offline render "
        f"of the ramp itself, the bounce's first glug comes {abs(late)} samples "
        f"({ms(abs(late))}) {'earlier' if late > 0 else 'later'} and the largest difference is "
        f"{difference_db(bounced, true_ramp):+.1f} dB of the peak.\n"
        "<!-- generated:vst3-ramps:end -->"
    )


def test_a_ramped_tilt_bounces_to_the_offline_render_of_what_ardour_delivered(
    ardour_home, tmp_path
):
    bounced, _, cycle, queues = bounce(ardour_home, tmp_path, RAMP)
    knob = tilt_knob()
    steps = delivered_steps(cycle, queues, knob)
    as_delivered = offline(tmp_path, "delivered", steps_lane(steps))
    assert len(bounced) == len(as_delivered) == LENGTH
    assert np.array_equal(bounced, as_delivered), (
        f"the bounce is not the automation Ardour delivered: "
        f"{np.count_nonzero(bounced != as_delivered)} samples differ, from sample "
        f"{np.flatnonzero(bounced != as_delivered)[0]}, by up to "
        f"{difference_db(bounced, as_delivered):+.1f} dB"
    )
    # The ramp itself, sample by sample, as a CLAP host or the offline renderer plays it: the
    # steps move the glugs.
    true_ramp = offline(tmp_path, "ramp", "[[0.0, 0.0], [0.5, 0.0], [0.5, 90.0], [1.0, 135.0]]")
    assert first_sound(bounced) != first_sound(true_ramp)
    figures = ramp_figures(bounced, true_ramp, cycle, steps)
    page = REPO / "docs" / "guide" / "sound-designer.md"
    text = page.read_text()
    block = re.compile(
        r"<!-- generated:vst3-ramps:begin -->\n.*?<!-- generated:vst3-ramps:end -->", re.S
    )
    if os.environ.get("SAKE_GLUG_WRITE_DOCS") == "1":
        page.write_text(block.sub(lambda _: figures, text))
    else:
        found = block.search(text)
        assert found and found.group(0) == figures, f"{page}'s figures are not these:\n{figures}"
