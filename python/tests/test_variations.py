"""Seeds, sets of takes, trimming and the silent render's warning: the module against
`sake-glug render --seed / --variations / --take-from / --trim` of the same scene, bit for bit,
with the same messages (MODEL.md §10.2)."""

import csv
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import sake_glug
from conftest import cli_render, read_f32_wav, run_cli

SET_SCENE = """\
tilt_deg = [[0.0, 90.0], [0.5, 135.0]]

[variations]
count = 4
tilt_end_deg = [120, 150]
ramp_s = [0.3, 0.8]
fill_percent = [60, 100]
viscosity_c = [0.2, 0.5]
glug.f1_hz = [70, 90]
"""


def same_bits(ours: np.ndarray, theirs: np.ndarray) -> bool:
    return ours.shape == theirs.shape and np.array_equal(ours.view(np.uint32), theirs.view(np.uint32))


@pytest.fixture
def set_file(tmp_path: Path) -> Path:
    path = tmp_path / "set.toml"
    path.write_text(SET_SCENE)
    return path


def test_seed_overrides_the_scenes_as_the_cli_does(cli, tmp_path):
    ours = sake_glug.render(seed=42)
    assert same_bits(ours, cli_render(cli, tmp_path, "--seed", "42"))
    assert not same_bits(ours, sake_glug.render())


def test_a_set_is_the_clis_set_and_a_row_renders_its_take_again(cli, tmp_path, set_file):
    out = tmp_path / "out"
    out.mkdir()
    done = run_cli(cli, "render", str(set_file), "--seed", "9", "--trim", "-o", str(out / "set.wav"))
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader((out / "set.variations.csv").open()))
    manifest = json.loads((out / "set.variations.json").read_text())
    takes = sake_glug.render_variations(set_file, seed=9, trim=True)
    assert len(takes) == len(rows) == 4
    for (row, samples), cli_row, json_row in zip(takes, rows, manifest["takes"]):
        number = row["take"]
        assert same_bits(samples, read_f32_wav(out / f"set_{number:02d}.wav")), number
        # The row is the manifest's, value for value (the CSV's text reads back as the same float;
        # an option the set was rendered without is empty there, None here).
        assert {key: None if value is None else float(value) for key, value in row.items()} == {
            key: float(value) if value else None for key, value in cli_row.items() if key != "name"
        }
        assert row["trim_db"] == -60.0 and row["loudness_target_lufs"] is None
        assert {**row, "name": f"set_{number:02d}"} == json_row
        # The row alone renders the take again, with the set's trim it records; so does the
        # CLI's JSON row. A trim that is not the set's is refused.
        assert same_bits(sake_glug.render(set_file, take=row, trim=True), samples)
        assert same_bits(sake_glug.render(set_file, take=row), samples)
        assert same_bits(sake_glug.render(set_file, take=json_row), samples)
        assert same_bits(sake_glug.render_tables(set_file, take=row).samples, samples)
        with pytest.raises(sake_glug.SakeGlugError, match="the set's takes were rendered with --trim -60"):
            sake_glug.render(set_file, take=row, trim=-40.0)
    # The same seed, the same set; the count of the call over the scene's.
    again = sake_glug.render_variations(set_file, seed=9, trim=True, count=2)
    assert [row for row, _ in again] == [row for row, _ in takes[:2]]


def test_trim_is_the_clis(cli, tmp_path):
    for level, args in ((True, ["--trim"]), (-40.0, ["--trim=-40"])):
        ours = sake_glug.render(preset="syrup", trim=level)
        assert same_bits(ours, cli_render(cli, tmp_path, "--preset", "syrup", *args))
        assert ours.size < sake_glug.render(preset="syrup").size
    tables = sake_glug.render_tables(trim=True)
    assert same_bits(tables.samples, sake_glug.render(trim=True))
    for bad in (0.0, 3.0, float("nan")):
        with pytest.raises(sake_glug.SakeGlugError, match="--trim"):
            sake_glug.render(trim=bad)


def test_bad_ranges_are_refused_naming_the_key_as_the_cli_does(cli, tmp_path):
    for table, key in (
        ("fill_percent = [90, 60]", "variations.fill_percent"),
        ("viscosity_c = [0.2, 1.5]", "variations.viscosity_c"),
        ("glug.f1_hz = [nan, 90]", "variations.glug.f1_hz"),
        ("fill = [60, 100]", "unknown key `fill` in [variations]"),
    ):
        scene = tmp_path / "bad.toml"
        scene.write_text(f"tilt_deg = 135\n[variations]\ncount = 2\n{table}\n")
        done = run_cli(cli, "render", str(scene), "-o", str(tmp_path / "bad.wav"))
        assert done.returncode == 1
        with pytest.raises(sake_glug.SakeGlugError) as raised:
            sake_glug.render_variations(scene)
        assert key in str(raised.value)
        assert str(raised.value) in done.stderr


def test_a_take_that_is_no_row_is_refused():
    with pytest.raises(sake_glug.SakeGlugError, match="unknown column `fill`"):
        sake_glug.render(take={"seed": 1, "fill": 3.0})
    with pytest.raises(sake_glug.SakeGlugError, match="needs its `seed`"):
        sake_glug.render(take={"fill_percent": 80.0})
    with pytest.raises(TypeError):
        sake_glug.render(take=[1, 2])


def test_a_render_that_pours_nothing_warns_why_as_the_cli_does(cli, tmp_path):
    for scene in ("seed = 7\n[glug]\nf1_hz = 90\n", "tilt_deg = 135\nfill_percent = 0\n"):
        path = tmp_path / "quiet.toml"
        path.write_text(scene)
        done = run_cli(cli, "render", str(path), "-o", str(tmp_path / "quiet.wav"))
        assert done.returncode == 0
        reason = done.stderr.strip().removeprefix("warning: quiet: ")
        assert reason.startswith("nothing sounds: "), done.stderr
        with pytest.warns(UserWarning) as caught:
            sake_glug.render(scene)
        assert [str(warning.message) for warning in caught] == [reason]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sake_glug.render()
