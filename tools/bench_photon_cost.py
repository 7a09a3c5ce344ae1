#!/usr/bin/env python3
"""What a photon and a camera sample cost in the photon-map integrator (issue 15, "photon counts
that fit the job"): for each benchmark scene (testenv/bench/*.usda) at its settings, 4 passes at
defaults, the photon pass's ns per traced photon, the camera pass's ns per pixel-sample, and the
photons per pixel that would make the two passes take equally long.

    python tools/bench_photon_cost.py                 # 80x60
    python tools/bench_photon_cost.py --resolution 160 120 --passes 8
"""

import argparse
import os

from pxr import Usd
from volphoton import _core, usdscene

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(REPO, "testenv", "bench")
SCENES = ["homogeneous_cube", "vdb_cloud", "dense_cloud", "fog_spotlight", "atmosphere_sunset", "emissive_smoke"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resolution", nargs=2, type=int, default=[80, 60])
    ap.add_argument("--passes", type=int, default=4)
    args = ap.parse_args(argv)
    w, h = args.resolution
    vdb = os.path.join(BENCH, "cloud.vdb")
    if not os.path.exists(vdb):
        _core.write_procedural_cloud_vdb(vdb, 64, 1.0 / 64, 1)  # the benchmark's cloud
    print("| scene | ns per photon | ns per camera pixel-sample | photons per pixel for equal pass times |")
    print("|---|---|---|---|")
    for name in SCENES:
        stage = Usd.Stage.Open(os.path.join(BENCH, name + ".usda"))
        rs = usdscene.read_render_settings(stage)
        tr = usdscene.translate(stage, Usd.TimeCode.EarliestTime(), w, h, rs.camera_path, rs.conform_policy)
        s = _core.RenderSettings()
        s.width, s.height, s.samples_per_pixel, s.max_depth = w, h, args.passes, rs.settings.max_depth
        s.integrator = _core.RenderSettings.Integrator.PhotonMap
        stats = _core.Renderer(_core.Scene(tr.desc), s).render()
        photon = stats["photon_seconds"] / max(stats["photons_traced"], 1) * 1e9
        camera = stats["camera_seconds"] / (w * h * args.passes) * 1e9
        print("| %s | %.0f | %.0f | %.0f |" % (name, photon, camera, camera / photon if photon > 0 else float("nan")),
              flush=True)


if __name__ == "__main__":
    main()
