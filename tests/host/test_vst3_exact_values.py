"""Exact values in a JUCE host (pedalboard): every float parameter of the VST3 is continuous to
the host, and a value typed lands as typed and reads back as typed.

- The VST3 declares stepCount 0 for each float parameter: JUCE then reports its default number
  of steps (2³¹ − 1). pedalboard's repr calls every VST3 parameter "discrete" whatever it
  declares (JUCE 7's VST3Parameter initialises `discrete` from `numSteps` before `numSteps`
  itself), and its `range=(0.0, 180.0, 0.18)` is its own probe of 1001 raw values.
- A value typed (the host asks the plugin to parse the text, as a host's text entry and JUCE's
  `getValueForText` do) lands exactly: Tilt 100 reads 100, f2 300 reads 300, and so for values
  across every float parameter's range, off pedalboard's probe grid.
- pedalboard's attribute setter (`plugin.tilt = 100`) is another path: when the plugin's parse
  of the value falls outside the raw interval of the nearest of its 1001 probed values, it
  takes that probe's raw value instead (`AudioProcessorParameter.get_raw_value_for` in
  pedalboard/_pedalboard.py), so Tilt 100 arrives as 100.08 whatever the plugin declares. The
  last test shows that this is pedalboard's probe, not the plugin.

Needs `cargo xtask bundle sake-glug-plugin --release`.
"""

from pathlib import Path

import pytest
from pedalboard import load_plugin

REPO = Path(__file__).resolve().parents[2]
BUNDLE = REPO / "target" / "bundled" / "Sake Glug.vst3"

# What JUCE reports as a parameter's number of steps when the VST3 declares stepCount 0
# (AudioProcessor::getDefaultNumParameterSteps).
CONTINUOUS_STEPS = 0x7FFFFFFF
# Points across each range, in eighths: none of them on pedalboard's grid of 1000 probes for
# most ranges once rounded to the parameter's decimals.
EIGHTHS = range(1, 8)


@pytest.fixture(scope="module")
def plugin():
    if not BUNDLE.exists():
        pytest.fail(f"{BUNDLE} is missing: run `cargo xtask bundle sake-glug-plugin --release`")
    # A generator never passes pedalboard's instrument warm-up (it waits for a note to sound):
    # without a short initialization_timeout every load waits the default 10 s.
    return load_plugin(str(BUNDLE), initialization_timeout=0.2)


# The one integer parameter: pedalboard reads its text as a number too; it is stepped, rightly.
INTEGER_PARAMETERS = {"seed"}


def float_parameters(plugin):
    return {
        name: p
        for name, p in plugin.parameters.items()
        if p.type is float and name not in INTEGER_PARAMETERS
    }


def decimals(text: str) -> int:
    number = text.split()[0].rstrip("°%")
    return len(number.partition(".")[2])


def typed(plugin, name, text):
    """Types `text` into parameter `name` as a host's text entry does; returns what reads back."""
    parameter = plugin.parameters[name]
    parameter.raw_value = parameter.get_raw_value_for_text(text)
    return float(getattr(plugin, name))


def test_every_float_parameter_is_continuous_to_the_host(plugin):
    parameters = float_parameters(plugin)
    assert {"tilt", "f2_hz", "output_ceiling_db"} <= set(parameters), sorted(plugin.parameters)
    for name, parameter in parameters.items():
        assert parameter.num_steps == CONTINUOUS_STEPS, f"{name}: {parameter.num_steps} steps"


def test_the_values_of_the_issue_land_as_typed(plugin):
    assert typed(plugin, "tilt", "100") == 100.0
    assert typed(plugin, "f2_hz", "300") == 300.0
    assert typed(plugin, "tilt", "97.5") == 97.5


def test_every_float_parameter_takes_values_across_its_range_as_typed(plugin):
    wrong = []
    for name, parameter in float_parameters(plugin).items():
        places = decimals(parameter.string_value)
        low, high = parameter.min_value, parameter.max_value
        for eighth in EIGHTHS:
            value = round(low + (high - low) * eighth / 8, places)
            text = f"{value:.{places}f}"
            landed = typed(plugin, name, text)
            if landed != float(text):
                wrong.append(f"{name} {text} → {landed}")
    assert not wrong, wrong


def test_pedalboards_attribute_setter_snaps_to_its_own_probe(plugin):
    """Not the plugin: pedalboard's setter falls back to a probed value (see the docstring)."""
    parameter = plugin.parameters["tilt"]
    assert parameter.range == (0.0, 180.0, 0.18), "pedalboard probes 1001 raw values"
    plugin.tilt = 100
    assert float(plugin.tilt) == 100.08
    # The plugin's own parse of the same value is exact.
    assert parameter.get_raw_value_for_text("100") * 180 == pytest.approx(100.0, abs=1e-4)
