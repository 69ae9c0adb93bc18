"""render_tables(): the samples of render() with the glug data, the same rows as the files of
`sake-glug render --units/--state` for the same scene."""

import csv

import numpy as np
import pytest

import sake_glug
from conftest import cli_render, run_cli

SCENE = "tilt_deg = [[0.0, 90.0], [0.5, 135.0]]\nduration_s = 2.0\nseed = 3\n"


def read_csv(path):
    with open(path, newline="") as file:
        rows = list(csv.reader(file))
    return rows[0], np.array(rows[1:], dtype=float).reshape(len(rows) - 1, len(rows[0]))


@pytest.mark.parametrize("state_rate", [1000.0, 441.0])
def test_the_tables_are_the_command_lines_files(cli, tmp_path, state_rate):
    tables = sake_glug.render_tables(SCENE, state_rate=state_rate)
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE)
    samples = cli_render(
        cli,
        tmp_path,
        str(scene),
        "--units",
        str(tmp_path / "units.csv"),
        "--state",
        str(tmp_path / "state.csv"),
        "--state-rate",
        repr(state_rate),
    )
    assert tables.samples.dtype == np.float32
    assert np.array_equal(tables.samples.view(np.uint32), samples.view(np.uint32))
    for table, name in [(tables.units, "units.csv"), (tables.state, "state.csv")]:
        header, rows = read_csv(tmp_path / name)
        assert list(table) == header
        assert len(rows) > 0
        for index, column in enumerate(header):
            # The files write each number's shortest round trip: equal to the bit.
            assert np.array_equal(table[column], rows[:, index]), column


def test_a_state_rate_the_render_cannot_take_is_refused_with_the_command_lines_message(cli):
    with pytest.raises(sake_glug.SakeGlugError) as error:
        sake_glug.render_tables(SCENE, state_rate=96000.0)
    done = run_cli(cli, "render", "--state", "s.csv", "--state-rate", "96000")
    assert done.returncode != 0
    assert str(error.value).split(": ", 1)[-1] in done.stderr
    with pytest.raises(sake_glug.SakeGlugError):
        sake_glug.render_tables(SCENE, state_rate=0.0)
