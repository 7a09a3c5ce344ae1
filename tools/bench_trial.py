"""The measured choice against the truth (README, "The measured choice").

For each scene: the truth is each side's cost to a given noise at equal time, measured the long way
(per-pixel variance of the beauty's channel average over SEEDS renders of PASSES passes, times seconds a
pass after the first, whose pilots are a render's setup): the path tracer, and `combined` with the photons the trial tries (the automatic share of a
render too short for a trial: PASSES < 16 passes, with auto's choice of open media forced to the
photons as the trial's first passes render them). Then the trial itself: `combined` renders of 16
passes with trial seeds 0..TRIALS-1, stopped after the trial's 4 passes, with the cost ratio it read
and the side it kept.

    . .venv/bin/activate
    python tools/bench_trial.py                      # all ten benchmark scenes, 80 x 60
    python tools/bench_trial.py --scenes subsurface_bunny,ball_behind_fog --seeds 16

Prints a Markdown table: path tracer / photons cost ratio (truth; < 1: the path tracer is cheaper),
the trial's reads, and what it kept. Run alone on the machine (it times renders).
"""
import argparse
import contextlib
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "bench"))
import ours  # noqa: E402  (the benchmark's USD -> core settings builder)

SCENES = ("homogeneous_cube,vdb_cloud,dense_cloud,fog_spotlight,atmosphere_sunset,emissive_smoke,surfaces_only,"
          "subsurface_ball,subsurface_bunny,ball_behind_fog")
TRIAL_PASSES = 4  # PhotonNoisePasses + TrialPasses (core/integrator.h)


@contextlib.contextmanager
def changed(settings, **values):
    """The scene's settings with `values` set, as they were afterwards (a Renderer copies them)."""
    before = {k: getattr(settings, k) for k in values}
    for k, v in values.items():
        setattr(settings, k, v)
    try:
        yield settings
    finally:
        for k, v in before.items():
            setattr(settings, k, v)


def truth(core, scene, s, passes, seeds):
    imgs, seconds = [], 0.0
    for seed in range(seeds):
        with changed(s, seed=100 + seed, samples_per_pixel=passes):
            r = core.Renderer(scene, s)
        r.render_pass()  # not timed: pass 1 holds the pilots (photon count, integrator), a render's setup
        t = time.perf_counter()
        for _ in range(passes - 1):
            r.render_pass()
        seconds += time.perf_counter() - t
        imgs.append(np.array(r.film.beauty, dtype=np.float64).mean(axis=-1))
    variance = np.array(imgs).var(axis=0, ddof=1).mean() * passes  # of one sample
    return variance, seconds / (seeds * (passes - 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=SCENES)
    ap.add_argument("--size", type=int, nargs=2, default=(80, 60))
    ap.add_argument("--passes", type=int, default=12, help="passes of each truth render (< 16: no trial)")
    ap.add_argument("--seeds", type=int, default=8, help="truth renders per side")
    ap.add_argument("--trials", type=int, default=4, help="trial renders (seeds 0..N-1)")
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    if a.passes >= 16:
        sys.exit("--passes must be below 16 (MinTrialRenderPasses): the truth renders must not run the trial")
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "testenv", "bench")
    print("| scene | what the trial tries | path tracer / photons, truth | trial read (kept) |")
    print("|---|---|---|---|")
    for name in a.scenes.split(","):
        usd = os.path.join(root, name + ".usda")
        # The scene translated once; what a trial-length render of combined tries: auto's choice at 16 passes.
        core, scene, s, _, _ = ours.build(usd, a.size[0], a.size[1], "combined", a.threads, 0, None,
                                          {"samples_per_pixel": 16})
        choice = core.choose_integrator(scene, s)
        photons = {}
        if choice["open_media_by_photons"]:
            photons = dict(combined_photon_share=1.0, photon_beams=bool(choice["photon_beams"]))
        reads, measured = [], False
        for seed in range(a.trials):
            with changed(s, seed=seed):
                r = core.Renderer(scene, s)
            for _ in range(TRIAL_PASSES + 1):
                r.render_pass()
            st = r.stats
            measured |= st["measured_photon_cost"] > 0
            if st["measured_photon_cost"] > 0:
                reads.append("%.2f (%s)" % (st["measured_path_tracer_cost"] / st["measured_photon_cost"],
                                            "PT" if st["integrator_used"] == "pathTracer" else "photons"))
            else:
                reads.append("not measured (%s)" % st["integrator_used"])
        if choice["open_media_by_photons"]:
            tries = "photons in open media (%s)" % ("beams" if choice["photon_beams"] else "points")
        elif measured:
            tries = "photons in translucent objects"
        else:
            print("| %s | nothing: combined renders as the path tracer | - | %s |" % (name, ", ".join(reads)), flush=True)
            continue
        with changed(s, integrator=core.RenderSettings.Integrator.PathTracer):
            pt_var, pt_s = truth(core, scene, s, a.passes, a.seeds)
        with changed(s, **photons):
            ph_var, ph_s = truth(core, scene, s, a.passes, a.seeds)
        ratio = (pt_var * pt_s) / (ph_var * ph_s) if ph_var * ph_s > 0 else float("inf")
        print("| %s | %s | %.3g (variance %.3g / %.3g, ms a pass %.2f / %.2f) | %s |" % (
            name, tries, ratio, pt_var, ph_var, 1e3 * pt_s, 1e3 * ph_s, ", ".join(reads)), flush=True)


if __name__ == "__main__":
    main()
