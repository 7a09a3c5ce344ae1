"""The translation layer (hdVolPhoton/core/translate/) as the usd-core front end sees it: the one
settings table reaches the CLI, the RenderSettings reader and the README; UsdLux's blackbody is
reproduced; the Python side keeps no attribute-to-parameter rules of its own."""

import os
import subprocess
import sys

import pytest
from pxr import UsdLux

from conftest import REPO, volphoton_exe
from volphoton import _core, cli, schema as vs, usdscene

sys.path.insert(0, os.path.join(REPO, "tools"))
import settings_table  # noqa: E402


@pytest.mark.parametrize("kelvin", [800, 1000, 1250, 1777, 2500, 3333, 4000, 5000, 6500, 7250, 8000, 9999, 10000, 12000])
def test_blackbody_matches_usdlux(kelvin):
    ours = _core.usd_lux_blackbody(kelvin)
    theirs = UsdLux.BlackbodyTemperatureAsRgb(kelvin)  # float32 in OpenUSD
    assert ours == pytest.approx(tuple(theirs), rel=2e-5, abs=2e-6)


def test_settings_table_is_the_one_source():
    table = _core.render_settings_table()
    names = [e["name"] for e in table]
    assert tuple(names) == usdscene.SETTINGS_ATTRIBUTES
    defaults = _core.RenderSettings()
    for e in table:
        assert _core.get_setting(defaults, e["name"]) == e["default"], e["name"]
    # Every flag of the table is a flag of the CLI, with the table's meaning in its help.
    help_text = subprocess.run([volphoton_exe(), "render", "--help"], capture_output=True, text=True).stdout
    for e in table:
        if e["cli_flag"]:
            assert e["cli_flag"] in help_text, e["cli_flag"]
            assert "volphoton:%s" % e["name"] in help_text, e["name"]


def test_readme_settings_table_is_generated_from_the_core_table():
    text = open(os.path.join(REPO, "README.md")).read()
    assert settings_table.readme_block(text) == settings_table.table(), \
        "README.md's settings table is stale: run python tools/settings_table.py --write"


def test_render_settings_prim_goes_through_the_table(tmp_path):
    from pxr import Usd

    path = tmp_path / "rs.usda"
    path.write_text('#usda 1.0\ndef RenderSettings "rs" {\n    int volphoton:maxDepth = 9\n'
                    '    double volphoton:radiusAlpha = 3\n    string volphoton:integrator = "photonMap"\n'
                    '    float volphoton:maxGridVoxels = 1000\n    int volphoton:bogus = 1\n}\n')
    info = usdscene.read_render_settings(Usd.Stage.Open(str(path)))
    assert info.settings.max_depth == 9 and info.settings.radius_alpha == 1.0
    assert info.settings.integrator == _core.RenderSettings.Integrator.PhotonMap
    assert info.max_grid_voxels == 1000 and info.settings.max_grid_voxels == 1000
    text = "\n".join(map(str, info.diagnostics))
    assert "warning: /rs.volphoton:radiusAlpha: radiusAlpha = 3 is outside [1e-06, 1]; clamped to 1" in text
    assert "warning: /rs.volphoton:bogus: unknown render setting" in text


def test_cli_flags_are_validated_by_the_table():
    args = cli.build_parser().parse_args(["render", "x.usda", "-o", "x.exr", "--max-depth", "5", "--integrator",
                                          "photonmap"])
    info = usdscene.RenderSettingsInfo()
    s = cli._settings(_core, args, info, 8, 4)
    assert s.max_depth == 5 and s.integrator == _core.RenderSettings.Integrator.PhotonMap and s.width == 8


def test_python_front_end_has_no_medium_or_light_rules():
    """The front end only reads attributes: the numbers of the rules (clamps, k(g), the preset
    mapping, the light units) live in core/translate. A cheap guard against them creeping back."""
    src = "".join(open(os.path.join(REPO, "hdVolPhoton", "python", "volphoton", f)).read()
                  for f in ("schema.py", "usdscene.py"))
    for rule in ("1.55 * g", "math.sin(half)", "4.0 * math.pi * r * r", "BlackbodyTemperatureAsRgb",
                 "preset_coefficients(", "G_LIMIT, G_LIMIT"):
        assert rule not in src, rule
    assert vs.DEFAULTS["volphoton:density"] == 1.0 and vs.LOBE_DEFAULTS["weight"] == 1.0
