#!/usr/bin/env python3
"""Equal-time error of emissive geometry sampled as a light against hits only (issue 14, part 3).

A small emissive sphere (radius 0.1, radiance 50) inside a fog box (sigma_t 0.3, albedo 0.9, 6
units wide) over a grey floor, seen from inside the fog; the sphere is out of view (above and
behind the camera), so every pixel is light it sends through the fog and off the floor.  Rendered with the path tracer with the sphere as a mesh light (next-event
estimation + MIS, the default) and with hits only (SceneDesc.emissive_mesh_lights = False, as
before issue 14), and with the photon map (default settings), each for the same wall-clock
budgets; RMSE against a long path-tracer reference.  Each run renders passes until its budget is
spent (the last pass may overrun it by one pass).

    python tools/bench_emissive.py                 # 64x48, budgets 1 2 4 s, reference 8192 passes
    python tools/bench_emissive.py --budgets 2 8 --ref-passes 2048
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import platform
import time

import numpy as np

from volphoton import _core as core

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_spec = importlib.util.spec_from_file_location("volphoton_stress", os.path.join(REPO, "tools", "stress.py"))
stress = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(stress)


def build_scene(mesh_lights: bool):
    d = core.SceneDesc()
    boundary = core.SurfaceMaterial(kind=core.SurfaceMaterial.Kind.Boundary)
    grey = core.SurfaceMaterial(kind=core.SurfaceMaterial.Kind.Lambertian, albedo=(0.5, 0.5, 0.5))
    glow = core.SurfaceMaterial(kind=core.SurfaceMaterial.Kind.Lambertian, albedo=(0.0, 0.0, 0.0),
                                emission=(50.0, 50.0, 50.0))
    fog = core.HomogeneousMedium(core.MediumCoefficients.from_albedo(
        0.3, (1.0, 1.0, 1.0), (0.9, 0.9, 0.9), (0.0, 0.0, 0.0), core.isotropic_phase()))
    mi = d.add_medium(fog, False)
    d.add_instance(d.add_mesh(stress._box_mesh(core, (-3, -3, -3), (3, 3, 3), boundary, mi, name="fog")), np.eye(4))
    d.add_instance(d.add_mesh(stress._box_mesh(core, (-3, -1.2, -3), (3, -1, 3), grey, name="floor")), np.eye(4))
    d.add_instance(d.add_mesh(stress._sphere_mesh(core, (0.5, 1.0, 0.5), 0.1, glow)), np.eye(4))
    cam = core.CameraDesc()
    cam.tan_half_fov_x = 0.5
    cam.camera_to_world = stress._look_at((0.0, 0.2, 1.5), (0.0, -0.3, -1.5))
    d.camera = cam
    d.emissive_mesh_lights = mesh_lights
    return core.Scene(d)


def render(scene, integrator, width, height, seed, budget=None, passes=None):
    s = core.RenderSettings()
    s.width, s.height = width, height
    s.seed = seed
    s.samples_per_pixel = passes or 1 << 30
    if integrator == "photonMap":
        s.integrator = core.RenderSettings.Integrator.PhotonMap
    r = core.Renderer(scene, s)
    t0, done = time.perf_counter(), 0
    while (passes is None or done < passes) and (budget is None or time.perf_counter() - t0 < budget):
        r.render_pass()
        done += 1
    return np.array(r.film.beauty, np.float64), done, time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--width", type=int, default=64)
    ap.add_argument("--height", type=int, default=48)
    ap.add_argument("--budgets", type=float, nargs="+", default=[1.0, 2.0, 4.0], help="seconds per run")
    ap.add_argument("--ref-passes", type=int, default=8192)
    ap.add_argument("--seeds", type=int, default=3, help="runs per budget and method (RMSE averaged)")
    args = ap.parse_args(argv)

    lights, hits = build_scene(True), build_scene(False)
    t0 = time.perf_counter()
    ref, _, _ = render(lights, "pathTracer", args.width, args.height, 1000, passes=args.ref_passes)
    print("reference: path tracer with mesh light, %d passes, %.1f s; image mean %.5f" %
          (args.ref_passes, time.perf_counter() - t0, ref.mean()))
    print("machine: %s, %d cores; %dx%d; RMSE averaged over %d seeds" %
          (platform.processor() or platform.machine(), os.cpu_count(), args.width, args.height, args.seeds))
    methods = (("PT hits only", hits, "pathTracer"), ("PT mesh light", lights, "pathTracer"),
               ("PM mesh light", lights, "photonMap"))
    print("| budget (s) | " + " | ".join("%s RMSE (passes)" % m for m, _, _ in methods) + " | hits/light RMSE |")
    print("|---" * (len(methods) + 2) + "|")
    for budget in args.budgets:
        row = []
        for name, scene, integrator in methods:
            errs, counts = [], []
            for seed in range(1, args.seeds + 1):
                img, n, _ = render(scene, integrator, args.width, args.height, seed, budget=budget)
                errs.append(math.sqrt(((img - ref) ** 2).mean()))
                counts.append(n)
            row.append((float(np.mean(errs)), int(np.mean(counts))))
        ratio = row[0][0] / row[1][0] if row[1][0] > 0 else float("inf")
        print("| %g | " % budget + " | ".join("%.4g (%d)" % r for r in row) + " | %.2f |" % ratio)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
