#!/usr/bin/env python3
"""A camera orbit through the Hydra delegate (issue 15, "reuse what does not change"): usdrecord
renders the cloud and fog benchmark scenes with the photon map along an orbit of --views views
(--step degrees apart about the vertical axis through the origin, where both scenes' cameras look),
--seconds of rendering per view (volphoton:timeLimit), once as one usdrecord process over all views
(one render delegate: a camera move keeps its photon maps, hdVolPhoton/hd/renderPass.cpp) and once
as a fresh usdrecord process per view (photons traced from scratch). Each view after the first is
compared with a long photon-map render of that view by the standalone front end (--reference-passes
passes, another seed): RMSE of the orbit's frame / RMSE of the fresh one. Below 1: reuse pays.

    PATH=/opt/openusd/bin:$PATH python tools/bench_hydra_orbit.py     # 80x60, 2 s a view, 4 views
"""

import math
import os
import subprocess
import sys
import tempfile

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "testenv", "hydra"))
sys.path.insert(0, os.path.join(REPO, "testenv"))
from hydra_util import make_hydra_env, run_usdrecord, volphoton_exe  # noqa: E402
from bench_photon_reuse import orbit_arguments  # noqa: E402
from volphoton import output  # noqa: E402

SCENES = ["vdb_cloud", "fog_spotlight"]
BENCH = os.path.join(REPO, "testenv", "bench")


def orbit_layer(scene, views, step, size, settings):
    """A stage over the benchmark scene: the camera's transform keyed per frame 1..views, rotated by
    step degrees a frame about the vertical (y) axis, and the RenderSettings prim's overrides."""
    from pxr import Gf, Usd, UsdGeom

    base = Usd.Stage.Open(os.path.join(BENCH, scene + ".usda"))
    cam = base.GetPrimAtPath("/World/camera")
    m0 = UsdGeom.Xformable(cam).GetLocalTransformation()
    samples = []
    for f in range(1, views + 1):
        rot = Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(0, 1, 0), step * (f - 1)))
        m = m0 * rot  # row vectors: the camera's placement, then the orbit
        samples.append("%d: %s" % (f, "( " + ", ".join("(%s)" % ", ".join(repr(m[i][j]) for j in range(4)) for i in range(4)) + " )"))
    lines = "\n".join("        %s" % s for s in settings)
    return '''#usda 1.0
(
    subLayers = [@%s@]
    startTimeCode = 1
    endTimeCode = %d
)

over "World"
{
    over "camera"
    {
        matrix4d xformOp:transform.timeSamples = {
            %s
        }
    }
}

over "Render"
{
    over "settings"
    {
        uniform int2 resolution = (%d, %d)
%s
    }
}
''' % (os.path.join(BENCH, scene + ".usda"), views, ",\n            ".join(samples), size[0], size[1], lines)


def rgb(path):
    channels, _ = output.read_exr(path)
    return np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)


def main(argv=None):
    args = orbit_arguments(__doc__.splitlines()[0], argv)
    w, h = args.resolution
    env = make_hydra_env()
    timed = ['token volphoton:integrator = "photonMap"', "float volphoton:timeLimit = %g" % args.seconds,
             "int volphoton:maxSamplesPerPixel = 100000", "int volphoton:samplesPerPixel = 1"]
    reference = ['token volphoton:integrator = "photonMap"', "int volphoton:samplesPerPixel = %d" % args.reference_passes,
                 "int volphoton:seed = 1000"]
    print("| scene | view | RMSE, orbit (photon maps kept) | RMSE, fresh process | orbit / fresh |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        if not os.path.exists(os.path.join(BENCH, "cloud.vdb")):
            from bench_load import load_bench_scene  # writes the benchmark's cloud.vdb
            load_bench_scene(SCENES[0], 8, 6)
        for scene in SCENES:
            timed_stage = os.path.join(tmp, scene + ".timed.usda")
            ref_stage = os.path.join(tmp, scene + ".reference.usda")
            with open(timed_stage, "w") as f:
                f.write(orbit_layer(scene, args.views, args.step, (w, h), timed))
            with open(ref_stage, "w") as f:
                f.write(orbit_layer(scene, args.views, args.step, (w, h), reference))
            common = ["--renderSettingsPrimPath", "/Render/settings", "--enableDomeLightVisibility", "--camera", "/World/camera",
                      "--imageWidth", w]
            orbit_out = os.path.join(tmp, scene + ".orbit.#.exr")
            r = run_usdrecord(env, common + ["--frames", "1:%d" % args.views, timed_stage, orbit_out])
            assert r.returncode == 0, r.stdout + r.stderr
            for view in range(2, args.views + 1):
                fresh_out = os.path.join(tmp, scene + ".fresh.%d.exr" % view)
                r = run_usdrecord(env, common + ["--frames", "%d:%d" % (view, view), timed_stage,
                                                 fresh_out.replace(".%d.exr" % view, ".#.exr")])
                assert r.returncode == 0, r.stdout + r.stderr
                ref_out = os.path.join(tmp, scene + ".ref.%04d.exr" % view)
                p = subprocess.run([volphoton_exe(), "render", ref_stage, "-o", ref_out.replace("%04d" % view, "####"),
                                    "--frames", "%d:%d" % (view, view), "--no-png", "-q"], capture_output=True, text=True)
                assert p.returncode == 0, p.stdout + p.stderr
                truth = rgb(ref_out)
                errors = [math.sqrt(np.mean((rgb(path) - truth) ** 2))
                          for path in (orbit_out.replace("#", str(view)), fresh_out)]
                print("| %s | %d | %.5f | %.5f | %.2f |" % (scene, view, errors[0], errors[1], errors[0] / errors[1]),
                      flush=True)


if __name__ == "__main__":
    main()
