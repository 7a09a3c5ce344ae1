#!/usr/bin/env python3
"""What a photon and a camera sample cost in the photon-map integrator (issue 15, "photon counts
that fit the job"): for each benchmark scene (testenv/bench/*.usda) at its settings, 4 passes at
defaults, the photon pass's ns per traced photon, the camera pass's ns per pixel-sample, and the
photons per pixel that would make the two passes take equally long; then the counted work
(core/workCount.h: rays and medium lookups, the latter weighted by each medium's lookup cost, of a
camera pass and of a photon, from the pilots) and the balance the automatic photon count derives from
it, against the measured balance, and the RayCost, PhotonLookupCost and PhotonBaseCost that fit the
measured balances best (least squares of the log ratio).

    python tools/bench_photon_cost.py                 # 80x60
    python tools/bench_photon_cost.py --resolution 160 120 --passes 8
"""

import argparse
import math

from bench_load import load_bench_scene
from volphoton import _core

SCENES = ["homogeneous_cube", "vdb_cloud", "dense_cloud", "fog_spotlight", "atmosphere_sunset", "emissive_smoke"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resolution", nargs=2, type=int, default=[80, 60])
    ap.add_argument("--passes", type=int, default=4)
    args = ap.parse_args(argv)
    w, h = args.resolution
    print("| scene | ns per photon | ns per camera pixel-sample | photons per pixel for equal pass times "
          "| camera pass rays, lookups per pixel | photon rays, lookups | modelled photons per pixel | model / measured |")
    print("|---|---|---|---|---|---|---|---|")
    rows = []
    for name in SCENES:
        rs, tr = load_bench_scene(name, w, h)
        s = _core.RenderSettings()
        s.width, s.height, s.samples_per_pixel, s.max_depth = w, h, args.passes, rs.settings.max_depth
        s.integrator = _core.RenderSettings.Integrator.PhotonMap
        stats = _core.Renderer(_core.Scene(tr.desc), s).render()
        photon = stats["photon_seconds"] / max(stats["photons_traced"], 1) * 1e9
        camera = stats["camera_seconds"] / (w * h * args.passes) * 1e9
        measured = camera / photon if photon > 0 else float("nan")
        cw, pw = stats["camera_pass_work"], stats["photon_work"]
        modelled = stats["photon_work_ratio"] / (w * h)
        rows.append((measured, cw, pw))
        print("| %s | %.0f | %.0f | %.1f | %.2f, %.1f | %.2f, %.1f | %.1f | %.2f |" % (
            name, photon, camera, measured, cw["rays"] / (w * h), cw["lookups"] / (w * h), pw["rays"], pw["lookups"],
            modelled, modelled / measured), flush=True)
    best = None
    for ray_cost in range(10, 301, 10):
        for lookup_factor in [x * 0.1 for x in range(10, 41)]:
            for base in range(0, 101, 5):
                err = sum(math.log((cw["rays"] * ray_cost + cw["lookups"]) /
                                   (base + pw["rays"] * ray_cost + pw["lookups"] * lookup_factor) / (w * h) / m) ** 2
                          for m, cw, pw in rows if m > 0)
                if best is None or err < best[3]:
                    best = (ray_cost, lookup_factor, base, err)
    print("\nfit to the measured balances (core/workCount.h; lookups weighted by the media's lookup costs as they "
          "stand): RayCost %.0f, PhotonLookupCost %.1f, PhotonBaseCost %.0f (rms log error %.2f)"
          % (best[0], best[1], best[2], math.sqrt(best[3] / len(rows))))

if __name__ == "__main__":
    main()
