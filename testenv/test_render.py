"""Renders through the whole pipeline (USD -> volphoton.usdscene -> core -> EXR/PNG).

Statistics and their tolerances
    Tiny images (24 x 24, 8 samples per pixel) of a medium in front of the camera.  The noise of a
    region's mean is estimated from the image itself: se = std(pixel means) / sqrt(pixels) (the
    pixels of a region are independent estimates; real spatial variation only inflates se, which
    makes the checks conservative).  A documented effect must exceed 5 se of both images; a value
    with a closed form (transmittance exp(-tau), emission e (1 - exp(-tau)) / sigma_t) must be within
    5 se (+ 2e-3 for float rounding) of it.  Seeds are fixed, so the results are deterministic.

Run:  cd /work/main && . .venv/bin/activate && python -m pytest testenv/test_render.py -q
"""

import json
import math
import os
import shutil
import textwrap

import numpy as np
import pytest

from conftest import REPO, TESTENV, run_cli, usda

from pxr import Usd  # noqa: E402

from volphoton import _core, output, usdscene  # noqa: E402

RES = 24
SPP = 8


def render_stage_text(tmp_path, body, name="s.usda", width=RES, height=RES, spp=SPP, seed=0, max_depth=64):
    """Translates and renders a stage in-process; returns {aov: array} and the translated scene."""
    path = tmp_path / name
    path.write_text('#usda 1.0\n(\n    upAxis = "Y"\n)\n' + usda(textwrap.dedent(body)))
    stage = Usd.Stage.Open(str(path))
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), width, height, "/cam")
    assert not sc.errors, "\n".join(map(str, sc.errors))
    s = _core.RenderSettings()
    s.width, s.height, s.samples_per_pixel, s.seed, s.max_depth = width, height, spp, seed, max_depth
    r = _core.Renderer(_core.Scene(sc.desc), s)
    r.render()
    f = r.film
    out = {"beauty": f.beauty, "single": f.single, "multiple": f.multiple, "emission": f.emission,
           "surface": f.surface, "alpha": f.alpha()}
    for k, v in out.items():
        assert np.all(np.isfinite(v)), k
    return out


def mean_se(region):
    """(mean, standard error of the mean) over pixels of an (H, W) or (H, W, C) region per channel."""
    r = region.reshape(-1, region.shape[-1]) if region.ndim == 3 else region.reshape(-1, 1)
    n = r.shape[0]
    return r.mean(axis=0), r.std(axis=0, ddof=1) / math.sqrt(n)


def clearly_greater(a, b, k=5.0):
    ma, sa = mean_se(a)
    mb, sb = mean_se(b)
    return np.all(ma - mb > k * np.sqrt(sa ** 2 + sb ** 2) + 1e-6), (ma, sa, mb, sb)


def near(region, expected, k=5.0, floor=2e-3):
    m, se = mean_se(region)
    ok = np.all(np.abs(m - np.asarray(expected)) <= k * se + floor)
    return ok, (m, se, expected)


# An orthographic camera looking down -Z at the 2 x 2 x 2 box [-1, 1]^3: every camera ray crosses
# exactly 2 units of medium (the view is 1 unit wide, inside the box's face).
BOX = """
    def Camera "cam" {{
        token projection = "orthographic"
        float horizontalAperture = 10
        float verticalAperture = 10
        double3 xformOp:translate = (0, 0, 5)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }}
    def Volume "box" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {{
        point3f volphoton:bounds:min = (-1, -1, -1)
        point3f volphoton:bounds:max = (1, 1, 1)
        {attrs}
    }}
    {lights}
"""
DOME = 'def DomeLight "dome" { float inputs:intensity = 1 }'
SIDE_SUN = """def DistantLight "sun" {
        float inputs:intensity = 3
        bool inputs:normalize = 1
        float inputs:angle = 0
        float3 xformOp:rotateXYZ = (0, -90, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }"""
BACK_SUN = """def DistantLight "sun" {
        float inputs:intensity = 3
        bool inputs:normalize = 1
        float inputs:angle = 0
        float3 xformOp:rotateXYZ = (0, 180, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }"""


def box(tmp_path, attrs, lights=DOME, **kw):
    return render_stage_text(tmp_path, BOX.format(attrs=attrs, lights=lights), **kw)


def test_density_darkens_the_background_as_exp_minus_tau(tmp_path):
    thin = box(tmp_path, "float volphoton:density = 0.25\ncolor3f volphoton:albedo = (0, 0, 0)")
    thick = box(tmp_path, "float volphoton:density = 1\ncolor3f volphoton:albedo = (0, 0, 0)")
    for img, tau in ((thin, 0.5), (thick, 2.0)):
        ok, info = near(img["surface"], [math.exp(-tau)] * 3)
        assert ok, info
    ok, info = clearly_greater(thin["surface"], thick["surface"])
    assert ok, info


def test_density_brightens_scattering(tmp_path):
    lo = box(tmp_path, "float volphoton:density = 0.1\ncolor3f volphoton:albedo = (0.9, 0.9, 0.9)", SIDE_SUN)
    hi = box(tmp_path, "float volphoton:density = 0.4\ncolor3f volphoton:albedo = (0.9, 0.9, 0.9)", SIDE_SUN)
    ok, info = clearly_greater(hi["single"], lo["single"])
    assert ok, info


def test_albedo_zero_means_no_scattering(tmp_path):
    black = box(tmp_path, "float volphoton:density = 1\ncolor3f volphoton:albedo = (0, 0, 0)", SIDE_SUN + "\n" + DOME)
    assert black["single"].max() == 0 and black["multiple"].max() == 0
    white = box(tmp_path, "float volphoton:density = 1\ncolor3f volphoton:albedo = (0.9, 0.9, 0.9)", SIDE_SUN + "\n" + DOME)
    ok, info = clearly_greater(white["single"], black["single"])
    assert ok, info
    ok, info = clearly_greater(white["multiple"], black["multiple"])
    assert ok, info


def test_extinction_color_filters_per_channel(tmp_path):
    img = box(tmp_path, "float volphoton:density = 1\ncolor3f volphoton:albedo = (0, 0, 0)\n"
              "color3f volphoton:extinctionColor = (1, 0.25, 0.5)")
    ok, info = near(img["surface"], [math.exp(-2.0), math.exp(-0.5), math.exp(-1.0)])
    assert ok, info


def test_emission_adds_closed_form_radiance(tmp_path):
    e = np.array([1.0, 0.5, 0.25])
    img = box(tmp_path, "float volphoton:density = 1\ncolor3f volphoton:albedo = (0, 0, 0)\n"
              "color3f volphoton:emission = (1, 0.5, 0.25)", lights="")
    # no scattering: L = e * integral_0^2 exp(-t) dt = e (1 - exp(-2))
    ok, info = near(img["emission"], e * (1 - math.exp(-2.0)))
    assert ok, info
    scaled = box(tmp_path, "float volphoton:density = 1\ncolor3f volphoton:albedo = (0, 0, 0)\n"
                 "color3f volphoton:emission = (1, 0.5, 0.25)\nfloat volphoton:emissionScale = 2", lights="")
    ok, info = near(scaled["emission"], 2 * e * (1 - math.exp(-2.0)))
    assert ok, info
    none = box(tmp_path, "float volphoton:density = 1\ncolor3f volphoton:albedo = (0, 0, 0)", lights=DOME)
    assert none["emission"].max() == 0


def test_phase_g_forward_versus_backward(tmp_path):
    # the sun shines from behind the box towards the camera: forward scattering sends it to the lens
    fwd = box(tmp_path, "float volphoton:density = 0.3\ncolor3f volphoton:albedo = (0.9, 0.9, 0.9)\n"
              "float volphoton:phase:g = 0.8", BACK_SUN)
    back = box(tmp_path, "float volphoton:density = 0.3\ncolor3f volphoton:albedo = (0.9, 0.9, 0.9)\n"
               "float volphoton:phase:g = -0.8", BACK_SUN)
    ok, info = clearly_greater(fwd["single"], 10 * back["single"])
    assert ok, info
    # single scattering at exactly 0 degrees: L = E p(1) sigma_s * 2 * exp(-sigma_t * 2)
    hg1 = (1 - 0.64) / (4 * math.pi * (1 + 0.64 - 1.6) ** 1.5)
    expected = 3 * hg1 * 0.27 * 2 * math.exp(-0.6)
    m, se = mean_se(fwd["single"])
    assert np.all(np.abs(m - expected) <= 5 * se + 0.02 * expected), (m, se, expected)


def test_density_mode_exponential_versus_constant(tmp_path):
    common = "float volphoton:density = 1\ncolor3f volphoton:albedo = (0, 0, 0)\n"
    const = box(tmp_path, common)
    expo = box(tmp_path, common + 'uniform token volphoton:densityMode = "exponential"\n'
               "float volphoton:exponential:b = 2\npoint3f volphoton:exponential:origin = (0, -1, 0)")
    top, bottom = slice(0, 6), slice(RES - 6, RES)
    # constant: top and bottom rows agree; exponential: the thin top is much brighter
    ok, info = near(const["surface"][top], mean_se(const["surface"][bottom])[0], k=6)
    assert ok, info
    ok, info = clearly_greater(expo["surface"][top], expo["surface"][bottom])
    assert ok, info
    # rows against the closed form T(y) = exp(-2 exp(-2 (y + 1))) (the view spans y in [-0.5, 0.5])
    ys = 0.5 - (np.arange(RES) + 0.5) / RES
    for row in (0, RES // 2, RES - 1):
        t = math.exp(-2.0 * math.exp(-2.0 * (ys[row] + 1.0)))
        # one row is a small region: the pixel footprint spans 1/24 in y, add the slope of T over it
        slope = abs(t - math.exp(-2.0 * math.exp(-2.0 * (ys[row] + 1.0 + 1 / RES)))) / 2
        ok, info = near(expo["surface"][row], [t] * 3, floor=slope + 2e-3)
        assert ok, (row, info)


IOR_SCENE = """
    def Camera "cam" {{
        float focalLength = 50
        float horizontalAperture = 24
        float verticalAperture = 24
        double3 xformOp:translate = (0, 0, 6)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }}
    def Cube "glassy" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {{
        double size = 2
        float volphoton:density = 0.2
        color3f volphoton:albedo = (0, 0, 0)
        float volphoton:ior = {ior}
        float3 xformOp:rotateXYZ = (0, 35, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }}
    def Material "glow" {{
        token outputs:surface.connect = </glow/s.outputs:surface>
        def Shader "s" {{
            uniform token info:id = "UsdPreviewSurface"
            color3f inputs:diffuseColor = (0, 0, 0)
            color3f inputs:emissiveColor = (1, 1, 1)
            token outputs:surface
        }}
    }}
    def Mesh "panel" (prepend apiSchemas = ["MaterialBindingAPI"]) {{
        point3f[] points = [(-0.3, -3, -4), (3, -3, -4), (3, 3, -4), (-0.3, 3, -4)]
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        rel material:binding = </glow>
    }}
"""


def test_ior_refracts_the_background(tmp_path):
    a = render_stage_text(tmp_path, IOR_SCENE.format(ior=1), seed=1)["beauty"]
    a2 = render_stage_text(tmp_path, IOR_SCENE.format(ior=1), seed=2)["beauty"]
    b = render_stage_text(tmp_path, IOR_SCENE.format(ior=1.5), seed=1)["beauty"]
    noise = np.abs(a - a2).mean()
    change = np.abs(a - b).mean()
    assert change > 4 * noise + 1e-3, (change, noise)


def test_white_furnace_through_the_whole_pipeline(tmp_path):
    """furnace.usda: an albedo-1 medium in a dome of radiance 1 renders 1 everywhere.

    Three seeds.  sigma = the per-pixel noise, pooled over the medium's pixels from the spread of
    each pixel around its mean over the seeds.  Every pixel's mean over the seeds must be within k =
    5.5 sigma / sqrt(3) of 1, and the mean over all of them within 4 sigma / sqrt(n) of 1.  Per-seed
    pixels are not Gaussian at 16 samples: a path grazing the sphere's surface collects a next-event
    estimate at many vertices, so one sample can be ~9.  Over 8 seed triples (seeds 1-12 at 856aa00
    and at fb4f565) the worst per-seed pixel reached 4.4-6.3 sigma (the check on them, k = 5.5, failed
    one triple in four), the worst 3-seed mean 3.1-4.7 sigma / sqrt(3): the check on means is both
    robust to single spikes and tighter in radiance (0.28 against 0.48)."""
    shutil.copy(os.path.join(TESTENV, "furnace.usda"), tmp_path / "furnace.usda")
    images = []
    for seed in (1, 2, 3):
        out = tmp_path / ("f%d.exr" % seed)
        r = run_cli("render", tmp_path / "furnace.usda", "-o", out, "--seed", seed, "--quiet", "--no-png")
        assert r.returncode == 0, r.stderr
        ch, _ = output.read_exr(str(out))
        images.append(np.stack([ch["R"], ch["G"], ch["B"]], axis=-1))
        assert ch["R"].shape == (32, 32)
    stack = np.stack(images)  # (seeds, H, W, 3)
    # Pixels whose whole footprint misses the sphere (radius 1, camera 5 units away, tan(half fov)
    # 0.24) see the dome directly and must be exactly 1; all others are tested statistically.
    t = (np.arange(32) + 0.5) / 32 * 2 - 1
    sx, sy = np.meshgrid(t * 0.24, -t * 0.24)
    miss_distance = 5 * np.hypot(sx, sy) / np.sqrt(1 + sx ** 2 + sy ** 2)  # closest approach to the centre
    outside = miss_distance > 1.08  # one pixel footprint of margin
    inside = ~outside
    assert inside.sum() > 200 and outside.sum() > 50
    np.testing.assert_allclose(stack[:, outside], 1.0, atol=1e-6)  # the dome seen directly
    assert np.all(ch["A"][miss_distance < 0.95] > 0)
    vals = stack[:, inside]  # (seeds, n, 3)
    dev = vals - vals.mean(axis=0, keepdims=True)
    sigma = math.sqrt((dev ** 2).sum() / (dev.size * (len(images) - 1) / len(images)))
    k = 5.5
    worst = np.abs(vals.mean(axis=0) - 1).max()
    print("white furnace: sigma = %.4f per pixel, k = %.1f, worst |3-seed pixel mean - 1| = %.4f (%.2f sigma / sqrt 3), "
          "mean = %.5f" % (sigma, k, worst, worst / (sigma / math.sqrt(len(images))), vals.mean()))
    assert 0 < sigma < 0.25
    assert worst <= k * sigma / math.sqrt(len(images))
    assert abs(vals.mean() - 1) <= 4 * sigma / math.sqrt(vals.size)


README_RENDER = ["render", "testenv/vdb_cloud.usda", "-o", "out/vdb_cloud.exr", "--resolution", "640", "360",
                 "--noise-target", "0.03", "--time-limit", "40"]


def test_readme_command_writes_exr_and_png_with_all_layers(tmp_path, cloud_vdb):
    """The README's first command, as written there (checked: the README holds these arguments), from
    a checkout's root: a 640x360 cloud, a median estimated per-pixel error at or below 3%, every
    layer, the summary naming the image and its layers."""
    readme = open(os.path.join(REPO, "README.md")).read()
    assert ".venv/bin/volphoton " + " ".join(README_RENDER) in readme
    work = tmp_path / "checkout"
    (work / "testenv").mkdir(parents=True)
    shutil.copy(os.path.join(TESTENV, "vdb_cloud.usda"), work / "testenv" / "vdb_cloud.usda")
    shutil.copy(cloud_vdb, work / "testenv" / "cloud.vdb")
    r = run_cli(*README_RENDER, "--stats", "stats.json", cwd=work)
    assert r.returncode == 0, r.stderr
    assert "ETA" in r.stderr  # the progress bar (stderr is not a terminal: one line per update)
    assert "out/vdb_cloud.exr" in r.stderr and "EXR layers:" in r.stderr, r.stderr
    ch, attrs = output.read_exr(str(work / "out" / "vdb_cloud.exr"))
    expected = ({"R", "G", "B", "A", "depth.Z", "error.Y", "samples.Y"} |
                {"%s.%s" % (l, c) for l in output.LAYERS for c in "RGB"})
    assert set(ch) == expected
    assert ch["R"].shape == (360, 640)
    assert attrs["software"].startswith("volphoton") and '"noiseTarget": 0.03' in attrs["volphoton:settings"]
    frame = json.load(open(work / "stats.json"))["frames"][0]
    assert frame["timings"]["render_seconds"] < 40 + max(p["seconds"] for p in frame["passes"]) + 1
    assert 0 <= frame["render"]["median_relative_error"] <= 0.03
    assert float(np.median(ch["error.Y"])) <= 0.03
    for c in "RGB":
        total = sum(ch["%s.%s" % (l, c)] for l in output.LAYERS)
        np.testing.assert_allclose(ch[c], total, rtol=1e-5, atol=1e-6)
        assert np.all(np.isfinite(ch[c]))
    assert ch["single.R"].mean() > 0 and ch["multiple.R"].mean() > 0  # the cloud scatters once and more
    from PIL import Image

    png = Image.open(work / "out" / "vdb_cloud.png")
    assert png.size == (640, 360) and png.mode == "RGB"
    assert np.asarray(png).max() > 40  # not black


@pytest.mark.parametrize("name", ["fog_spotlight.usda", "vdb_cloud.usda", "atmosphere_sunset.usda",
                                  "emissive_smoke.usda", "marble.usda", "furnace.usda"])
def test_example_scenes_render(scene_copy, tmp_path, name):
    path = scene_copy(name)
    out = tmp_path / (name + ".exr")
    stats = tmp_path / (name + ".json")
    r = run_cli("render", path, "-o", out, "--resolution", "40", "24", "--spp", "2", "--quiet", "--stats", stats)
    assert r.returncode == 0, r.stderr
    assert "warning" not in r.stderr and "error" not in r.stderr, r.stderr
    ch, _ = output.read_exr(str(out))
    beauty = np.stack([ch["R"], ch["G"], ch["B"]], -1)
    assert np.all(np.isfinite(beauty)) and beauty.mean() > 1e-3
    if name == "emissive_smoke.usda":
        # blackbody below 2000 K: red-orange (blue is clamped to 0 at these temperatures)
        assert ch["emission.R"].mean() > ch["emission.G"].mean() >= ch["emission.B"].mean() >= 0
        assert ch["emission.R"].mean() > 0.01
    if name == "atmosphere_sunset.usda":
        sky = beauty[:6].reshape(-1, 3).mean(axis=0)
        assert sky[2] > sky[0], sky  # Rayleigh: the upper sky is blue
    if name == "vdb_cloud.usda":
        assert ch["multiple.R"].mean() > 0
    assert (tmp_path / (name + ".png")).exists()


def test_photon_map_integrator_option_runs(tmp_path):
    shutil.copy(os.path.join(TESTENV, "fog_spotlight.usda"), tmp_path / "f.usda")
    r = run_cli("render", tmp_path / "f.usda", "-o", tmp_path / "pm.exr", "--integrator", "photonmap",
                "--photons", "2000", "--resolution", "32", "18", "--spp", "2", "--quiet")
    assert r.returncode == 0, r.stderr
    ch, attrs = output.read_exr(str(tmp_path / "pm.exr"))
    assert '"integrator": "photonMap"' in attrs["volphoton:settings"]
    assert np.all(np.isfinite(ch["R"])) and ch["R"].mean() > 0
