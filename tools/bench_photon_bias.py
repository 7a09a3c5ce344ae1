#!/usr/bin/env python3
"""The photon map's kernel bias per benchmark scene: the image mean per channel of --seeds renders of
--seconds each (80x60, the scene's settings, 2 threads) against the benchmark's path-traced reference
(`<out>/<scene>/reference_ours.npz` from tools/bench/run.py), with the standard error of that mean over
the seeds, and the mean per-pixel RMSE. --integrator pathTracer gives the same figures for the path
tracer (its mean must agree within noise). To compare two builds, run it once with each on PYTHONPATH.

    python tools/bench_photon_bias.py --scenes atmosphere_sunset,subsurface_ball,subsurface_bunny
    python tools/bench_photon_bias.py --scenes atmosphere_sunset --rows   # the bias per band of rows
    python tools/bench_photon_bias.py --scenes dense_cloud --size 4       # at 320x240, compared at 80x60
"""

import argparse
import os

import numpy as np
from bench_load import REPO, load_bench_scene
from volphoton import _core

SIZE = (80, 60)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", required=True, help="comma-separated benchmark scene names")
    ap.add_argument("--seconds", type=float, default=4.0)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--integrator", default="photonMap", choices=("photonMap", "pathTracer", "combined", "auto"))
    ap.add_argument("--out", default=os.path.join(REPO, "tools", "out", "bench-emission"),
                    help="a tools/bench/run.py output folder with the scenes' references")
    ap.add_argument("--rows", action="store_true", help="also the relative bias per band of 6 rows")
    ap.add_argument("--size", type=int, default=1, metavar="K",
                    help="render at K x 80 by K x 60 and box-average K x K pixels to the 80x60 reference")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="a RenderSettings attribute (Python spelling, e.g. photon_radius_mfp=2) over the scene's")
    a = ap.parse_args()
    enum = {"photonMap": "PhotonMap", "pathTracer": "PathTracer", "combined": "Combined", "auto": "Auto"}[a.integrator]
    width, height = SIZE[0] * a.size, SIZE[1] * a.size
    for name in a.scenes.split(","):
        ref = np.load(os.path.join(a.out, name, "reference_ours.npz"))["mean"]
        rs, tr = load_bench_scene(name, width, height)
        scene = _core.Scene(tr.desc)
        images, rmse, passes, seconds = [], [], [], []
        for seed in range(a.seeds):
            s = rs.settings
            s.width, s.height, s.seed, s.threads = width, height, seed, 2
            s.noise_target, s.time_limit = 0, a.seconds
            s.samples_per_pixel = s.max_samples_per_pixel = 100000
            s.integrator = getattr(_core.RenderSettings.Integrator, enum)
            for kv in a.set:
                k, v = kv.split("=", 1)
                setattr(s, k, type(getattr(s, k))(float(v)))
            r = _core.Renderer(scene, s)
            r.render()
            img = np.asarray(r.film.beauty, np.float64)
            img = img.reshape(SIZE[1], a.size, SIZE[0], a.size, 3).mean((1, 3))
            images.append(img)
            rmse.append(np.sqrt(((img - ref) ** 2).mean()))
            passes.append(r.stats["passes"])
            seconds.append(r.stats["seconds"])
        per_seed = np.array([[im[..., c].mean() for c in range(3)] for im in images])
        rel = per_seed.mean(0) / ref.reshape(-1, 3).mean(0) - 1
        se = per_seed.std(0, ddof=1) / np.sqrt(a.seeds) / ref.reshape(-1, 3).mean(0)
        print("%s, %s, %g s x %d seeds: RMSE %.5f, %d passes in %.1f s; mean vs reference per channel %s" % (
            name, a.integrator, a.seconds, a.seeds, np.mean(rmse), np.mean(passes), np.mean(seconds),
            " ".join("%+.2f%% (se %.2f%%)" % (100 * rel[c], 100 * se[c]) for c in range(3))), flush=True)
        if a.rows:
            mean = np.mean(images, 0)
            for r0 in range(0, SIZE[1], 6):
                band = mean[r0:r0 + 6].mean((0, 1)) / ref[r0:r0 + 6].mean((0, 1)) - 1
                print("  rows %2d-%2d: %s" % (r0, r0 + 5, " ".join("%+.1f%%" % (100 * b) for b in band)))


if __name__ == "__main__":
    main()
