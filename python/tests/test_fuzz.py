"""Property-based fuzz tests of the Python entry points, as tests/offline/research_fuzz.rs fuzzes
the researcher's files for the command line: render, render_tables, fit, analyze_paired and
analyze_constant given structures that contain themselves or nest thousands deep, numbers past
any machine type, values of every odd type, and files of mutated text. Whatever they are given,
they return, or raise SakeGlugError (its message free of raw control characters but toml's line
breaks), or a TypeError or OverflowError for an argument of the wrong kind; never anything else,
never a crash (which would end this run), never a hang (a case still running after HANG_AFTER_S
ends it with every thread's traceback).

SAKE_GLUG_FUZZ_EXAMPLES sets the cases per test (default 50, a few seconds in all); Hypothesis
draws new ones each run and prints the seed of a failure to reproduce it."""

import faulthandler
import os
import unicodedata
import warnings
import wave
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import sake_glug

EXAMPLES = int(os.environ.get("SAKE_GLUG_FUZZ_EXAMPLES", "50"))

# A case that runs this long is taken for a hang. Not a speed claim: cases take milliseconds.
HANG_AFTER_S = 60

FUZZ = settings(
    max_examples=EXAMPLES,
    # No deadline: a case's time is no verdict (a slow machine is no failure).
    deadline=None,
    # Nothing written next to the sources.
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)


class Enough(Exception):
    """Raised by the progress callback below: a render has shown it runs, and need not finish."""


def stop_at_first_progress(_done, _total):
    raise Enough


def held(call):
    """`call()`, held to what any argument may bring about."""
    faulthandler.dump_traceback_later(HANG_AFTER_S, exit=True)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an empty scene's, and NumPy's about odd values
            call()
    except (sake_glug.SakeGlugError, TypeError, OverflowError, Enough) as error:
        message = str(error)
        assert isinstance(error, Enough) or message, f"{type(error).__name__} without a message"
        # Line breaks are toml's own layout of a parse error (as research_fuzz.rs allows them).
        raw = sorted({c for c in message if unicodedata.category(c) == "Cc" and c != "\n"})
        assert not raw, f"raw control characters {raw} in {message[:500]!r}"
    finally:
        faulthandler.cancel_dump_traceback_later()


# ---- Values of every kind ----

ODD = st.sampled_from(
    [
        object(),
        {1, 2},
        frozenset(),
        1 + 2j,
        b"bytes",
        bytearray(b"x"),
        range(3),
        Decimal("1.5"),
        Fraction(1, 3),
        np.float32(1.5),
        np.int64(7),
        np.bool_(True),
        np.array([1.0, 2.0]),
        Ellipsis,
        type,
        print,
        Path("nowhere.toml"),
    ]
)
HUGE_INTS = st.integers() | st.sampled_from([2**63 - 1, 2**63, -(2**63) - 1, 2**64, 10**30, 10**400])
TEXT = st.text(max_size=24) | st.sampled_from(["\x1b[31mred", "a\x00b", "\n", "=", "\u202e", "x" * 5000])
LEAVES = st.none() | st.booleans() | HUGE_INTS | st.floats() | TEXT | ODD

# The keys of a scene, at every level (MODEL.md §10), and some that are not.
SCENE_KEYS = [
    "sample_rate", "duration_s", "seed", "deterministic", "midi_take", "tilt_deg", "viscosity_c",
    "fill_percent", "pour_time_s", "gain_db", "output", "drain", "glug", "f1_hz", "f2_hz",
    "b1_per_s", "b2_per_s", "timing_jitter", "freq_jitter", "decay_sigma", "bottle", "pocket_ml",
    "capacity_ml", "amplitude", "silent_below_ml", "spread", "curves", "midi", "csv", "column",
]
KEYS = st.sampled_from(SCENE_KEYS) | TEXT


def containers(children):
    lists = st.lists(children, max_size=4)
    return lists | lists.map(tuple) | st.dictionaries(KEYS, children, max_size=4)


VALUES = st.recursive(LEAVES, containers, max_leaves=16)
SCENE_DICTS = st.dictionaries(KEYS, VALUES, max_size=6)


@st.composite
def deep(draw):
    """A dict, list or tuple nested up to 50,000 deep (pythonize overflowed the stack at 20,000)."""
    depth = draw(st.integers(min_value=1, max_value=50_000))
    kind = draw(st.sampled_from(["dict", "list", "tuple"]))
    key = draw(KEYS)
    value = draw(LEAVES)
    for _ in range(depth):
        value = {key: value} if kind == "dict" else [value] if kind == "list" else (value,)
    return value


def mutable_containers(value, path=()):
    """Every dict and list in `value`, each with the containers it is inside of."""
    if isinstance(value, (dict, list, tuple)) and any(value is outer for outer in path):
        return
    if isinstance(value, (dict, list)):
        yield value, path
    if isinstance(value, (dict, list, tuple)):
        for item in value.values() if isinstance(value, dict) else value:
            yield from mutable_containers(item, path + (value,))


@st.composite
def cyclic(draw):
    """A structure with a container put inside itself or inside one it is in."""
    value = draw(st.one_of(SCENE_DICTS, st.lists(VALUES, max_size=4)).filter(bool))
    found = list(mutable_containers(value))
    container, path = draw(st.sampled_from(found))
    outer = draw(st.sampled_from(path + (container,)))
    if isinstance(container, dict):
        container[draw(KEYS)] = outer
    else:
        container.append(outer)
    return value


@st.composite
def toml_texts(draw):
    """Scene text: lines of known keys and odd values, and text of any kind."""
    values = st.sampled_from(
        ["1", "-1", "1e400", "nan", "-inf", '"x"', "[1, 2]", "{a = 1}", "[[0.0, 90.0], [1.0, 135.0]]",
         "9" * 40, '"\\u001b[31m"', "[[[[[[[[1]]]]]]]]", "[" * 200 + "]" * 200]
    ) | TEXT.map(repr)
    lines = draw(st.lists(st.tuples(KEYS, values), max_size=6))
    text = "\n".join(f"{key} = {value}" for key, value in lines) + "\n"
    return draw(st.sampled_from([text, text + draw(TEXT) + "\n", draw(TEXT) + "=\n"]))


SCENES = st.one_of(SCENE_DICTS, deep(), cyclic(), toml_texts(), LEAVES, VALUES)
SAMPLE_RATES = st.none() | st.floats() | HUGE_INTS | st.sampled_from([1000, 8000, 48000.0, 768000]) | ODD
PRESETS = st.none() | st.sampled_from([preset.id for preset in sake_glug.presets()]) | TEXT | ODD


@FUZZ
@given(scene=SCENES, sample_rate=SAMPLE_RATES, preset=PRESETS)
def test_render_takes_any_argument(scene, sample_rate, preset):
    # A render that runs past its first progress call is stopped there: what it was given ran.
    held(lambda: sake_glug.render(scene, sample_rate=sample_rate, preset=preset, progress=stop_at_first_progress))


# render_tables takes no progress callback: every scene it renders lasts at most two seconds.
SHORT_OR_REFUSED = (
    st.floats(min_value=1e-3, max_value=2.0)
    | st.floats(max_value=0.0)
    | st.floats(min_value=86_400.5)
    | st.integers(max_value=0)
    | st.integers(min_value=86_401)
    | TEXT
    | st.none()
    | VALUES.filter(lambda value: not isinstance(value, (int, float)))
)


@st.composite
def short_scenes(draw):
    scene = draw(st.one_of(SCENE_DICTS, cyclic().filter(lambda value: isinstance(value, dict))))
    scene["duration_s"] = draw(SHORT_OR_REFUSED)
    return scene


@FUZZ
@given(
    scene=st.one_of(short_scenes(), deep(), LEAVES),
    sample_rate=SAMPLE_RATES,
    state_rate=st.floats() | HUGE_INTS | ODD | st.just(1000.0),
)
def test_render_tables_takes_any_argument(scene, sample_rate, state_rate):
    held(lambda: sake_glug.render_tables(scene, sample_rate=sample_rate, state_rate=state_rate))


# ---- Files of mutated text ----


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A folder with a second of pour as a 16-bit WAV at 8 kHz (what a session's recording is)."""
    folder = tmp_path_factory.mktemp("fuzz")
    samples = sake_glug.render({"sample_rate": 8000, "tilt_deg": 135.0, "duration_s": 1.0})
    with wave.open(str(folder / "pour.wav"), "wb") as pour:
        pour.setnchannels(1)
        pour.setsampwidth(2)
        pour.setframerate(8000)
        pour.writeframes((np.clip(samples, -1, 1) * 32767).astype("<i2").tobytes())
    (folder / "weight.csv").write_text("time_s,grams\n0,600\n0.5,580\n1,560\n")
    return folder


FIELD_VALUES = st.sampled_from(
    ['"pour.wav"', '"weight.csv"', '"missing.wav"', '"/dev/null"', '"."', "135.0", "-1", "1e400", "nan",
     "300.0", "0", '"grams"', '"time_s"', '"\\u001b]0;title\\u0007"', '"' + "w" * 5000 + '"', "[]", "{}"]
) | TEXT.map(lambda text: '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"')
SESSION_KEYS = st.sampled_from(
    ["audio", "tilt_deg", "start_ml", "liquid", "capacity_ml", "weight", "csv", "time", "column",
     "density_g_per_ml"]
) | TEXT


@st.composite
def session_texts(draw):
    """A valid session with lines replaced, added or cut."""
    lines = [
        "[[recording]]",
        'audio = "pour.wav"',
        "tilt_deg = 135.0",
        "start_ml = 300.0",
        'liquid = "water"',
        "[recording.weight]",
        'csv = "weight.csv"',
        'column = "grams"',
    ]
    for _ in range(draw(st.integers(0, 4))):
        index = draw(st.integers(0, len(lines)))
        action = draw(st.sampled_from(["replace", "insert", "cut"]))
        line = f"{draw(SESSION_KEYS)} = {draw(FIELD_VALUES)}"
        if action == "insert" or index == len(lines):
            lines.insert(index, line)
        elif action == "replace":
            lines[index] = line
        else:
            del lines[index]
    return "\n".join(lines) + "\n"


NOT_PATHS = st.one_of(HUGE_INTS, st.floats(), ODD, VALUES, deep(), cyclic(), st.just(""))


@FUZZ
@given(data=st.data())
def test_fit_takes_any_argument(folder, data):
    if data.draw(st.booleans()):
        session = folder / "session.toml"
        session.write_text(data.draw(session_texts()))
    else:
        session = data.draw(NOT_PATHS | TEXT)
    held(lambda: sake_glug.fit(session))


CSV_FIELDS = st.one_of(
    st.sampled_from(["a", "b", "c", "p1", "0", "1", "0.3", "nan", "inf", "-1e400", "1e308", "", '"', '","', "x" * 5000]),
    HUGE_INTS.map(str),
    st.floats().map(repr),
    TEXT,
)


@st.composite
def log_texts(draw, columns):
    """A trial log: its columns (some missing, some extra), then rows of odd fields."""
    header = draw(st.permutations(columns + ["extra"]))
    header = header[: len(header) - draw(st.integers(0, 2))]
    rows = draw(st.lists(st.lists(CSV_FIELDS, min_size=len(header), max_size=len(header)), max_size=12))

    def quoted(field):
        return '"' + field.replace('"', '""') + '"' if any(c in field for c in ',"\n\r') else field

    return "\n".join(",".join(quoted(field) for field in row) for row in [header] + rows) + "\n"


@st.composite
def logs(draw, folder, columns):
    if not draw(st.booleans()):
        return draw(NOT_PATHS | TEXT)
    paths = []
    for index in range(draw(st.integers(1, 3))):
        path = folder / f"log{index}.csv"
        path.write_text(draw(log_texts(columns)))
        paths.append(path)
    return paths + draw(st.lists(NOT_PATHS, max_size=1))


@FUZZ
@given(data=st.data())
def test_analyze_paired_takes_any_argument(folder, data):
    logged = data.draw(logs(folder, ["participant", "first", "second", "answer"]))
    held(lambda: sake_glug.analyze_paired(logged))


COUNTS = st.integers(min_value=1, max_value=20) | HUGE_INTS | st.floats() | ODD | st.none()


@FUZZ
@given(data=st.data())
def test_analyze_constant_takes_any_argument(folder, data):
    logged = data.draw(logs(folder, ["participant", "level", "chose_comparison"]))
    resamples = data.draw(COUNTS)
    seed = data.draw(HUGE_INTS | ODD | st.none())
    lapse = data.draw(st.floats() | st.sampled_from([0.0, 0.1, 0.2]) | HUGE_INTS | ODD | st.none())
    held(lambda: sake_glug.analyze_constant(logged, resamples=resamples, seed=seed, lapse=lapse))
