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


def render_clip(cli, tmp_path, name="glugs.wav"):
    """A 3 s pour at 25 kHz, as a recording of glugs would come."""
    scene = tmp_path / "clip.toml"
    scene.write_text("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 3.0\n")
    done = run_cli(cli, "render", str(scene), "-o", str(tmp_path / name))
    assert done.returncode == 0, done.stderr
    return tmp_path / name


def test_a_bare_clip_is_fitted_as_the_command_line_fits_it(cli, tmp_path):
    clip = render_clip(cli, tmp_path)
    done = run_cli(cli, "fit", str(clip), "--json")
    assert done.returncode == 0, done.stderr
    assert sake_glug.fit(clip) == json.loads(done.stdout)
    assert sake_glug.fit(str(clip)) == json.loads(done.stdout)
    # The clips' bottle, as --capacity-ml and --tilt-deg give it; a list of clips.
    other = render_clip(cli, tmp_path, "again.wav")
    done = run_cli(
        cli, "fit", str(clip), str(other), "--capacity-ml", "500", "--tilt-deg", "120", "--json"
    )
    assert done.returncode == 0, done.stderr
    fitted = sake_glug.fit([clip, str(other)], capacity_ml=500, tilt_deg=120)
    assert fitted == json.loads(done.stdout)
    assert set(fitted["explained"]) == {str(clip), str(other)}


def test_what_a_fit_of_clips_refuses_is_said_as_the_command_line_says_it(cli, tmp_path):
    clip = render_clip(cli, tmp_path)
    # An option out of range, named as the argument that gave it.
    done = run_cli(cli, "fit", str(clip), "--tilt-deg", "200", "--json")
    assert done.returncode == 1 and "--tilt-deg 200: a tilt lies within 0 to 180 degrees" in done.stderr
    with pytest.raises(sake_glug.SakeGlugError, match=r"^tilt_deg=200: a tilt lies within 0 to 180 degrees$"):
        sake_glug.fit(clip, tilt_deg=200)
    with pytest.raises(sake_glug.SakeGlugError, match=r"^capacity_ml=0: outside the capacity's range"):
        sake_glug.fit(clip, capacity_ml=0)
    # A session file with the clips' options, or among clips; no input at all.
    session = tmp_path / "session.toml"
    session.write_text('[[recording]]\naudio = "glugs.wav"\ntilt_deg = 135.0\nstart_ml = 300.0\n')
    for args, call in [
        ((str(session), "--capacity-ml", "500"), lambda: sake_glug.fit(session, capacity_ml=500)),
        ((str(session), str(clip)), lambda: sake_glug.fit([session, clip])),
    ]:
        done = run_cli(cli, "fit", *args, "--json")
        assert done.returncode == 2, done.stderr
        with pytest.raises(sake_glug.SakeGlugError) as error:
            call()
        assert f"error: {error.value}\n" == done.stderr
    with pytest.raises(sake_glug.SakeGlugError, match="no recording: name a session file or WAV clips"):
        sake_glug.fit([])
    with pytest.raises(TypeError, match="a session file or a WAV clip"):
        sake_glug.fit(3)


def test_a_dry_runs_log_is_refused_unless_asked_for_and_then_counted(cli, tmp_path):
    log = tmp_path / "paired.csv"
    write_paired_log(log)
    rows = log.read_text().splitlines()
    # The experiment marks a dry run's rows; the first two trials here were a dry run's.
    marked = [rows[0] + ",dry_run"] + [row + (",1" if n < 2 else ",0") for n, row in enumerate(rows[1:])]
    log.write_text("\n".join(marked) + "\n")
    done = run_cli(cli, "analyze", "paired", str(log), "--json")
    assert done.returncode == 1
    with pytest.raises(sake_glug.SakeGlugError) as error:
        sake_glug.analyze_paired([log])
    assert f"error: {error.value}\n" == done.stderr
    done = run_cli(cli, "analyze", "paired", str(log), "--json", "--dry-run-logs")
    assert done.returncode == 0, done.stderr
    assert "2 of these trials were answered in a dry run" in done.stderr
    analysis = sake_glug.analyze_paired([log], dry_run_logs=True)
    assert analysis == json.loads(done.stdout)
    assert analysis["dry_run_trials"] == 2


def test_the_constant_analysis_reads_a_dry_run_only_when_asked(cli, tmp_path):
    log = tmp_path / "constant.csv"
    write_constant_log(log)
    rows = log.read_text().splitlines()
    log.write_text("\n".join([rows[0] + ",dry_run"] + [row + ",1" for row in rows[1:]]) + "\n")
    with pytest.raises(sake_glug.SakeGlugError, match="a dry run's trial"):
        sake_glug.analyze_constant([log], resamples=50)
    analysis = sake_glug.analyze_constant([log], resamples=50, dry_run_logs=True)
    assert analysis["dry_run_trials"] == len(rows) - 1


def test_the_discrimination_analysis_reads_a_dry_run_only_when_asked(cli, tmp_path):
    log = tmp_path / "triangle.csv"
    rows = ["participant,trial,design,correct,dry_run"]
    rows += [f"p1,{trial + 1},triangle,{trial % 2},1" for trial in range(12)]
    log.write_text("\n".join(rows) + "\n")
    with pytest.raises(sake_glug.SakeGlugError, match="a dry run's trial"):
        sake_glug.analyze_discrimination([log])
    done = run_cli(cli, "analyze", "discrimination", str(log), "--json", "--dry-run-logs")
    assert done.returncode == 0, done.stderr
    analysis = sake_glug.analyze_discrimination([log], dry_run_logs=True)
    assert analysis == json.loads(done.stdout) and analysis["dry_run_trials"] == 12
