"""Adaptive sampling, the noise target and the time limit through the standalone front end (issue 17,
item 1): the CLI flags and RenderSettings attributes reach the core's stopping rule
(core/integrator.h, Renderer::finished), the EXR gets the error and sample-count layers, and
adaptivity moves no converged mean.

Tolerances: image means of independent seeds are the samples; adaptive and uniform renders must
agree within K = 4 standard errors of their difference (one comparison per case).
"""

import json
import math
import os

import numpy as np
import pytest

import slab_scene
from conftest import run_cli
from volphoton import _core, output

HERE = os.path.dirname(os.path.abspath(__file__))
K = 4.0


def volphoton(*args):
    return run_cli(*args)


def slab_stage(tmp_path, name, **settings):
    stage = tmp_path / (name + ".usda")
    stage.write_text(slab_scene.stage_text(
        slab_scene.camera("above") + slab_scene.SLAB + slab_scene.ground(10) + slab_scene.DOME,
        settings=dict(dict(size=16, spp=8, seed=1, integrator="pathTracer"), **settings)))
    return stage


def test_noise_target_from_the_command_line_writes_error_and_sample_layers(tmp_path):
    stage = slab_stage(tmp_path, "slab")
    out, stats = tmp_path / "slab.exr", tmp_path / "slab.json"
    r = volphoton("render", stage, "-o", out, "--camera", "/World/cam", "--resolution", 24, 16,
                  "--noise-target", 0.05, "--spp", 4, "--stats", stats)
    assert r.returncode == 0, r.stderr
    assert "noise target met" in r.stderr and "median estimated error" in r.stderr, r.stderr
    assert "error.Y (estimated relative error)" in r.stderr
    frame = json.loads(stats.read_text())["frames"][0]
    assert frame["render"]["stop_reason"] == "noiseTarget"
    assert frame["settings"]["noiseTarget"] == 0.05
    assert 0 <= frame["render"]["median_relative_error"] <= 0.05
    ch, _ = output.read_exr(str(out))
    error, samples = ch["error.Y"], ch["samples.Y"]
    assert np.isfinite(error).all() and (error <= 0.05 + 1e-6).all()
    assert samples.min() >= 4 and samples.max() > samples.min()  # adaptive: pixels stop at different counts
    assert frame["render"]["camera_samples"] == int(samples.sum())


def test_time_limit_from_the_command_line(tmp_path):
    out, stats = tmp_path / "cloud.exr", tmp_path / "cloud.json"
    r = volphoton("render", os.path.join(HERE, "fog_spotlight.usda"), "-o", out, "--resolution", 96, 54,
                  "--time-limit", 1.0, "--no-png", "--stats", stats)
    assert r.returncode == 0, r.stderr
    frame = json.loads(stats.read_text())["frames"][0]
    assert frame["render"]["stop_reason"] == "timeLimit"
    passes = [p["seconds"] for p in frame["passes"]]
    assert len(passes) > 1
    # Within one pass of the limit (the progress callback's pass times include its own overhead).
    assert sum(passes) <= 1.0 + max(passes) + 0.05, passes


def test_render_settings_prim_attributes_and_their_validation(tmp_path):
    stage = slab_stage(tmp_path, "slab", noiseTarget=0.2, maxSamplesPerPixel=64)
    out, stats = tmp_path / "slab.exr", tmp_path / "slab.json"
    r = volphoton("render", stage, "-o", out, "--no-png", "--stats", stats, "--camera", "/World/cam")
    assert r.returncode == 0, r.stderr
    frame = json.loads(stats.read_text())["frames"][0]
    assert frame["settings"]["noiseTarget"] == 0.2 and frame["settings"]["maxSamplesPerPixel"] == 64
    assert frame["render"]["stop_reason"] in ("noiseTarget", "maxSamplesPerPixel")
    bad = slab_stage(tmp_path, "bad", noiseTarget=-0.5)
    r = volphoton("render", bad, "-o", tmp_path / "bad.exr", "--no-png", "--camera", "/World/cam")
    assert "volphoton:noiseTarget" in r.stderr and "clamped to 0" in r.stderr, r.stderr
    r = volphoton("render", stage, "-o", tmp_path / "x.exr", "--no-png", "--time-limit", "nan")
    assert r.returncode != 0 and "--time-limit: unusable value nan" in r.stderr, r.stderr


def _image_means(path, integrator, seeds, configure):
    stage = slab_scene.Usd.Stage.Open(str(path))
    sc = slab_scene.usdscene.translate(stage, slab_scene.Usd.TimeCode.Default(), 16, 16, "/World/cam")
    assert not sc.errors
    scene = _core.Scene(sc.desc)
    means = []
    for seed in seeds:
        s = _core.RenderSettings()
        s.width = s.height = 16
        s.seed = seed
        if integrator == "photonMap":
            s.integrator = _core.RenderSettings.Integrator.PhotonMap
        configure(s)
        r = _core.Renderer(scene, s)
        stats = r.render()
        img = r.film.beauty.astype(np.float64)
        assert np.isfinite(img).all()
        means.append(img.mean())
    return np.array(means), stats


@pytest.mark.parametrize("integrator", ("pathTracer", "photonMap"))
def test_adaptive_sampling_moves_no_mean_on_the_slab(tmp_path, integrator):
    """The slab seen from above at default settings but the noise target (0.05, after the default
    16 passes) against 64 uniform passes: image means over 8 seeds agree within K sigma."""
    stage = slab_stage(tmp_path, "slab")

    def adaptive(s):
        s.noise_target = 0.05

    def uniform(s):
        s.samples_per_pixel = 64

    a, astats = _image_means(stage, integrator, range(8), adaptive)
    u, _ = _image_means(stage, integrator, range(100, 108), uniform)
    assert astats["stop_reason"] == "noiseTarget"
    se = math.sqrt(a.var(ddof=1) / len(a) + u.var(ddof=1) / len(u))
    print("%s adaptive %.5f uniform %.5f se %.5f" % (integrator, a.mean(), u.mean(), se))
    assert abs(a.mean() - u.mean()) <= K * se, (a, u)


def test_furnace_stays_one_with_a_noise_target(tmp_path):
    out = tmp_path / "furnace.exr"
    r = volphoton("render", os.path.join(HERE, "furnace.usda"), "-o", out, "--no-png", "--noise-target", 0.01)
    assert r.returncode == 0, r.stderr
    ch, _ = output.read_exr(str(out))
    img = np.stack([ch[c] for c in "RGB"], axis=-1)
    # An albedo-1 medium in a uniform dome: every pixel is 1 in expectation. Each pixel ends with an
    # estimated relative error <= 1% (its sigma); every pixel within K_PIXEL = 5.5 of its sigma (1024
    # pixels: a false-failure rate near 4e-5), and the image mean -- where a bias of the stopping rule
    # would show -- within K sigma of the mean of 1024 independent pixels.
    error = ch["error.Y"]
    assert (error <= 0.01 + 1e-7).all()
    sigma = np.maximum(error, 1e-7)[..., None]
    assert (np.abs(img - 1) <= 5.5 * sigma).all()
    assert abs(img.mean() - 1) <= K * math.sqrt((error ** 2).mean() / error.size)
