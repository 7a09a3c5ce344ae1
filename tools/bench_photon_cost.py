#!/usr/bin/env python3
"""What a photon and a camera sample cost in the photon-map integrator (issue 15, "photon counts
that fit the job"): for each benchmark scene (testenv/bench/*.usda) at its settings, --passes passes
at the automatic photon count and again at 4096 photons a pass, the photon pass's ns per traced
photon, the camera pass's ns per pixel-sample without gathers, and the ns each stored photon adds to
a camera pass (its gathers: the difference of the two camera passes), hence the photons per pixel
that would make the photon pass (tracing and gathers) take as long as the camera pass; then the
counted work (core/workCount.h: rays, medium lookups weighted by each medium's lookup cost, and
gather candidates, of a camera pass, of tracing a photon, of a stored photon's gathers, all from the
pilots) and the balance the automatic photon count derives from it, against the measured balance,
and the RayCost, PhotonLookupCost, PhotonBaseCost and GatherCost that fit the measured balances best
(least squares of the log ratio). Fog + spot is measured with points and with beams (auto's choice).

    python tools/bench_photon_cost.py                 # 80x60
    python tools/bench_photon_cost.py --resolution 160 120 --passes 8
"""

import argparse
import math

from bench_load import load_bench_scene
from volphoton import _core

SCENES = [("homogeneous_cube", False), ("vdb_cloud", False), ("dense_cloud", False), ("fog_spotlight", False),
          ("fog_spotlight", True), ("atmosphere_sunset", False), ("emissive_smoke", False)]
FEW = 4096  # photons a pass whose gathers are next to nothing (MinAutoPhotons)


def render(name, w, h, passes, beams, photons):
    rs, tr = load_bench_scene(name, w, h)
    s = rs.settings
    s.width, s.height, s.samples_per_pixel, s.threads = w, h, passes, 2
    s.integrator = _core.RenderSettings.Integrator.PhotonMap
    s.photon_beams = beams
    s.photons_per_pass = photons
    return _core.Renderer(_core.Scene(tr.desc), s).render()


def modelled(cw, pw, gw, ray_cost, lookup_factor, base, gather_cost):
    camera = cw["rays"] * ray_cost + cw["lookups"]  # a camera pass without photons gathers none
    photon = base + pw["rays"] * ray_cost + pw["lookups"] * lookup_factor
    photon += gw["rays"] * ray_cost + gw["lookups"] + gw["gathers"] * gather_cost
    return camera / photon


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resolution", nargs=2, type=int, default=[80, 60])
    ap.add_argument("--passes", type=int, default=4)
    args = ap.parse_args(argv)
    w, h = args.resolution
    pixels = w * h
    print("| scene | automatic photons a pass | ns per photon traced | ns per camera pixel-sample | gather ns per photon "
          "and camera pass | photons per pixel for equal pass times | camera rays, lookups per pixel | photon rays, "
          "lookups | gather lookups, candidates per photon | modelled photons per pixel | model / measured |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for name, beams in SCENES:
        auto = render(name, w, h, args.passes, beams, 0)
        n = auto["photons_per_pass"]
        if not n:
            print("| %s | no photon pass (%s) |" % (name, "; ".join(auto["passes_skipped"])))
            continue
        few = render(name, w, h, args.passes, beams, FEW)
        photon = auto["photon_seconds"] / max(auto["photons_traced"], 1) * 1e9
        cam_auto, cam_few = (auto["camera_seconds"] / args.passes * 1e9, few["camera_seconds"] / args.passes * 1e9)
        gather = max(0.0, (cam_auto - cam_few) / (n - FEW)) if n > FEW else 0.0  # ns per photon per camera pass
        camera = max(cam_few - FEW * gather, 0.0)  # a camera pass without gathers
        measured = camera / (photon + gather) / pixels
        cw, pw, gw = auto["camera_pass_work"], auto["photon_work"], auto["gather_work"]
        model = auto["photon_work_ratio"] / pixels
        rows.append((measured, cw, pw, gw))
        print("| %s%s | %d | %.0f | %.0f | %.1f | %.1f | %.2f, %.1f | %.2f, %.1f | %.1f, %.1f | %.1f | %.2f |" % (
            name, " (beams)" if beams else "", n, photon, camera / pixels, gather, measured, cw["rays"] / pixels,
            cw["lookups"] / pixels, pw["rays"], pw["lookups"], gw["lookups"], gw["gathers"], model, model / measured),
            flush=True)
    best = None
    for ray_cost in range(10, 61, 5):
        for lookup_factor in [x * 0.25 for x in range(4, 17)]:
            for base in range(0, 41, 5):
                for gather_cost in [x * 0.5 for x in range(0, 21)]:
                    err = sum(math.log(modelled(cw, pw, gw, ray_cost, lookup_factor, base, gather_cost) / pixels / m) ** 2
                              for m, cw, pw, gw in rows if m > 0)
                    if best is None or err < best[4]:
                        best = (ray_cost, lookup_factor, base, gather_cost, err)
    print("\nfit to the measured balances (core/workCount.h; lookups weighted by the media's lookup costs as they "
          "stand): RayCost %.0f, PhotonLookupCost %.2f, PhotonBaseCost %.0f, GatherCost %.1f (rms log error %.2f)"
          % (best[0], best[1], best[2], best[3], math.sqrt(best[4] / len(rows))))


if __name__ == "__main__":
    main()
