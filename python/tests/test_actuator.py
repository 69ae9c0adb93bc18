"""render(actuator=..., felt=...) and render_tables(actuator=...) give the samples and tables of
`sake-glug render --actuator X [--felt]`, bit for bit, and refuse a bad profile as it does,
naming the file and the key."""

from pathlib import Path

import numpy as np
import pytest

import sake_glug
from conftest import cli_render, run_cli
from test_tables import read_csv

SCENE = "tilt_deg = [[0.0, 90.0], [0.5, 135.0]]\nduration_s = 1.5\nseed = 5\nviscosity_c = 0.35\n"
SHIPPED = ["flat", "haptuator-mark2", "lra", "phone", "dualsense", "vr-controller"]

# A profile of its own, as a lab's measurement would write one.
PROFILE = """\
name = "bench"
response = [[40.0, -20.0], [120.0, -3.0], [300.0, 0.0], [1000.0, -6.0]]
band_hz = [60.0, 800.0]
max_amplitude = 0.9
sample_rate_hz = 48000
"""


def same_bits(ours: np.ndarray, theirs: np.ndarray) -> bool:
    return ours.shape == theirs.shape and np.array_equal(ours.view(np.uint32), theirs.view(np.uint32))


@pytest.fixture
def scene_file(tmp_path: Path) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(SCENE)
    return path


@pytest.mark.parametrize("felt", [False, True], ids=["acceleration", "felt"])
@pytest.mark.parametrize("name", SHIPPED)
def test_a_shipped_profile_renders_as_the_cli(cli, tmp_path, scene_file, name, felt):
    ours = sake_glug.render(SCENE, actuator=name, felt=felt)
    theirs = cli_render(cli, tmp_path, str(scene_file), "--actuator", name, *(["--felt"] if felt else []))
    assert np.any(ours != 0), "a silent render proves nothing"
    assert same_bits(ours, theirs)
    if name != "flat" or felt:
        # The profile reached the render: without it the samples differ.
        assert not same_bits(ours, sake_glug.render(SCENE))


def test_a_profile_file_renders_as_the_cli_whether_named_by_str_or_path(cli, tmp_path, scene_file):
    profile = tmp_path / "bench.toml"
    profile.write_text(PROFILE)
    theirs = cli_render(cli, tmp_path, str(scene_file), "--actuator", str(profile))
    assert same_bits(sake_glug.render(SCENE, actuator=profile), theirs)
    assert same_bits(sake_glug.render(scene_file, actuator=str(profile)), theirs)
    assert not same_bits(theirs, sake_glug.render(SCENE))


def test_the_tables_with_a_profile_are_the_command_lines_files(cli, tmp_path, scene_file):
    tables = sake_glug.render_tables(SCENE, actuator="phone", felt=True)
    samples = cli_render(
        cli, tmp_path, str(scene_file), "--actuator", "phone", "--felt",
        "--units", str(tmp_path / "units.csv"), "--state", str(tmp_path / "state.csv"),
    )
    assert same_bits(tables.samples, samples)
    for table, name in [(tables.units, "units.csv"), (tables.state, "state.csv")]:
        header, rows = read_csv(tmp_path / name)
        assert list(table) == header and len(rows) > 0
        for index, column in enumerate(header):
            assert np.array_equal(table[column], rows[:, index]), column


@pytest.mark.parametrize(
    "line, replacement, key",
    [
        ("band_hz = [60.0, 800.0]", "band_hz = [800.0, 60.0]", "band_hz"),
        ("max_amplitude = 0.9", "max_amplitude = -1.0", "max_amplitude"),
        ("[120.0, -3.0], ", "[20.0, -3.0], ", "response"),
    ],
)
def test_a_bad_profile_is_refused_naming_the_file_and_the_key_as_the_cli_does(
    cli, tmp_path, monkeypatch, line, replacement, key
):
    # A short relative path, which the message gives whole (a long one is cut short).
    monkeypatch.chdir(tmp_path)
    profile = Path("bad.toml")
    assert line in PROFILE
    profile.write_text(PROFILE.replace(line, replacement))
    done = run_cli(cli, "render", "--actuator", str(profile), "-o", "x.wav", cwd=tmp_path)
    assert done.returncode == 2 and not (tmp_path / "x.wav").exists()
    for render in (sake_glug.render, sake_glug.render_tables):
        with pytest.raises(sake_glug.SakeGlugError) as refused:
            render(SCENE, actuator=profile)
        message = str(refused.value)
        assert "bad.toml" in message and f"`{key}`" in message, message
        assert f"error: --{message}" in done.stderr


def test_an_unknown_name_and_felt_alone_are_refused():
    with pytest.raises(sake_glug.SakeGlugError, match="haptuator-mark2"):
        sake_glug.render(SCENE, actuator="no-such-device")
    with pytest.raises(sake_glug.SakeGlugError, match="needs an actuator"):
        sake_glug.render(SCENE, felt=True)
    with pytest.raises(TypeError, match="actuator"):
        sake_glug.render(SCENE, actuator=3)
