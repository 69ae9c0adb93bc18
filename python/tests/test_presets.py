"""sake_glug.presets() lists what `sake-glug presets` lists."""

import sake_glug
from conftest import run_cli


def test_the_presets_are_the_clis(cli):
    listing = run_cli(cli, "presets").stdout.splitlines()
    presets = sake_glug.presets()
    assert [f"{p.id:<13} {p.name}: {p.description}" for p in presets] == listing
    for preset in presets:
        assert preset.scene == run_cli(cli, "presets", preset.id).stdout


def test_a_preset_renders_by_its_id():
    water = sake_glug.presets()[0]
    assert water.id == "water"
    assert sake_glug.render(preset=water.id).size > 0
