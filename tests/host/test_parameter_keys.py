"""The guide's parameter table (docs/guide/sound-designer.md, written by `sake-glug parameters`)
gives each parameter's key in pedalboard, the names `plugin.parameters[...]` takes: here they
are held to the keys pedalboard gives the VST3's own parameters, every one of them, and each to
the parameter of its row's name.

Needs `cargo xtask bundle sake-glug-plugin --release`.
"""

import re
from pathlib import Path

import pytest
from pedalboard import load_plugin

REPO = Path(__file__).resolve().parents[2]
BUNDLE = REPO / "target" / "bundled" / "Sake Glug.vst3"
GUIDE = REPO / "docs" / "guide" / "sound-designer.md"


def guide_rows():
    """{pedalboard key: name} of the guide's table, rows with a key only."""
    text = GUIDE.read_text()
    block = text.split("<!-- generated:parameters:begin -->")[1].split("<!-- generated:parameters:end -->")[0]
    lines = [line for line in block.splitlines() if line.startswith("|")]
    header = [cell.strip() for cell in lines[0].strip("|").split("|")]
    key, name = header.index("pedalboard key"), header.index("name")
    rows = {}
    for line in lines[2:]:
        cells = [cell.strip() for cell in line.strip("|").split("|")]
        found = re.fullmatch(r"`([^`]+)`", cells[key])
        if found:
            rows[found.group(1)] = cells[name]
    return rows


@pytest.fixture(scope="module")
def plugin():
    if not BUNDLE.exists():
        pytest.skip(f"{BUNDLE} is missing: cargo xtask bundle sake-glug-plugin --release")
    # A generator never passes pedalboard's instrument warm-up: a short timeout.
    return load_plugin(str(BUNDLE), initialization_timeout=0.2)


def test_the_guides_keys_are_pedalboards(plugin):
    rows = guide_rows()
    assert set(rows) == set(plugin.parameters), (
        f"only in the guide: {sorted(set(rows) - set(plugin.parameters))}; "
        f"only in pedalboard: {sorted(set(plugin.parameters) - set(rows))}"
    )
    for key, name in rows.items():
        assert plugin.parameters[key].name == name, key
