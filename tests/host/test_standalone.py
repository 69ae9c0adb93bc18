"""The standalone app under a real JACK server: the paper's setup without a DAW.

A JACK server runs on the dummy driver (no sound card needed). A JACK MIDI client ("tilt")
sends the tilt device's CCs to the app, another client ("recorder") records the app's output,
in the same JACK cycles, so frame times compare directly. Checked: the upright bottle is silent;
tilted past the pouring point it glugs, and the first glug sample comes when the model says
(the offline renderer, fed the same tilt, is the yardstick), with no delay added by the app;
MIDI learn (`--learn tilt`) takes the next CC and the bottle follows it; OSC over loopback tilts
it too, garbage packets are counted, and OSC listens on loopback
unless asked; any sequence of SIGINT, SIGTERM and SIGHUP ends it within half a second, with exit
status 0 and its JACK client gone, also with its editor open (under Xvfb); a JACK server that
goes away is logged and ends it with exit status 1. Every process started here is stopped, also
on failure.

Needs `jackd` (Debian's jackd2), `Xvfb` (Debian's xvfb) for the editor, the release
`sake-glug-standalone` (`cargo build --release --bin sake-glug-standalone --no-default-features
--features standalone`) and `sake-glug`.
"""

import os
import shutil
import signal
import socket
import struct
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from jack_server import (
    RATE,
    LeavableCallback,
    close_client,
    connect_once_active,
    forget_jack,
    start_jack,
    stop,
    wait_for,
)

REPO = Path(__file__).resolve().parents[2]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
APP = TARGET / "release" / "sake-glug-standalone"
CLI = TARGET / "release" / "sake-glug"

PERIOD = 256
# The app may add at most this to the model's own time to the first glug.
MAX_ADDED_LATENCY_S = 0.050
# The tilt the device sends: 14-bit on CC 16 (MSB) and CC 48 (LSB), 0..16383 over 0..180°.
TILT_VALUE = 12287
TILT_DEG = TILT_VALUE / 16383 * 180.0  # 134.995…°, as the plugin's decoder computes it
# A quit signal, or several in a row, must end the app within this: twelve times the app's own
# grace after a signal (250 ms), so that a busy machine cannot fail it, and below the seconds a
# stalled JACK client would take, which the app's watch is there to cut.
QUIT_BOUND_S = 3.0
# A JACK server that goes away must end the app within this (it waits 1 s for the audio; the
# rest is margin for a busy machine).
LOST_SERVER_BOUND_S = 6.0


def own_jack_server(prefix, needs, period=PERIOD):
    """A JACK server on the dummy driver, named `prefix` and this process (other host tests may
    run a server at the same time), for a module fixture to yield from: skipped (failed in CI)
    without jackd, failed if the program `needs` is not built; stopped afterwards, cleanly."""
    if shutil.which("jackd") is None:
        if os.environ.get("CI"):
            pytest.fail("jackd is not installed (Debian: jackd2); .ci/run installs it")
        pytest.skip("jackd is not installed (Debian: jackd2)")
    import jack  # noqa: F401  libjack is loaded here, so only when a server can run

    program, build = needs
    assert program.exists(), f"{program} is missing: build it with {build}"
    name = f"{prefix}-{os.getpid()}"
    server, log = start_jack(name, period)
    try:
        yield name
    finally:
        status = stop(server, signal.SIGTERM)
        log.seek(0)
        print(log.read().decode(errors="replace")[-2000:])
        log.close()
        assert server.poll() is not None, "the JACK server is stopped"
        assert status == 0, f"jackd exit status {status}"


@pytest.fixture(scope="module")
def jack_server():
    yield from own_jack_server("sakeglug-test", (APP, "--features standalone"))


@pytest.fixture(scope="module")
def display():
    """An X display of our own (Xvfb) for the editor window; stopped after the tests."""
    if shutil.which("Xvfb") is None:
        if os.environ.get("CI"):
            pytest.fail("Xvfb is not installed (Debian: xvfb); .ci/run installs it")
        pytest.skip("Xvfb is not installed (Debian: xvfb)")
    read_end, write_end = os.pipe()
    server = subprocess.Popen(
        # -displayfd: Xvfb picks a free display and writes its number once it is ready.
        ["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1024x768x24", "+extension", "GLX",
         "-nolisten", "tcp"],
        pass_fds=[write_end],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
    )
    os.close(write_end)
    try:
        with os.fdopen(read_end) as ready:
            number = ready.readline().strip()
        assert number, "Xvfb did not start"
        yield f":{number}"
    finally:
        stop(server, signal.SIGTERM)


class Rig:
    """A MIDI sender and an audio recorder, two JACK clients so that the graph runs
    tilt → app → recorder within one cycle."""

    def __init__(self, server):
        import jack

        self.tilt = jack.Client("tilt", servername=server, no_start_server=True)
        self.recorder = jack.Client("recorder", servername=server, no_start_server=True)
        self.midi_out = self.tilt.midi_outports.register("out")
        self.audio_in = self.recorder.inports.register("in")
        self.pending = []
        self.sent_frames = []
        self.recording = False
        self.chunks = []
        self.callbacks = [
            LeavableCallback(self.tilt, self._send),
            LeavableCallback(self.recorder, self._record),
        ]
        self.tilt.activate()
        self.recorder.activate()

    def _send(self, frames):
        self.midi_out.clear_buffer()
        if self.pending:
            events, self.pending = self.pending, []
            for event in events:
                self.midi_out.write_midi_event(0, event)
            self.sent_frames.append(self.tilt.last_frame_time)

    def _record(self, frames):
        if self.recording:
            self.chunks.append((self.recorder.last_frame_time, self.audio_in.get_array().copy()))

    def connect(self):
        connect_once_active(self.tilt, "tilt:out", "sake_glug:midi_input")
        connect_once_active(self.recorder, "sake_glug:output_1", "recorder:in")

    def send(self, *events):
        """Sends `events` at the start of the next cycle; returns that cycle's frame time."""
        count = len(self.sent_frames)
        self.pending = [bytes(event) for event in events]
        wait_for(lambda: len(self.sent_frames) > count, 5, "the MIDI cycle")
        return self.sent_frames[count]

    def freewheel(self, on):
        """JACK's freewheel mode: the server runs each cycle once every client has finished the
        last, as fast as they go, with no clock to miss; a busy machine then only slows the
        test down. The frames still count up, so every time is measured in frames."""
        self.tilt.set_freewheel(on)

    def record(self, seconds, keep=False, gaps=False):
        """Records `seconds` of audio (after what was recorded so far if `keep`): for that long
        in real time, or, freewheeling, until that many frames came; returns (first frame,
        samples), or (first frame, None) if cycles were missed (an xrun) and not `gaps`."""
        if not keep:
            self.chunks = []
        self.recording = True
        wanted = int(seconds * RATE) + sum(len(block) for _, block in self.chunks)
        time.sleep(seconds)
        wait_for(
            lambda: sum(len(block) for _, block in list(self.chunks)) >= wanted,
            60,
            f"{seconds} s of audio",
        )
        self.recording = False
        chunks = list(self.chunks)
        assert chunks, "the recorder got no audio"
        start = chunks[0][0]
        for (frame, block), (next_frame, _) in zip(chunks, chunks[1:]):
            if next_frame != frame + len(block) and not gaps:
                return start, None
        return start, np.concatenate([block for _, block in chunks])

    def close(self):
        for client, callback in zip((self.tilt, self.recorder), self.callbacks):
            close_client(client, callback)


NOTE_ON = [0x90, 60, 100]  # any note-on refills the bottle


def tilt_ccs(value):
    """The device's 14-bit tilt: `B0 10 mm`, then `B0 30 ll`."""
    return [0xB0, 16, value >> 7], [0xB0, 48, value & 0x7F]


@pytest.fixture
def app(jack_server):
    """Starts the app; yields (start function). Every app started is stopped afterwards."""
    started = []

    def start(*extra, server=jack_server, display=None):
        """Starts the app on JACK server `server`, headless, or with its editor on `display`;
        returns once its JACK ports are there."""
        env = dict(os.environ, JACK_DEFAULT_SERVER=server, JACK_NO_START_SERVER="1")
        if display is None:
            extra = ("--no-editor", *extra)
        else:
            env["DISPLAY"] = display
        log = tempfile.TemporaryFile()
        process = subprocess.Popen(
            [str(APP), "--backend", "jack", *extra],
            env=env,
            stdout=log,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
        )
        started.append((process, log))
        import jack

        probe = jack.Client("probe", servername=server, no_start_server=True)
        try:

            def ports_up():
                assert process.poll() is None, f"the app exited: {read(log)}"
                names = {port.name for port in probe.get_ports("sake_glug:")}
                return {"sake_glug:output_1", "sake_glug:midi_input"} <= names

            wait_for(ports_up, 15, "the app's JACK ports")
        finally:
            probe.close()
        return process, log

    yield start
    for process, log in started:
        stop(process, signal.SIGKILL)
        print(read(log)[-3000:])


def read(log):
    log.seek(0)
    return log.read().decode(errors="replace")


def client_gone(server):
    import jack

    probe = jack.Client("probe", servername=server, no_start_server=True)
    try:
        return not probe.get_ports("sake_glug:")
    finally:
        probe.close()


def quits_cleanly(process, log, server, *signals):
    """Sends `signals` one right after the other; the app must end within QUIT_BOUND_S of the
    first, with exit status 0, its JACK client gone."""
    start = time.monotonic()
    for sig in signals:
        process.send_signal(sig)
    try:
        status = process.wait(10)
    except subprocess.TimeoutExpired:
        pytest.fail(f"the app did not end within 10 s of {signals!r}")
    took_s = time.monotonic() - start
    print(f"{' + '.join(sig.name for sig in signals)}: ended after {took_s * 1000:.0f} ms")
    assert status == 0, f"exit status {status} after {signals!r}: {read(log)}"
    assert took_s <= QUIT_BOUND_S, f"{took_s:.2f} s to end after {signals!r}"
    assert not Path(f"/proc/{process.pid}").exists(), "reaped, no zombie"
    wait_for(lambda: client_gone(server), 5, "the app's JACK client to go")
    if "did not stop within" in read(log):
        print("(the app ended through its watch: the JACK backend did not stop in time)")


def model_first_glug_s(tilt_deg, *render_options):
    """When the model makes the first glug of a full bottle tilted at t = 0, and its samples: the
    offline renderer's first non-zero sample, with the plugin's defaults (seed 1, −6 dB), and
    `render_options` (an actuator)."""
    with tempfile.TemporaryDirectory() as directory:
        scene = Path(directory) / "tilt.toml"
        scene.write_text(f"sample_rate = {RATE}\nduration_s = 1.0\ntilt_deg = {tilt_deg!r}\n")
        samples_csv = Path(directory) / "tilt.csv"
        subprocess.run([str(CLI), "render", str(scene), "-o", str(samples_csv), *render_options],
                       check=True)
        samples = np.loadtxt(samples_csv, dtype=np.float32)
    first = int(np.flatnonzero(samples)[0])
    return first, samples


def pour_live(jack_server, app, *app_options):
    """Starts the app with `app_options`, checks that it is silent upright, tilts it to
    TILT_DEG by MIDI and records a second; returns (the app and its log, the CC's frame, the
    recording's first frame, the recording)."""
    rig = Rig(jack_server)
    try:
        # Freewheeling, no cycle can be missed however busy the machine is. Should one still be
        # (a server that cannot freewheel), the measurement is taken again with a fresh app: a
        # refill would keep the random draws going, so the glugs would differ.
        for attempt in range(3):
            process, log = app(*app_options)
            rig.connect()
            # A client cannot join a freewheeling server: the app first, then freewheel.
            rig.freewheel(True)
            rig.send(*tilt_ccs(0))
            _, upright = rig.record(0.4)
            if upright is not None:
                assert len(upright) >= 0.3 * RATE
                assert np.all(upright == 0.0), f"upright bottle: peak {np.abs(upright).max()}"
                rig.chunks = []
                rig.recording = True
                cc_frame = rig.send(*tilt_ccs(TILT_VALUE))
                start, poured = rig.record(1.0, keep=True)
                if poured is not None:
                    return (process, log), cc_frame, start, poured
            print(f"attempt {attempt + 1}: the recording missed a cycle; again")
            rig.freewheel(False)
            stop(process, signal.SIGKILL)
            wait_for(lambda: client_gone(jack_server), 5, "the killed app's JACK client to go")
        pytest.fail("every attempt missed JACK cycles")
    finally:
        rig.freewheel(False)
        rig.close()


def difference_from(live, offline):
    """The largest difference between two renders, relative to the offline one's peak."""
    n = min(len(live), len(offline))
    return np.abs(live[:n] - offline[:n]).max() / np.abs(offline[:n]).max()


def test_tilt_glugs_as_the_model_says_and_upright_is_silent(jack_server, app):
    expected, offline = model_first_glug_s(TILT_DEG)
    model_s = expected / RATE
    (process, log), cc_frame, start, poured = pour_live(jack_server, app)
    assert start <= cc_frame, "the recording began before the CC's cycle"
    offset = cc_frame - start
    assert np.all(poured[:offset] == 0.0)
    nonzero = np.flatnonzero(poured)
    assert nonzero.size, "no glug within a second of tilting to 135°"
    first_glug_frame = start + int(nonzero[0])
    latency_s = (first_glug_frame - cc_frame) / RATE
    added_s = latency_s - model_s
    print(
        f"\nCC → first glug sample: {latency_s * 1000:.2f} ms "
        f"({first_glug_frame - cc_frame} frames at {RATE} Hz); the model's own time to the "
        f"first glug (5 ml of outflow at {TILT_DEG:.2f}°): {model_s * 1000:.2f} ms; added by "
        f"the app: {added_s * 1000:.2f} ms ({first_glug_frame - cc_frame - expected} frames); "
        f"JACK period {PERIOD} frames = {PERIOD / RATE * 1000:.2f} ms"
    )
    assert 0.0 <= added_s <= MAX_ADDED_LATENCY_S
    # The same glugs as the offline renderer, from the CC's sample on.
    error = difference_from(poured[offset:], offline)
    print(f"largest difference from the offline render: {20 * np.log10(error + 1e-30):.1f} dB")
    assert error < 1e-3
    quits_cleanly(process, log, jack_server, signal.SIGINT)


def test_the_app_compensates_for_its_actuator_as_the_renderer_does(jack_server, app, tmp_path):
    """`--actuator` and `--felt` on the app's command line: the glugs of `sake-glug render
    --actuator … --felt`, not the model's drive. A profile file of one's own, as
    `measure-actuator` writes it, is taken by path."""
    profile = tmp_path / "shaker.toml"
    profile.write_text(
        'name = "shaker"\nresponse = [[20.0, -24.0], [1000.0, 0.0]]\nband_hz = [20.0, 1000.0]\n'
        "max_amplitude = 1.0\nsample_rate_hz = 48000\n"
    )
    _, plain = model_first_glug_s(TILT_DEG)
    for options in (["--actuator", "haptuator-mark2", "--felt"], ["--actuator", str(profile)]):
        _, offline = model_first_glug_s(TILT_DEG, *options)
        (process, log), cc_frame, start, poured = pour_live(jack_server, app, *options)
        live = poured[cc_frame - start :]
        assert difference_from(live, offline) < 1e-3, options
        # Not the model's drive: the compensation shows.
        assert difference_from(live, plain) > 0.05, options
        quits_cleanly(process, log, jack_server, signal.SIGINT)


def test_an_actuator_the_app_cannot_read_ends_it_at_once():
    done = subprocess.run(
        [str(APP), "--no-editor", "--backend", "dummy", "--actuator", "no-such-profile"],
        capture_output=True, text=True, timeout=30,
    )
    assert done.returncode == 2
    assert "--actuator: no actuator profile no-such-profile" in done.stderr, done.stderr


def osc_message(address, *floats):
    def padded(text):
        data = text.encode() + b"\0"
        return data + b"\0" * (-len(data) % 4)

    return padded(address) + padded("," + "f" * len(floats)) + b"".join(
        struct.pack(">f", value) for value in floats
    )


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def non_loopback_address():
    """An IPv4 address of this machine other than loopback (the one it would send from), if any."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.connect(("192.0.2.1", 9))
        except OSError:
            return None
        address = probe.getsockname()[0]
    return None if address.startswith("127.") or address == "0.0.0.0" else address


def udp_listeners(pid):
    """The local addresses `ss` shows for the UDP sockets of process `pid`, or None without ss."""
    if shutil.which("ss") is None:
        return None
    table = subprocess.run(["ss", "-u", "-l", "-n", "-p", "-H"], capture_output=True, text=True)
    return {line.split()[3] for line in table.stdout.splitlines() if f"pid={pid}," in line}


def test_osc_tilt_from_loopback_pours_and_garbage_is_counted(jack_server, app):
    port = free_udp_port()
    process, log = app("--osc-port", str(port), "--osc-axis", "+y")
    wait_for(lambda: "OSC: listening" in read(log), 5, "the app to listen for OSC")
    rig = Rig(jack_server)
    try:
        rig.connect()
        _, before = rig.record(0.3, gaps=True)
        assert np.all(before == 0.0), "upright until OSC tilts it"
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(b"\x00garbage\xff", ("127.0.0.1", port))
            # A phone (GyrOSC: gravity to the earth) with its top edge 135° from up.
            sender.sendto(osc_message("/gyrosc/grav", 0.0, 0.7071068, -0.7071068), ("127.0.0.1", port))
        _, poured = rig.record(0.6, gaps=True)
        assert np.abs(poured).max() > 0.01, "OSC tilt made the bottle glug"
        wait_for(lambda: "1 malformed packet" in read(log), 5, "the malformed packet's log line")
    finally:
        rig.close()
    quits_cleanly(process, log, jack_server, signal.SIGINT)


def test_midi_learn_takes_the_next_cc_and_the_tilt_follows_it(jack_server, app):
    """`--learn tilt`, MIDI learn without the editor (as the MIDI panel's Learn button): the
    first CC the device sends, CC 20 on channel 4, is taken for tilt with its channel, and the
    app says so; the bottle then follows CC 20 on channel 4, and no longer the default CC 16."""
    process, log = app("--learn", "tilt")
    rig = Rig(jack_server)
    try:
        rig.connect()
        rig.send([0xB3, 20, 0])  # channel 4: status B0 + 3
        wait_for(lambda: "MIDI learn: " in read(log), 5, "the app to say what it learnt")
        learnt = [line for line in read(log).splitlines() if "MIDI learn: " in line]
        assert learnt[-1].endswith("MIDI learn: Tilt CC (MSB) = CC 20 on channel 4"), learnt
        # The old tilt CC, 135° on CC 16 and its LSB, on the learnt channel: the bottle stays up.
        rig.send(*[[0xB3, cc, value] for _, cc, value in tilt_ccs(TILT_VALUE)])
        _, upright = rig.record(0.4, gaps=True)
        assert np.all(upright == 0.0), f"CC 16 still tilts: peak {np.abs(upright).max()}"
        # The learnt CC on another channel: still up.
        rig.send([0xB0, 20, TILT_VALUE >> 7])
        _, other_channel = rig.record(0.4, gaps=True)
        assert np.all(other_channel == 0.0), "channel 1 is not listened to any more"
        # The learnt CC on its channel tilts it to 135°: it glugs.
        rig.send([0xB3, 20, TILT_VALUE >> 7])
        _, poured = rig.record(0.8, gaps=True)
        assert np.abs(poured).max() > 0.01, "the learnt CC tilts the bottle"
    finally:
        rig.close()
    quits_cleanly(process, log, jack_server, signal.SIGINT)


def test_osc_listens_on_loopback_unless_asked(jack_server, app):
    port = free_udp_port()
    process, log = app("--osc-port", str(port))
    wait_for(lambda: "OSC: listening" in read(log), 5, "the app to listen for OSC")
    assert f"OSC: listening on UDP 127.0.0.1:{port}," in read(log)
    listeners = udp_listeners(process.pid)
    if listeners is not None:
        assert listeners == {f"127.0.0.1:{port}"}, listeners
    outside = non_loopback_address()
    if outside is not None:
        # Nothing of the app's on the network side: that address's port is free.
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as other:
            other.bind((outside, port))
    quits_cleanly(process, log, jack_server, signal.SIGTERM)

    # Every interface when asked: a packet to the network address arrives.
    port = free_udp_port()
    process, log = app("--osc-port", str(port), "--osc-bind", "0.0.0.0")
    wait_for(lambda: "OSC: listening" in read(log), 5, "the app to listen for OSC")
    assert f"OSC: listening on UDP 0.0.0.0:{port}," in read(log)
    if outside is not None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(b"\x00garbage", (outside, port))
        wait_for(lambda: "1 malformed packet" in read(log), 5, f"a packet sent to {outside}")
    quits_cleanly(process, log, jack_server, signal.SIGTERM)


def test_sigterm_ends_the_app_cleanly(jack_server, app):
    process, log = app()
    time.sleep(0.2)
    quits_cleanly(process, log, jack_server, signal.SIGTERM)


@pytest.mark.parametrize(
    "signals",
    [
        (signal.SIGINT,),
        (signal.SIGHUP,),
        (signal.SIGTERM, signal.SIGTERM),
        (signal.SIGINT, signal.SIGINT),
        (signal.SIGTERM, signal.SIGINT, signal.SIGHUP),
    ],
    ids=lambda signals: "+".join(sig.name for sig in signals),
)
def test_quit_signals_end_the_app_at_once(jack_server, app, signals):
    # A few times each: how long JACK takes to let the client go varies from run to run.
    for _ in range(3):
        process, log = app()
        time.sleep(0.3)
        quits_cleanly(process, log, jack_server, *signals)


def test_sigterm_ends_the_app_at_once_with_its_editor_open(jack_server, display, app):
    for _ in range(2):
        process, log = app(display=display)
        # The window is up and idle (nothing to repaint) when the signal comes.
        time.sleep(1.5)
        assert process.poll() is None, f"the app with its editor ended: {read(log)}"
        assert "No GUI available" not in read(log), "the editor is open"
        quits_cleanly(process, log, jack_server, signal.SIGTERM)


@pytest.mark.parametrize("kill", [signal.SIGKILL, signal.SIGTERM], ids=lambda sig: sig.name)
def test_a_jack_server_that_goes_away_is_logged_and_ends_the_app(jack_server, app, kill):
    name = f"sakeglug-lost-{kill.name}-{os.getpid()}"
    server, server_log = start_jack(name, PERIOD)
    try:
        process, log = app(server=name)
        time.sleep(0.3)
        server.send_signal(kill)
        start = time.monotonic()
        try:
            status = process.wait(LOST_SERVER_BOUND_S + 5)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the app outlived its JACK server by {LOST_SERVER_BOUND_S + 5} s")
        took_s = time.monotonic() - start
    finally:
        stop(server, signal.SIGKILL)
        server_log.close()
        forget_jack(name, PERIOD)
    print(f"the app ended {took_s * 1000:.0f} ms after its JACK server")
    said = [line for line in read(log).splitlines() if "audio stopped" in line]
    assert len(said) == 1, f"one line says the audio stopped: {read(log)}"
    assert "JACK server" in said[0], said[0]
    assert status == 1, f"exit status {status}"
    assert took_s <= LOST_SERVER_BOUND_S, f"{took_s:.2f} s after the server went"
