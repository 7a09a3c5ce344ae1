"""One benchmark scene (testenv/bench/<name>.usda) as the probe tools under tools/ read it: the cloud
VDB written first when missing (the benchmark's: write_procedural_cloud_vdb(path, 64, 1/64, seed 1),
tools/bench/README.md), the stage's RenderSettings prim, the translation at width x height."""

import os

from pxr import Usd
from volphoton import _core, usdscene

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(REPO, "testenv", "bench")


def load_bench_scene(name, width, height):
    """(RenderSettingsInfo, TranslatedScene) of benchmark scene `name` (or of the .usda file it names)
    at its earliest time."""
    vdb = os.path.join(BENCH, "cloud.vdb")
    if not os.path.exists(vdb):
        _core.write_procedural_cloud_vdb(vdb, 64, 1.0 / 64, 1)
    stage = Usd.Stage.Open(name if name.endswith(".usda") else os.path.join(BENCH, name + ".usda"))
    rs = usdscene.read_render_settings(stage)
    tr = usdscene.translate(stage, Usd.TimeCode.EarliestTime(), width, height, rs.camera_path, rs.conform_policy)
    return rs, tr
