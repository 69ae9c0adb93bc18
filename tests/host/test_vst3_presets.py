"""The VST3 preset files, loaded by a real VST3 host: pedalboard's `load_preset`, which reads a
`.vstpreset` with Steinberg's own reader (`PresetFile::loadPreset`, through JUCE): it checks the
class ID and hands the 'Comp' chunk to the plugin's `IComponent::setState`. Each file must leave
the plugin holding its preset's values (those `sake-glug presets` lists), every other parameter
back at its default.

What the plugin holds is read back from the plugin itself: pedalboard's `preset_data` is a
`.vstpreset` that JUCE writes from the plugin's `IComponent::getState`. pedalboard's parameter
objects cannot tell: JUCE caches parameter values and its preset path does not read them again
after `setState` (Steinberg leaves that rescan to the host), so they keep showing the values from
before the load, and `reset=True` (which re-creates the plugin and re-applies those cached
values) overwrites the preset. A DAW rescans the parameters after loading a preset.

Needs the release bundle and CLI (`cargo xtask bundle sake_glug --release --no-default-features
--features editor`, `cargo build --release --bin sake-glug --no-default-features --features
cli`); both are looked for under $CARGO_TARGET_DIR, else target/.
"""

import json
import os
import subprocess
import tomllib
from pathlib import Path

import pytest
from pedalboard import load_plugin

REPO = Path(__file__).resolve().parents[2]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
BUNDLE = TARGET / "bundled" / "Sake Glug.vst3"
CLI = TARGET / "release" / "sake-glug"
PRESET_FOLDER = REPO / "presets" / "vst3"

# Where each parameter a preset sets is in the preset's scene file (`sake-glug presets ID`).
SCENE_KEYS = {
    "Viscosity": ("viscosity_c",),
    "Pour time": ("pour_time_s",),
    "Capacity": ("bottle", "capacity_ml"),
    "Pocket volume": ("bottle", "pocket_ml"),
    "f1": ("glug", "f1_hz"),
    "f2": ("glug", "f2_hz"),
    "B1": ("glug", "b1_per_s"),
    "B2": ("glug", "b2_per_s"),
    # The headspace law and the glide (MODEL.md §5.1, §5.2): only a preset that follows them
    # names them; the others leave them at their defaults.
    "Headspace": ("bottle", "headspace_ml"),
    "f1 headspace exponent": ("glug", "f1_headspace_exponent"),
    "f2 headspace exponent": ("glug", "f2_headspace_exponent"),
    "f1 glide ratio": ("glug", "f1_glide_ratio"),
    "f2 glide ratio": ("glug", "f2_glide_ratio"),
    "f1 glide time": ("glug", "f1_glide_ms"),
    "f2 glide time": ("glug", "f2_glide_ms"),
}

# The IDs the plugin saves its parameters under (crates/plugin/src/params.rs).
PARAMETER_IDS = {
    "Viscosity": "visc",
    "Pour time": "pour",
    "Capacity": "cap",
    "Pocket volume": "pocket",
    "f1": "f1",
    "f2": "f2",
    "B1": "b1",
    "B2": "b2",
    "Headspace": "headsp",
    "f1 headspace exponent": "f1exp",
    "f2 headspace exponent": "f2exp",
    "f1 glide ratio": "f1glide",
    "f2 glide ratio": "f2glide",
    "f1 glide time": "f1glms",
    "f2 glide time": "f2glms",
}

# A user's changes before picking a preset: the preset must undo them.
MOVED = {"Tilt": "120", "Output gain": "-20", "Seed": "77", "Drain mode": "Follow"}


def cli(*args: str) -> str:
    if not CLI.exists():
        pytest.fail(f"{CLI} is missing: run `cargo build --release --bin sake-glug`")
    return subprocess.run([str(CLI), *args], check=True, capture_output=True, text=True).stdout


def presets() -> list[tuple[str, dict[str, float]]]:
    """Every preset as (name, {parameter: value}), from the code's own list and scene files."""
    found = []
    for line in cli("presets").splitlines():
        preset_id, rest = line.split(maxsplit=1)
        name = rest.split(": ", 1)[0]
        scene = tomllib.loads(cli("presets", preset_id))
        values = {}
        for parameter, keys in SCENE_KEYS.items():
            value = scene
            for key in keys:
                value = value.get(key) if isinstance(value, dict) else None
            if value is not None:
                values[parameter] = float(value)
        found.append((name, values))
    return found


PRESETS = presets() if CLI.exists() else []


def load() -> object:
    if not BUNDLE.exists():
        pytest.fail(f"{BUNDLE} is missing: run `cargo xtask bundle sake_glug --release`")
    # A generator never passes pedalboard's instrument warm-up (it waits for a note to sound).
    return load_plugin(str(BUNDLE), initialization_timeout=0.2)


def chunks(data: bytes) -> dict[bytes, bytes]:
    """The chunks of a .vstpreset by id, found through its chunk list."""
    assert data[:4] == b"VST3"
    list_offset = int.from_bytes(data[40:48], "little")
    assert data[list_offset : list_offset + 4] == b"List"
    count = int.from_bytes(data[list_offset + 4 : list_offset + 8], "little")
    found = {}
    for index in range(count):
        entry = list_offset + 8 + 20 * index
        offset = int.from_bytes(data[entry + 4 : entry + 12], "little")
        size = int.from_bytes(data[entry + 12 : entry + 20], "little")
        found[data[entry : entry + 4]] = data[offset : offset + size]
    return found


def held_state(plugin) -> dict:
    """The state the plugin itself reports (IComponent::getState, as JUCE saves a preset)."""
    return json.loads(chunks(plugin.preset_data)[b"Comp"])


@pytest.fixture(scope="module")
def plugin():
    return load()


@pytest.fixture(scope="module")
def defaults() -> dict:
    """The state of a newly loaded plugin."""
    return held_state(load())


def test_every_preset_has_a_file_and_every_file_a_preset():
    assert PRESETS, f"no presets listed by {CLI}"
    assert sorted(f"{name}.vstpreset" for name, _ in PRESETS) == sorted(
        path.name for path in PRESET_FOLDER.iterdir()
    )


@pytest.mark.parametrize("name, values", PRESETS, ids=[name for name, _ in PRESETS])
def test_load_preset_sets_the_presets_values_and_resets_the_rest(plugin, defaults, name, values):
    parameters = {parameter.name: parameter for parameter in plugin.parameters.values()}
    for parameter, text in MOVED.items():
        parameters[parameter].raw_value = parameters[parameter].get_raw_value_for_text(text)
    # The moves reach the plugin: pedalboard sets them on the edit controller at once.
    assert held_state(plugin)["params"]["tilt"] == {"f32": 120.0}

    path = PRESET_FOLDER / f"{name}.vstpreset"
    plugin.load_preset(str(path))

    held = plugin.preset_data
    file = path.read_bytes()
    assert held[8:40] == file[8:40], "the host spells the class ID as the file does"
    assert chunks(held)[b"Comp"] == chunks(file)[b"Comp"], (
        "the plugin saves the file's state back, byte for byte"
    )
    state = json.loads(chunks(held)[b"Comp"])
    for parameter, expected in values.items():
        saved = state["params"][PARAMETER_IDS[parameter]]["f32"]
        # The plain value is the f32 nearest the decimal the parameter shows.
        assert saved == pytest.approx(expected, rel=1e-6), f"{name}: {parameter} is {saved}"
    for parameter_id, value in defaults["params"].items():
        if parameter_id not in (PARAMETER_IDS[p] for p in values):
            assert state["params"][parameter_id] == value, f"{name}: {parameter_id} not default"
    assert state["fields"] == defaults["fields"], f"{name}: the saved settings are the defaults"


def test_a_file_of_another_plugin_is_refused(plugin, tmp_path):
    """The host checks the class ID: the same state under another plugin's ID does not load."""
    data = bytearray((PRESET_FOLDER / "Water.vstpreset").read_bytes())
    data[8:40] = b"0" * 32
    other = tmp_path / "other.vstpreset"
    other.write_bytes(bytes(data))
    with pytest.raises(RuntimeError):
        plugin.load_preset(str(other))
