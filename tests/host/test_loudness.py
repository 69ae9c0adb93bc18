"""`sake-glug render --loudness` held against an independent implementation of ITU-R BS.1770-4
and EBU R128's gating: pyloudnorm (PyPI). First pyloudnorm itself on EBU Tech 3341's signals,
generated from their definitions (1 kHz sine, stereo, at -23 and -33 dBFS → -23.0 and -33.0
LUFS), so the yardstick is known to be right; then the renderer's files: each rendered at a
loudness reads that loudness in pyloudnorm within 0.1 LU, and the figure the renderer reports
for a file (--fidelity) is pyloudnorm's within 0.1 LU too.

Needs the release CLI (`cargo build --release --bin sake-glug`; SAKE_GLUG_CLI names another).
"""

import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pyloudnorm
import pytest
from scipy.io import wavfile

REPO = Path(__file__).resolve().parents[2]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
CLI = Path(os.environ.get("SAKE_GLUG_CLI", TARGET / "release" / "sake-glug"))

RATE = 48_000
TOLERANCE_LU = 0.1


def stereo_sine(dbfs, seconds=20.0, hz=1000.0):
    """Tech 3341's tone: a sine whose peak is at `dbfs`, on both channels."""
    t = np.arange(int(seconds * RATE)) / RATE
    y = 10 ** (dbfs / 20) * np.sin(2 * np.pi * hz * t)
    return np.stack([y, y], axis=1)


def lufs(samples, rate=RATE):
    return pyloudnorm.Meter(rate).integrated_loudness(samples)


@pytest.mark.parametrize("dbfs", [-23.0, -33.0])
def test_pyloudnorm_reads_tech_3341_tones(dbfs):
    assert abs(lufs(stereo_sine(dbfs)) - dbfs) <= TOLERANCE_LU


def render(directory, *options, name="pour.wav"):
    assert CLI.exists(), f"{CLI} is missing: cargo build --release --bin sake-glug"
    result = subprocess.run(
        [str(CLI), "render", "-o", name, *options],
        cwd=directory,
        capture_output=True,
        text=True,
        check=True,
    )
    rate, samples = wavfile.read(directory / name)
    return result.stdout, rate, samples.astype(np.float64)


@pytest.mark.parametrize(
    "options",
    [
        ["--loudness", "-23"],
        ["--loudness", "-16"],
        ["--preset", "syrup", "--loudness", "-18"],
        ["--preset", "water", "--sample-rate", "44100", "--loudness", "-23"],
    ],
)
def test_a_render_reads_its_loudness_in_pyloudnorm(tmp_path, options):
    target = float(options[options.index("--loudness") + 1])
    _, rate, samples = render(tmp_path, *options)
    assert abs(lufs(samples, rate) - target) <= TOLERANCE_LU


def test_the_reported_loudness_is_pyloudnorms(tmp_path):
    """The renderer's own reading of its file (the --fidelity table's level column)."""
    stdout, rate, samples = render(tmp_path, "--fidelity")
    row = next(line for line in stdout.splitlines() if line.startswith("| `wav` |"))
    reported = float(re.search(r"(-?[0-9.]+) LUFS", row).group(1))
    assert abs(lufs(samples, rate) - reported) <= TOLERANCE_LU
