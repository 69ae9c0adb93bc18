"""A JACK server of our own on the dummy driver, as the host tests and tests/host/latency.py
start, wait for and stop it: one module, so that each does it the same way.

Nothing here needs pytest; `jack` (the JACK-Client package) is imported only where a server is
started, so that importing this module does not load libjack.
"""

import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

RATE = 48000


def wait_for(condition, timeout_s, what, poll_s=0.02):
    """Polls `condition` until it holds; raises TimeoutError naming `what` after `timeout_s`."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(poll_s)
    raise TimeoutError(f"timed out after {timeout_s} s waiting for {what}")


def connect_once_active(client, source, destination, timeout_s=60):
    """Connects two ports as soon as JACK lets it: a client's ports are visible as soon as it
    registers them, but connecting them fails (-1) until it has activated, a window that a busy
    machine stretches."""
    import jack

    def connected():
        try:
            client.connect(source, destination)
            return True
        except jack.JackErrorCode:
            return False

    wait_for(connected, timeout_s, f"{source} → {destination} to connect")


class LeavableCallback:
    """`client`'s process callback, set by this, which `close_client` makes instant before the
    client leaves. jack_deactivate cancels the client's process thread (pthread_cancel) once the
    server lets it go: cancelled inside a Python callback, that thread keeps the GIL and this
    process hangs. So the callback first returns at once, and the client leaves once a cycle has
    seen that: its thread is then cancelled waiting for a cycle, or in a callback of a few
    instructions, not in the test's work."""

    def __init__(self, client, callback):
        self._callback = callback
        self._leaving = threading.Event()
        self._left = threading.Event()
        client.set_process_callback(self)

    def __call__(self, frames):
        if self._leaving.is_set():
            self._left.set()
            return
        self._callback(frames)

    def leave(self, timeout_s=10):
        """Makes the callback instant and waits for a cycle to have seen it (no longer than
        `timeout_s`: a client the server no longer runs is in no callback)."""
        self._leaving.set()
        self._left.wait(timeout_s)


def close_client(client, callback):
    """Deactivates and closes `client`, whose process callback is the LeavableCallback
    `callback`, made instant first."""
    callback.leave()
    client.deactivate()
    client.close()


def stop(process, sig=signal.SIGTERM, timeout_s=10):
    """Stops a child we started, however it is doing; returns its exit status."""
    if process.poll() is None:
        process.send_signal(sig)
        try:
            process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    return process.returncode


# Outside real time, a client the server waits on this long (ms) before it drops it: jackd's
# 500 ms default let a loaded machine (CI beside other work) starve the app's callback past it,
# the server dropped the app's client, and the app ended on its own lost-audio watch mid-test.
NO_REALTIME = ("--no-realtime", "-t", "10000")


def start_jack(name, period, scheduling=NO_REALTIME):
    """Starts a JACK server called `name` on the dummy driver at RATE, `period` frames a cycle,
    with `scheduling` (`-R -P 70` for real time, whose client timeout must stay below jackd's
    watchdog); returns (process, its log). Raises RuntimeError with the server's last words if
    it does not come up."""
    import jack

    log = tempfile.TemporaryFile()
    server = subprocess.Popen(
        # Not --sync: a client leaving mid-cycle can stall a synchronous server.
        ["jackd", *scheduling, "-n", name, "-d", "dummy", "-r", str(RATE), "-p", str(period)],
        stdout=log,
        stderr=subprocess.STDOUT,
        stdin=subprocess.DEVNULL,
    )

    def said():
        log.seek(0)
        return log.read().decode(errors="replace")[-2000:]

    def up():
        if server.poll() is not None:
            raise RuntimeError(f"jackd exited at start ({server.returncode}): {said()}")
        try:
            jack.Client("probe", servername=name, no_start_server=True).close()
            return True
        except jack.JackOpenError:
            return False

    try:
        wait_for(up, 10, "the JACK server")
    except TimeoutError as error:
        stop(server, signal.SIGKILL)
        raise RuntimeError(f"{error}: {said()}") from error
    except BaseException:
        stop(server, signal.SIGKILL)
        raise
    return server, log


def forget_jack(name, period):
    """Cleans up after a JACK server `name` that was killed: a server killed with SIGKILL keeps
    its slot in JACK's registry of servers (8 per machine), which only a server of the same name
    frees, and its clients' semaphores stay in /dev/shm."""
    server, log = start_jack(name, period)
    stop(server, signal.SIGTERM)
    log.close()
    for semaphore in Path("/dev/shm").glob(f"jack_sem.*_{name}_*"):
        semaphore.unlink(missing_ok=True)
