"""What the tests compare the module with: the release `sake-glug` command line of the same
checkout (`cargo build --release --bin sake-glug --no-default-features --features cli`, which
`cargo xtask test` runs first), found in $CARGO_TARGET_DIR or target/, or at $SAKE_GLUG_CLI."""

import os
import signal
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def cli_path() -> Path:
    if "SAKE_GLUG_CLI" in os.environ:
        return Path(os.environ["SAKE_GLUG_CLI"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return (REPO / target / "release" / "sake-glug").resolve()


@pytest.fixture(scope="session")
def cli() -> Path:
    path = cli_path()
    if not path.exists():
        pytest.fail(
            f"{path} is missing: build it with `cargo build --release --bin sake-glug "
            "--no-default-features --features cli` (or set SAKE_GLUG_CLI)"
        )
    return path


def run_cli(cli: Path, *args: str, cwd: Path = REPO) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli), *args], cwd=cwd, capture_output=True, text=True)


def read_f32_wav(path: Path) -> np.ndarray:
    """The samples of a mono 32-bit float WAV, as stored (no conversion that could round)."""
    data = path.read_bytes()
    assert data[:4] == b"RIFF" and data[8:12] == b"WAVE", f"{path} is no WAV file"
    chunks, offset = {}, 12
    while offset + 8 <= len(data):
        name, size = data[offset : offset + 4], struct.unpack("<I", data[offset + 4 : offset + 8])[0]
        chunks[name] = data[offset + 8 : offset + 8 + size]
        offset += 8 + size + (size & 1)
    tag, channels, _rate, _bytes_per_s, _align, bits = struct.unpack("<HHIIHH", chunks[b"fmt "][:16])
    if tag == 0xFFFE:  # WAVE_FORMAT_EXTENSIBLE: the format is the sub-format GUID's first two bytes.
        tag = struct.unpack("<H", chunks[b"fmt "][24:26])[0]
    assert (tag, channels, bits) == (3, 1, 32), f"{path}: not mono f32 (tag {tag}, {channels} ch, {bits} bits)"
    return np.frombuffer(chunks[b"data"], dtype="<f4")


def cli_render(cli: Path, tmp_path: Path, *args: str) -> np.ndarray:
    """`sake-glug render ARGS -o WAV` (f32), its samples."""
    wav = tmp_path / "cli.wav"
    done = run_cli(cli, "render", *args, "-o", str(wav), "--sample-format", "f32")
    assert done.returncode == 0, done.stderr
    return read_f32_wav(wav)


class CtrlC(Exception):
    """What Ctrl-C raises in the tests that send it (`_thread.interrupt_main`): were the code
    under test to ignore it until later, a KeyboardInterrupt would then stop pytest itself, where
    this fails the test."""


@pytest.fixture
def ctrl_c():
    """SIGINT raises CtrlC for the test's duration: Ctrl-C as Python handles it, by the handler."""

    def handler(_signum, _frame):
        raise CtrlC

    previous = signal.signal(signal.SIGINT, handler)
    yield CtrlC
    signal.signal(signal.SIGINT, previous)
