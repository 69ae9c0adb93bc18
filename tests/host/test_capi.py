"""The C library's faces against the command line: the C, C++, C# (Mono) and Python `ctypes`
examples of examples/ each write the built-in pour, and each file holds the samples of
`sake-glug render -o x.wav --sample-format f32`, bit for bit. The C example is also linked
statically. At a haptic rate (2 kHz, a controller's PCM haptics) the ctypes example renders the
CLI's samples at `--sample-rate 2000` too.

Needs the release library and CLI (`cargo xtask test` builds them: `cargo build --release -p
sake-glug-c`), gcc and g++, and Mono (Debian's mono-mcs and mono-runtime; .ci/run installs them).
"""

import importlib.util
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.io import wavfile

REPO = Path(__file__).resolve().parents[2]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
RELEASE = TARGET / "release"
CLI = RELEASE / "sake-glug"
SHARED = RELEASE / "libsake_glug.so"
STATIC = RELEASE / "libsake_glug.a"
INCLUDE = REPO / "include"
EXAMPLES = REPO / "examples"


def tool(name, package):
    if shutil.which(name) is None:
        if os.environ.get("CI"):
            pytest.fail(f"{name} is not installed (Debian: {package}); .ci/run installs it")
        pytest.skip(f"{name} is not installed (Debian: {package})")


def with_library():
    return dict(os.environ, LD_LIBRARY_PATH=str(RELEASE))


def read_f32(path):
    rate, samples = wavfile.read(path)
    assert samples.dtype == np.float32 and samples.ndim == 1, (samples.dtype, samples.shape)
    return rate, samples


@pytest.fixture(scope="module")
def cli_pour(tmp_path_factory):
    """The CLI's built-in pour as 48 kHz f32 samples."""
    assert CLI.exists(), f"{CLI} is missing: cargo build --release --bin sake-glug"
    assert SHARED.exists(), f"{SHARED} is missing: cargo build --release -p sake-glug-c"
    path = tmp_path_factory.mktemp("cli") / "x.wav"
    subprocess.run([str(CLI), "render", "-o", str(path), "--sample-format", "f32"], check=True)
    rate, samples = read_f32(path)
    assert rate == 48000 and np.abs(samples).max() > 0.01
    return samples


def assert_bit_identical(path, expected):
    rate, samples = read_f32(path)
    assert rate == 48000
    assert samples.shape == expected.shape, f"{samples.shape} samples, the CLI {expected.shape}"
    differ = np.flatnonzero(samples.view(np.uint32) != expected.view(np.uint32))
    assert differ.size == 0, f"{differ.size} samples differ, the first at {differ[:1]}"


def run_example(command, tmp_path):
    out = tmp_path / "pour.wav"
    done = subprocess.run([*command, str(out)], env=with_library(), capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    # The one argument is the output path: no argument is refused with a usage line.
    refused = subprocess.run(command, env=with_library(), capture_output=True, text=True)
    assert refused.returncode == 2 and "usage" in refused.stderr
    return out


def test_c_example_renders_the_clis_samples(cli_pour, tmp_path):
    tool("gcc", "gcc")
    program = tmp_path / "pour_c"
    subprocess.run(
        ["gcc", "-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I", str(INCLUDE),
         str(EXAMPLES / "c" / "pour.c"), "-L", str(RELEASE), "-lsake_glug", "-o", str(program)],
        check=True,
    )
    assert_bit_identical(run_example([str(program)], tmp_path), cli_pour)


def test_c_example_linked_statically_renders_the_clis_samples(cli_pour, tmp_path):
    tool("gcc", "gcc")
    assert STATIC.exists(), f"{STATIC} is missing"
    program = tmp_path / "pour_static"
    subprocess.run(
        ["gcc", "-std=c11", "-I", str(INCLUDE), str(EXAMPLES / "c" / "pour.c"), str(STATIC),
         "-lpthread", "-ldl", "-lm", "-o", str(program)],
        check=True,
    )
    linked = subprocess.run(["ldd", str(program)], capture_output=True, text=True).stdout
    assert "sake_glug" not in linked, linked
    out = tmp_path / "pour.wav"
    subprocess.run([str(program), str(out)], check=True, env=dict(os.environ, LD_LIBRARY_PATH=""))
    assert_bit_identical(out, cli_pour)


def test_cpp_example_renders_the_clis_samples(cli_pour, tmp_path):
    tool("g++", "g++")
    program = tmp_path / "pour_cpp"
    subprocess.run(
        ["g++", "-std=c++17", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I", str(INCLUDE),
         str(EXAMPLES / "cpp" / "pour.cpp"), "-L", str(RELEASE), "-lsake_glug", "-o",
         str(program)],
        check=True,
    )
    assert_bit_identical(run_example([str(program)], tmp_path), cli_pour)


def test_csharp_example_on_mono_renders_the_clis_samples(cli_pour, tmp_path):
    tool("mcs", "mono-mcs")
    tool("mono", "mono-runtime")
    program = tmp_path / "pour.exe"
    subprocess.run(
        ["mcs", "-warnaserror", f"-out:{program}", str(EXAMPLES / "csharp" / "Pour.cs"),
         str(REPO / "bindings" / "csharp" / "SakeGlug.cs")],
        check=True,
    )
    assert_bit_identical(run_example(["mono", str(program)], tmp_path), cli_pour)


def test_python_ctypes_example_renders_the_clis_samples(cli_pour, tmp_path):
    example = EXAMPLES / "python" / "pour.py"
    # Its own interpreter without the venv's packages: it needs nothing but the library.
    python = shutil.which("python3") or "python3"
    command = [python, "-I", "-S", str(example)]
    assert_bit_identical(run_example(command, tmp_path), cli_pour)


def ctypes_example():
    spec = importlib.util.spec_from_file_location("pour", EXAMPLES / "python" / "pour.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_at_a_haptic_rate_the_library_renders_the_clis_samples(tmp_path):
    assert CLI.exists() and SHARED.exists()
    path = tmp_path / "haptic.wav"
    subprocess.run(
        [str(CLI), "render", "-o", str(path), "--sample-format", "f32", "--sample-rate", "2000"],
        check=True,
    )
    rate, expected = read_f32(path)
    assert rate == 2000
    pour = ctypes_example()
    samples = np.array(pour.render_pour(pour.load(str(SHARED)), 2000), dtype=np.float32)
    assert samples.shape == expected.shape
    assert np.array_equal(samples.view(np.uint32), expected.view(np.uint32))
    assert np.abs(samples).max() > 0.01, "it glugs at 2 kHz"


def test_a_bad_model_text_raises_the_librarys_message():
    pour = ctypes_example()
    with pytest.raises(RuntimeError, match="`tilt_deg` does not belong in a model"):
        pour.render_pour(pour.load(str(SHARED)), 48000, model_text="tilt_deg = [[0.0, 90.0]]")


def test_a_shipped_preset_plays_as_the_clis_render_of_its_file(tmp_path):
    assert CLI.exists() and SHARED.exists()
    path = tmp_path / "syrup.wav"
    subprocess.run(
        [str(CLI), "render", str(REPO / "presets" / "syrup.toml"), "-o", str(path),
         "--sample-format", "f32"],
        check=True,
    )
    rate, expected = read_f32(path)
    pour = ctypes_example()
    samples = np.array(pour.render_pour(pour.load(str(SHARED)), rate, preset="syrup"),
                       dtype=np.float32)
    assert samples.shape == expected.shape
    assert np.array_equal(samples.view(np.uint32), expected.view(np.uint32))


def test_an_unknown_preset_raises_the_librarys_message():
    pour = ctypes_example()
    with pytest.raises(RuntimeError, match="no preset `rum`: the presets are water, "):
        pour.render_pour(pour.load(str(SHARED)), 48000, preset="rum")
