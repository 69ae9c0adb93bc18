"""`sake-glug measure-actuator` on a real JACK server (dummy driver).

A test client stands in for the device and its accelerometer: it filters what the command plays
into what it records with a known response (SciPy's second-order Butterworth high-pass at 90 Hz
and first-order low-pass at 600 Hz, at half gain). The profile the command writes gives that
response within 0.5 dB at every point, relative to its strongest point as the profile's levels
are; with `--repeat 2` it gives each point's spread; the renderer takes it as `--actuator`. A
port the server does not have is refused by name, and no file is written.

The command measures with `--freewheel`: once connected it turns the server's freewheel on, so
that each cycle runs when every client has finished the last instead of on a clock that a busy
machine makes the Python client miss, and turns it off again before it leaves (the device client
hears both). Its pace is then the clients', not a clock's: a busy machine slows it down (from
well under the steps' length on an idle one) rather than making it drop cycles.

Needs the release `sake-glug` built with audio (`cargo xtask test` builds it), `jackd` (Debian's
jackd2) and the JACK-Client and SciPy packages (tests/host/requirements.txt).
"""

import os
import subprocess
import tomllib
from dataclasses import dataclass, field

import numpy as np
import pytest

from jack_server import RATE, LeavableCallback, close_client, wait_for
from test_standalone import CLI, own_jack_server

FILTER = "device-under-test"
GAIN = 0.5


def device_response():
    """The test device's filter, as second-order sections."""
    from scipy.signal import butter

    return np.vstack([
        butter(2, 90.0, "highpass", fs=RATE, output="sos"),
        butter(1, 600.0, "lowpass", fs=RATE, output="sos"),
    ])


@pytest.fixture(scope="module")
def jack_server():
    # Long cycles (2048 frames): a freewheeling server runs as fast as the Python callback, whose
    # cost is mostly per call.
    yield from own_jack_server("sakeglug-measure", (CLI, "--features audio"), period=2048)


@dataclass
class Device:
    sos: np.ndarray
    # What the server said of freewheel, in turn (True: started).
    freewheel: list = field(default_factory=list)


@pytest.fixture
def device(jack_server):
    """The filter between `device-under-test:drive_in` and `device-under-test:accel_out`."""
    import jack
    from scipy.signal import sosfilt

    device = Device(device_response())
    client = jack.Client(FILTER, servername=jack_server, no_start_server=True)
    drive = client.inports.register("drive_in")
    accelerometer = client.outports.register("accel_out")
    state = [np.zeros((device.sos.shape[0], 2))]

    def process(frames):
        filtered, state[0] = sosfilt(device.sos, drive.get_array(), zi=state[0])
        accelerometer.get_array()[:] = GAIN * filtered

    callback = LeavableCallback(client, process)
    client.set_freewheel_callback(device.freewheel.append)
    client.activate()
    try:
        yield device
    finally:
        close_client(client, callback)


def measure(jack_server, tmp_path, *options):
    env = dict(os.environ, JACK_DEFAULT_SERVER=jack_server, JACK_NO_START_SERVER="1")
    return subprocess.run(
        [CLI, "measure-actuator", "-o", "device.toml", "--client-name", "measure-under-test",
         "--play-to", f"{FILTER}:drive_in", "--record-from", f"{FILTER}:accel_out", *options],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300,
    )


def measured_freewheeling(jack_server, device, tmp_path, *options):
    """The profile `measure-actuator --freewheel` writes; checks that the server freewheeled
    while it measured and was back in real time before the command ended."""
    done = measure(jack_server, tmp_path, "--freewheel", *options)
    assert done.returncode == 0, done.stderr
    # The device hears of it through its own notification thread, a moment later.
    wait_for(lambda: len(device.freewheel) >= 2, 30, "the device to hear freewheel end")
    assert device.freewheel == [True, False]
    return tomllib.loads((tmp_path / "device.toml").read_text())


def levels_match_the_device(profile, device):
    """The profile's points are the device's response within 0.5 dB, relative to its strongest
    point as the profile's are; returns the frequencies."""
    from scipy.signal import sosfreqz

    hz = np.array([point[0] for point in profile["response"]])
    db = np.array([point[1] for point in profile["response"]])
    _, response = sosfreqz(device.sos, worN=hz, fs=RATE)
    expected = 20 * np.log10(GAIN * np.abs(response))
    expected -= expected.max()
    error = db - expected
    print(f"\nlargest error of the measured profile: {np.abs(error).max():.1e} dB over "
          f"{len(hz)} points")
    assert np.abs(error).max() < 0.5, dict(zip(hz.round(1), error.round(3)))
    return hz


def test_the_measured_profile_is_the_device_response_within_half_a_db(
    jack_server, device, tmp_path
):
    profile = measured_freewheeling(
        jack_server, device, tmp_path, "--from", "40", "--to", "1000", "--per-octave", "2",
        "--settle", "0.2", "--measure", "0.3", "--repeat", "2")
    hz = levels_match_the_device(profile, device)
    assert hz[0] == pytest.approx(40.0) and hz[-1] == pytest.approx(1000.0)
    assert len(hz) == 11, hz
    # The same filter twice: the repeats agree.
    spread = np.array(profile["spread_db"])
    assert len(spread) == len(hz) and spread.max() < 0.5, spread
    assert profile["band_hz"] == [hz[0], hz[-1]]
    assert profile["sample_rate_hz"] == RATE
    assert profile["name"] == "device"
    assert "freewheeled" in (tmp_path / "device.toml").read_text()
    # The renderer takes it.
    render = subprocess.run([CLI, "render", "--actuator", "device.toml",
                             "-o", "pour.wav"], cwd=tmp_path, capture_output=True, text=True)
    assert render.returncode == 0, render.stderr


def test_a_port_the_server_lacks_is_refused_by_name_and_nothing_is_written(
    jack_server, tmp_path
):
    done = measure(jack_server, tmp_path, "--from", "40", "--to", "1000")
    assert done.returncode == 1
    assert f"no port named {FILTER}:drive_in" in done.stderr, done.stderr
    assert not (tmp_path / "device.toml").exists()
