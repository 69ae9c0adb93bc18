"""The level stage (MODEL.md §19) in Python: render(loudness=, true_peak=) and
render_variations(loudness=, true_peak=) against `sake-glug render --loudness / --true-peak` of
the same scene, bit for bit (the same Rust function), with the same messages for what both
refuse; and a set's rows carry each take's measured level, as its manifest does."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import sake_glug
from conftest import cli_render, read_f32_wav, run_cli


def same_bits(ours: np.ndarray, theirs: np.ndarray) -> bool:
    return ours.shape == theirs.shape and np.array_equal(ours.view(np.uint32), theirs.view(np.uint32))


@pytest.mark.parametrize(
    "kwargs, args",
    [
        ({"loudness": -16.0, "true_peak": -1.0}, ["--loudness", "-16", "--true-peak", "-1"]),
        ({"loudness": -23.0}, ["--loudness", "-23"]),
        ({"true_peak": -12.0}, ["--true-peak", "-12"]),
        ({"preset": "syrup", "trim": True, "loudness": -20.0}, ["--preset", "syrup", "--trim", "--loudness", "-20"]),
    ],
)
def test_a_level_is_the_clis(cli, tmp_path, kwargs, args):
    ours = sake_glug.render(**kwargs)
    assert same_bits(ours, cli_render(cli, tmp_path, *args))
    plain = {key: value for key, value in kwargs.items() if key not in ("loudness", "true_peak")}
    assert not same_bits(ours, sake_glug.render(**plain)), "the level stage changed nothing"


def test_what_cannot_be_levelled_is_refused_with_the_clis_message(cli, tmp_path):
    for name, scene in (
        ("short", "tilt_deg = 135\nduration_s = 0.3\n"),
        ("silent", "tilt_deg = 135\nfill_percent = 0\nduration_s = 2.0\n"),
    ):
        path = tmp_path / f"{name}.toml"
        path.write_text(scene)
        done = run_cli(cli, "render", str(path), "--loudness", "-23", "-o", str(tmp_path / f"{name}.wav"))
        assert done.returncode == 1, done.stderr
        assert not (tmp_path / f"{name}.wav").exists()
        with pytest.raises(sake_glug.SakeGlugError) as raised:
            sake_glug.render(path, loudness=-23.0)
        message = str(raised.value)
        assert message.startswith("--loudness: "), message
        assert f"error: {name}: {message}" in done.stderr
    # A ceiling alone leaves silence as it is, as the command line does.
    with pytest.warns(UserWarning, match="nothing sounds"):
        assert not sake_glug.render(tmp_path / "silent.toml", true_peak=-1.0).any()


@pytest.mark.parametrize(
    "keyword, value, flag, typed",
    [
        ("loudness", -80.0, "--loudness", "-80"),
        ("loudness", 3.0, "--loudness", "3"),
        ("true_peak", -61.0, "--true-peak", "-61"),
        ("true_peak", 0.5, "--true-peak", "0.5"),
    ],
)
def test_bad_levels_are_refused_as_the_cli_refuses_them(cli, tmp_path, keyword, value, flag, typed):
    done = run_cli(cli, "render", flag, typed, "-o", str(tmp_path / "bad.wav"))
    assert done.returncode == 2
    with pytest.raises(sake_glug.SakeGlugError) as raised:
        sake_glug.render(**{keyword: value})
    message = str(raised.value)
    assert message.startswith(f"{keyword}: "), message
    assert message.removeprefix(f"{keyword}: ") in done.stderr
    nan = {keyword: float("nan")}
    with pytest.raises(sake_glug.SakeGlugError, match=keyword):
        sake_glug.render(**nan)
    with pytest.raises(sake_glug.SakeGlugError, match=keyword):
        sake_glug.render_variations(count=1, **nan)


def test_a_levelled_set_is_the_clis_with_each_takes_level(cli, tmp_path):
    scene = tmp_path / "set.toml"
    scene.write_text(
        "tilt_deg = [[0.0, 90.0], [0.5, 135.0]]\n\n[variations]\ncount = 3\nfill_percent = [60, 100]\nviscosity_c = [0.2, 0.5]\n"
    )
    out = tmp_path / "out"
    out.mkdir()
    done = run_cli(
        cli, "render", str(scene), "--seed", "5", "--loudness", "-18", "--true-peak", "-1",
        "-o", str(out / "set.wav"),
    )
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader((out / "set.variations.csv").open()))
    manifest = json.loads((out / "set.variations.json").read_text())
    takes = sake_glug.render_variations(scene, seed=5, loudness=-18.0, true_peak=-1.0)
    assert len(takes) == len(rows) == 3
    for (row, samples), cli_row, json_row in zip(takes, rows, manifest["takes"]):
        number = row["take"]
        assert same_bits(samples, read_f32_wav(out / f"set_{number:02d}.wav")), number
        # The take's level, measured on its samples as written: in the row, the CSV and the JSON.
        assert list(row)[-2:] == ["loudness_lufs", "true_peak_dbtp"]
        assert float(cli_row["loudness_lufs"]) == row["loudness_lufs"] == json_row["loudness_lufs"]
        assert float(cli_row["true_peak_dbtp"]) == row["true_peak_dbtp"] == json_row["true_peak_dbtp"]
        assert row["true_peak_dbtp"] <= -1.0
        assert row["loudness_lufs"] <= -18.0 + 0.05
        # The row, its level columns in it, renders the take again at the same level.
        assert same_bits(sake_glug.render(scene, take=row, loudness=-18.0, true_peak=-1.0), samples)
        # Its level options are in it too: the row alone renders the take at the set's level.
        assert row["loudness_target_lufs"] == -18.0 and row["true_peak_ceiling_dbtp"] == -1.0
        assert same_bits(sake_glug.render(scene, take=row), samples)
        assert same_bits(sake_glug.render(scene, take=json_row), samples)
