#!/usr/bin/env python3
"""How heavy-tailed a scene's samples are: renders a small image pass by pass with the path tracer
at the scene's settings and, for a block of pixels, reports how much of each pixel's mean comes
from its 10 largest samples, and the largest sample against the mean (the fireflies that keep a
noise target out of reach; see the fog_spotlight notes of 2026-12-02).

    python tools/sample_tails.py testenv/fog_spotlight.usda                   # 16x9, 4096 passes, multiple AOV
    python tools/sample_tails.py SCENE.usda --aov beauty --passes 1024 --block 0 0 4 4
"""

import argparse

import numpy as np

from pxr import Usd
from volphoton import _core, usdscene


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--resolution", nargs=2, type=int, default=[16, 9])
    ap.add_argument("--passes", type=int, default=4096)
    ap.add_argument("--aov", default="multiple", choices=("beauty", "single", "multiple", "emission", "surface"))
    ap.add_argument("--block", nargs=4, type=int, default=[2, 2, 5, 5], metavar=("X0", "Y0", "X1", "Y1"),
                    help="pixels [X0, X1) x [Y0, Y1) (default 2 2 5 5)")
    args = ap.parse_args(argv)
    w, h = args.resolution
    stage = Usd.Stage.Open(args.scene)
    rs = usdscene.read_render_settings(stage)
    tr = usdscene.translate(stage, Usd.TimeCode.Default(), w, h, rs.camera_path, rs.conform_policy)
    s = _core.RenderSettings()
    s.width, s.height, s.samples_per_pixel, s.max_depth = w, h, args.passes, rs.settings.max_depth
    r = _core.Renderer(_core.Scene(tr.desc), s)
    x0, y0, x1, y1 = args.block
    previous, samples = np.zeros((y1 - y0, x1 - x0)), []
    for k in range(1, args.passes + 1):
        r.render_pass()
        total = getattr(r.film, args.aov)[y0:y1, x0:x1, 1].astype(np.float64) * k  # green channel sums
        samples.append(total - previous)
        previous = total
    v = np.array(samples).reshape(args.passes, -1)
    top10 = np.sort(v, axis=0)[-10:].sum(axis=0) / np.maximum(v.sum(axis=0), 1e-300)
    print("%s, %s AOV, %d passes, pixels [%d,%d)x[%d,%d): mean %.4f, median share of the 10 largest samples %.3f, "
          "largest sample %.1f (%.0fx the mean)" % (args.scene, args.aov, args.passes, x0, x1, y0, y1, v.mean(),
                                                   float(np.median(top10)), v.max(), v.max() / max(v.mean(), 1e-300)))


if __name__ == "__main__":
    main()
