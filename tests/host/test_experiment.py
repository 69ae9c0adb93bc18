"""`sake-glug experiment` on JACK and on ALSA, answers piped on stdin.

On JACK: a real JACK server (dummy driver), where a recorder client records the runner's three
output channels in the same JACK cycles, so the frames the log gives for each stimulus's onset
compare directly with the recording. On ALSA: ALSA's `file` PCM, which writes what it is given
into a WAV file (its slave is `null`: no sound card), whose frame n is the n-th frame written,
the runner's position. Checked on both: each trial's two stimuli sit on the actuator channel at
the logged frames, sample for sample what the dry run of the same spec and participant writes
(the level-matched stimuli), with equal peaks; the actuator channel is silent everywhere else;
the masking noise is on the headphone channels alone, at its level, and none of the stimulus
leaks into them. A device ALSA does not know is refused with a message naming it.

The same for a triangle test of a recording against a scene: three stimuli a trial in the
participant's seeded order, the recording resampled to JACK's rate, level-matched, the same
samples at each presentation; and on ALSA a session killed mid-way and resumed.

Needs the release `sake-glug` built with audio (`cargo build --release --bin sake-glug
--no-default-features --features cli,audio`), and `jackd` (Debian's jackd2) for the JACK test.
"""

import csv
import os
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view

from jack_server import LeavableCallback, close_client, connect_once_active, stop, wait_for
from test_standalone import CLI, PERIOD, own_jack_server

NOISE_DBFS = -30.0
SPEC = f"""
design = "paired"
duration_s = 0.5
gap_s = 0.2
repetitions = 1
seed = 5
equalize = "peak"
noise_dbfs = {NOISE_DBFS}

[channels]
actuator = [1]
headphones = [2, 3]

[stimuli.model]
preset = "water"

[stimuli.high]
preset = "water"
viscosity_c = 0.0

[stimuli.low]
preset = "water"
viscosity_c = 1.0
"""
CLIENT = "experiment-under-test"


def read_f32_wav_channels(path):
    """A 32-bit float WAV's channels and sample rate (ALSA's `file` PCM interleaves them).

    Only the sample size is checked: ALSA's `file` PCM labels float samples as integer PCM."""
    data = Path(path).read_bytes()
    fmt = data.index(b"fmt ") + 8
    channels, rate, bits = (int.from_bytes(data[fmt + a : fmt + b], "little")
                            for a, b in ((2, 4), (4, 8), (14, 16)))
    assert bits == 32, f"{path}: {bits}-bit samples"
    at = data.index(b"data")
    size = int.from_bytes(data[at + 4 : at + 8], "little")
    samples = np.frombuffer(data[at + 8 : at + 8 + size], dtype="<f4")
    return list(samples.reshape(-1, channels).T), rate


def read_f32_wav(path):
    """A mono 32-bit float WAV's samples (the format the dry run writes)."""
    (samples,), _ = read_f32_wav_channels(path)
    return samples


# A busy machine can hand the recorder the runner's output under another cycle's frame: the
# JACK server does not wait for its clients (not --sync), so the frame timer moves on (by any
# number of frames after a late cycle) while they run, the runner's port buffer is rewritten
# every cycle, and a recorder in Python (the GIL) reads both whenever it gets to run. Such a
# chunk holds samples the runner played near its frame but not at it. It is left out, as one
# the recorder missed, and counted: a runner that plays wrong samples matches nothing it should
# play, and one that plays them at the wrong frames is "mislabelled" in nearly every chunk, far
# above this share.
MOST_MISLABELLED = 0.1
# The share of the stimuli's frames played that must be compared: a test that
# compared little would prove little.
LEAST_COMPARED = 0.25
# How far (in frames) a mislabelled chunk's samples may lie from its frame.
MISLABEL_REACH = 16 * PERIOD


def without_mislabelled(chunks, timeline, start, channel=0):
    """`chunks` ((frame, arrays) as the recorder took them) without those whose `channel` holds
    not what `timeline` (what the runner plays, from frame `start`) has at the chunk's frame but
    what it has within MISLABEL_REACH frames of it. Fails if they are more than MOST_MISLABELLED
    of the chunks where a stimulus sounds or should."""
    reach = MISLABEL_REACH
    longest = max(len(arrays[channel]) for _, arrays in chunks)
    padded = np.concatenate([np.zeros(reach, np.float32), np.nan_to_num(timeline),
                             np.zeros(reach + longest, np.float32)])
    kept, mislabelled, sounding = [], 0, 0
    for frame, arrays in chunks:
        got = arrays[channel]
        at = frame - start + reach
        # Silence recorded where the runner is silent proves nothing, so is not counted.
        sounding += bool(np.any(got) or np.any(padded[at : at + len(got)]))
        if not np.array_equal(got, padded[at : at + len(got)]):
            nearby = sliding_window_view(padded[at - reach : at + reach + len(got)], len(got))
            if np.all(nearby == got, axis=1).any():
                mislabelled += 1
                continue
        kept.append((frame, arrays))
    assert mislabelled <= MOST_MISLABELLED * sounding, \
        f"{mislabelled} of {sounding} chunks with a stimulus recorded under another frame"
    return kept


def dry_run(tmp_path):
    """Writes the spec and runs its dry run for participant p1: the stimuli as they must be
    heard, in `dry/`."""
    assert CLI.exists(), f"{CLI} is missing: build it with --features cli,audio"
    (tmp_path / "study.toml").write_text(SPEC)
    dry = subprocess.run(
        [CLI, "experiment", "study.toml", "--participant", "p1", "--log", "dry.csv",
         "--dry-run", "dry"],
        cwd=tmp_path, input="\n" + "1\n" * 6, capture_output=True, text=True, timeout=120,
    )
    assert dry.returncode == 0, dry.stderr


@pytest.fixture(scope="module")
def jack_server():
    yield from own_jack_server("sakeglug-experiment", (CLI, "--features cli,audio"))


def test_the_runner_plays_level_matched_stimuli_at_the_logged_frames(jack_server, tmp_path):
    import jack

    dry_run(tmp_path)

    recorder = jack.Client("recorder", servername=jack_server, no_start_server=True)
    inputs = [recorder.inports.register(f"in_{channel}") for channel in (1, 2, 3)]
    chunks = []
    recording = [True]

    def record(frames):
        if recording[0]:
            chunks.append((recorder.last_frame_time, [p.get_array().copy() for p in inputs]))

    callback = LeavableCallback(recorder, record)
    recorder.activate()
    env = dict(os.environ, JACK_DEFAULT_SERVER=jack_server)
    runner = subprocess.Popen(
        [CLI, "experiment", "study.toml", "--participant", "p1", "--log", "log.csv",
         "--client-name", CLIENT],
        cwd=tmp_path, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
    )
    try:
        def ports_up():
            return len(recorder.get_ports(f"{CLIENT}:out_")) == 3

        wait_for(ports_up, 60, "the runner's ports")
        for channel in (1, 2, 3):
            connect_once_active(recorder, f"{CLIENT}:out_{channel}", f"recorder:in_{channel}")
        # Answers typed ahead: each is read once its trial has ended.
        out, err = runner.communicate("\n" + "x\n1\n2\n" * 3, timeout=60)
        assert runner.returncode == 0, err
        assert out.count("Please answer 1 or 2") == 3
        time.sleep(0.1)
    finally:
        stop(runner)
        recording[0] = False
        close_client(recorder, callback)

    rows = list(csv.DictReader(open(tmp_path / "log.csv")))
    # Each cycle's samples at its frame; a cycle the recorder missed (a busy machine) stays NaN.
    start = chunks[0][0]
    length = chunks[-1][0] + len(chunks[-1][1][0]) - start
    chunks = without_mislabelled(chunks, paired_timeline(tmp_path, rows, start, length), start)
    recorded = [np.full(length, np.nan, dtype=np.float32) for _ in range(3)]
    runner_missed = 0
    previous_noise = None
    for frame, arrays in chunks:
        # A cycle the runner missed under load shows on the noise channel, which is never
        # silent and never repeats: silence, or the previous cycle's buffer again. Such a cycle
        # is not the runner's output, and is left out like one the recorder missed.
        stale = previous_noise is not None and np.array_equal(arrays[1], previous_noise)
        previous_noise = arrays[1]
        if not np.any(arrays[1]) or stale:
            runner_missed += 1
            continue
        for channel, array in zip(recorded, arrays):
            channel[frame - start : frame - start + len(array)] = array
    print(f"cycles recorded {len(chunks)}, frames missed {np.isnan(recorded[0]).sum()} of "
          f"{length}, cycles without the runner {runner_missed}")
    check_recording(tmp_path, rows, recorded, start)


def paired_timeline(tmp_path, rows, start, length):
    """What the runner plays on the actuator from frame `start`, `length` frames: the dry run's
    stimuli at the logged onsets, silence elsewhere."""
    trials = list(csv.DictReader(open(tmp_path / "dry" / "trials.csv")))
    timeline = np.zeros(length, np.float32)
    for row, trial in zip(rows, trials):
        for place in ("first", "second"):
            expected = read_f32_wav(tmp_path / "dry" / trial[f"{place}_file"])
            at = int(row[f"{place}_onset_frame"]) - start
            timeline[at : at + len(expected)] = expected[: max(length - at, 0)]
    return timeline


def test_the_runner_plays_on_alsa_level_matched_stimuli_at_the_logged_frames(tmp_path):
    dry_run(tmp_path)
    recording = tmp_path / "out.wav"
    began = time.monotonic()
    # Answers typed ahead: each is read once its trial has ended.
    runner = subprocess.run(
        [CLI, "experiment", "study.toml", "--participant", "p1", "--log", "log.csv",
         "--audio", "alsa", "--alsa-device", f"file:FILE={recording},FORMAT=wav"],
        cwd=tmp_path, input="\n" + "x\n1\n2\n" * 3, capture_output=True, text=True,
        timeout=120,
    )
    took = time.monotonic() - began
    assert runner.returncode == 0, runner.stderr
    assert runner.stdout.count("Please answer 1 or 2") == 3
    recorded, rate = read_f32_wav_channels(recording)
    assert rate == 48000 and len(recorded) == 3
    seconds = len(recorded[0]) / rate
    print(f"recorded {len(recorded[0])} frames ({seconds:.2f} s) in a run of {took:.2f} s")
    # The `file` PCM takes samples as fast as they come; the runner then keeps to the clock,
    # so that the recording lasts no longer than the session did (give or take the period it
    # writes ahead).
    assert seconds <= took + 0.1
    rows = list(csv.DictReader(open(tmp_path / "log.csv")))
    check_recording(tmp_path, rows, recorded, 0)


def test_an_alsa_device_alsa_does_not_know_is_refused_by_name(tmp_path):
    assert CLI.exists(), f"{CLI} is missing: build it with --features cli,audio"
    (tmp_path / "study.toml").write_text(SPEC)
    result = subprocess.run(
        [CLI, "experiment", "study.toml", "--participant", "p1", "--log", "log.csv",
         "--audio", "alsa", "--alsa-device", "sake-glug-no-such-device"],
        cwd=tmp_path, input="\n", capture_output=True, text=True, timeout=120,
    )
    assert result.returncode == 1, result.stderr
    assert "error: ALSA device `sake-glug-no-such-device`: cannot open it" in result.stderr
    assert not (tmp_path / "log.csv").exists(), "nothing was logged"


@pytest.mark.parametrize("options, says", [
    (["--alsa-device", "hw:1"], "--alsa-device names an ALSA device: add `--audio alsa`"),
    (["--audio", "alsa", "--client-name", "x"], "--client-name names a JACK client"),
])
def test_an_option_of_the_other_audio_interface_is_refused(tmp_path, options, says):
    assert CLI.exists(), f"{CLI} is missing: build it with --features cli,audio"
    (tmp_path / "study.toml").write_text(SPEC)
    result = subprocess.run(
        [CLI, "experiment", "study.toml", "--participant", "p1", "--log", "log.csv", *options],
        cwd=tmp_path, capture_output=True, text=True, timeout=60,
    )
    assert result.returncode == 2 and says in result.stderr, result.stderr


def check_recording(tmp_path, rows, recorded, start):
    """The runner's three channels as recorded from frame `start` of its output (NaN where a
    frame was not recorded) hold the stimuli of the logged trials at their logged frames and
    the noise on the headphone channels alone."""
    trials = list(csv.DictReader(open(tmp_path / "dry" / "trials.csv")))
    assert len(rows) == 6
    missed = np.isnan(recorded[0])
    actuator = recorded[0]
    stimulus_mask = np.zeros(len(actuator), dtype=bool)
    # A busy machine may leave any one stimulus mostly unrecorded, but not all of them.
    compared, presented = 0, 0
    peaks = {}
    for row, trial in zip(rows, trials):
        assert (row["first"], row["second"]) == (trial["first"], trial["second"])
        assert float(row["rt_s"]) >= 0.0
        assert row["answer"] == (row["first"] if row["pressed"] == "1" else row["second"])
        for place in ("first", "second"):
            expected = read_f32_wav(tmp_path / "dry" / trial[f"{place}_file"])
            at = int(row[f"{place}_onset_frame"]) - start
            assert 0 <= at and at + len(expected) <= len(actuator), "recorded whole"
            heard = actuator[at : at + len(expected)]
            # Compared where the recorder ran (a busy machine may skip a cycle of the graph).
            kept = ~np.isnan(heard)
            compared += kept.sum()
            presented += len(kept)
            wrong = np.nonzero(kept & (heard != expected))[0]
            assert len(wrong) == 0, f"trial {row['trial']} {place} ({row[place]}): {len(wrong)} " \
                f"samples differ from the dry run's, the first at {wrong[:1]} of {len(expected)}"
            stimulus_mask[at : at + len(expected)] = True
            peaks[row[place]] = np.max(np.abs(expected))
            assert np.max(np.abs(heard[kept])) <= peaks[row[place]]
        gap = int(row["second_onset_frame"]) - int(row["first_onset_frame"])
        assert gap == len(read_f32_wav(tmp_path / "dry" / trial["first_file"])) + round(0.2 * 48000)
    assert len(peaks) == 3
    assert compared > LEAST_COMPARED * presented, \
        f"{compared} of {presented} frames of the stimuli recorded"
    assert max(peaks.values()) / min(peaks.values()) - 1 < 1e-6, f"peaks matched: {peaks}"
    recorded_ok = ~missed
    assert not np.any(actuator[~stimulus_mask & recorded_ok]), "the actuator is silent between"
    target = 10 ** (NOISE_DBFS / 20)
    # The session: from the first onset to the last stimulus's end (before it, the recorder
    # was not yet connected).
    session = np.zeros(len(actuator), dtype=bool)
    session[np.argmax(stimulus_mask) : len(actuator) - np.argmax(stimulus_mask[::-1])] = True
    session &= recorded_ok
    for headphone in recorded[1:]:
        during = np.sqrt(np.mean(headphone[stimulus_mask & session] ** 2))
        outside = np.sqrt(np.mean(headphone[session & ~stimulus_mask] ** 2))
        assert abs(during / target - 1) < 0.05 and abs(outside / target - 1) < 0.05
        # No stimulus in the noise: uncorrelated with the actuator's signal.
        both = stimulus_mask & session
        correlation = np.corrcoef(headphone[both], actuator[both])[0, 1]
        assert abs(correlation) < 0.05, correlation


# A triangle test of a recording (44.1 kHz) against the built-in pour: the recording is
# resampled to a 48 kHz interface, level-matched by RMS, the same samples at every presentation.
RECORDING = Path(__file__).resolve().parents[1] / "fixtures" / "recordings" / \
    "isbeorn-bottle-glugs-44k.wav"
TRIANGLE_SPEC = f"""
design = "triangle"
duration_s = 0.4
gap_s = 0.2
repetitions = 1
seed = 11
equalize = "rms"

[stimuli.recording]
audio = "{RECORDING}"

[stimuli.model]
preset = "water"
"""
TRIANGLE_TRIALS = 6
PLACES = ("first", "second", "third")


def triangle_dry_run(tmp_path, participant="p1"):
    """The triangle spec written, and its dry run's trial list for `participant` (the seeded
    order; the dry run plays at the recording's own rate, so only its order is compared)."""
    assert CLI.exists(), f"{CLI} is missing: build it with --features cli,audio"
    (tmp_path / "triangle.toml").write_text(TRIANGLE_SPEC)
    dry = subprocess.run(
        [CLI, "experiment", "triangle.toml", "--participant", participant, "--dry-run",
         f"dry-{participant}", "--no-answers"],
        cwd=tmp_path, capture_output=True, text=True, timeout=120,
    )
    assert dry.returncode == 0, dry.stderr
    return list(csv.DictReader(open(tmp_path / f"dry-{participant}" / "trials.csv")))


def check_triangle_log(rows, trials):
    """The log holds the seeded order, and whether each answer named the odd one."""
    assert len(rows) == TRIANGLE_TRIALS
    for row, trial in zip(rows, trials):
        assert row["design"] == "triangle"
        assert tuple(row[place] for place in PLACES) == tuple(trial[place] for place in PLACES)
        played = [row[place] for place in PLACES]
        chosen = played[int(row["pressed"]) - 1]
        assert row["answer"] == chosen
        assert row["correct"] == ("1" if played.count(chosen) == 1 else "0")


def check_triangle_recording(rows, actuator, start, rate):
    """Each trial's three stimuli on the actuator at their logged frames (NaN: not recorded),
    the gap between them; every presentation of a stimulus the same samples, as long as the
    spec's duration at the interface's rate, and the two stimuli at one RMS level."""
    length = round(0.4 * rate)
    heard = {}
    compared, presented = 0, 0
    for row in rows:
        onsets = [int(row[f"{place}_onset_frame"]) - start for place in PLACES]
        assert onsets[1] - onsets[0] == onsets[2] - onsets[1] == length + round(0.2 * rate)
        for place, at in zip(PLACES, onsets):
            samples = actuator[at : at + length]
            assert len(samples) == length, "recorded whole"
            name = row[place]
            if name in heard:
                kept = ~np.isnan(samples) & ~np.isnan(heard[name])
                compared += kept.sum()
                presented += len(kept)
                assert np.array_equal(samples[kept], heard[name][kept]), \
                    f"trial {row['trial']}: `{name}` differs from its earlier presentations"
                # A frame the recorder missed in one presentation is filled from another.
                missing = np.isnan(heard[name])
                heard[name][missing] = samples[missing]
            else:
                heard[name] = samples.copy()
            # Silence before and after, up to the gap.
            assert not np.any(np.nan_to_num(actuator[at + length : at + length + 100]))
    assert set(heard) == {"recording", "model"}
    assert compared > LEAST_COMPARED * presented, \
        f"{compared} of {presented} frames compared with an earlier presentation"
    assert not any(np.isnan(samples).any() for samples in heard.values()), \
        "every frame of each stimulus heard in one presentation or another"
    levels = {name: np.sqrt(np.mean(samples.astype(np.float64) ** 2))
              for name, samples in heard.items()}
    assert abs(levels["recording"] / levels["model"] - 1) < 1e-3, f"RMS matched: {levels}"


def triangle_timeline(rows, actuator, start, rate):
    """What the runner plays on the actuator as recorded (`actuator`, from frame `start`, NaN
    where not recorded): each stimulus as most of its presentations hold it, cycle by cycle
    from its onset, at every logged onset; silence elsewhere."""
    length = round(0.4 * rate)
    onsets = {}
    for row in rows:
        for place in PLACES:
            onsets.setdefault(row[place], []).append(int(row[f"{place}_onset_frame"]) - start)
    timeline = np.zeros(len(actuator), np.float32)
    for name, ats in onsets.items():
        presentations = [actuator[at : at + length] for at in ats if at + length <= len(actuator)]
        stimulus = np.zeros(length, np.float32)
        for begin in range(0, length, PERIOD):
            versions = [samples[begin : begin + PERIOD] for samples in presentations
                        if not np.isnan(samples[begin : begin + PERIOD]).any()]
            if versions:
                keys = [version.tobytes() for version in versions]
                stimulus[begin : begin + PERIOD] = max(
                    versions, key=lambda version: keys.count(version.tobytes()))
        for at in ats:
            timeline[at : at + length] = stimulus[: max(len(actuator) - at, 0)]
    return timeline


def test_a_triangle_test_of_a_recording_plays_on_jack_in_the_seeded_order(jack_server, tmp_path):
    import jack

    trials = triangle_dry_run(tmp_path)
    recorder = jack.Client("recorder3", servername=jack_server, no_start_server=True)
    inport = recorder.inports.register("in_1")
    chunks = []
    recording = [True]

    def record(frames):
        if recording[0]:
            chunks.append((recorder.last_frame_time, inport.get_array().copy()))

    callback = LeavableCallback(recorder, record)
    recorder.activate()
    env = dict(os.environ, JACK_DEFAULT_SERVER=jack_server)
    client = "triangle-under-test"
    runner = subprocess.Popen(
        [CLI, "experiment", "triangle.toml", "--participant", "p1", "--log", "log.csv",
         "--client-name", client],
        cwd=tmp_path, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
    )
    try:
        wait_for(lambda: len(recorder.get_ports(f"{client}:out_")) == 1, 60, "the runner's port")
        connect_once_active(recorder, f"{client}:out_1", "recorder3:in_1")
        # Key 4 is no answer in a triangle: asked again.
        out, err = runner.communicate("\n" + "4\n1\n2\n3\n" * 2, timeout=60)
        assert runner.returncode == 0, err
        assert out.count("Please answer 1, 2 or 3") == 2
        assert "(48000 Hz)" in out
        time.sleep(0.1)
    finally:
        stop(runner)
        recording[0] = False
        close_client(recorder, callback)
    rows = list(csv.DictReader(open(tmp_path / "log.csv")))
    check_triangle_log(rows, trials)
    start = chunks[0][0]
    length = chunks[-1][0] + len(chunks[-1][1]) - start

    def assembled(chunks):
        actuator = np.full(length, np.nan, dtype=np.float32)
        for frame, array in chunks:
            actuator[frame - start : frame - start + len(array)] = array
        return actuator

    # What the runner plays: each stimulus as most of its presentations hold it.
    chunks = without_mislabelled([(frame, [array]) for frame, array in chunks],
                                 triangle_timeline(rows, assembled(chunks), start, 48000), start)
    check_triangle_recording(rows, assembled([(frame, array) for frame, (array,) in chunks]),
                             start, 48000)


def test_a_triangle_test_killed_on_alsa_resumes_in_the_seeded_order(tmp_path):
    """On ALSA's `file` device (asked for the recording's rate, 44.1 kHz, and given it): three
    trials answered, the runner killed while it waits for the fourth, then `--resume` plays the
    other three into a second file; the log holds the six in the seeded order."""
    trials = triangle_dry_run(tmp_path)
    first = subprocess.Popen(
        [CLI, "experiment", "triangle.toml", "--participant", "p1", "--log", "log.csv",
         "--audio", "alsa", "--alsa-device", f"file:FILE={tmp_path / 'a.wav'},FORMAT=wav"],
        cwd=tmp_path, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True,
    )
    try:
        first.stdin.write("\n1\n2\n3\n")
        first.stdin.flush()

        def rows_logged():
            log = tmp_path / "log.csv"
            return log.exists() and len(list(csv.DictReader(open(log)))) == 3

        wait_for(rows_logged, 60, "three rows in the log")
    finally:
        stop(first, signal.SIGKILL)
    resumed = subprocess.run(
        [CLI, "experiment", "triangle.toml", "--participant", "p1", "--log", "log.csv",
         "--resume", "--audio", "alsa", "--alsa-device",
         f"file:FILE={tmp_path / 'b.wav'},FORMAT=wav"],
        cwd=tmp_path, input="\n1\n2\n3\n", capture_output=True, text=True, timeout=120,
    )
    assert resumed.returncode == 0, resumed.stderr
    assert "Resuming after trial 3 of 6." in resumed.stdout
    rows = list(csv.DictReader(open(tmp_path / "log.csv")))
    check_triangle_log(rows, trials)
    # The second run's device got the recording's own rate (ALSA is asked for it), and holds
    # its three trials at their logged frames.
    recorded, rate = read_f32_wav_channels(tmp_path / "b.wav")
    assert rate == 44100
    check_triangle_recording(rows[3:], recorded[0], 0, rate)
