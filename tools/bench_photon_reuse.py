#!/usr/bin/env python3
"""Photon maps kept across a camera orbit (issue 15, "reuse what does not change"): for the cloud and
fog benchmark scenes, the photon-map integrator renders an orbit of views, each for --seconds of
render time (as an artist orbiting in usdview and pausing at each view), once with one PhotonCache
shared by the views (what the Hydra delegate does on a camera move) and once starting every view from
scratch. At each view after the first: passes done, photon passes reused, and the RMSE against a
long photon-map render of that view (same integrator, so kernel bias cancels and the figure is the
noise left). Default settings otherwise (automatic photon count).

    python tools/bench_photon_reuse.py                  # 80x60, 2 s a view, 4 views, ~1.5 min
    python tools/bench_photon_reuse.py --resolution 160 120 --seconds 2 --views 6
"""

import argparse
import math

import numpy as np
from bench_load import load_bench_scene
from volphoton import _core

SCENES = ["vdb_cloud", "fog_spotlight"]


def orbit(camera_to_world, center, degrees):
    """The camera rotated about the vertical axis through `center` by `degrees`."""
    a = math.radians(degrees)
    r = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    m = np.array(camera_to_world, dtype=float).reshape(3, 4) if np.size(camera_to_world) == 12 else np.array(camera_to_world)
    out = m.copy()
    out[:3, :3] = r @ m[:3, :3]
    out[:3, 3] = r @ (m[:3, 3] - center) + center
    return out


def orbit_arguments(description, argv):
    """The orbit's options, shared with tools/bench_hydra_orbit.py (the same orbit through the delegate)."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--resolution", nargs=2, type=int, default=[80, 60])
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--views", type=int, default=4)
    ap.add_argument("--step", type=float, default=6.0, help="degrees between views")
    ap.add_argument("--reference-passes", type=int, default=256)
    return ap.parse_args(argv)


def main(argv=None):
    args = orbit_arguments(__doc__.splitlines()[0], argv)
    w, h = args.resolution
    print("| scene | view | passes, reuse | passes, from scratch | photon passes reused | RMSE reuse / from scratch |")
    print("|---|---|---|---|---|---|")
    for name in SCENES:
        rs, tr = load_bench_scene(name, w, h)
        base = tr.desc.camera.camera_to_world
        lo, hi = (np.array(v) for v in tr.bounds) if tr.bounds else (np.zeros(3), np.zeros(3))
        center = 0.5 * (lo + hi)

        def settings(seconds=0.0, passes=1, seed=0):
            s = _core.RenderSettings()
            s.width, s.height, s.max_depth, s.seed = w, h, rs.settings.max_depth, seed
            s.integrator = _core.RenderSettings.Integrator.PhotonMap
            if seconds > 0:
                s.time_limit, s.max_samples_per_pixel, s.samples_per_pixel = seconds, 100000, 1
            else:
                s.samples_per_pixel = passes
            return s

        def scene_at(view):
            tr.desc.camera.camera_to_world = orbit(base, center, args.step * view)
            return _core.Scene(tr.desc)

        cache = _core.PhotonCache()
        for view in range(args.views):
            scene = scene_at(view)
            kept = _core.Renderer(scene, settings(args.seconds), cache)
            kept.render()
            if view == 0:
                continue
            fresh = _core.Renderer(scene, settings(args.seconds))
            fresh.render()
            ref = _core.Renderer(scene, settings(passes=args.reference_passes, seed=1000))
            ref.render()
            truth = ref.film.beauty.astype(np.float64)
            rmse = [math.sqrt(np.mean((r.film.beauty - truth) ** 2)) for r in (kept, fresh)]
            print("| %s | %d | %d | %d | %d | %.2f |" % (name, view, kept.stats["passes"], fresh.stats["passes"],
                                                      kept.stats["photon_passes_reused"], rmse[0] / rmse[1]), flush=True)


if __name__ == "__main__":
    main()
