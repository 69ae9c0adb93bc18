"""The live loop, measured: how long a tilt message takes to reach the standalone app's output
under a JACK server (dummy driver, 64-frame periods at 48 kHz), net of the model's own delay.

Not a test (nothing is asserted: a figure depends on the machine's load); `cargo xtask docs`
runs it and writes its Markdown to docs/latency.md. Each trial starts from the same bottle: the
tilt is set upright, the JACK transport is stopped and started (the app resets the bottle when
its host's transport starts, MODEL.md §8), then one message tilts it to about 135°. The offline
render of that step (`sake-glug render`, the same defaults as the app's) says how many samples
the model takes from the step to its first glug; the first non-zero output sample, less that
delay, is where the app applied the tilt, and its distance from the message's time is the
latency the app and its inputs add.

- MIDI: the tilt device's 14-bit CCs from a JACK MIDI client, at a random frame of its cycle;
  the message's time is that frame.
- OSC: `/sakeglug/tilt` over loopback UDP at a random moment, timed by the monotonic clock
  just before it is sent; its effect is timed by the same clock as the recorder receives the
  JACK cycle that holds it (plus its place in the cycle), so the figure is the time until the
  output leaves the graph, whatever the cycles' jitter (JACK's own estimate of the current
  frame drifts by periods on a loaded machine).

A trial during which JACK reported an xrun is dropped and counted.

    .venv/bin/python tests/host/latency.py --app target/release/sake-glug-standalone \
        --cli target/release/sake-glug [--trials 300]
"""

import argparse
import os
import random
import socket
import struct
import subprocess
import sys
import tempfile
import time
from collections import deque
from pathlib import Path

import numpy as np

from jack_server import (
    RATE,
    LeavableCallback,
    close_client,
    connect_once_active,
    start_jack,
    stop,
    wait_for,
)

PERIOD = 64
# The device's 14-bit tilt on CC 16 (MSB) and CC 48 (LSB), 0..16383 over 0..180°.
MIDI_TILT_VALUE = 12287
MIDI_TILT_DEG = MIDI_TILT_VALUE / 16383 * 180.0
# OSC carries a float32: 135.0 exactly.
OSC_TILT_DEG = 135.0
# How long to wait after the transport restarts (the app fades the old units over 5 ms).
SETTLE_S = 0.06
# A trial counts only if the output was silent this long before its message (the reset worked).
QUIET_S = 0.02
# ... and its first glug's first samples are the offline render's (the bottle was a fresh one).
COMPARED = 256
# How often a trial looks for its glug (s).
POLL_S = 0.001


def model_delay(cli, tilt_deg):
    """Samples from a step to `tilt_deg` (from upright, a full bottle, the defaults) to the first
    non-zero output sample, by the offline renderer, and the first glug's first samples."""
    with tempfile.TemporaryDirectory() as directory:
        scene = Path(directory) / "step.toml"
        scene.write_text(f"sample_rate = {RATE}\nduration_s = 1.0\ntilt_deg = {tilt_deg!r}\n")
        samples_csv = Path(directory) / "step.csv"
        subprocess.run([str(cli), "render", str(scene), "-o", str(samples_csv)], check=True,
                       stdout=subprocess.DEVNULL)
        samples = np.loadtxt(samples_csv, dtype=np.float32)
    first = int(np.flatnonzero(samples)[0])
    return first, samples[first : first + COMPARED]


class Rig:
    """Two JACK clients, so that the graph runs tilt → app → recorder in one cycle: "tilt"
    sends MIDI at a chosen frame, "recorder" finds the first non-zero sample after a frame."""

    def __init__(self, server):
        import jack

        self.jack = jack
        self.tilt = jack.Client("tilt", servername=server, no_start_server=True)
        self.recorder = jack.Client("recorder", servername=server, no_start_server=True)
        self.midi_out = self.tilt.midi_outports.register("out")
        self.audio_in = self.recorder.inports.register("in")
        self.pending = None  # (events, offset) to send in the next cycle
        self.sent_frame = None
        self.watch_from = None  # a frame: find the first non-zero sample at or after it
        self.first_sound = None
        self.first_samples = []
        self.last_loud_frame = None
        # (first frame, monotonic time as the recorder received it) of the recent cycles.
        self.cycles = deque(maxlen=8192)
        self.xruns = 0
        self.callbacks = [
            LeavableCallback(self.tilt, self._send),
            LeavableCallback(self.recorder, self._record),
        ]
        self.recorder.set_xrun_callback(self._xrun)
        self.tilt.activate()
        self.recorder.activate()
        # The app's ports are visible before it has activated, when connecting them still fails.
        for client, source, destination in (
            (self.tilt, "tilt:out", "sake_glug:midi_input"),
            (self.recorder, "sake_glug:output_1", "recorder:in"),
        ):
            connect_once_active(client, source, destination)

    def _xrun(self, delay):
        self.xruns += 1

    def _send(self, frames):
        self.midi_out.clear_buffer()
        if self.pending is not None:
            events, offset = self.pending
            self.pending = None
            for event in events:
                self.midi_out.write_midi_event(offset, event)
            self.sent_frame = self.tilt.last_frame_time + offset

    def _record(self, frames):
        block = self.audio_in.get_array()
        start = self.recorder.last_frame_time
        self.cycles.append((start, time.monotonic()))
        loud = np.flatnonzero(block)
        if loud.size:
            self.last_loud_frame = start + int(loud[-1])
        watch_from = self.watch_from
        if watch_from is not None and self.first_sound is None and loud.size:
            later = loud[start + loud >= watch_from]
            if later.size:
                self.first_sound = start + int(later[0])
                self.first_samples = [block[int(later[0]) :].copy()]
        elif self.first_sound is not None and sum(map(len, self.first_samples)) < COMPARED:
            self.first_samples.append(block.copy())

    def received_at(self, frame):
        """The monotonic time at which the recorder received `frame` (its cycle's arrival plus
        its place in the cycle), or None if that cycle is no longer remembered."""
        for start, arrived in reversed(self.cycles):
            if start <= frame < start + PERIOD:
                return arrived + (frame - start) / RATE
        return None

    def send_midi(self, events, offset):
        """Sends `events` at frame `offset` of the next cycle; returns that frame."""
        self.sent_frame = None
        self.pending = ([bytes(event) for event in events], offset)
        wait_for(lambda: self.sent_frame is not None, 5, "the MIDI cycle")
        return self.sent_frame

    def restart_transport(self):
        """Stops and starts JACK's transport: the app resets its bottle at the start."""
        self.tilt.transport_stop()
        time.sleep(0.02)
        self.tilt.transport_start()
        time.sleep(SETTLE_S)

    def close(self):
        self.tilt.transport_stop()
        for client, callback in zip((self.tilt, self.recorder), self.callbacks):
            close_client(client, callback)


def tilt_ccs(value):
    return [0xB0, 16, value >> 7], [0xB0, 48, value & 0x7F]


def osc_message(address, *floats):
    def padded(text):
        data = text.encode() + b"\0"
        return data + b"\0" * (-len(data) % 4)

    return padded(address) + padded("," + "f" * len(floats)) + b"".join(
        struct.pack(">f", value) for value in floats
    )


def trial(rig, send, delay, glug):
    """One step from a reset bottle: returns the added latency (s), or why the trial is dropped
    (an xrun, no glug within a second, or sound before the message). `send` returns the
    message's time: a frame (MIDI) or a monotonic time (OSC)."""
    send("upright")
    rig.restart_transport()
    xruns = rig.xruns
    # A random moment, so that messages fall anywhere in a cycle.
    time.sleep(random.uniform(0.0, 0.01))
    rig.first_sound = None
    rig.first_samples = []
    last_loud = rig.last_loud_frame
    watch_from = rig.recorder.frame_time
    sent = send("tilt")
    rig.watch_from = watch_from
    try:
        wait_for(lambda: rig.first_sound is not None, 1.0, "the first glug", POLL_S)
    except TimeoutError:
        return "no glug within a second"
    finally:
        rig.watch_from = None
    # The reset silenced the bottle: nothing sounded in the QUIET_S before the message.
    if rig.xruns != xruns:
        return "an xrun"
    if last_loud is not None and last_loud >= watch_from - QUIET_S * RATE:
        return "sound before the message"
    wait_for(lambda: sum(map(len, rig.first_samples)) >= COMPARED, 1.0, "the first glug", POLL_S)
    heard = np.concatenate(rig.first_samples)[:COMPARED]
    if np.abs(heard - glug).max() > 1e-3 * np.abs(glug).max():
        return "a first glug other than a fresh bottle's"
    effect = rig.first_sound - delay
    if isinstance(sent, int):
        return (effect - sent) / RATE
    effect_at = rig.received_at(effect)
    if effect_at is None:
        return "the effect's cycle not remembered"
    return effect_at - sent


def measure(rig, channel, model, trials, osc_port):
    delay, glug = model
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)

    def send(what):
        if channel == "MIDI":
            value = 0 if what == "upright" else MIDI_TILT_VALUE
            return rig.send_midi(tilt_ccs(value), random.randrange(PERIOD))
        degrees = 0.0 if what == "upright" else OSC_TILT_DEG
        packet = osc_message("/sakeglug/tilt", degrees)
        now = time.monotonic()
        sock.sendto(packet, ("127.0.0.1", osc_port))
        return now

    added, dropped = [], {}
    try:
        for _ in range(trials):
            latency = trial(rig, send, delay, glug)
            if isinstance(latency, str):
                dropped[latency] = dropped.get(latency, 0) + 1
            else:
                added.append(latency)
    finally:
        send("upright")
        sock.close()
    return np.array(added, dtype=float), dropped


def start_jack_for_latency(name):
    """A JACK server with real-time scheduling, as an audio machine runs one (64-frame periods
    on a busy machine without it are mostly xruns), or without it where it is refused. Returns
    the server and whether it runs in real time."""
    try:
        server, _log = start_jack(name, PERIOD, ("-R", "-P", "70"))
        return server, True
    except RuntimeError:
        server, _log = start_jack(name, PERIOD)
        return server, False


def start_app(app, server, osc_port):
    import jack

    env = dict(os.environ, JACK_DEFAULT_SERVER=server, JACK_NO_START_SERVER="1")
    process = subprocess.Popen(
        [str(app), "--backend", "jack", "--no-editor", "--osc-port", str(osc_port)],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
    )
    probe = jack.Client("probe", servername=server, no_start_server=True)
    try:
        def ports_up():
            if process.poll() is not None:
                raise RuntimeError(f"the app exited ({process.returncode})")
            names = {port.name for port in probe.get_ports("sake_glug:")}
            return {"sake_glug:output_1", "sake_glug:midi_input"} <= names

        wait_for(ports_up, 15, "the app's JACK ports")
    finally:
        probe.close()
    return process


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def ms(seconds):
    return seconds * 1000.0


def report(results, delays, trials, realtime):
    period_ms = ms(PERIOD / RATE)
    scheduling = "real-time scheduling (`-R`)" if realtime else "no real-time scheduling"
    load = Path("/proc/loadavg").read_text().split()[0] if Path("/proc/loadavg").exists() else "?"
    lines = [
        f"{trials} messages of each kind; JACK dummy driver at {RATE} Hz, {PERIOD}-frame periods "
        f"({period_ms:.2f} ms), {scheduling}, the machine's load average {load} at the end; "
        f"the model's own delay from the step to its first glug, by the "
        f"offline render, taken off: {delays['MIDI']} samples for the MIDI tilt "
        f"({MIDI_TILT_DEG:.3f}°), {delays['OSC']} for the OSC tilt ({OSC_TILT_DEG:.0f}°). A trial "
        f"counts when its first glug's first {COMPARED} samples are the offline render's (within "
        f"10⁻³ of its peak): the reset gave a fresh bottle.",
        "",
        "| message | median | worst | spread (25–75 %) | 95 % | best | trials kept | goal |",
        "|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    drops = []
    for channel, (added, dropped) in results.items():
        drops += [f"{channel}: {count} for {why}" for why, count in dropped.items()]
        if added.size == 0:
            lines.append(f"| {channel} | – | – | – | – | – | 0 of {trials} | – |")
            continue
        median, worst, best = np.median(added), added.max(), added.min()
        q25, q75, q95 = np.percentile(added, [25, 75, 95])
        met = median <= (PERIOD / RATE + 0.001) and worst <= 2 * PERIOD / RATE
        lines.append(
            f"| {channel} | {ms(median):.2f} ms | {ms(worst):.2f} ms | "
            f"{ms(q25):.2f}–{ms(q75):.2f} ms | {ms(q95):.2f} ms | {ms(best):.2f} ms | "
            f"{added.size} of {trials} | {'met' if met else 'missed'} |"
        )
    lines += [
        "",
        f"Trials dropped: {'; '.join(drops) if drops else 'none'}.",
        "",
        f"Goal: median within one period + 1 ms ({period_ms + 1:.2f} ms), worst within two "
        f"periods ({2 * period_ms:.2f} ms).",
    ]
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--app", required=True)
    parser.add_argument("--cli", required=True)
    parser.add_argument("--trials", type=int, default=300)
    args = parser.parse_args()
    models = {"MIDI": model_delay(args.cli, MIDI_TILT_DEG), "OSC": model_delay(args.cli, OSC_TILT_DEG)}
    name = f"sakeglug-latency-{os.getpid()}"
    server, realtime = start_jack_for_latency(name)
    app = None
    rig = None
    try:
        osc_port = free_udp_port()
        app = start_app(args.app, name, osc_port)
        rig = Rig(name)
        results = {}
        for channel in ("MIDI", "OSC"):
            results[channel] = measure(rig, channel, models[channel], args.trials, osc_port)
            print(f"{channel}: {len(results[channel][0])} trials kept", file=sys.stderr)
    finally:
        if rig is not None:
            rig.close()
        if app is not None:
            stop(app)
        stop(server)
    delays = {channel: delay for channel, (delay, _) in models.items()}
    sys.stdout.write(report(results, delays, args.trials, realtime))


if __name__ == "__main__":
    main()
