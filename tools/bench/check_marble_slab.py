"""Which renderer is right about marble?  A thick slab of benchmark scene 9's marble, per channel,
against the exact adding-doubling solution (issue 16, part 4).

    python tools/bench/check_marble_slab.py [--seeds 8] [--mitsuba-spp 64]

The slab: Jensen et al. 2001's marble (the "marble" preset, g = 0: sigma_t relative to blue
(0.729, 0.873, 1), albedo (0.99904, 0.99844, 0.99764)), n = 1.3, 400 blue mean free paths deep and
500 wide, under a constant dome of radiance 1, seen straight down by an orthographic camera 20 mean
free paths wide at its centre.  By reciprocity each pixel's radiance is the slab's total reflectance
for normal incidence (UR1 of iadpython; the transmittance is below 4e-8).  The same geometry as
testenv/test_subsurface.py's test_marble_slab_matches_the_transport_solution_per_channel.

Rendered by volphoton's path tracer at its defaults and by Mitsuba 3 (scalar_rgb) three ways: volpath
with rr_depth 5 (the benchmark's mapping until issue 16), volpath without roulette, and volpathmis
without roulette (the benchmark's mapping for scenes 8 and 9 since).  Each row: per-channel mean over
seeds, its standard error, (mean - exact) / standard error, and the largest seed's mean over the
median seed's (a heavy tail shows as a large ratio with a mean below the exact value).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

IOR, DEPTH, HALF, VIEW = 1.3, 400.0, 250.0, 20.0
MARBLE = ((2.19, 2.62, 3.00), (0.0021, 0.0041, 0.0071))  # sigma_s', sigma_a per mm (Jensen et al. 2001, Table 2)


def coefficients():
    ssp, sa = (np.array(v) for v in MARBLE)
    st = ssp + sa
    return st / st.max(), ssp / st


def exact():
    import iadpython

    st, alb = coefficients()
    return np.array([iadpython.Sample(a=alb[c], b=st[c] * DEPTH, g=0.0, n=IOR, n_above=1.0, n_below=1.0,
                                      quad_pts=16).rt()[0] for c in range(3)])


def ours(seeds: int, size: int, spp: int):
    from volphoton import _core

    st, alb = coefficients()
    d = _core.SceneDesc()
    coeffs = _core.MediumCoefficients.from_albedo(1.0, tuple(st), tuple(alb), (0, 0, 0), _core.isotropic_phase())
    medium = d.add_medium(_core.HomogeneousMedium(coeffs), False)
    m = _core.MeshDesc()
    m.name = "slab"
    x0, y0, z0, x1, y1, z1 = -HALF, -HALF, -DEPTH, HALF, HALF, 0.0
    m.points = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                         [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], dtype=np.float64)
    m.indices = np.array([0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                          1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7])
    m.material = _core.SurfaceMaterial(kind=_core.SurfaceMaterial.Kind.Dielectric, ior=IOR)
    m.interior_medium = medium
    d.add_instance(d.add_mesh(m), np.eye(4))
    d.add_light(_core.dome_light((1, 1, 1)))
    cam = _core.CameraDesc()
    cam.projection = _core.CameraDesc.Projection.Orthographic
    cam.ortho_width = VIEW
    to_world = np.eye(4)
    to_world[2, 3] = 10.0
    cam.camera_to_world = to_world
    d.camera = cam
    scene = _core.Scene(d)
    vals = []
    for seed in range(seeds):
        s = _core.RenderSettings()
        s.width = s.height = size
        s.samples_per_pixel = spp
        s.seed = seed
        r = _core.Renderer(scene, s)
        r.render()
        vals.append(np.asarray(r.film.beauty, np.float64).mean(axis=(0, 1)))
    return np.array(vals)


def mitsuba(integrator: str, rr_depth: int, seeds: int, size: int, spp: int):
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    st, alb = coefficients()
    T = mi.ScalarTransform4f
    sc = mi.load_dict({
        "type": "scene",
        "integrator": {"type": integrator, "max_depth": 100001, "rr_depth": rr_depth},
        "sensor": {"type": "orthographic",
                   "to_world": T().look_at(origin=[0, 0, 10], target=[0, 0, 0], up=[0, 1, 0])
                   @ T().scale([VIEW / 2, VIEW / 2, 1]),
                   "sampler": {"type": "independent", "sample_count": spp},
                   "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                            "pixel_format": "rgb"}},
        "marble": {"type": "homogeneous", "sigma_t": {"type": "rgb", "value": st.tolist()}, "scale": 1.0,
                   "albedo": {"type": "rgb", "value": alb.tolist()}, "phase": {"type": "isotropic"}},
        "slab": {"type": "cube", "to_world": T().translate([0, 0, -DEPTH / 2]) @ T().scale([HALF, HALF, DEPTH / 2]),
                 "bsdf": {"type": "dielectric", "int_ior": IOR, "ext_ior": 1.0},
                 "interior": {"type": "ref", "id": "marble"}},
        "dome": {"type": "constant", "radiance": {"type": "rgb", "value": [1, 1, 1]}}})
    return np.array([np.array(mi.render(sc, spp=spp, seed=seed))[..., :3].mean(axis=(0, 1)) for seed in range(seeds)])


def row(name, vals, ref, seconds):
    m = vals.mean(axis=0)
    se = vals.std(axis=0, ddof=1) / np.sqrt(len(vals))
    z = (m - ref) / np.maximum(se, 1e-12)
    tail = vals.max(axis=0) / np.median(vals, axis=0)
    cells = " | ".join("%.4f +- %.4f (z %+.1f, %+.2f%%)" % (m[c], se[c], z[c], 100 * (m[c] / ref[c] - 1)) for c in range(3))
    print("| %s | %s | %s | %.0f s |" % (name, cells, " ".join("%.2f" % t for t in tail), seconds), flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--ours-spp", type=int, default=16, help="per seed, 64 x 64 pixels")
    ap.add_argument("--mitsuba-spp", type=int, default=64, help="per seed, 16 x 16 pixels")
    ap.add_argument("--no-mitsuba", action="store_true")
    a = ap.parse_args(argv)
    ref = exact()
    print("| renderer | R | G | B | max/median seed (R G B) | time |")
    print("|---|---|---|---|---|---|")
    print("| exact (iadpython, UR1) | %s | | |" % " | ".join("%.4f" % r for r in ref))
    t = time.perf_counter()
    vals = ours(a.seeds, 64, a.ours_spp)
    row("volphoton pathTracer (defaults)", vals, ref, time.perf_counter() - t)
    if a.no_mitsuba:
        return 0
    for integ, rr in (("volpath", 5), ("volpath", 100001), ("volpathmis", 100001)):
        t = time.perf_counter()
        vals = mitsuba(integ, rr, a.seeds, 16, a.mitsuba_spp)
        row("Mitsuba 3 %s, rr_depth %d" % (integ, rr), vals, ref, time.perf_counter() - t)
    return 0


if __name__ == "__main__":
    sys.exit(main())
