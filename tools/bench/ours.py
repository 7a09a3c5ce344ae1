"""volphoton worker of the benchmark: renders one USD scene progressively and snapshots the film.

Runs in its own process (run.py starts it), so the peers never share a process with pxr or the core.

    python tools/bench/ours.py render    --usd S.usda --integrator pathTracer --size W H --budgets 0.5,1,2 --out f.npz
    python tools/bench/ours.py reference --usd S.usda --size W H --seconds 30 --batches 8 --out f.npz
    python tools/bench/ours.py passes    --usd S.usda --size W H --passes 16 --out f.json [--core path/_core.so]
    python tools/bench/ours.py voxels    --vdb cloud.vdb --resolution 64 --out voxels.npy

render: passes through Renderer.render_pass until each time budget (seconds of rendering, scene
loading excluded) is reached; the film is copied at each budget (the copy is not timed).
reference: path tracer, as many passes as fit in --seconds (a multiple of --batches), with the
cumulative film copied after every batch so that run.py can form independent batch means.
passes: times a fixed number of passes (scene 7 against a core built with VOLPHOTON_NO_VOLUMES).
--core loads another build of volphoton._core (e.g. build-novol/_core*.so) in place of the installed one.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np


def _load_core(core_path):
    import volphoton

    volphoton.register_usd_plugin(include_source_tree=True)
    if core_path:
        import importlib.util

        spec = importlib.util.spec_from_file_location("volphoton._core", core_path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        sys.modules["volphoton._core"] = mod
        volphoton._core = mod
    from volphoton import _core

    return _core


def build(usd_path, width, height, integrator="pathTracer", threads=0, seed=0, core_path=None, overrides=None):
    """USD -> (core module, core Scene, RenderSettings, seconds to translate and build)."""
    core = _load_core(core_path)
    from pxr import Usd
    from volphoton import usdscene

    warnings = []
    core.set_diagnostic_sink(lambda sev, msg: warnings.append((sev, msg)))
    t0 = time.perf_counter()
    stage = Usd.Stage.Open(usd_path)
    rs = usdscene.read_render_settings(stage)
    tr = usdscene.translate(stage, Usd.TimeCode.EarliestTime(), width, height, rs.camera_path, rs.conform_policy)
    errors = [str(d) for d in tr.diagnostics if d.severity == "error"]
    if errors:
        raise RuntimeError("translating %s: %s" % (usd_path, "; ".join(errors)))
    s = rs.settings  # the stage's volphoton:* settings (the integrator is the caller's)
    s.width, s.height = width, height
    s.threads = threads
    s.seed = seed
    s.integrator = {"photonMap": core.RenderSettings.Integrator.PhotonMap, "combined": core.RenderSettings.Integrator.Combined,
                    "auto": core.RenderSettings.Integrator.Auto}.get(integrator, core.RenderSettings.Integrator.PathTracer)
    for k, v in (overrides or {}).items():
        setattr(s, k, v)
    scene = core.Scene(tr.desc)
    return core, scene, s, time.perf_counter() - t0, warnings


def cmd_render(a) -> int:
    core, scene, s, build_s, warnings = build(a.usd, a.size[0], a.size[1], a.integrator, a.threads, a.seed,
                                              a.core, json.loads(a.overrides) if a.overrides else None)
    budgets = sorted(float(b) for b in a.budgets.split(","))
    t0 = time.perf_counter()
    r = core.Renderer(scene, s)
    setup = time.perf_counter() - t0
    elapsed, passes = 0.0, 0
    times, spps, images = [], [], []
    # Each pass's own image mean (from the cumulative film's, untimed): the spread of these gives the
    # final image mean's noise where pixels share randomness (a pass's photon map), run.mean_check.
    pass_means, cumulative = [], 0.0
    bi = 0
    while bi < len(budgets) and passes < a.max_passes:
        t = time.perf_counter()
        r.render_pass()
        elapsed += time.perf_counter() - t
        passes += 1
        m = float(np.mean(r.film.beauty, dtype=np.float64))  # float32 sums would lose the later passes
        pass_means.append(passes * m - (passes - 1) * cumulative)
        cumulative = m
        if elapsed >= budgets[bi]:
            times.append(elapsed)
            spps.append(passes)
            images.append(np.array(r.film.beauty, dtype=np.float32))
            while bi < len(budgets) and elapsed >= budgets[bi]:
                bi += 1
    stats = r.stats
    np.savez_compressed(a.out, times=np.array(times), spp=np.array(spps), images=np.array(images),
                        pass_means=np.array(pass_means),
                        meta=json.dumps({"build_seconds": build_s, "renderer_setup_seconds": setup,
                                         "settings": s.to_dict(), "stats": _jsonable(stats),
                                         "warnings": warnings[:20], "core_no_volumes": bool(core.NO_VOLUMES)}))
    return 0


def cmd_reference(a) -> int:
    core, scene, s, build_s, warnings = build(a.usd, a.size[0], a.size[1], "pathTracer", a.threads, a.seed, a.core)
    r = core.Renderer(scene, s)
    # Pilot: time a few passes to size the reference to the time allowed.
    t0 = time.perf_counter()
    pilot = 0
    while pilot < 4 or time.perf_counter() - t0 < 0.5:
        r.render_pass()
        pilot += 1
    per_pass = (time.perf_counter() - t0) / pilot
    total = max(a.batches * 2, int(a.seconds / per_pass))
    total = max(a.min_passes, min(total, a.max_passes))
    total -= total % a.batches
    # One renderer per batch, each with its own seed: the camera samples of one render are stratified
    # over its passes (Rng::stratify), so consecutive batches of one render are not independent and
    # their spread would misstate the reference's noise; separate seeds are independent randomisations.
    per_batch = total // a.batches
    batches = []
    t0 = time.perf_counter()
    for b in range(a.batches):
        s.seed = a.seed * 1000 + b
        r = core.Renderer(scene, s)
        for _ in range(per_batch):
            r.render_pass()
        batches.append(np.array(r.film.beauty, dtype=np.float64))
    seconds = time.perf_counter() - t0
    snaps = [np.mean(batches, axis=0)]
    np.savez_compressed(a.out, mean=snaps[-1].astype(np.float32), batches=np.array(batches, dtype=np.float32),
                        meta=json.dumps({"passes": total, "seconds": seconds, "build_seconds": build_s,
                                         "settings": s.to_dict(), "stats": _jsonable(r.stats),
                                         "warnings": warnings[:20]}))
    return 0


def cmd_passes(a) -> int:
    core, scene, s, build_s, warnings = build(a.usd, a.size[0], a.size[1], a.integrator, a.threads, a.seed, a.core)
    r = core.Renderer(scene, s)
    r.render_pass()  # warm-up (page faults, TBB start)
    times = []
    for _ in range(a.passes):
        t = time.perf_counter()
        r.render_pass()
        times.append(time.perf_counter() - t)
    img = np.array(r.film.beauty)
    with open(a.out, "w") as f:
        json.dump({"pass_seconds": times, "no_volumes": bool(core.NO_VOLUMES), "has_media": scene.has_media,
                   "image_mean": float(img.mean()), "core": a.core or "installed", "build_seconds": build_s}, f)
    return 0


def cmd_voxels(a) -> int:
    """Dense voxel values of the procedural cloud, shape (Z, Y, X): voxel (i, j, k) sits at grid
    position (i, j, k) * voxel_size (OpenVDB cell centres)."""
    core = _load_core(None)
    d = core.GridMediumDesc()
    d.file_path = a.vdb
    d.density_scale = 1.0
    g = core.load_grid_medium(d)
    n = a.resolution
    vs = 1.0 / n
    out = np.zeros((n, n, n), np.float32)
    for k in range(n):
        for j in range(n):
            out[k, j, :] = [g.density((i * vs, j * vs, k * vs)) for i in range(n)]
    np.save(a.out, out)
    return 0


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, float) and not np.isfinite(x):
        return str(x)
    return x


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    for name in ("render", "reference", "passes"):
        p = sub.add_parser(name)
        p.add_argument("--usd", required=True)
        p.add_argument("--size", nargs=2, type=int, default=(80, 60))
        p.add_argument("--threads", type=int, default=2)
        p.add_argument("--seed", type=int, default=0)
        p.add_argument("--core", default=None, help="path of another volphoton _core module")
        p.add_argument("--out", required=True)
    r = sub.choices["render"]
    r.add_argument("--integrator", default="pathTracer", choices=["pathTracer", "photonMap", "combined", "auto"])
    r.add_argument("--budgets", required=True, help="comma-separated seconds")
    r.add_argument("--max-passes", type=int, default=1 << 20)
    r.add_argument("--overrides", default="", help="JSON {RenderSettings attribute: value}")
    f = sub.choices["reference"]
    f.add_argument("--seconds", type=float, default=30.0)
    f.add_argument("--batches", type=int, default=8)
    f.add_argument("--min-passes", type=int, default=64)
    f.add_argument("--max-passes", type=int, default=1 << 20)
    q = sub.choices["passes"]
    q.add_argument("--integrator", default="pathTracer", choices=["pathTracer", "photonMap", "combined", "auto"])
    q.add_argument("--passes", type=int, default=16)
    v = sub.add_parser("voxels")
    v.add_argument("--vdb", required=True)
    v.add_argument("--resolution", type=int, default=64)
    v.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    return {"render": cmd_render, "reference": cmd_reference, "passes": cmd_passes, "voxels": cmd_voxels}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
