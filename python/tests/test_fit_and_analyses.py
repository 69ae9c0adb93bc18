"""fit(), analyze_paired(), analyze_constant() and analyze_discrimination(): the numbers of `sake-glug fit` and
`sake-glug analyze … --json` for the same inputs."""

import json
import random

import pytest

import sake_glug
from conftest import run_cli


def write_paired_log(path):
    stimuli = ["model", "high", "low"]
    preference = {"model": 2.0, "high": 1.0, "low": 0.0}
    chance = random.Random(5)
    rows = ["participant,first,second,answer"]
    for participant in range(4):
        for first in stimuli:
            for second in stimuli:
                if first == second:
                    continue
                for _ in range(3):
                    edge = preference[first] - preference[second]
                    answer = first if chance.random() < 1 / (1 + 10 ** (-edge / 2)) else second
                    rows.append(f"p{participant},{first},{second},{answer}")
    path.write_text("\n".join(rows) + "\n")


def write_constant_log(path, participants=2):
    chance = random.Random(9)
    rows = ["participant,level,chose_comparison"]
    for participant in range(participants):
        for level in [0.18, 0.22, 0.26, 0.29, 0.33, 0.37, 0.41, 0.45, 0.49]:
            for _ in range(10):
                chosen = chance.random() < 1 / (1 + 2.718 ** (-(level - 0.35) / 0.04))
                rows.append(f"p{participant},{level},{int(chosen)}")
    path.write_text("\n".join(rows) + "\n")


def test_the_paired_analysis_is_the_command_lines(cli, tmp_path):
    log = tmp_path / "paired.csv"
    write_paired_log(log)
    done = run_cli(cli, "analyze", "paired", str(log), "--json")
    assert done.returncode == 0, done.stderr
    assert sake_glug.analyze_paired([log]) == json.loads(done.stdout)


def test_the_constant_analysis_is_the_command_lines(cli, tmp_path):
    log = tmp_path / "constant.csv"
    write_constant_log(log)
    done = run_cli(
        cli, "analyze", "constant", str(log), "--json", "--resamples", "200", "--seed", "4"
    )
    assert done.returncode == 0, done.stderr
    analysis = sake_glug.analyze_constant([log], resamples=200, seed=4)
    assert analysis == json.loads(done.stdout)
    assert set(analysis["points"]) == {"25", "50", "75"}


def test_the_discrimination_analysis_is_the_command_lines(cli, tmp_path):
    log = tmp_path / "triangle.csv"
    chance = random.Random(3)
    rows = ["participant,trial,design,correct"]
    for participant in range(3):
        for trial in range(12):
            rows.append(f"p{participant},{trial + 1},triangle,{int(chance.random() < 0.6)}")
    log.write_text("\n".join(rows) + "\n")
    done = run_cli(cli, "analyze", "discrimination", str(log), "--json")
    assert done.returncode == 0, done.stderr
    analysis = sake_glug.analyze_discrimination([log])
    assert analysis == json.loads(done.stdout)
    assert analysis["design"] == "triangle" and analysis["trials"] == 36
    assert set(analysis["participants"]) == {"p0", "p1", "p2"}


def test_a_bad_log_raises_the_command_lines_message(cli, tmp_path):
    log = tmp_path / "bad.csv"
    log.write_text("participant,first,second,answer\np1,a,b,c\n")
    done = run_cli(cli, "analyze", "paired", str(log))
    with pytest.raises(sake_glug.SakeGlugError) as error:
        sake_glug.analyze_paired([log])
    assert str(error.value) in done.stderr


def test_the_fit_gives_the_model_the_command_line_writes(cli, tmp_path):
    scene = tmp_path / "pour.toml"
    scene.write_text("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 3.0\n")
    done = run_cli(cli, "render", str(scene), "-o", str(tmp_path / "pour.wav"))
    assert done.returncode == 0, done.stderr
    session = tmp_path / "session.toml"
    session.write_text('[[recording]]\naudio = "pour.wav"\ntilt_deg = 135.0\nstart_ml = 300.0\n')
    done = run_cli(cli, "fit", str(session), "-o", str(tmp_path / "model.toml"))
    assert done.returncode == 0, done.stderr
    fitted = sake_glug.fit(session)
    (liquid,) = fitted["liquids"].values()
    assert liquid["model"] == (tmp_path / "model.toml").read_text()
    f1 = liquid["estimates"]["glug.f1_hz"]
    assert f1["in_model"] and abs(f1["value"] / 80.0 - 1) < 0.03
    with pytest.raises(sake_glug.SakeGlugError) as error:
        sake_glug.fit(tmp_path / "absent.toml")
    assert "absent.toml" in str(error.value)
