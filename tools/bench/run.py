#!/usr/bin/env python3
"""Error against time: volphoton (path tracer, photon map) side by side with Mitsuba 3 and Cycles.

    python tools/bench/run.py --quick          # the quick set: 80x60, budgets 0.25..4 s (< 15 min on 2 cores)
    python tools/bench/run.py                  # the full set: 160x120, budgets 0.5..32 s
    python tools/bench/run.py --quick --scenes homogeneous_cube,surfaces_only --no-cycles

For every scene of tools/bench/scenes.py (one shared description; testenv/bench/<name>.usda is
regenerated from it) and every renderer, the image is snapshotted at a series of rendering-time
budgets and compared with a converged reference (volphoton's path tracer at many samples, other
seed) by RMSE over all pixels and channels.  Mitsuba's reference of the same scene cross-checks
ours (difference of the image means against its standard error, per-pixel chi^2); Cycles' converged
mean is checked on scene (1).  Each renderer runs in its own process, one at a time, with 2 threads.

Outputs (tools/out/bench/, git-ignored): results.csv (every snapshot), results.json, results.md
(the tables of tools/bench/README.md), error_vs_time.png (log-log RMSE against seconds), logs/.
Times are rendering time only: scene loading, Mitsuba's JIT compilation and Cycles' per-render set-up
(scene sync, BVH, volume preprocessing) are excluded and reported separately.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)

import scenes as S  # noqa: E402

PY = sys.executable
BENCH_DIR = os.path.join(REPO, "testenv", "bench")
NOVOL_BUILD = os.path.join(REPO, "build-novol")
WITHVOL_BUILD = os.path.join(REPO, "build-withvol")

QUICK = {"size": (80, 60), "budgets": [0.25, 0.5, 1.0, 2.0, 4.0], "ref_seconds": 45.0, "peer_ref_seconds": 15.0,
         "batches": 8, "novol_passes": 24, "novol_size": (320, 240)}
FULL = {"size": (160, 120), "budgets": [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0], "ref_seconds": 240.0,
        "peer_ref_seconds": 120.0, "batches": 8, "novol_passes": 48, "novol_size": (640, 480)}
REF_SEED = 4242  # never the seed of a timed render, so reference noise is independent
RENDERERS = ["volphoton pathTracer", "volphoton photonMap", "volphoton combined", "Mitsuba 3 volpath", "Cycles"]


class Run:
    def __init__(self, args):
        self.args = args
        self.cfg = dict(QUICK if args.quick else FULL)
        self.out = os.path.abspath(args.out)
        self.logs = os.path.join(self.out, "logs")
        os.makedirs(self.logs, exist_ok=True)
        self.t_start = time.perf_counter()
        self.rss = {}
        self.build_errors = {}
        self.core = None  # None: the installed volphoton._core

    def log(self, msg):
        print("[%6.0f s] %s" % (time.perf_counter() - self.t_start, msg), flush=True)

    def sub(self, name, cmd, timeout=1800):
        """Runs a worker; returns (ok, stdout).  The worker's peak RSS goes to self.rss[name]."""
        logf = os.path.join(self.logs, name + ".log")
        t0 = time.perf_counter()
        code, hung, out, err, rss = run_with_rusage(cmd, timeout, REPO)
        self.rss[name] = rss
        with open(logf, "w") as f:
            f.write("$ %s\n# %.1f s, exit %s%s, peak RSS %.0f MB\n--- stdout\n%s\n--- stderr\n%s" % (
                " ".join(cmd), time.perf_counter() - t0, code, " (TIMEOUT)" if hung else "", rss, out[-20000:],
                err[-20000:]))
        if hung:
            return False, "timeout after %d s" % timeout
        if code != 0:
            tail = (out + err).strip().splitlines()[-1:] or [""]
            return False, tail[0]
        return True, out


# One subprocess runner (timeout, signal, peak RSS) for the benchmarks and the stress suite.
sys.path.insert(0, os.path.dirname(HERE))
from stress import run_with_rusage  # noqa: E402


# --------------------------------------------------------------------------------------------------
# Metrics
# --------------------------------------------------------------------------------------------------


def rmse(img, ref):
    return float(np.sqrt(np.mean((np.asarray(img, np.float64) - ref) ** 2)))


def ref_noise(batches):
    """RMSE of the reference mean itself: sqrt(mean over pixels of var(batch means) / K)."""
    b = np.asarray(batches, np.float64)
    return float(np.sqrt(np.mean(b.var(axis=0, ddof=1) / len(b))))


def loglog_at(times, errs, t, reach=1.3):
    """Piecewise log-log interpolation of a curve at time t.  Within a factor `reach` outside the
    measured range (a snapshot lands just after its budget) the nearest point is extended with the
    Monte Carlo slope -1/2; further out: None."""
    times, errs = np.asarray(times, float), np.asarray(errs, float)
    ok = (times > 0) & (errs > 0)
    times, errs = times[ok], errs[ok]
    if len(times) == 0:
        return None
    order = np.argsort(times)
    times, errs = times[order], errs[order]
    if t < times[0]:
        return float(errs[0] * math.sqrt(times[0] / t)) if t * reach >= times[0] else None
    if t > times[-1]:
        return float(errs[-1] * math.sqrt(times[-1] / t)) if t <= times[-1] * reach else None
    return float(np.exp(np.interp(np.log(t), np.log(times), np.log(errs))))


def cross_check(ref_a, ref_b):
    """Our reference against another renderer's: image means, their difference with its standard
    error (from the batch means), and the per-pixel chi^2 per degree of freedom."""
    ba, bb = np.asarray(ref_a["batches"], np.float64), np.asarray(ref_b["batches"], np.float64)
    ma, mb = ba.mean(axis=0), bb.mean(axis=0)
    means_a, means_b = ba.mean(axis=(1, 2, 3)), bb.mean(axis=(1, 2, 3))
    d = float(ma.mean() - mb.mean())
    sigma = float(math.sqrt(means_a.var(ddof=1) / len(ba) + means_b.var(ddof=1) / len(bb)))
    var = ba.var(axis=0, ddof=1) / len(ba) + bb.var(axis=0, ddof=1) / len(bb)
    # Noise-free pixels (the constant environment seen directly) differ only by float32 rounding:
    # floor the variance at (1e-5 of the value)^2 so they do not dominate chi^2.
    var = var + (1e-5 * np.maximum(np.abs(ma), np.abs(mb))) ** 2
    mask = var > 0
    chi2 = float(np.mean((ma - mb)[mask] ** 2 / var[mask])) if mask.any() else float("nan")
    zero_var_diff = float(np.abs(ma - mb)[~mask].max()) if (~mask).any() else 0.0
    return {"mean_ours": float(ma.mean()), "mean_peer": float(mb.mean()), "difference": d, "sigma": sigma,
            "z": d / sigma if sigma > 0 else float("inf") if d else 0.0,
            "relative_difference": d / float(mb.mean()) if mb.mean() else float("nan"),
            "pixel_chi2_per_dof": chi2, "max_abs_diff_where_noiseless": zero_var_diff,
            "rmse_between": rmse(ma, mb), "expected_rmse_from_noise": float(np.sqrt(np.mean(var)))}


def mean_check(img, ref, err, pass_means=None):
    """A single converged-ish image against our reference: difference of the image means and its
    standard error. From the pixels (pixels independent: noise RMSE / sqrt(pixel count)); a pixel's
    channels share its paths, so they count as one sample, not three: in grey scenes they move
    together, and counting them apart understated sigma by sqrt(3) (seeds' image means of 24 renders
    of benchmark scene 2 spread 1.13x sigma computed per pixel, 1.96x sigma computed per channel).
    Where the render's passes' own image means are known (ours.py render, `pass_means`, at least 8
    passes) sigma is the larger of that and their spread / sqrt(passes): a photon map's noise is shared
    by every pixel of its pass, which the pixel count does not see (benchmark scene 10's photon map at
    4 s, 25 passes: sigma 0.00044 from the pixels, 0.00082 from the passes, so z -3.3 became -1.8;
    converged, the photon map and the path tracer agree, tools/bench/README.md)."""
    d = float(np.mean(img) - np.mean(ref))
    a = np.asarray(img)
    n = a.shape[0] * a.shape[1] if a.ndim == 3 else a.size
    sigma_pixels = err / math.sqrt(n)
    sigma_passes = float("nan")
    if pass_means is not None and len(pass_means) >= 8:
        pm = np.asarray(pass_means, np.float64)
        sigma_passes = float(pm.std(ddof=1) / math.sqrt(len(pm)))
    sigma = max(sigma_pixels, sigma_passes) if sigma_passes == sigma_passes else sigma_pixels
    return {"difference": d, "sigma": sigma, "z": d / sigma if sigma > 0 else float("nan"),
            "sigma_pixels": sigma_pixels, "sigma_passes": sigma_passes,
            "relative_difference": d / float(np.mean(ref)) if np.mean(ref) else float("nan")}


# --------------------------------------------------------------------------------------------------
# Steps
# --------------------------------------------------------------------------------------------------


def prepare(run: Run):
    sys.path.insert(0, HERE)
    import export_usd

    for s in S.SCENES:
        export_usd.write_usda(s, os.path.join(BENCH_DIR, s.name + ".usda"))
    vdb = os.path.join(BENCH_DIR, "cloud.vdb")
    grids = {(m.resolution, m.seed) for s in S.SCENES for m in s.grid_media()}
    assert len(grids) == 1, "one cloud file per run"
    res, seed = grids.pop()
    ok, msg = run.sub("make_vdb", [PY, "-c", "from volphoton import _core; _core.write_procedural_cloud_vdb(%r, %d, %r, %d)"
                                   % (vdb, res, 1.0 / res, seed)])
    if not ok:
        raise SystemExit("cannot write the cloud VDB: %s" % msg)
    ok, msg = run.sub("voxels", [PY, os.path.join(HERE, "ours.py"), "voxels", "--vdb", vdb, "--resolution", str(res),
                                 "--out", os.path.join(run.out, "cloud_voxels.npy")])
    if not ok:
        raise SystemExit("cannot export the voxels: %s" % msg)


def peer_status(run: Run):
    status = {}
    for key, script, flag in (("mitsuba", "peer_mitsuba.py", run.args.no_mitsuba), ("cycles", "peer_cycles.py", run.args.no_cycles)):
        if flag:
            status[key] = {"available": False, "why": "disabled on the command line"}
            continue
        ok, out = run.sub("check_" + key, [PY, os.path.join(HERE, script), "check"], timeout=300)
        try:
            status[key] = json.loads(out.strip().splitlines()[-1]) if ok else {"available": False, "why": out}
        except (ValueError, IndexError):
            status[key] = {"available": False, "why": "check failed: %s" % out[-300:]}
    return status


def load_npz(path):
    d = np.load(path)
    out = {k: d[k] for k in d.files}
    if "meta" in out:
        out["meta"] = json.loads(str(out["meta"]))
    return out


def bench_scene(run: Run, scene: S.BenchScene, peers: dict) -> dict:
    cfg = run.cfg
    W, H = cfg["size"]
    size = [str(W), str(H)]
    budgets = ",".join("%g" % b for b in cfg["budgets"])
    usd = os.path.join(BENCH_DIR, scene.name + ".usda")
    od = os.path.join(run.out, scene.name)
    os.makedirs(od, exist_ok=True)
    res = {"scene": scene.name, "title": scene.title, "curves": {}, "skipped": {}, "references": {}}
    voxels = os.path.join(run.out, "cloud_voxels.npy")

    # Reference: our path tracer, other seed.
    run.log("%s: reference (volphoton path tracer, %.0f s)" % (scene.name, cfg["ref_seconds"]))
    ref_path = os.path.join(od, "reference_ours.npz")
    core_arg = ["--core", run.core] if run.core else []
    ok, msg = run.sub(scene.name + "_ref_ours", [PY, os.path.join(HERE, "ours.py"), "reference", "--usd", usd, "--size",
                                                 *size, "--seconds", str(cfg["ref_seconds"]), "--batches",
                                                 str(cfg["batches"]), "--seed", str(REF_SEED), "--out", ref_path]
                      + core_arg)
    if not ok:
        raise SystemExit("%s: our reference failed: %s" % (scene.name, msg))
    ref = load_npz(ref_path)
    ref_img = ref["mean"].astype(np.float64)
    floor = ref_noise(ref["batches"])
    res["references"]["ours"] = {"passes": ref["meta"]["passes"], "seconds": ref["meta"]["seconds"],
                                 "noise_rmse": floor, "mean": float(ref_img.mean())}

    # Cross-check references.
    for key, script in (("mitsuba", "peer_mitsuba.py"), ("cycles", "peer_cycles.py")):
        if not peers[key].get("available"):
            continue
        if key == "cycles" and scene.name != "homogeneous_cube" and not run.args.cycles_references:
            continue
        run.log("%s: %s reference (%.0f s)" % (scene.name, key, cfg["peer_ref_seconds"]))
        p = os.path.join(od, "reference_%s.npz" % key)
        cmd = [PY, os.path.join(HERE, script), "reference", "--scene", scene.name, "--size", *size, "--seconds",
               str(cfg["peer_ref_seconds"]), "--batches", str(cfg["batches"]), "--out", p]
        if key == "mitsuba":
            cmd += ["--voxels", voxels]
        ok, msg = run.sub("%s_ref_%s" % (scene.name, key), cmd)
        if not ok:
            res["references"][key] = {"skipped": msg}
            continue
        pref = load_npz(p)
        cc = cross_check(ref, pref)
        cc.update({"spp": pref["meta"].get("spp"), "seconds": pref["meta"].get("seconds")})
        res["references"][key] = cc

    # Timed curves.
    jobs = [("volphoton pathTracer", [PY, os.path.join(HERE, "ours.py"), "render", "--usd", usd, "--size", *size,
                                      "--integrator", "pathTracer", "--budgets", budgets] + core_arg),
            ("volphoton photonMap", [PY, os.path.join(HERE, "ours.py"), "render", "--usd", usd, "--size", *size,
                                     "--integrator", "photonMap", "--budgets", budgets] + core_arg),
            ("volphoton combined", [PY, os.path.join(HERE, "ours.py"), "render", "--usd", usd, "--size", *size,
                                    "--integrator", "combined", "--budgets", budgets] + core_arg)]
    if peers["mitsuba"].get("available"):
        jobs.append(("Mitsuba 3 volpath", [PY, os.path.join(HERE, "peer_mitsuba.py"), "render", "--scene", scene.name,
                                           "--size", *size, "--budgets", budgets, "--voxels", voxels]))
    else:
        res["skipped"]["Mitsuba 3 volpath"] = peers["mitsuba"].get("why", "unavailable")
    if peers["cycles"].get("available"):
        jobs.append(("Cycles", [PY, os.path.join(HERE, "peer_cycles.py"), "render", "--scene", scene.name, "--size",
                                *size, "--budgets", budgets]))
    else:
        res["skipped"]["Cycles"] = peers["cycles"].get("why", "unavailable")
    for label, cmd in jobs:
        run.log("%s: %s" % (scene.name, label))
        p = os.path.join(od, label.split()[0].lower() + "_" + label.split()[-1].lower() + ".npz")
        ok, msg = run.sub("%s_%s" % (scene.name, label.replace(" ", "_")), cmd + ["--out", p])
        if not ok:
            res["skipped"][label] = msg.replace("SKIP: ", "")
            continue
        d = load_npz(p)
        rss = run.rss.get("%s_%s" % (scene.name, label.replace(" ", "_")))
        errs = [rmse(img, ref_img) for img in d["images"]]
        # MSE against a noisy reference = MSE + the reference's variance: subtract it.  Points whose
        # corrected RMSE is below half the reference noise are not resolved (-> 0, left out).
        corrected = [math.sqrt(e * e - floor * floor) if e * e - floor * floor > 0.25 * floor * floor else 0.0
                     for e in errs]
        curve = {"times": d["times"].tolist(), "spp": d["spp"].tolist(), "rmse": errs, "rmse_corrected": corrected,
                 "meta": d["meta"], "peak_rss_mb": rss}
        # The passes of the last snapshot (a render may run a pass or more past its last budget).
        pass_means = d["pass_means"][:int(d["spp"][-1])] if "pass_means" in d else None
        curve["mean_check"] = mean_check(d["images"][-1], ref_img, corrected[-1] or errs[-1], pass_means)
        res["curves"][label] = curve
    return res


def equal_time(res: dict, budgets) -> dict:
    """Ratios ours/theirs of the (reference-noise corrected) RMSE at each budget both curves reach."""
    out = {}
    curves = res["curves"]
    for ours in ("volphoton pathTracer", "volphoton photonMap", "volphoton combined"):
        for theirs in ("Mitsuba 3 volpath", "Cycles", "volphoton pathTracer", "volphoton photonMap"):
            if ours == theirs or ours not in curves or theirs not in curves:
                continue
            a, b = curves[ours], curves[theirs]
            ratios = {}
            for t in budgets:
                ea = loglog_at(a["times"], a["rmse_corrected"], t)
                eb = loglog_at(b["times"], b["rmse_corrected"], t)
                if ea is not None and eb is not None and eb > 0:
                    ratios["%g" % t] = ea / eb
            if ratios:
                out["%s / %s" % (ours, theirs)] = ratios
    return out


def _find_core(build_dir):
    for root, _, files in os.walk(build_dir) if os.path.isdir(build_dir) else []:
        for f in files:
            if f.startswith("_core") and f.endswith(".so"):
                return os.path.join(root, f)
    return None


def no_volumes_overhead(run: Run) -> dict:
    """Scene 7: the bindings built with VOLPHOTON_NO_VOLUMES against the same sources built without it
    (two build directories, identical flags otherwise; both brought up to date incrementally first)."""
    scene = "surfaces_only"
    cores = {}
    for key, build_dir in (("with_volumes", WITHVOL_BUILD), ("no_volumes", NOVOL_BUILD)):
        if run.build_errors.get(build_dir):
            return {"skipped": "building %s failed: %s" % (build_dir, run.build_errors[build_dir])}
        cores[key] = _find_core(build_dir)
        if cores[key] is None:
            return {"skipped": "no %s/_core*.so (run without --no-build, see tools/bench/README.md)" % build_dir}
    usd = os.path.join(BENCH_DIR, scene + ".usda")
    W, H = run.cfg["novol_size"]
    rows = {"with_volumes": [], "no_volumes": []}
    info = {}
    for rep in range(3):
        for key in ("with_volumes", "no_volumes"):
            p = os.path.join(run.out, "novol_%s_%d.json" % (key, rep))
            cmd = [PY, os.path.join(HERE, "ours.py"), "passes", "--usd", usd, "--size", str(W), str(H), "--passes",
                   str(run.cfg["novol_passes"]), "--out", p, "--core", cores[key]]
            ok, msg = run.sub("novol_%s_%d" % (key, rep), cmd)
            if not ok:
                return {"skipped": "%s run failed: %s" % (key, msg)}
            with open(p) as f:
                d = json.load(f)
            rows[key].append(float(np.median(d["pass_seconds"])))
            info[key] = {"no_volumes": d["no_volumes"], "has_media": d["has_media"], "image_mean": d["image_mean"]}
    a, b = min(rows["with_volumes"]), min(rows["no_volumes"])
    return {"pass_seconds_with_volumes": a, "pass_seconds_no_volumes": b, "ratio": a / b, "runs": rows, "info": info,
            "cores": cores, "size": [W, H], "passes": run.cfg["novol_passes"]}


def build_cores(run: Run):
    """Brings build-withvol/ and build-novol/ (the bindings with and without VOLPHOTON_NO_VOLUMES, same
    sources and flags otherwise) up to date, -j1; incremental after the first time."""
    run.build_errors = {}
    for build_dir, flag in ((WITHVOL_BUILD, "OFF"), (NOVOL_BUILD, "ON")):
        run.log("bringing %s up to date (VOLPHOTON_NO_VOLUMES=%s, -j1)" % (os.path.basename(build_dir), flag))
        ok, msg = build_bindings(run, build_dir, flag)
        if not ok:
            run.build_errors[build_dir] = msg
            run.log("  build failed: %s" % msg)


def build_bindings(run: Run, build_dir: str, no_volumes: str):
    import pybind11

    if not os.path.exists(os.path.join(build_dir, "build.ninja")):
        cmd = ["cmake", "-S", REPO, "-B", build_dir, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
               "-DVOLPHOTON_NO_VOLUMES=" + no_volumes, "-DVOLPHOTON_BUILD_PYTHON=ON", "-DVOLPHOTON_BUILD_TESTS=OFF",
               "-DVOLPHOTON_BUILD_HYDRA=OFF", "-Dpybind11_DIR=" + pybind11.get_cmake_dir(), "-DPython_EXECUTABLE=" + PY]
        ok, msg = run.sub("configure_" + os.path.basename(build_dir), cmd)
        if not ok:
            return ok, msg
    return run.sub("build_" + os.path.basename(build_dir), ["cmake", "--build", build_dir, "--target", "_core", "-j", "1"],
                   timeout=7200)


# --------------------------------------------------------------------------------------------------
# Reports
# --------------------------------------------------------------------------------------------------


def write_outputs(run: Run, results: list, peers: dict, novol: dict, wall: float):
    budgets = run.cfg["budgets"]
    with open(os.path.join(run.out, "results.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "renderer", "seconds", "spp", "rmse", "rmse_corrected", "relative_rmse"])
        for r in results:
            m = r["references"]["ours"]["mean"]
            for label, c in r["curves"].items():
                for t, spp, e, ec in zip(c["times"], c["spp"], c["rmse"], c["rmse_corrected"]):
                    w.writerow([r["scene"], label, "%.4f" % t, spp, "%.6g" % e, "%.6g" % ec, "%.6g" % (e / m if m else 0)])
    for r in results:
        r["equal_time"] = equal_time(r, budgets)
    machine = machine_info()
    machine["git"] = git_info()
    machine["volphoton_core"] = run.core or "installed volphoton._core"
    summary = {"mode": "quick" if run.args.quick else "full", "config": run.cfg, "machine": machine, "peers": peers,
               "results": results, "no_volumes": novol, "wall_seconds": wall, "command": " ".join(sys.argv)}
    with open(os.path.join(run.out, "results.json"), "w") as f:
        json.dump(summary, f, indent=1, default=_json_default)
    md = markdown(summary)
    with open(os.path.join(run.out, "results.md"), "w") as f:
        f.write(md)
    plot(results, os.path.join(run.out, "error_vs_time.png"), summary)
    return md


def _json_default(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def git_info():
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "hdVolPhoton"], cwd=REPO,
                               capture_output=True, text=True).stdout.strip()
        return head + (" + uncommitted changes in hdVolPhoton/" if dirty else "")
    except OSError:
        return "unknown"


def machine_info():
    cpu = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(), "platform": platform.platform()}


def _fmt(x, nd=3):
    if x is None:
        return "–"
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    return ("%%.%dg" % nd) % x


def markdown(s: dict) -> str:
    cfg = s["config"]
    L = []
    L.append("## Error against time (%s set: %dx%d, budgets %s s, 2 threads each)\n" % (
        s["mode"], cfg["size"][0], cfg["size"][1], ", ".join("%g" % b for b in cfg["budgets"])))
    L.append("Machine: %s, %s cores (shared with other jobs); wall time of the run %.0f s; command `%s`; "
             "sources %s; volphoton core %s.\n" % (
                 s["machine"]["cpu"], s["machine"]["cores"], s["wall_seconds"], s["command"], s["machine"].get("git"),
                 os.path.relpath(s["machine"]["volphoton_core"], REPO) if os.path.isabs(s["machine"]["volphoton_core"])
                 else s["machine"]["volphoton_core"]))
    peers = s["peers"]
    L.append("Peers: Mitsuba %s; Cycles %s.\n" % (
        (peers["mitsuba"].get("version", "") + " (" + peers["mitsuba"].get("variant", "") + ")") if peers["mitsuba"].get("available") else "unavailable: " + peers["mitsuba"].get("why", ""),
        ("Blender " + peers["cycles"].get("version", "")) if peers["cycles"].get("available") else "unavailable: " + peers["cycles"].get("why", "")))
    # Equal-time summary
    L.append("### Equal-time RMSE ratios (ours / theirs; < 1: ours is better) at the largest common budget\n")
    L.append("| scene | PT / Mitsuba | PT / Cycles | PM / Mitsuba | PM / Cycles | PM / PT | C / PT | C / PM |")
    L.append("|---|---|---|---|---|---|---|---|")
    for r in s["results"]:
        et = r["equal_time"]

        def last(key):
            d = et.get(key)
            if not d:
                return "–"
            t = max(d, key=float)
            return "%.2f (%s s)" % (d[t], t)

        def skip(label):
            return "skip" if label in r["skipped"] else None

        row = [r["title"],
               skip("Mitsuba 3 volpath") or last("volphoton pathTracer / Mitsuba 3 volpath"),
               skip("Cycles") or last("volphoton pathTracer / Cycles"),
               skip("Mitsuba 3 volpath") or last("volphoton photonMap / Mitsuba 3 volpath"),
               skip("Cycles") or last("volphoton photonMap / Cycles"),
               last("volphoton photonMap / volphoton pathTracer"),
               last("volphoton combined / volphoton pathTracer"),
               last("volphoton combined / volphoton photonMap")]
        L.append("| " + " | ".join(row) + " |")
    L.append("")
    skipped = [(r["title"], k, v) for r in s["results"] for k, v in r["skipped"].items()]
    if skipped:
        L.append("Skipped cells: " + "; ".join("%s — %s: %s" % x for x in skipped) + ".\n")
    # Per scene RMSE tables
    L.append("### RMSE against the reference at each budget (reference-noise corrected)\n")
    for r in s["results"]:
        ro = r["references"]["ours"]
        L.append("**%s** — reference: volphoton path tracer, %d spp in %.0f s, image mean %.4g, its own noise RMSE %.3g.\n"
                 % (r["title"], ro["passes"], ro["seconds"], ro["mean"], ro["noise_rmse"]))
        L.append("| renderer | " + " | ".join("%g s" % b for b in cfg["budgets"]) + " | spp at the last | mean vs ref (z) | notes |")
        L.append("|---|" + "---|" * (len(cfg["budgets"]) + 3))
        for label in RENDERERS:
            c = r["curves"].get(label)
            if c is None:
                if label in r["skipped"]:
                    L.append("| %s | skipped: %s |" % (label, r["skipped"][label]))
                continue
            cells = []
            for b in cfg["budgets"]:
                v = loglog_at(c["times"], c["rmse_corrected"], b)
                if v is None and any(x == 0.0 for x in c["rmse_corrected"]) and b >= min(c["times"]) / 1.3:
                    cells.append("< %.2g" % (0.5 * ro["noise_rmse"]))
                else:
                    cells.append(_fmt(v))
            mc = c["mean_check"]
            note = ""
            meta = c.get("meta", {})
            if label == "Cycles" and meta.get("renders"):
                rr = meta["renders"]
                note = "per-render set-up %.2f s, of which volume preprocessing %.2f s" % (
                    float(np.median([x["setup_seconds"] for x in rr])), float(np.median([x["volume_preprocess_seconds"] for x in rr])))
            elif label.startswith("Mitsuba"):
                note = "JIT/first render %.2f s excluded" % meta.get("jit_warmup_seconds", float("nan"))
            elif label in ("volphoton photonMap", "volphoton combined"):
                st = meta.get("stats", {})
                # The count used (stats): the settings hold 0 for the automatic one.
                note = "%s photons/pass, skipped: %s" % (st.get("photons_per_pass", "?"),
                                                        "; ".join(st.get("passes_skipped", [])) or "none")
            if c.get("peak_rss_mb"):
                note = (note + "; " if note else "") + "peak RSS %.0f MB" % c["peak_rss_mb"]
            L.append("| %s | %s | %d | %+.2g%% (%.1f) | %s |" % (label, " | ".join(cells), c["spp"][-1],
                                                              100 * mc["relative_difference"], mc["z"], note))
        refs = [(k, v) for k, v in r["references"].items() if k != "ours"]
        for k, v in refs:
            if "skipped" in v:
                L.append("\n%s reference: skipped (%s)" % (k, v["skipped"]))
                continue
            L.append("\nCross-check with %s's reference (%s spp, %.0f s): means ours %.5g vs %.5g, difference %+.3g ± %.2g "
                     "(z = %.1f, %+.2f%%), per-pixel chi²/dof %.2f, RMSE between the references %.3g (noise alone: %.3g)."
                     % (k, v.get("spp"), v.get("seconds") or 0, v["mean_ours"], v["mean_peer"], v["difference"], v["sigma"],
                        v["z"], 100 * v["relative_difference"], v["pixel_chi2_per_dof"], v["rmse_between"],
                        v["expected_rmse_from_noise"]))
        L.append("")
    nv = s.get("no_volumes") or {}
    L.append("### Scene (7) against a core with the volume code compiled out\n")
    if "skipped" in nv:
        L.append("Skipped: %s\n" % nv["skipped"])
    elif nv:
        L.append("Path tracer, %dx%d, median seconds per pass over %d passes (best of 3 alternating runs): core with "
                 "volumes %.4f s, VOLPHOTON_NO_VOLUMES core %.4f s (same sources, same flags): ratio **%.3f** "
                 "(target <= 1.1). Image means %.6g / %.6g.\n"
                 % (nv["size"][0], nv["size"][1], nv["passes"], nv["pass_seconds_with_volumes"], nv["pass_seconds_no_volumes"],
                    nv["ratio"], nv["info"]["with_volumes"]["image_mean"], nv["info"]["no_volumes"]["image_mean"]))
    return "\n".join(L) + "\n"


def plot(results, path, summary):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    n = len(results)
    cols = min(4, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.6 * rows), squeeze=False)
    style = {"volphoton pathTracer": ("C0", "o"), "volphoton photonMap": ("C1", "s"), "volphoton combined": ("C4", "v"),
             "Mitsuba 3 volpath": ("C2", "^"), "Cycles": ("C3", "D")}
    for ax, r in zip(axes.flat, results):
        for label, c in r["curves"].items():
            col, mk = style.get(label, ("k", "x"))
            order = np.argsort(c["times"])
            t = np.array(c["times"])[order]
            e = np.array(c["rmse_corrected"])[order]
            ok = e > 0
            ax.loglog(t[ok], e[ok], marker=mk, color=col, label=label, lw=1.2, ms=4)
        floor = r["references"]["ours"]["noise_rmse"]
        ax.axhline(floor, color="0.6", ls=":", lw=1, label="reference noise")
        ax.set_title(r["title"], fontsize=8)
        ax.set_xlabel("render seconds (2 threads)", fontsize=7)
        ax.set_ylabel("RMSE vs reference", fontsize=7)
        ax.tick_params(labelsize=7)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: "%g" % v))
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    handles, labels = [], []
    for ax in axes.flat:
        for h, l in zip(*ax.get_legend_handles_labels()):
            if l not in labels:
                handles.append(h)
                labels.append(l)
    fig.legend(handles, labels, loc="lower right", fontsize=8)
    fig.suptitle("Error against time (%s set, %dx%d)" % (summary["mode"], *summary["config"]["size"]), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the quick set (< 15 min on 2 cores)")
    ap.add_argument("--scenes", default="", help="comma-separated scene names (default: the quick set's seven, "
                                                 "or all nine for the full set)")
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--no-cycles", action="store_true")
    ap.add_argument("--cycles-references", action="store_true",
                    help="a Cycles reference for every scene (default: scene 1 only)")
    ap.add_argument("--no-build", action="store_true",
                    help="use build-novol/ and build-withvol/ as they are (default: bring both up to date, -j1)")
    ap.add_argument("--out", default=os.path.join(REPO, "tools", "out", "bench"))
    ap.add_argument("--ours-core", choices=["build", "installed"], default="build",
                    help="volphoton core of the timed renders: build-withvol/ built from the working tree (default; "
                         "the same sources as the VOLPHOTON_NO_VOLUMES copy) or the installed package")
    ap.add_argument("--replot", action="store_true", help="rewrite results.md and the plot from results.json only")
    args = ap.parse_args(argv)
    if args.replot:
        with open(os.path.join(args.out, "results.json")) as f:
            summary = json.load(f)
        with open(os.path.join(args.out, "results.md"), "w") as f:
            f.write(markdown(summary))
        plot(summary["results"], os.path.join(args.out, "error_vs_time.png"), summary)
        return 0
    run = Run(args)
    names = [n for n in args.scenes.split(",") if n] or (S.QUICK_DEFAULT if args.quick else [s.name for s in S.SCENES])
    for n in names:
        if n not in S.BY_NAME:
            ap.error("unknown scene %r (known: %s)" % (n, ", ".join(S.BY_NAME)))
    if not args.no_build:
        build_cores(run)
    if args.ours_core == "build":
        run.core = _find_core(WITHVOL_BUILD)
        if run.core is None:
            run.log("no build-withvol core: volphoton runs with the installed volphoton._core")
    run.log("volphoton core: %s" % (run.core or "installed volphoton._core"))
    run.log("preparing scenes (USD, VDB, voxels) in %s" % BENCH_DIR)
    prepare(run)
    peers = peer_status(run)
    for k, v in peers.items():
        run.log("peer %s: %s" % (k, ("available " + v.get("version", "") + " " + v.get("variant", "")) if v.get("available")
                                  else "UNAVAILABLE: " + v.get("why", "")))
    results = []
    for n in names:
        results.append(bench_scene(run, S.get(n), peers))
    novol = no_volumes_overhead(run) if "surfaces_only" in names else {"skipped": "scene 7 not in this run"}
    md = write_outputs(run, results, peers, novol, time.perf_counter() - run.t_start)
    print(md)
    run.log("wrote %s/results.{csv,json,md} and error_vs_time.png" % run.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
