"""Per-sample variance of our path tracer (or --integrator) on benchmark scenes: for each pixel, the
variance across seeds of its mean over `spp` samples, times spp, averaged over the pixels (so
independent samples give the same figure at any spp, and stratified samples a lower one). Also the
mean and the time per pass. The scene's own RenderSettings are used except integrator, adaptive
sampling and time limit (off), spp, seed, --dims (stratifiedDims) and --set overrides.

    python tools/bench/per_sample_variance.py homogeneous_cube,surfaces_only --spp 64 --seeds 16
    python tools/bench/per_sample_variance.py atmosphere_sunset --spp 16 --seeds 8 --aovs   # and per AOV
    python tools/bench/per_sample_variance.py subsurface_bunny --spp 16 --seeds 8 --channels  # and per channel
    python tools/bench/per_sample_variance.py subsurface_bunny --integrator Combined --set photons_per_pass=16000

Compare two builds side by side by running it once with each on PYTHONPATH (a copy of another
build's installed `volphoton` package first on PYTHONPATH)."""

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from bench_load import load_bench_scene  # noqa: E402
from volphoton import _core  # noqa: E402


AOVS = ("single", "multiple", "surface", "emission")


def per_sample_variance(name, spp, seeds, dims, width=80, height=60, overrides=(), integrator="PathTracer"):
    """(per-sample variance, image mean, seconds per pass, CPU seconds per pass (every thread's, renders
    only: steadier than wall time on a shared machine), {aov: per-sample variance}) of scene `name`."""
    rs, tr = load_bench_scene(name, width, height)
    scene = _core.Scene(tr.desc)
    images, aovs = [], {a: [] for a in AOVS}
    cpu = 0.0
    t0 = time.perf_counter()
    for seed in range(seeds):
        s = rs.settings
        s.width, s.height, s.samples_per_pixel, s.seed = width, height, spp, seed
        s.noise_target, s.time_limit = 0, 0
        s.integrator = getattr(_core.RenderSettings.Integrator, integrator)
        if dims is not None:
            s.stratified_dims = dims
        for key, value in overrides:
            setattr(s, key, type(getattr(s, key))(value))
        r = _core.Renderer(scene, s)
        c0 = time.process_time()
        r.render()
        cpu += time.process_time() - c0
        images.append(np.asarray(r.film.beauty, np.float64))
        for a in AOVS:
            aovs[a].append(np.asarray(getattr(r.film, a), np.float64))
    seconds = (time.perf_counter() - t0) / (seeds * spp)
    images = np.array(images)
    per_aov = {a: np.array(v).var(axis=0, ddof=1).mean() * spp for a, v in aovs.items()}
    per_aov["channels"] = images.var(axis=0, ddof=1).mean(axis=(0, 1)) * spp  # red, green, blue
    return images.var(axis=0, ddof=1).mean() * spp, images.mean(), seconds, cpu / (seeds * spp), per_aov


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", help="comma-separated benchmark scene names (testenv/bench/<name>.usda)")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--dims", type=int, default=None, help="stratifiedDims (default: the build's default)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a RenderSettings field (snake_case, e.g. roulette_depth=1000); repeatable")
    ap.add_argument("--integrator", default="PathTracer", choices=["PathTracer", "PhotonMap", "Combined", "Auto"])
    ap.add_argument("--aovs", action="store_true", help="also the per-sample variance of each AOV")
    ap.add_argument("--channels", action="store_true", help="also the per-sample variance of each colour channel")
    a = ap.parse_args()
    extra = "".join(" %s |" % k for k in AOVS) if a.aovs else ""
    extra += " red | green | blue |" if a.channels else ""
    print("| scene | per-sample variance | mean | ms per pass (80x60, all cores) | CPU ms per pass |%s\n|---|---|---|---|---|%s"
          % (extra, "---|" * (len(AOVS) * a.aovs + 3 * a.channels)))
    for name in a.scenes.split(","):
        overrides = [kv.split("=", 1) for kv in a.set]
        v, m, sec, cpu, per_aov = per_sample_variance(name, a.spp, a.seeds, a.dims, overrides=overrides,
                                                      integrator=a.integrator)
        cells = "".join(" %.5f |" % per_aov[k] for k in AOVS) if a.aovs else ""
        cells += "".join(" %.5f |" % c for c in per_aov["channels"]) if a.channels else ""
        print("| %s | %.5f | %.5f | %.2f | %.2f |%s" % (name, v, m, sec * 1e3, cpu * 1e3, cells), flush=True)


if __name__ == "__main__":
    main()
