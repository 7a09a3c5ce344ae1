#!/usr/bin/env python3
"""Equal-time RMSE where a point-like light is in view (issue 15, scene 4): a path-traced reference of
--reference seconds in 8 batches (its own noise estimated from them and removed from every MSE), then
--seeds renders of --seconds each with the path tracer, the photon map with points and with beams
(or the integrators of --variants; 80x60 unless --resolution, the scene's settings, 2 threads), the
share of each render's squared error in its worst pixel (the light's pixel held most of it before
Renderer::lightPixels_), and each variant's image mean per channel against the reference's with its
standard error over the seeds (the kernel bias).

    python tools/bench_light_pixel.py                        # fog + spot, 320 s reference, ~7 min
    python tools/bench_light_pixel.py --reference 60 --seeds 2
To compare two builds, run it once with each on PYTHONPATH (the reference is saved with --save and
read back with --load).
"""

import argparse

import numpy as np
from bench_load import load_bench_scene
from volphoton import _core

SIZE = [80, 60]


# --variants: label -> (integrator, photonBeams, combinedPhotonShare; -1: automatic, the default).
VARIANTS = {
    "pathTracer": ("PathTracer", False, -1.0),
    "points": ("PhotonMap", False, -1.0),
    "beams": ("PhotonMap", True, -1.0),
    "auto": ("Auto", False, -1.0),
    "combined": ("Combined", False, -1.0),
    "combined0": ("Combined", False, 0.0),
    "combined1": ("Combined", False, 1.0),
    "combined1beams": ("Combined", True, 1.0),
}


def render(scene, rs, integrator, seed, seconds, beams=False, share=-1.0):
    s = rs.settings
    s.width, s.height, s.seed, s.threads = SIZE[0], SIZE[1], seed, 2
    s.noise_target, s.time_limit = 0, seconds
    s.samples_per_pixel = s.max_samples_per_pixel = 10000000
    s.integrator = getattr(_core.RenderSettings.Integrator, integrator)
    s.photon_beams = beams
    s.combined_photon_share = share
    r = _core.Renderer(scene, s)
    r.render()
    return np.asarray(r.film.beauty, np.float64)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="fog_spotlight")
    ap.add_argument("--seconds", type=float, default=4.0)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--resolution", nargs=2, type=int, default=list(SIZE), metavar=("W", "H"))
    ap.add_argument("--reference", type=float, default=320.0, help="seconds of the path-traced reference")
    ap.add_argument("--variants", default="pathTracer,points,beams",
                    help="comma-separated, of " + ", ".join(VARIANTS) + " (combined: its defaults; combined0/1: photon share 0/1)")
    ap.add_argument("--save", help="write the reference's batches to this .npz")
    ap.add_argument("--load", help="read the reference's batches from this .npz instead of rendering it")
    a = ap.parse_args()
    SIZE[:] = a.resolution
    rs, tr = load_bench_scene(a.scene, *SIZE)
    scene = _core.Scene(tr.desc)
    if a.load:
        batches = np.load(a.load)["batches"]
    else:
        batches = np.array([render(scene, rs, "PathTracer", 777000 + k, a.reference / 8) for k in range(8)])
        if a.save:
            np.savez(a.save, batches=batches)
    ref = batches.mean(0)
    ref_var = (batches.var(0, ddof=1) / len(batches)).mean()
    print("%s: reference %s, its noise RMSE %.6f (removed below); %s" % (
        a.scene, a.load or "%g s" % a.reference, np.sqrt(ref_var), _core.__file__))
    ref_means = batches.reshape(len(batches), -1, 3).mean(1)  # per batch and channel
    for label in a.variants.split(","):
        integrator, beams, share = VARIANTS[label]
        mse, worst, means = [], [], []
        for seed in range(a.seeds):
            img = render(scene, rs, integrator, seed, a.seconds, beams, share)
            d2 = ((img - ref) ** 2).mean(2)
            mse.append(d2.mean() - ref_var)
            worst.append(d2.max() / d2.sum())
            means.append(img.reshape(-1, 3).mean(0))
        print("%s, %g s x %d seeds: RMSE %.6f; per seed %s; worst pixel's share of the squared error %s" % (
            label, a.seconds, a.seeds, np.sqrt(max(np.mean(mse), 0)), " ".join("%.5f" % np.sqrt(max(m, 0)) for m in mse),
            " ".join("%.0f%%" % (100 * w) for w in worst)), flush=True)
        # The image mean per channel against the reference's: the kernel bias shows here when it
        # exceeds the standard error over the seeds (combined with the reference's over its batches).
        rel = np.mean(means, 0) / ref_means.mean(0) - 1
        se = np.hypot(np.std(means, 0, ddof=1) / np.sqrt(a.seeds), ref_means.std(0, ddof=1) / np.sqrt(len(batches))) / ref_means.mean(0)
        print("    image mean vs reference per channel: %s" % ", ".join(
            "%+.2f%% (se %.2f%%, z %.1f)" % (100 * r, 100 * e, r / e if e > 0 else 0) for r, e in zip(rel, se)), flush=True)


if __name__ == "__main__":
    main()
