#!/usr/bin/env python3
"""Photon points against photon beams (issue 15): for benchmark scenes, a path-traced reference of
--reference seconds, then the path tracer, the photon map with points and with beams for --seconds
each (time limit; default settings otherwise, the photon count as given); prints each AOV's mean and
RMSE against the reference (beauty, single, multiple, surface), so the multiple-scattering column
compares the two photon estimators and the beauty column the integrators.

    python tools/bench_photon_beams.py                                   # 3 scenes, 1e5 photons, ~6 min
    python tools/bench_photon_beams.py --scenes fog_spotlight --photons 0   # automatic photon count
"""

import argparse
import math

import numpy as np
from bench_load import load_bench_scene
from volphoton import _core

AOVS = ("beauty", "single", "multiple", "surface")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default="fog_spotlight,vdb_cloud,dense_cloud")
    ap.add_argument("--resolution", nargs=2, type=int, default=[80, 60])
    ap.add_argument("--seconds", type=float, default=4.0)
    ap.add_argument("--reference", type=float, default=30.0, help="seconds of the path-traced reference")
    ap.add_argument("--photons", type=int, default=100000, help="photons per pass (0: automatic)")
    args = ap.parse_args(argv)
    w, h = args.resolution
    print("| scene | estimator | passes | photons a pass | " + " | ".join("%s mean / RMSE" % a for a in AOVS) + " |")
    print("|---|---|---|---|" + "---|" * len(AOVS))
    for name in args.scenes.split(","):
        rs, tr = load_bench_scene(name, w, h)
        scene = _core.Scene(tr.desc)

        def run(kind, seconds, seed=0):
            s = _core.RenderSettings()
            s.width, s.height, s.max_depth, s.seed = w, h, rs.settings.max_depth, seed
            s.time_limit, s.samples_per_pixel, s.max_samples_per_pixel = seconds, 1, 1000000
            if kind != "path tracer":
                s.integrator = _core.RenderSettings.Integrator.PhotonMap
                s.photons_per_pass = args.photons
                s.photon_beams = kind == "beams"
            r = _core.Renderer(scene, s)
            stats = r.render()
            return {a: getattr(r.film, a).astype(np.float64) for a in AOVS}, stats

        ref, _ = run("path tracer", args.reference, seed=99)
        for kind in ("path tracer", "points", "beams"):
            img, st = run(kind, args.seconds)
            cells = ["%.5f / %.5f" % (img[a].mean(), math.sqrt(np.mean((img[a] - ref[a]) ** 2))) for a in AOVS]
            print("| %s | %s | %d | %s | %s |" % (name, kind, st["passes"], st["photons_per_pass"] or "-", " | ".join(cells)),
                  flush=True)


if __name__ == "__main__":
    main()
