#!/usr/bin/env python3
"""Equal-time error of adaptive sampling (a noise target) against uniform passes (issue 17).

For each benchmark scene (testenv/bench/*.usda, tools/bench/README.md), the path tracer at its
defaults renders, for each time budget, (a) uniform passes until the budget (``timeLimit`` only)
and (b) adaptive sampling (``noiseTarget`` and the same ``timeLimit``: every pixel gets the minimum
16 passes, then only pixels whose estimated relative error or a neighbour's is above the target).
Both are scored against a long uniform reference (``--ref-factor`` x the largest budget, so that its
own error is ~1/4 of the largest budget's) with
  * RMSE: root mean square of the RGB difference (what tools/bench reports), and
  * relative error: the median, over the pixels whose reference alpha is > 0 (the subject: the
    noiseless background would flatter it), of |luminance difference| / max(reference luminance,
    2% of the image mean) -- the quantity the noise target controls.
Adaptive sampling spends samples where the relative error is high (dark, noisy pixels), so it may
lower the relative error more than the RMSE: both are reported.

    python tools/bench_adaptive.py                       # 80x60, budgets 0.5 2 s, 3 seeds, 32 s references
    python tools/bench_adaptive.py --scenes homogeneous_cube vdb_cloud --budgets 2 8 --seeds 5
"""

from __future__ import annotations

import argparse
import os
import platform

import numpy as np

from bench_load import load_bench_scene
from volphoton import _core as core

LUM = np.array([0.2126, 0.7152, 0.0722])


def load(name, width, height):
    rs, tr = load_bench_scene(name, width, height)
    settings = rs.settings
    settings.width, settings.height = width, height
    return core.Scene(tr.desc), settings


def render(scene, base, seed, time_limit, noise_target=None):
    s = core.RenderSettings()
    s.width, s.height, s.max_depth, s.seed = base.width, base.height, base.max_depth, seed
    s.time_limit = time_limit
    s.max_samples_per_pixel = 1 << 20
    if noise_target:
        s.noise_target = noise_target
    r = core.Renderer(scene, s)
    stats = r.render()
    return r.film.beauty.astype(np.float64), r.film.alpha(), stats


def scores(img, ref, subject):
    rmse = float(np.sqrt(((img - ref) ** 2).mean()))
    y, yr = img @ LUM, ref @ LUM
    rel = np.abs(y - yr) / np.maximum(yr, 0.02 * yr.mean())
    return rmse, float(np.median(rel[subject])) if subject.any() else float("nan")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="*", default=["homogeneous_cube", "vdb_cloud", "dense_cloud", "fog_spotlight",
                                                      "atmosphere_sunset", "emissive_smoke", "surfaces_only"])
    ap.add_argument("--budgets", nargs="*", type=float, default=[0.5, 2.0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--noise-target", type=float, default=0.01)
    ap.add_argument("--ref-factor", type=float, default=16.0)
    ap.add_argument("--resolution", nargs=2, type=int, default=[80, 60])
    args = ap.parse_args(argv)
    print("# machine: %s, %d cores; %dx%d; path tracer; noise target %g; %d seeds; references %g s"
          % (platform.processor() or platform.machine(), os.cpu_count(), args.resolution[0], args.resolution[1],
             args.noise_target, args.seeds, args.ref_factor * max(args.budgets)))
    print("| scene | budget (s) | uniform RMSE | adaptive RMSE | ratio | uniform rel. err | adaptive rel. err | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for name in args.scenes:
        scene, base = load(name, *args.resolution)
        ref, alpha, ref_stats = render(scene, base, 1000, args.ref_factor * max(args.budgets))
        subject = alpha > 0
        for budget in args.budgets:
            u, a = [], []
            for seed in range(args.seeds):
                u.append(scores(render(scene, base, seed, budget)[0], ref, subject))
                a.append(scores(render(scene, base, seed, budget, noise_target=args.noise_target)[0], ref, subject))
            u, a = np.mean(u, axis=0), np.mean(a, axis=0)
            print("| %s | %g | %.5f | %.5f | %.2f | %.4f | %.4f | %.2f |" % (
                name, budget, u[0], a[0], a[0] / u[0], u[1], a[1], a[1] / u[1]), flush=True)
        print("<!-- %s reference: %d passes -->" % (name, ref_stats["passes"]), flush=True)


if __name__ == "__main__":
    main()
