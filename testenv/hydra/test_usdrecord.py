"""usdrecord --renderer VolPhoton against the standalone front end, scene by scene.

Both front ends render the same wrapper stage (the example scene as a sublayer, with the
RenderSettings prim overridden to a small resolution, a few samples and a seed), SEEDS seeds each.
Tolerance: the images are averaged over 8x8-pixel blocks; per block z = (mean_hydra - mean_cli) /
sqrt(var_hydra / n + var_cli / n), variances from the spread over the n seeds.  If both front ends
translate the scene alike, z is roughly Student-t with 2n - 2 degrees of freedom: we require the
mean of z^2 over the blocks below 3 (its expectation is about 1.5 for n = 4) and every |z| below 10
(a systematic difference -- a missing light, a wrong unit, a flipped image -- gives z in the tens
or hundreds on most blocks).  Blocks where both front ends agree to 1e-6 count as z = 0; sigma includes 1e-4 of the block's value
(float rounding between the front ends' conversions, visible only where there is no noise).
"""

import os
import subprocess
import sys

import numpy as np
import pytest

from hydra_util import TESTENV, run_usdrecord, volphoton_exe

from pxr import Sdf, Usd, UsdGeom  # noqa: E402
from volphoton import output  # noqa: E402

# Eight seeds: with four, the per-block z of the speckled fog scenes at 4 spp follows a t-distribution
# with few degrees of freedom (fog_spotlight: mean z^2 3.02 at seeds 1-4 although the image means
# agree within 0.5 sigma over 12 seeds: CLI 0.0915 +- 0.0040, usdrecord 0.0892 +- 0.0021).
SEEDS = [1, 2, 3, 4, 5, 6, 7, 8]
SIZE = (64, 36)
SPP = 4
SCENES = sorted(f for f in os.listdir(TESTENV) if f.endswith(".usda"))


def image_size(scene):
    """usdrecord's image: SIZE[0] wide, the height from the camera's aperture aspect ratio (it does not
    read the settings prim's resolution); the standalone render gets the same size."""
    stage = Usd.Stage.Open(os.path.join(TESTENV, scene))
    src = Sdf.Layer.FindOrOpen(os.path.join(TESTENV, scene))
    settings = stage.GetPrimAtPath(src.pseudoRoot.GetInfo("renderSettingsPrimPath"))
    camera = UsdGeom.Camera(stage.GetPrimAtPath(settings.GetRelationship("camera").GetTargets()[0]))
    h, v = camera.GetHorizontalApertureAttr().Get(), camera.GetVerticalApertureAttr().Get()
    return SIZE[0], max(1, int(SIZE[0] / (h / v)))  # usdrecord: int(width / aspect)


def wrapper(tmp_path, scene, seed, spp=SPP, size=SIZE):
    """A stage whose root layer sublayers the scene and overrides its RenderSettings prim."""
    src = Sdf.Layer.FindOrOpen(os.path.join(TESTENV, scene))
    root = src.pseudoRoot
    settings = src.GetPrimAtPath(root.GetInfo("renderSettingsPrimPath") if root.HasInfo("renderSettingsPrimPath")
                                 else "/Render/settings")
    assert settings, "%s has no RenderSettings prim" % scene
    path = tmp_path / ("%s.seed%d.usda" % (scene[:-5], seed))
    meta = {k: root.GetInfo(k) for k in ("defaultPrim", "metersPerUnit", "upAxis", "renderSettingsPrimPath")
            if root.HasInfo(k)}
    meta.setdefault("renderSettingsPrimPath", str(settings.path))
    header = "\n".join("    %s = %s" % (k, ('"%s"' % v) if isinstance(v, str) else repr(v)) for k, v in meta.items())
    parts = str(settings.path).strip("/").split("/")
    body = ""
    for depth, name in enumerate(parts):
        body += "    " * depth + 'over "%s"\n' % name + "    " * depth + "{\n"
    d = "    " * len(parts)
    body += (d + "int2 resolution = (%d, %d)\n" % size + d + "int volphoton:samplesPerPixel = %d\n" % spp
             + d + "int volphoton:seed = %d\n" % seed)
    for depth in reversed(range(len(parts))):
        body += "    " * depth + "}\n"
    path.write_text('#usda 1.0\n(\n%s\n    subLayers = [@%s@]\n)\n\n%s' % (header, os.path.join(TESTENV, scene), body))
    camera = settings.relationships.get("camera")
    targets = list(camera.targetPathList.explicitItems) if camera else []
    assert targets, "%s: the RenderSettings prim names no camera" % scene
    return str(path), str(settings.path), str(targets[0])


def rgb(exr):
    channels, _ = output.read_exr(exr)
    return np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)


def render_cli(stage, out):
    r = subprocess.run([volphoton_exe(), "render", stage, "-o", out, "--no-png", "-q"], capture_output=True,
                       text=True, timeout=600)
    assert r.returncode in (0, 1), r.stderr
    return rgb(out)


def render_hydra(hydra_env, stage, settings_path, camera, out, scene_index=False):
    # usdrecord takes the image width from --imageWidth (the settings prim has no render products)
    # and the height from the camera's aspect ratio.
    r = run_usdrecord(hydra_env, ["--renderSettingsPrimPath", settings_path, "--enableDomeLightVisibility",
                                  "--camera", camera, "--imageWidth", SIZE[0], stage, out], scene_index=scene_index)
    assert r.returncode == 0 and os.path.exists(out), r.stdout + r.stderr
    return rgb(out)


def block_z(a, b, block=8):
    """z per block of the per-seed means (arrays: seeds x H x W x 3)."""
    n, h, w, _ = a.shape
    hb, wb = h // block, w // block

    def blocks(x):
        return x[:, :hb * block, :wb * block].reshape(n, hb, block, wb, block, 3).mean(axis=(2, 4))
    ba, bb = blocks(a), blocks(b)
    diff = ba.mean(0) - bb.mean(0)
    # Plus 1e-4 of the block's value: pixels without noise (a dome seen directly, a surface lit by a
    # delta light) differ by float rounding only (the two front ends convert transforms and points
    # at different precisions), which is not a translation error.
    scale = np.maximum(np.abs(ba.mean(0)), np.abs(bb.mean(0)))
    sigma = np.sqrt(ba.var(0, ddof=1) / n + bb.var(0, ddof=1) / n + (1e-4 * scale) ** 2)
    z = np.where(np.abs(diff) < 1e-6, 0.0, diff / np.maximum(sigma, 1e-12))
    return z


@pytest.mark.parametrize("scene", SCENES)
def test_usdrecord_matches_the_standalone_front_end(tmp_path, hydra_env, scene):
    cli, hyd = [], []
    for seed in SEEDS:
        stage, settings_path, camera = wrapper(tmp_path, scene, seed, size=image_size(scene))
        cli.append(render_cli(stage, str(tmp_path / ("cli%d.exr" % seed))))
        hyd.append(render_hydra(hydra_env, stage, settings_path, camera, str(tmp_path / ("hydra%d.exr" % seed))))
    cli, hyd = np.array(cli), np.array(hyd)
    assert cli.shape == hyd.shape, (cli.shape, hyd.shape)
    assert np.isfinite(hyd).all()
    z = block_z(hyd, cli)
    assert (z ** 2).mean() < 3 and np.abs(z).max() < 10, (scene, (z ** 2).mean(), np.abs(z).max(),
                                                          hyd.mean(axis=(0, 1, 2)), cli.mean(axis=(0, 1, 2)))


# XXX: OpenUSD 24.08's scene-index path emits nothing for UsdGeomPlane prims (UsdImagingPlaneAdapter
# has no data-source support: "Datasource support not yet added"), so scenes with a Plane render
# without it there. Every other scene arrives the same on both paths.
SCENE_INDEX_SCENES = [s for s in SCENES if "def Plane " not in open(os.path.join(TESTENV, s)).read()]


@pytest.mark.parametrize("scene", SCENE_INDEX_SCENES)
def test_scene_index_path_renders_like_the_default_path(tmp_path, hydra_env, scene):
    """USDIMAGINGGL_ENGINE_ENABLE_SCENE_INDEX=1: the same prims reach the delegate, so with the same
    seed the image is bit-identical to the default (legacy scene delegate) path."""
    stage, settings_path, camera = wrapper(tmp_path, scene, SEEDS[0])
    default = render_hydra(hydra_env, stage, settings_path, camera, str(tmp_path / "default.exr"))
    indexed = render_hydra(hydra_env, stage, settings_path, camera, str(tmp_path / "index.exr"), scene_index=True)
    assert default.shape == indexed.shape
    assert np.array_equal(default, indexed), "max difference %g" % np.abs(default - indexed).max()
