"""Parity of the two doors into the renderer (issue 18): usdrecord through the Hydra delegate
(hdVolPhoton/hd/) and the usd-core front end `volphoton render` (hdVolPhoton/python/volphoton/)
must translate the same USD into the same picture.

Each test renders one small stage (written into the test's tmp dir) through both doors with the
same settings and SEEDS seeds each, and compares the images.  The delegate is expected to render
what the front end renders; the comments of each test say what it measured on the code of
2026-12-02 (before the shared translation layer), with the command
    . .venv/bin/activate && PATH=/opt/openusd/bin:$PATH python -m pytest testenv/hydra/test_parity.py -q

Statistics (pixel_z): the path tracer's pixels are independent (every random stream hashes pixel,
pass and seed), so the variance of a block's mean over n seeds and P pixels is estimated from the
per-pixel variance over the seeds, var = sum_p s_p^2 / (n P^2), with P (n - 1) = 192 degrees of
freedom for the 8x8-pixel blocks and 4 seeds used throughout.  z = (mean_a - mean_b) / sqrt(var_a +
var_b + (1e-4 mean)^2) per block and channel; the 1e-4 term is float rounding between the two front
ends' conversions, visible only where there is no noise (a dome seen directly).  If both doors
translate alike, z is close to N(0, 1): we require |z| < Z_AGREE = 6 on every block (P(|t_192| > 6)
is about 1e-8 per block and channel), and a change "beyond noise" is |z| > Z_DIFFER = 8 on some
block.  Smaller blocks (4x4) were tried and dropped: a rare bright path in one seed made the
16-pixel variance estimate unreliable (|z| up to 40 between two sets of seeds of the same door).
Checked: with the delegate replaced by the CLI at other seeds (a copy of render_hydra calling
render_cli with --seed), every image test of this file passes, block |z| at most about 3.  A
translation difference gives z in the tens or hundreds.
"""

import math
import os
import re
import subprocess
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from hydra_util import REPO, run_usdrecord, volphoton_exe

from pxr import Sdf, UsdLux  # noqa: E402
from volphoton import _core, output  # noqa: E402

SEEDS = [1, 2, 3, 4]
SPP = 4
W, H = 48, 32  # the camera aperture below is 3:2, so usdrecord's int(W / aspect) is exactly H
BLOCK = 8
Z_AGREE = 6.0
Z_DIFFER = 8.0

# --------------------------------------------------------------------------------------------------
# Stages and the two doors
# --------------------------------------------------------------------------------------------------

STAGE = '''#usda 1.0
(
    defaultPrim = "World"
    metersPerUnit = 1
    upAxis = "%(up)s"
    renderSettingsPrimPath = "/Render/settings"
)

def Scope "Render"
{
    def RenderSettings "settings"
    {
        int2 resolution = (%(w)d, %(h)d)
        rel camera = </World/camera>
%(settings)s
    }
}

def Xform "World"
{
%(camera)s
%(body)s
}
'''

# Perspective, at z = 6 looking down -Z, 3:2 (half field of view 13.5 degrees: x in +-1.44, y in
# +-0.96 at z = 0).
CAMERA = '''    def Camera "camera"
    {
        float focalLength = 50
        float horizontalAperture = 24
        float verticalAperture = 16
        double3 xformOp:translate = (0, 0, 6)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }'''

# A distant light behind the medium, 30 degrees off the view axis (its disk stays out of the
# 13.5-degree field of view): the camera sees light scattered forward, 30 degrees from the light's
# direction, where forward and backward phase functions differ most.  normalize: intensity is the
# irradiance.
BACKLIGHT = '''    def DistantLight "backlight"
    {
        float inputs:intensity = 3
        float inputs:angle = 1
        bool inputs:normalize = 1
        float3 xformOp:rotateXYZ = (0, 150, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }'''


def stage_text(body, seed, up="Y", spp=SPP, size=(W, H), settings=(), camera=CAMERA):
    """A stage: the RenderSettings prim authors samplesPerPixel, seed and the lines of settings (a
    line authoring samplesPerPixel or seed replaces the default one)."""
    lines = list(settings)
    for name, value in (("seed", seed), ("samplesPerPixel", spp)):
        if not any(re.search(r"\bvolphoton:%s\b" % name, l) for l in lines):
            lines.insert(0, "int volphoton:%s = %d" % (name, value))
    return STAGE % {"up": up, "w": size[0], "h": size[1], "camera": camera, "body": body,
                    "settings": "\n".join("        " + l for l in lines)}


def rgb(exr):
    channels, _ = output.read_exr(exr)
    return np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)


def render_cli(stage, out, args=()):
    """`volphoton render`; returns its log (stdout + stderr)."""
    r = subprocess.run([volphoton_exe(), "render", stage, "-o", out, "--no-png", "-q"] + list(args),
                       capture_output=True, text=True, timeout=600)
    assert r.returncode in (0, 1), r.stdout + r.stderr  # 1: rendered, with errors in the diagnostics
    return r.stdout + r.stderr


def render_hydra(hydra_env, stage, out, width, args=(), scene_index=False):
    """usdrecord --renderer VolPhoton (the width from --imageWidth, the height from the camera's aspect);
    scene_index: OpenUSD's scene-index path instead of the default (legacy scene delegate) one."""
    r = run_usdrecord(hydra_env, ["--renderSettingsPrimPath", "/Render/settings", "--enableDomeLightVisibility",
                                  "--camera", "/World/camera", "--imageWidth", width] + list(args) + [stage, out],
                      scene_index=scene_index)
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout + r.stderr


def run_parallel(jobs):
    """Runs the callables two at a time (the renders are small: process start-up dominates)."""
    with ThreadPoolExecutor(max_workers=2) as pool:
        return [f.result() for f in [pool.submit(j) for j in jobs]]


def render_both(hydra_env, tmp_path, name, text_of_seed, seeds=SEEDS, width=W, frames=None, scene_index=False):
    """Writes one stage per seed and renders each through both doors.  Returns (hydra, cli) arrays
    seeds x H x W x 3 and the two doors' logs of the first seed.  With frames ("1:2"), each door
    renders the frames in one process and the arrays are of the last frame."""
    jobs, outs = [], []
    for seed in seeds:
        stage = tmp_path / ("%s.seed%d.usda" % (name, seed))
        stage.write_text(text_of_seed(seed))
        if frames:
            hyd = str(tmp_path / ("%s.seed%d.hydra.#.exr" % (name, seed)))
            cli = str(tmp_path / ("%s.seed%d.cli.####.exr" % (name, seed)))
            last = int(frames.split(":")[-1])
            outs.append((hyd.replace("#", str(last)), cli.replace("####", "%04d" % last)))
            jobs.append(lambda s=str(stage), o=hyd: render_hydra(hydra_env, s, o, width, ["--frames", frames], scene_index))
            jobs.append(lambda s=str(stage), o=cli: render_cli(s, o, ["--frames", frames]))
        else:
            hyd = str(tmp_path / ("%s.seed%d.hydra.exr" % (name, seed)))
            cli = str(tmp_path / ("%s.seed%d.cli.exr" % (name, seed)))
            outs.append((hyd, cli))
            jobs.append(lambda s=str(stage), o=hyd: render_hydra(hydra_env, s, o, width, (), scene_index))
            jobs.append(lambda s=str(stage), o=cli: render_cli(s, o))
    logs = run_parallel(jobs)
    for hyd, cli in outs:
        assert os.path.exists(hyd), (hyd, logs[0])
        assert os.path.exists(cli), (cli, logs[1])
    hydra = np.array([rgb(h) for h, _ in outs])
    cli = np.array([rgb(c) for _, c in outs])
    assert hydra.shape == cli.shape, (hydra.shape, cli.shape)
    assert np.isfinite(hydra).all() and np.isfinite(cli).all()
    return hydra, cli, logs[0], logs[1]


# --------------------------------------------------------------------------------------------------
# Statistics
# --------------------------------------------------------------------------------------------------


def region_stats(images, rows, cols):
    """Mean over seeds and pixels of a region and the estimated variance of that mean, per channel."""
    x = images[:, rows, cols]  # seeds x h x w x 3
    n = x.shape[0]
    p = x.shape[1] * x.shape[2]
    mean = x.mean(axis=(0, 1, 2))
    var = x.var(axis=0, ddof=1).sum(axis=(0, 1)) / (n * p * p)
    return mean, var


def pixel_z(a, b, rows=slice(None), cols=slice(None)):
    """z of the difference of the region means of a and b (seeds x H x W x 3), per channel."""
    ma, va = region_stats(a, rows, cols)
    mb, vb = region_stats(b, rows, cols)
    diff = ma - mb
    scale = np.maximum(np.abs(ma), np.abs(mb))
    sigma = np.sqrt(va + vb + (1e-4 * scale) ** 2)
    return np.where(np.abs(diff) < 1e-7, 0.0, diff / np.maximum(sigma, 1e-12))


def block_z(a, b, block=BLOCK, rows=slice(None), cols=slice(None)):
    """pixel_z per block x block tile of the region (blocks x 3)."""
    h, w = a[:, rows, cols].shape[1:3]
    r0, c0 = rows.start or 0, cols.start or 0
    zs = [pixel_z(a, b, slice(r0 + i, r0 + i + block), slice(c0 + j, c0 + j + block))
          for i in range(0, h - block + 1, block) for j in range(0, w - block + 1, block)]
    return np.array(zs)


def summary(hydra, cli, rows=slice(None), cols=slice(None), block=BLOCK):
    """Means (RGB) of both doors over the region, their ratio and the block z: for failure messages."""
    mh, _ = region_stats(hydra, rows, cols)
    mc, _ = region_stats(cli, rows, cols)
    z = block_z(hydra, cli, block=block, rows=rows, cols=cols)
    ratio = np.where(mc > 0, mh / np.where(mc > 0, mc, 1), np.inf)
    return ("delegate mean %s, CLI mean %s, delegate/CLI %s; %dx%d-block |z| max %.1f (tolerance %g), mean z^2 %.2f"
            % (np.round(mh, 4), np.round(mc, 4), np.round(ratio, 3), block, block, np.abs(z).max(), Z_AGREE,
               (z ** 2).mean()))


def check(condition, message):
    """Fails with the message alone (the numbers), not with numpy's reprs of the images."""
    if not condition:
        pytest.fail(message, pytrace=False)


def assert_doors_agree(hydra, cli, what, rows=slice(None), cols=slice(None)):
    z = block_z(hydra, cli, rows=rows, cols=cols)
    check(np.abs(z).max() < Z_AGREE, "%s: the delegate differs from the CLI: %s" % (what, summary(hydra, cli, rows, cols)))


def warning_lines(log, *words):
    """Lines of a log that contain every one of words (case-insensitive)."""
    return [l for l in log.splitlines() if all(w.lower() in l.lower() for w in words)]


# --------------------------------------------------------------------------------------------------
# 1. Phase-function mixture
# --------------------------------------------------------------------------------------------------

MIXTURE = '''    def Cube "medium" (
        prepend apiSchemas = ["VolPhotonMediumAPI", "VolPhotonPhaseLobeAPI:forward", "VolPhotonPhaseLobeAPI:back"]
    )
    {
        double size = 1.6
        float volphoton:density = 1.5
        color3f volphoton:albedo = (0.95, 0.95, 0.95)
        uniform token volphoton:phase = "mixture"
        float volphoton:lobe:forward:weight = 0.8
        float volphoton:lobe:forward:g = 0.85
        float volphoton:lobe:back:weight = 0.2
        float volphoton:lobe:back:g = -0.5
    }
''' + BACKLIGHT


def test_phase_mixture_lobes_reach_both_doors(tmp_path, hydra_env):
    """volphoton:phase = "mixture" with two VolPhotonPhaseLobeAPI lobes (0.8 HG(0.85) + 0.2 HG(-0.5)),
    lit from behind: the forward lobe makes the medium bright.  Measured 2026-12-02: the delegate
    warns "mixtures are not read by the Hydra delegate yet" and renders HG(volphoton:phase:g = 0),
    delegate/CLI = 0.34 in every channel (8x8-block |z| up to 17.5)."""
    hydra, cli, hlog, _ = render_both(hydra_env, tmp_path, "mixture", lambda s: stage_text(MIXTURE, s))
    check(cli.mean() > 0.01, summary(hydra, cli))
    assert_doors_agree(hydra, cli, "phase mixture")


# --------------------------------------------------------------------------------------------------
# 2. Light colour temperature
# --------------------------------------------------------------------------------------------------

WARM_LIGHT = '''    def Cube "medium" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        double size = 1.6
        float volphoton:density = 1.5
        color3f volphoton:albedo = (1, 1, 1)
    }

    def SphereLight "light"
    {
        float inputs:intensity = 30
        float inputs:radius = 0.3
        bool inputs:enableColorTemperature = 1
        float inputs:colorTemperature = 2500
        double3 xformOp:translate = (2.5, 1.5, 1.5)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
'''


def test_light_color_temperature_reaches_both_doors(tmp_path, hydra_env):
    """A 2500 K sphere light (inputs:enableColorTemperature) on a white medium: orange light, R/B of
    the image well above 1 through both doors, and the same picture.  Expected colour:
    UsdLux.BlackbodyTemperatureAsRgb(2500).  Measured 2026-12-02: the delegate ignores the colour
    temperature (grey light): R/B 1.00 vs the CLI's 14.8 (the blackbody's R/B is 14.8),
    delegate/CLI = (0.48, 1.30, 7.2), block |z| up to 49."""
    hydra, cli, _, _ = render_both(hydra_env, tmp_path, "warm", lambda s: stage_text(WARM_LIGHT, s))
    expected = np.array(UsdLux.BlackbodyTemperatureAsRgb(2500.0))
    rb = {door: img[..., 0].mean() / max(img[..., 2].mean(), 1e-12) for door, img in (("delegate", hydra), ("CLI", cli))}
    # Single scattering in a white medium keeps the light's R/B; multiple scattering too (albedo 1).
    check(rb["CLI"] > 1.5 and rb["delegate"] > 1.5, "R/B of the images %s (needs > 1.5; blackbody 2500 K: %.2f); %s"
          % (rb, expected[0] / expected[2], summary(hydra, cli)))
    assert_doors_agree(hydra, cli, "colour temperature")


# --------------------------------------------------------------------------------------------------
# 3. Preset on a VDB volume
# --------------------------------------------------------------------------------------------------


def cloud_vdb(tmp_path):
    """A 16^3 procedural cloud (grid "density", values 0..1) filling the unit cube of its space."""
    path = str(tmp_path / "cloud.vdb")
    if not os.path.exists(path):
        _core.write_procedural_cloud_vdb(path, 16, 1.0 / 16, 1)
    return path


KETCHUP = '''    def Volume "ketchup" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        uniform token volphoton:preset = "ketchup"
        float volphoton:sceneUnitsPerMm = 0.25
        rel field:density = </World/ketchup/density>
        double3 xformOp:translate = (-1, -1, -1)
        float3 xformOp:scale = (2, 2, 2)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]

        def OpenVDBAsset "density"
        {
            asset filePath = @%(vdb)s@
            token fieldName = "density"
        }
    }

    def DomeLight "sky"
    {
        float inputs:intensity = 1
    }
'''


def test_preset_on_a_vdb_volume_reaches_both_doors(tmp_path, hydra_env):
    """volphoton:preset = "ketchup" (sceneUnitsPerMm 0.25) on a Volume with a VDB density field: the
    preset's coefficients (Jensen et al. 2001, red: sigma_t = (0.96, 4.2, 6.0) per unit times the
    grid) replace density, albedo and extinctionColor.  Measured 2026-12-02: the delegate's grid
    path ignores the preset (grey, density 1, albedo 0.8): delegate/CLI = (1.01, 1.26, 1.34) over the
    whole image (dome background included), block |z| up to 154."""
    body = KETCHUP % {"vdb": cloud_vdb(tmp_path)}
    hydra, cli, _, _ = render_both(hydra_env, tmp_path, "ketchup", lambda s: stage_text(body, s))
    assert_doors_agree(hydra, cli, "ketchup preset on a VDB volume")


SPLIT_FIELDS = '''    def Volume "smoke" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        float volphoton:density = 4
        color3f volphoton:albedo = (0.7, 0.7, 0.7)
        float volphoton:emissionScale = 5
        rel field:density = </World/smoke/density>
        rel field:emission = </World/smoke/glow>
        double3 xformOp:translate = (-1, -1, -1)
        float3 xformOp:scale = (2, 2, 2)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]

        def OpenVDBAsset "density"
        {
            asset filePath = @%(vdb)s@
            int fieldIndex = 1
        }

        def OpenVDBAsset "glow"
        {
            asset filePath = @%(other)s@
            token fieldName = "density"
        }
    }

    def DomeLight "sky"
    {
        float inputs:intensity = 1
    }
'''


def test_grid_fields_follow_one_set_of_rules_in_both_doors(tmp_path, hydra_env):
    """A Volume whose density asset has no fieldName (the grid is the slot's name, "density") and
    fieldIndex 1, and whose emission field is in another file: both doors take the first grid of the
    name with a warning naming the asset and fieldIndex (only there: the delegate sees 0 for an
    unauthored fieldIndex, which must not warn), ignore the emission field with an error
    naming the glow asset and filePath, and render the same non-emissive smoke
    (core/translate/volume.h).  Without the shared rules the delegate compared paths as strings and
    never warned about fieldIndex."""
    other = str(tmp_path / "other.vdb")
    _core.write_procedural_cloud_vdb(other, 16, 1.0 / 16, 2)
    body = SPLIT_FIELDS % {"vdb": cloud_vdb(tmp_path), "other": other}
    hydra, cli, hlog, clog = render_both(hydra_env, tmp_path, "split", lambda s: stage_text(body, s))
    for door, log in (("CLI", clog), ("delegate (usdrecord)", hlog)):
        check(warning_lines(log, "/World/smoke/density", "fieldIndex", "ignored"),
              "%s: no warning naming /World/smoke/density and fieldIndex:\n%s" % (door, log[-3000:]))
        check(not warning_lines(log, "/World/smoke/glow", "fieldIndex"),
              "%s: a fieldIndex warning for the glow asset, which has none:\n%s" % (door, log[-3000:]))
        check(warning_lines(log, "/World/smoke/glow", "filePath", "density's file"),
              "%s: no error naming /World/smoke/glow, filePath and the one-file rule:\n%s" % (door, log[-3000:]))
    # The smoke is there (it blocks part of the unit dome) and emits nothing (the emission field is
    # ignored, and emissionScale alone does not make a grid volume glow).
    check(0.05 < cli.mean() < 0.95, "the CLI's smoke is missing or glows: mean %.3f" % cli.mean())
    assert_doors_agree(hydra, cli, "grid fields from two files")


# A fog box under a downward-facing emissive panel (UsdPreviewSurface emissiveColor), the only light.
EMISSIVE_PANEL = '''    def Cube "medium" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        double size = 1.6
        float volphoton:density = 1.5
        color3f volphoton:albedo = (0.9, 0.9, 0.9)
    }

    def Material "glow"
    {
        token outputs:surface.connect = </World/glow/shader.outputs:surface>
        def Shader "shader"
        {
            uniform token info:id = "UsdPreviewSurface"
            color3f inputs:diffuseColor = (0, 0, 0)
            color3f inputs:emissiveColor = (2, 1.5, 1)
            token outputs:surface
        }
    }

    def Mesh "panel" (
        prepend apiSchemas = ["MaterialBindingAPI"]
    )
    {
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(-1, 1.5, -1), (1, 1.5, -1), (1, 1.5, 1), (-1, 1.5, 1)]
        rel material:binding = </World/glow>
    }
'''


@pytest.mark.parametrize("integrator", ["pathTracer", "photonMap"])
def test_emissive_geometry_lights_media_in_both_doors(tmp_path, hydra_env, integrator):
    """An emissive panel (the only light, out of view above the frame) lighting a fog box: both doors
    sample it as a light (core Scene::instanceLight, issue 14), in both integrators, and agree.  The
    fog must be lit (the panel is never seen directly: every pixel is scattered light)."""
    settings = ['token volphoton:integrator = "%s"' % integrator] + ([PHOTONS] if integrator == "photonMap" else [])
    hydra, cli, _, _ = render_both(hydra_env, tmp_path, "panel_" + integrator,
                                   lambda s: stage_text(EMISSIVE_PANEL, s, settings=settings))
    check(cli.mean() > 0.02, "the CLI's fog is not lit by the panel: mean %.4f" % cli.mean())
    assert_doors_agree(hydra, cli, "fog under an emissive panel (%s)" % integrator)


# A cube of dense medium lit by a small sphere light: translucent behind an n = 1.3 surface, or open.
AUTO_CUBE = '''    def Cube "marble" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        double size = 1.6
        float volphoton:density = %(density)s
        color3f volphoton:albedo = (0.99, 0.97, 0.95)
%(ior)s    }

    def SphereLight "lamp"
    {
        float inputs:intensity = 30
        float inputs:radius = 0.3
        double3 xformOp:translate = (1.5, 2, 1.5)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
'''


@pytest.mark.parametrize("translucent,density,size,chosen", [(True, 8, (W, H), "combined"), (False, 8, (W, H), "pathTracer"),
                                                             (False, 0.2, (W, H), "combined"),
                                                             (False, 8, (168, 112), "combined")])
def test_integrator_auto_renders_what_it_chooses_in_both_doors(tmp_path, hydra_env, translucent, density, size, chosen):
    """integrator = auto (core chooseIntegrator): the pilot sees a translucent cube filling the middle
    of the view (a dielectric with a medium inside) and picks the combined integrator, the same cube as an
    open medium and picks the path tracer at 48 x 32 pixels and combined with photon beams in open media
    at 168 x 112 (albedo 0.99 from 128 x 128 pixels: the image size reaches the pilot through both
    doors), or it as thin fog (optical depth 0.32 across) lit only by the sphere light and picks
    combined with photon beams in open media. In each door the auto image is bit-identical to the one
    rendered with the chosen integrator named (combined's automatic share asks the same pilot), so both
    doors make the same choice; that combined's photons in open media differ from none at all is the
    core's IntegratorCombined.TheDefaultShareFollowsAutosPilot."""
    body = AUTO_CUBE % {"ior": "        float volphoton:ior = 1.3\n" if translucent else "", "density": density}
    images = {}
    jobs, outs = [], []
    for integrator in ("auto", chosen):
        stage = tmp_path / ("%s.usda" % integrator)
        stage.write_text(stage_text(body, 1, size=size, settings=['token volphoton:integrator = "%s"' % integrator, PHOTONS]))
        for door in ("hydra", "cli"):
            out = str(tmp_path / ("%s.%s.exr" % (integrator, door)))
            outs.append(((integrator, door), out))
            if door == "hydra":
                jobs.append(lambda s=str(stage), o=out: render_hydra(hydra_env, s, o, size[0]))
            else:
                jobs.append(lambda s=str(stage), o=out: render_cli(s, o))
    logs = run_parallel(jobs)
    for (key, out), log in zip(outs, logs):
        assert os.path.exists(out), (key, log[-2000:])
        images[key] = rgb(out)
    for door in ("hydra", "cli"):
        check(np.array_equal(images["auto", door], images[chosen, door]),
              "%s: auto did not render as %s (max difference %.3g)"
              % (door, chosen, np.abs(images["auto", door] - images[chosen, door]).max()))
    lit = 0.01 if density > 1 else 0.002  # the thin fog scatters less of the lamp's light
    check(images["auto", "cli"].mean() > lit, "the cube is not lit: mean %.4f" % images["auto", "cli"].mean())


# The same panel as a UsdLux mesh light (no material: the light's colour is the emission).
MESH_LIGHT_PANEL = EMISSIVE_PANEL[:EMISSIVE_PANEL.index('    def Material "glow"')] + '''    def Mesh "panel" (
        prepend apiSchemas = ["MeshLightAPI"]
    )
    {
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(-1, 1.5, -1), (1, 1.5, -1), (1, 1.5, 1), (-1, 1.5, 1)]
        float inputs:intensity = 8
        color3f inputs:color = (1, 0.75, 0.5)
        bool inputs:normalize = 1
    }
'''


@pytest.mark.parametrize("scene_index", [False, True], ids=["legacy", "sceneIndex"])
def test_mesh_light_api_lights_media_in_both_doors(tmp_path, hydra_env, scene_index):
    """MeshLightAPI on the panel (intensity 8 normalized by its area 4, colour (1, 0.75, 0.5):
    radiance (2, 1.5, 1), as the emissive panel above): both doors make it an emitting surface and a
    light (core/translate/light.h, kind "mesh"), on the legacy scene delegate (read off the UsdPrim)
    and on the scene-index path (the LightAPI adapter's light data).  Without it the usd-core front
    end skipped the mesh as an unsupported light and the delegate rendered it as grey geometry."""
    hydra, cli, hlog, clog = render_both(hydra_env, tmp_path, "mesh_light", lambda s: stage_text(MESH_LIGHT_PANEL, s),
                                         scene_index=scene_index)
    check(cli.mean() > 0.02, "the CLI's fog is not lit by the mesh light: mean %.4f" % cli.mean())
    check(not warning_lines(clog, "/World/panel", "not supported"), clog[-2000:])
    assert_doors_agree(hydra, cli, "fog under a MeshLightAPI panel")


# --------------------------------------------------------------------------------------------------
# 4. Exponential haze on a Z-up stage
# --------------------------------------------------------------------------------------------------

# Z up: the camera at y = -6 looks along +Y (rotateX 90 turns its -Z into +Y and its +Y into +Z),
# so height (Z) runs up the image.
CAMERA_Y = '''    def Camera "camera"
    {
        float focalLength = 50
        float horizontalAperture = 24
        float verticalAperture = 16
        double3 xformOp:translate = (0, -6, 0)
        float3 xformOp:rotateXYZ = (90, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }'''

HAZE = '''    def Volume "haze" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        uniform token volphoton:densityMode = "exponential"
        float volphoton:density = 1
        float volphoton:exponential:a = 1
        float volphoton:exponential:b = 1.5
        color3f volphoton:albedo = (0.6, 0.6, 0.6)
        point3f volphoton:bounds:min = (-1.2, -1.2, -1.2)
        point3f volphoton:bounds:max = (1.2, 1.2, 1.2)
    }

    def DomeLight "sky"
    {
        float inputs:intensity = 1
    }
'''


def test_exponential_haze_follows_the_stage_up_axis_in_both_doors(tmp_path, hydra_env):
    """volphoton:densityMode = "exponential" with exponential:up unauthored on a Z-up stage: height is
    along +Z (the schema: "the stage's up axis"), so the haze thins towards the top of the image.
    Measured 2026-12-02: the delegate uses +Y (the view direction here), the image has no vertical
    gradient: delegate/CLI = 0.52, block |z| up to 66."""
    hydra, cli, _, _ = render_both(hydra_env, tmp_path, "haze",
                                   lambda s: stage_text(HAZE, s, up="Z", camera=CAMERA_Y))
    # The CLI's haze is denser at the bottom: more dome light is blocked there (dome 1 behind).
    top, bottom = cli[:, :H // 4].mean(), cli[:, -H // 4:].mean()
    check(top > bottom + 0.05, "the CLI's haze does not thin towards +Z: top %.3f, bottom %.3f" % (top, bottom))
    assert_doors_agree(hydra, cli, "exponential haze on a Z-up stage")


# --------------------------------------------------------------------------------------------------
# 5. A light with a negative colour channel
# --------------------------------------------------------------------------------------------------

NEGATIVE_LIGHT = '''    def Cube "medium" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        double size = 1.6
        float volphoton:density = 1.5
        color3f volphoton:albedo = (1, 1, 1)
    }

    def SphereLight "light"
    {
        float inputs:intensity = 30
        float inputs:radius = 0.3
        color3f inputs:color = (1, -0.5, 1)
        double3 xformOp:translate = (2.5, 1.5, 1.5)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
'''


def test_negative_light_color_is_clamped_with_a_warning_in_both_doors(tmp_path, hydra_env):
    """inputs:color = (1, -0.5, 1): the negative channel is clamped to 0 (a magenta light) with a
    warning naming the prim and inputs:color, in both doors.  Measured 2026-12-02: the delegate
    turns the light off (black image, delegate/CLI = 0) and its warning names inputs:intensity."""
    hydra, cli, hlog, clog = render_both(hydra_env, tmp_path, "negative", lambda s: stage_text(NEGATIVE_LIGHT, s))
    for door, log in (("CLI", clog), ("delegate (usdrecord)", hlog)):
        check(warning_lines(log, "/World/light", "inputs:color", "clamp"),
              "%s: no warning naming /World/light, inputs:color and the clamp:\n%s" % (door, log[-3000:]))
    check(cli[..., 0].mean() > 0.01 and cli[..., 1].max() == 0, summary(hydra, cli))  # magenta, green 0
    assert_doors_agree(hydra, cli, "negative light colour")


# --------------------------------------------------------------------------------------------------
# 7. The delegate's grid cache key
# --------------------------------------------------------------------------------------------------

# Three rows (schlick k, linear x, tabulated table), each a pair of Volumes on the same VDB file and
# grid with the same density and albedo: forward-scattering on the left, backward on the right.
TWIN_VOLUME = '''    def Volume "%(name)s" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        float volphoton:density = 10
        color3f volphoton:albedo = (0.95, 0.95, 0.95)
        uniform token volphoton:phase = "%(phase)s"
        %(param)s
        rel field:density = </World/%(name)s/density>
        double3 xformOp:translate = (%(x)g, %(y)g, -0.4)
        float3 xformOp:scale = (0.8, 0.8, 0.8)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]

        def OpenVDBAsset "density"
        {
            asset filePath = @%(vdb)s@
            token fieldName = "density"
        }
    }
'''

# The phase parameters the cache key leaves out (sceneRegistry.cpp keys on phase and g only):
# phase -> (forward, backward).
TWIN_PHASES = {
    "schlick": ("float volphoton:phase:k = 0.8", "float volphoton:phase:k = -0.8"),
    "linear": ("float volphoton:phase:x = 1", "float volphoton:phase:x = -1"),
    "tabulated": ("float[] volphoton:phase:table = [0.1, 0.3, 1, 4]", "float[] volphoton:phase:table = [4, 1, 0.3, 0.1]"),
}
TWIN_ROWS = sorted(TWIN_PHASES)
TWIN_SIZE = (48, 48)  # camera aperture 24 x 24: x and y in +-1.44 at z = 0; a row is 16 pixels, 0.96 units
TWIN_CAMERA = CAMERA.replace("float verticalAperture = 16", "float verticalAperture = 24")


def twins_body(vdb):
    body = ""
    for row, phase in enumerate(TWIN_ROWS):
        y = 0.96 - 0.96 * row - 0.4
        for side, x, param in (("forward", -1.2, TWIN_PHASES[phase][0]), ("backward", 0.4, TWIN_PHASES[phase][1])):
            body += TWIN_VOLUME % {"name": "%s_%s" % (phase, side), "phase": phase, "param": param, "x": x, "y": y,
                                   "vdb": vdb}
    return body + BACKLIGHT


@pytest.fixture(scope="module")
def twins(tmp_path_factory, hydra_env):
    tmp_path = tmp_path_factory.mktemp("twins")
    body = twins_body(cloud_vdb(tmp_path))
    hydra, cli, _, _ = render_both(hydra_env, tmp_path, "twins",
                                   lambda s: stage_text(body, s, size=TWIN_SIZE, camera=TWIN_CAMERA), width=TWIN_SIZE[0])
    return hydra, cli


@pytest.mark.parametrize("phase", TWIN_ROWS)
def test_twin_grid_volumes_differing_only_in_phase_parameters(twins, phase):
    """Two Volumes on the same VDB file and grid, same density and albedo, differing only in the
    phase parameter the delegate's grid cache key leaves out (k, x or table): forward-scattering on
    the left, backward on the right, lit from behind.  Each half of the row must match the CLI.
    Measured 2026-12-02: passes (the key holds the prim path, so two prims never share a medium;
    the stale-cache case is test_grid_volume_with_animated_phase_renders_each_frame)."""
    hydra, cli = twins
    row = TWIN_ROWS.index(phase)
    rows = slice(16 * row, 16 * row + 16)
    left, right = slice(0, 24), slice(24, 48)
    lc, rc = cli[:, rows, left].mean(), cli[:, rows, right].mean()
    check(lc > 1.5 * rc, "the CLI's forward volume (%.4f) is not brighter than the backward one (%.4f)" % (lc, rc))
    for name, cols in (("left (forward-scattering) volume", left), ("right (backward-scattering) volume", right)):
        assert_doors_agree(hydra, cli, "%s phase, %s" % (phase, name), rows=rows, cols=cols)


ANIMATED = '''    def Volume "cloud" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        float volphoton:density = 6
        color3f volphoton:albedo = (0.95, 0.95, 0.95)
        uniform token volphoton:phase = "%(phase)s"
        float volphoton:phase:%(param)s.timeSamples = {
            1: 0.8,
            2: -0.8,
        }
        rel field:density = </World/cloud/density>
        double3 xformOp:translate = (-0.75, -0.75, -0.75)
        float3 xformOp:scale = (1.5, 1.5, 1.5)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]

        def OpenVDBAsset "density"
        {
            asset filePath = @%(vdb)s@
            token fieldName = "density"
        }
    }
''' + BACKLIGHT

# (phase, animated parameter, OpenUSD scene path) -> what it isolates on the code of 2026-12-02.
ANIMATED_CASES = {
    # Scene-index path: the delegate re-syncs the Volume at frame 2 (an animated g does change the
    # picture there), reads k = -0.8, and the grid cache, keyed without k, returns frame 1's medium.
    "schlick-k-sceneIndex": ("schlick", "k", True),
    # Default (legacy scene delegate) path: the Volume is not re-synced when time changes, so even an
    # animated g (which the cache key holds) keeps frame 1's value.
    "henyeyGreenstein-g-default": ("henyeyGreenstein", "g", False),
}


@pytest.mark.parametrize("case", sorted(ANIMATED_CASES))
def test_grid_volume_with_animated_phase_renders_each_frame(tmp_path, hydra_env, case):
    """One VDB Volume whose phase parameter is time-sampled (0.8 at frame 1: forward, bright when lit
    from behind; -0.8 at frame 2: backward, dark), rendered over frames 1:2 in one process per door:
    frame 2 must be the backward-scattering picture.  Measured 2026-12-02: schlick-k-sceneIndex:
    delegate/CLI = 5.4, block |z| up to 24 (the grid cache key in sceneRegistry.cpp leaves out k, x
    and table; an animated g renders right on this path); henyeyGreenstein-g-default: delegate/CLI
    = 4.3, block |z| up to 16 (no re-sync on the default path: frame 2 is frame 1)."""
    phase, param, scene_index = ANIMATED_CASES[case]
    body = ANIMATED % {"vdb": cloud_vdb(tmp_path), "phase": phase, "param": param}
    hydra, cli, _, _ = render_both(hydra_env, tmp_path, "animated", lambda s: stage_text(body, s), frames="1:2",
                                   scene_index=scene_index)
    assert_doors_agree(hydra, cli, "frame 2 (%s = -0.8) of a grid volume with animated volphoton:phase:%s, %s path"
                       % (param, param, "scene-index" if scene_index else "default"))


# --------------------------------------------------------------------------------------------------
# 8a. Every VolPhotonMediumAPI / VolPhotonPhaseLobeAPI attribute reaches both doors
# --------------------------------------------------------------------------------------------------
#
# Contact sheets (sheets(): 4 of COLS x ROWS cells, at most MAX_VOLUMES Volumes each), each rendered
# per door and seed: a grid of CELL x CELL-pixel cells under an orthographic camera, each cell one
# small medium, so one render covers several attributes.  A "reference" cell is a medium in a context (a base medium,
# or a base with e.g. phase = schlick); a "case" cell is its reference plus one attribute authored at
# a non-default value.  Per attribute: (a) in each door, the case cell differs from its reference
# beyond noise (block |z| > Z_DIFFER somewhere), (b) the two doors agree on the case cell and on its
# reference (block |z| < Z_AGREE everywhere).  Three base media: "cloud" (a Volume on a 16^3 VDB
# density grid, scaled to 1.6 units), "cube" (a Cube Gprim, size 1.6, holding a constant medium) and
# "haze" (a Volume without fields, a constant medium in bounds of 1.6 units).

SCHEMA_FILE = os.path.join(REPO, "schemas", "generatedSchema.usda")
INSTANCE = "__INSTANCE_NAME__"
LOBE_PREFIX = "volphoton:lobe:%s:" % INSTANCE


def schema_attributes(api):
    """{attribute name: {type, uniform, default, tokens}} of an API schema class in
    generatedSchema.usda; the lobe API's names without the volphoton:lobe:__INSTANCE_NAME__: prefix."""
    layer = Sdf.Layer.FindOrOpen(SCHEMA_FILE)
    spec = layer.GetPrimAtPath("/" + api)
    assert spec, "%s has no class %s" % (SCHEMA_FILE, api)
    return {a.name.replace(LOBE_PREFIX, ""): {"type": str(a.typeName), "uniform": a.variability == Sdf.VariabilityUniform,
                                               "default": a.default,
                                               "tokens": list(a.allowedTokens) if a.HasInfo("allowedTokens") else []}
            for a in spec.attributes}


MEDIUM_ATTRS = schema_attributes("VolPhotonMediumAPI")
LOBE_ATTRS = schema_attributes("VolPhotonPhaseLobeAPI")


def declaration(spec, name):
    """`[uniform ]type name` of an attribute under the (full) attribute name."""
    return "%s%s %s" % ("uniform " if spec["uniform"] else "", spec["type"], name)


def lobe(name, prop):
    return "volphoton:lobe:%s:%s" % (name, prop)


BASES = {
    "cloud": {"volphoton:density": "4"},
    "cube": {"volphoton:density": "1"},
    "haze": {"volphoton:density": "1.5", "volphoton:bounds:min": "(-0.8, -0.8, -0.8)",
             "volphoton:bounds:max": "(0.8, 0.8, 0.8)"},
}
# Lobe "a" (weight 0.95 of the mixture) is the one the lobe cases change; lobe "b" stays isotropic.
MIXTURE_AB = {"volphoton:phase": '"mixture"', lobe("a", "weight"): "1", lobe("b", "weight"): "0.05"}

# Reference contexts: name -> (base, attributes authored on top of the base's).  A context that
# renders like its base (phase = schlick with k derived from g = 0, linear with x = 0, a mixture of
# isotropic lobes, a temperature field at 1 K) uses the base as its reference, which saves sheets.
REFERENCES = {
    "cloud": ("cloud", {}),
    "cube": ("cube", {}),
    "haze": ("haze", {}),
    "emission": ("cloud", {"volphoton:emission": "(0.6, 0.3, 0.1)"}),
    "exponential": ("cube", {"volphoton:densityMode": '"exponential"', "volphoton:exponential:b": "2"}),
    "preset": ("cloud", {"volphoton:preset": '"ketchup"'}),
    "mixtureG": ("cloud", dict(MIXTURE_AB, **{lobe("a", "g"): "0.8", lobe("b", "g"): "-0.6"})),
}

# Attribute -> (reference, extra context, value).  Values are chosen to change the picture of the
# reference: the sheet is lit from the camera's side (backscattering, where g, k, x, tables and
# lambertianSphere differ most from isotropic) and by a dim dome.
MEDIUM_CASES = {
    "volphoton:density": ("cloud", {}, "1"),
    "volphoton:albedo": ("cloud", {}, "(0.3, 0.6, 0.95)"),
    "volphoton:extinctionColor": ("cloud", {}, "(2, 1, 0.4)"),
    "volphoton:emission": ("cloud", {}, "(0.6, 0.3, 0.1)"),
    "volphoton:emissionScale": ("emission", {}, "4"),
    # T = 1500 K x grid value: blackbody luminance about (1500 / 1000)^4 = 5 where the grid is 1.
    "volphoton:temperatureScale": ("cloud", {"rel field:temperature": "<{prim}/temperature>"}, "1500"),
    "volphoton:phase": ("cloud", {}, '"lambertianSphere"'),
    "volphoton:phase:g": ("cloud", {}, "0.8"),
    "volphoton:phase:k": ("cloud", {"volphoton:phase": '"schlick"'}, "0.8"),
    "volphoton:phase:x": ("cloud", {"volphoton:phase": '"linear"'}, "-1"),
    # Against the isotropic cloud: an empty table is an error (isotropic) in both doors.
    "volphoton:phase:table": ("cloud", {"volphoton:phase": '"tabulated"'}, "[4, 1, 0.3, 0.1]"),
    # b = 3 (ignored by the constant reference): the density spans e^(+-2.4) over the cube.
    "volphoton:densityMode": ("cube", {"volphoton:exponential:b": "3"}, '"exponential"'),
    "volphoton:exponential:a": ("exponential", {}, "5"),
    "volphoton:exponential:b": ("exponential", {}, "0"),
    "volphoton:exponential:up": ("exponential", {}, "(1, 0, 0)"),
    "volphoton:exponential:origin": ("exponential", {}, "(0, 0.6, 0)"),
    "volphoton:ior": ("cube", {}, "1.5"),
    "volphoton:preset": ("cloud", {}, '"ketchup"'),
    "volphoton:sceneUnitsPerMm": ("preset", {}, "0.25"),
    "volphoton:bounds:min": ("haze", {}, "(0, -0.8, -0.8)"),
    "volphoton:bounds:max": ("haze", {}, "(0.8, 0, 0.8)"),
}
# Lobe property -> (reference, extra context, value of lobe "a").
LOBE_CASES = {
    "weight": ("mixtureG", {}, "0.02"),
    "phase": ("cloud", MIXTURE_AB, '"lambertianSphere"'),
    "g": ("cloud", MIXTURE_AB, "0.9"),
    "k": ("cloud", dict(MIXTURE_AB, **{lobe("a", "phase"): '"schlick"'}), "0.9"),
    "x": ("cloud", dict(MIXTURE_AB, **{lobe("a", "phase"): '"linear"'}), "-1"),
    "table": ("cloud", dict(MIXTURE_AB, **{lobe("a", "phase"): '"tabulated"'}), "[4, 1, 0.3, 0.1]"),
}


def generic_value(spec):
    """A non-default value for an attribute this file has no case for (a new schema attribute):
    the test then still renders it, and says so if the picture does not change."""
    t, default, tokens = spec["type"], spec["default"], spec["tokens"]
    if t == "token":
        return '"%s"' % next((tok for tok in tokens if tok != default), "none")
    if t in ("float", "double", "int"):
        return "%g" % ((default or 0) * 2 + 0.5)
    if t in ("color3f", "vector3f", "point3f", "float3", "normal3f"):
        return "(0.9, 0.5, 0.2)"
    if t.endswith("[]"):
        return "[4, 1, 0.3, 0.1]"
    return None


def attribute_cases():
    """Case id -> (reference, full context, attribute name, value) for every schema attribute."""
    cases = {}
    for name, spec in MEDIUM_ATTRS.items():
        ref, extra, value = MEDIUM_CASES.get(name, ("cloud", {}, generic_value(spec)))
        cases[name] = (ref, extra, name, value)
    for prop, spec in LOBE_ATTRS.items():
        ref, extra, value = LOBE_CASES.get(prop, ("cloud", MIXTURE_AB, generic_value(spec)))
        cases["VolPhotonPhaseLobeAPI:" + prop] = (ref, extra, lobe("a", prop), value)
    return cases


CASES = attribute_cases()
CELL = 16                        # pixels per cell side
COLS, ROWS = 3, 3                # cells per sheet
PITCH = 2.5                      # scene units per cell
# The core composes at most MediumAggregate::MaxMedia = 8 unbounded media (every Volume) per ray,
# plus the medium of the closed mesh it is in, and drops the others without a word: a sheet holds
# at most 7 Volumes, so that a Cube's medium is never the one dropped.
MAX_VOLUMES = 7
SHEET_SPP = 32


def attribute_type(name):
    if name.startswith("volphoton:lobe:"):
        prop = name.split(":")[-1]
        return declaration(LOBE_ATTRS[prop], name)
    return declaration(MEDIUM_ATTRS[name], name)


def medium_prim(prim_name, base, attrs, x, y, vdb):
    """usda of one cell's medium at (x, y) with the base's attributes overridden by attrs."""
    values = dict(BASES[base])
    values.update(attrs)
    lobes = sorted({n.split(":")[2] for n in values if n.startswith("volphoton:lobe:")})
    apis = ", ".join('"%s"' % a for a in ["VolPhotonMediumAPI"] + ["VolPhotonPhaseLobeAPI:" + l for l in lobes])
    path = "/World/" + prim_name
    lines = []
    for name, value in values.items():
        if name.startswith("rel "):
            lines.append("%s = %s" % (name, value.replace("{prim}", path)))
        else:
            lines.append("%s = %s" % (attribute_type(name), value))
    if base == "cloud":
        kind = "Volume"
        lines += ["rel field:density = <%s/density>" % path,
                  "double3 xformOp:translate = (%g, %g, -0.8)" % (x - 0.8, y - 0.8),
                  "float3 xformOp:scale = (1.6, 1.6, 1.6)",
                  'uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]']
        children = "".join('''
        def OpenVDBAsset "%s"
        {
            asset filePath = @%s@
            token fieldName = "density"
        }
''' % (child, vdb) for child in ("density", "temperature"))
    else:
        kind = "Cube" if base == "cube" else "Volume"
        if base == "cube":
            lines.append("double size = 1.6")
        lines += ["double3 xformOp:translate = (%g, %g, 0)" % (x, y), 'uniform token[] xformOpOrder = ["xformOp:translate"]']
        children = ""
    return '''    def %s "%s" (
        prepend apiSchemas = [%s]
    )
    {
%s
%s    }
''' % (kind, prim_name, apis, "\n".join("        " + l for l in lines), children)


def sheet_cells():
    """[(cell name, base, attributes)]: the references, then the cases."""
    cells = []
    for ref, (base, attrs) in REFERENCES.items():
        cells.append(("ref_" + ref, base, dict(attrs)))
    for case, (ref, extra, name, value) in CASES.items():
        base, attrs = REFERENCES[ref]
        attrs = dict(attrs, **extra)
        attrs[name] = value
        cells.append((case, base, attrs))
    return cells


def sheets():
    """The cells packed into sheets of COLS x ROWS cells with at most MAX_VOLUMES Volumes each."""
    cells = sheet_cells()
    volumes = [c for c in cells if c[1] != "cube"]
    cubes = [c for c in cells if c[1] == "cube"]
    n = max(math.ceil(len(volumes) / MAX_VOLUMES), math.ceil(len(cells) / (COLS * ROWS)))
    out = [volumes[i * MAX_VOLUMES:(i + 1) * MAX_VOLUMES] for i in range(n)]
    for group in out:
        while cubes and len(group) < COLS * ROWS:
            group.append(cubes.pop(0))
    assert not cubes and sum(map(len, out)) == len(cells)
    return out


SHEET_CAMERA = '''    def Camera "camera"
    {
        token projection = "orthographic"
        float horizontalAperture = %g
        float verticalAperture = %g
        double3 xformOp:translate = (0, 0, 10)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }''' % (COLS * PITCH * 10, ROWS * PITCH * 10)

# Lit from the camera's side, 20 degrees from above (shadows fall 0.6 units across a cell's depth,
# less than the 0.9-unit gap between cells), and a dim dome.
SHEET_LIGHTS = '''    def DistantLight "frontlight"
    {
        float inputs:intensity = 10
        bool inputs:normalize = 1
        float3 xformOp:rotateXYZ = (-20, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }

    def DomeLight "sky"
    {
        float inputs:intensity = 0.05
    }
'''


def sheet_body(cells, vdb):
    """usda of one sheet and {cell name: (rows, cols, prim name)}."""
    prims, where = [], {}
    for k, (name, base, attrs) in enumerate(cells):
        i, j = k % COLS, k // COLS
        x = -COLS * PITCH / 2 + PITCH * (i + 0.5)
        y = ROWS * PITCH / 2 - PITCH * (j + 0.5)
        prim = "cell%d" % k
        prims.append(medium_prim(prim, base, attrs, x, y, vdb))
        where[name] = (slice(j * CELL, (j + 1) * CELL), slice(i * CELL, (i + 1) * CELL), prim)
    return "".join(prims) + SHEET_LIGHTS, where


@pytest.fixture(scope="module")
def sheet(tmp_path_factory, hydra_env):
    """Every sheet through both doors, SEEDS seeds each: (cells, seconds) with cells {cell name:
    (hydra cell images, cli cell images, "sheet N cellK")}."""
    import time
    tmp_path = tmp_path_factory.mktemp("sheets")
    vdb = cloud_vdb(tmp_path)
    t0 = time.time()
    cells = {}
    for n, group in enumerate(sheets()):
        body, where = sheet_body(group, vdb)
        hydra, cli, _, _ = render_both(
            hydra_env, tmp_path, "sheet%d" % n,
            lambda s: stage_text(body, s, spp=SHEET_SPP, size=(COLS * CELL, ROWS * CELL), camera=SHEET_CAMERA),
            width=COLS * CELL)
        for name, (rows, cols, prim) in where.items():
            cells[name] = (hydra[:, rows, cols], cli[:, rows, cols], "sheet%d.%s" % (n, prim))
    return cells, time.time() - t0


@pytest.mark.parametrize("case", sorted(CASES))
def test_every_medium_attribute_reaches_both_doors(sheet, case):
    """(a) the attribute changes its cell's picture in each door, (b) the doors agree on it.
    Measured 2026-12-02 (delegate/CLI on the case cell): fail -- volphoton:preset (2.1, 2.4, 2.6: the
    grid path ignores presets), volphoton:sceneUnitsPerMm (1.6, 2.5, 2.7; no change in the delegate),
    and every VolPhotonPhaseLobeAPI property (the delegate renders mixtures as HG(phase:g)): weight
    0.42, phase 0.65, g 2.1, k 2.0, x 0.75, table 0.54, the reference mixture 1.6; no lobe property
    changes the delegate's picture.  The other 19 medium attributes pass."""
    cells, seconds = sheet
    ref, extra, name, value = CASES[case]
    refcell = "ref_" + ref
    problems = []
    for door, d in (("CLI", 1), ("delegate", 0)):
        a, b = cells[case][d], cells[refcell][d]
        z = block_z(a, b, block=CELL // 2)
        if np.abs(z).max() <= Z_DIFFER:
            problems.append("(a) %s: %s = %s does not change the picture of reference %s beyond noise (block |z| max "
                            "%.1f <= %g; means %s vs %s)" % (door, name, value, ref, np.abs(z).max(), Z_DIFFER,
                                                             np.round(a.mean(axis=(0, 1, 2)), 4),
                                                             np.round(b.mean(axis=(0, 1, 2)), 4)))
    for what in (case, refcell):
        h, c, where = cells[what]
        z = block_z(h, c, block=CELL // 2)
        if np.abs(z).max() >= Z_AGREE:
            problems.append("(b) cell %s (%s): %s" % (what, where, summary(h, c, block=CELL // 2)))
    check(not problems, "%s = %s (reference %s, extra %s; sheets rendered in %.0f s):\n  %s" % (
        name, value, ref, extra, seconds, "\n  ".join(problems)))


def test_every_schema_attribute_has_a_chosen_case():
    """New schema attributes get a generic value in the sheet; this names them so that a value that
    changes the picture (and its context) is chosen in MEDIUM_CASES / LOBE_CASES."""
    missing = sorted(set(MEDIUM_ATTRS) - set(MEDIUM_CASES)) + sorted(
        "VolPhotonPhaseLobeAPI:" + p for p in set(LOBE_ATTRS) - set(LOBE_CASES))
    assert not missing, "no chosen value for %s (test_parity.py MEDIUM_CASES / LOBE_CASES)" % missing
    assert len(MEDIUM_ATTRS) >= 21 and len(LOBE_ATTRS) >= 6, (sorted(MEDIUM_ATTRS), sorted(LOBE_ATTRS))


# --------------------------------------------------------------------------------------------------
# 8b. Every volphoton:* render setting reaches both doors
# --------------------------------------------------------------------------------------------------

from volphoton.usdscene import SETTINGS_ATTRIBUTES  # noqa: E402

SETTINGS_BODY = '''    def Cube "medium" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        double size = 1.4
        float volphoton:density = 3
        color3f volphoton:albedo = (0.95, 0.95, 0.95)
        float volphoton:phase:g = 0.3
        double3 xformOp:translate = (-0.55, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }

    def Volume "cloud" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        float volphoton:density = 8
        color3f volphoton:albedo = (0.3, 0.3, 0.3)
        rel field:density = </World/cloud/density>
        double3 xformOp:translate = (0.1, -0.6, -0.6)
        float3 xformOp:scale = (1.2, 1.2, 1.2)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]

        def OpenVDBAsset "density"
        {
            asset filePath = @%(vdb)s@
            token fieldName = "density"
        }
    }

    def DistantLight "sun"
    {
        float inputs:intensity = 2
        float3 xformOp:rotateXYZ = (-30, 30, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }

    def DomeLight "sky"
    {
        float inputs:intensity = 0.5
    }
'''
SETTINGS_SIZE = (16, 16)
SETTINGS_CAMERA = CAMERA.replace("float verticalAperture = 16", "float verticalAperture = 24")
PHOTONS = 'int volphoton:photonsPerPass = 4000'
PHOTON_MAP = ['token volphoton:integrator = "photonMap"', PHOTONS]
COMBINED = ['token volphoton:integrator = "combined"', PHOTONS]

# Setting -> (value, context, expectation).  The reference is the base scene with the context;
# expectations: "pixels" (the same seed gives other pixels), "same" (bit-identical), "darker" (the
# mean drops below 0.95 of the reference's), "changes" (the mean moves by more than 5%).  The mean
# of one 16 x 16 render moves by about 1% from seed to seed.
SETTING_CASES = {
    "integrator": ('token volphoton:integrator = "photonMap"', [PHOTONS], "pixels"),
    "samplesPerPixel": ("int volphoton:samplesPerPixel = 8", [], "pixels"),
    "maxDepth": ("int volphoton:maxDepth = 1", [], "darker"),
    "rouletteDepth": ("int volphoton:rouletteDepth = 0", [], "pixels"),
    "seed": ("int volphoton:seed = 7", [], "pixels"),
    "threads": ("int volphoton:threads = 1", [], "same"),
    "photonsPerPass": ("int volphoton:photonsPerPass = 1000", PHOTON_MAP[:1], "pixels"),
    "initialRadius": ("float volphoton:initialRadius = 0.05", PHOTON_MAP, "pixels"),
    "radiusAlpha": ("float volphoton:radiusAlpha = 0.3", PHOTON_MAP, "pixels"),
    # 0.05 mean free paths of the cloud (sigma_t 8): 0.006 units, below the automatic radius.
    "photonRadiusMfp": ("float volphoton:photonRadiusMfp = 0.05", PHOTON_MAP, "pixels"),
    "stratifiedDims": ("int volphoton:stratifiedDims = 0", [], "pixels"),
    "marchStep": ("float volphoton:marchStep = 0.05", PHOTON_MAP, "pixels"),
    "singleScattering": ("bool volphoton:singleScattering = 0", PHOTON_MAP, "darker"),
    "multipleScattering": ("bool volphoton:multipleScattering = 0", PHOTON_MAP, "darker"),
    "photonBeams": ("bool volphoton:photonBeams = 1", PHOTON_MAP, "pixels"),
    "combinedPhotonShare": ("float volphoton:combinedPhotonShare = 0.5", COMBINED, "pixels"),
    "multipleThreshold": ("float volphoton:multipleThreshold = 1000000", PHOTON_MAP, "darker"),
    "transmittanceCutoff": ("float volphoton:transmittanceCutoff = 0.5", [], "pixels"),
    # Adaptive sampling: an unreachable target renders to the cap (32 passes instead of SPP); a cap
    # ends a render whose target is unreachable earlier than the default 4096; a time limit renders
    # past SPP; the guides have their own random stream, so the beauty is bit-identical.
    "noiseTarget": ("float volphoton:noiseTarget = 0.001", ["int volphoton:maxSamplesPerPixel = 32"], "pixels"),
    "maxSamplesPerPixel": ("int volphoton:maxSamplesPerPixel = 24", ["float volphoton:noiseTarget = 0.001"], "pixels"),
    "timeLimit": ("float volphoton:timeLimit = 0.5", [], "pixels"),
    "guideAovs": ("bool volphoton:guideAovs = 1", [], "same"),
    # Not in SETTINGS_ATTRIBUTES (the CLI reads it beside them): the 16^3 cloud has more than 10
    # active voxels, so it is refused (an error naming it) and the picture changes.
    "maxGridVoxels": ("int volphoton:maxGridVoxels = 10", [], "changes"),
}
SETTING_NAMES = sorted(set(SETTINGS_ATTRIBUTES) | {"maxGridVoxels"})
UNKNOWN_SETTING = "float volphoton:noSuchSetting = 3"


def setting_context_key(context):
    return "|".join(context)


@pytest.fixture(scope="module")
def settings_renders(tmp_path_factory, hydra_env):
    """{key: (hydra image, cli image, hydra log, cli log)} for every reference context and setting
    (seed 1, one render per door each)."""
    import time
    tmp_path = tmp_path_factory.mktemp("settings")
    body = SETTINGS_BODY % {"vdb": cloud_vdb(tmp_path)}
    variants = {}
    for name in SETTING_NAMES:
        line, context, _ = SETTING_CASES.get(name, (None, [], None))
        variants["ref:" + setting_context_key(context)] = context
        if line:
            variants[name] = context + [line]
    variants["unknown"] = [UNKNOWN_SETTING]
    jobs, outs = [], {}
    for k, (key, lines) in enumerate(sorted(variants.items())):
        stage = tmp_path / ("settings%02d.usda" % k)
        stage.write_text(stage_text(body, 1, size=SETTINGS_SIZE, settings=lines, camera=SETTINGS_CAMERA))
        hyd, cli = str(tmp_path / ("settings%02d.hydra.exr" % k)), str(tmp_path / ("settings%02d.cli.exr" % k))
        outs[key] = (hyd, cli)
        jobs.append(lambda s=str(stage), o=hyd: render_hydra(hydra_env, s, o, SETTINGS_SIZE[0]))
        jobs.append(lambda s=str(stage), o=cli: render_cli(s, o))
    t0 = time.time()
    logs = run_parallel(jobs)
    seconds = time.time() - t0
    result = {}
    for k, key in enumerate(sorted(variants)):
        hyd, cli = outs[key]
        assert os.path.exists(hyd) and os.path.exists(cli), (key, logs[2 * k], logs[2 * k + 1])
        result[key] = (rgb(hyd), rgb(cli), logs[2 * k], logs[2 * k + 1])
    result["seconds"] = seconds
    return result


def complaints(log, name):
    """Lines of a log that complain about volphoton:<name> (unknown, unusable, ignored, wrong type)."""
    pattern = re.compile(r"volphoton:%s\b" % re.escape(name))
    words = ("unknown", "unusable", "ignored", "has type", "not supported")
    return [l for l in log.splitlines() if pattern.search(l) and any(w in l.lower() for w in words)]


@pytest.mark.parametrize("name", SETTING_NAMES)
def test_every_render_setting_reaches_both_doors(settings_renders, name):
    """Each volphoton:* setting is accepted by both doors (no complaint naming it) and changes the
    picture as it should in both.  Measured 2026-12-02: all pass but maxGridVoxels, which the
    delegate does not read (the cloud stays, mean ratio 1.000; the CLI refuses the grid)."""
    assert name in SETTING_CASES, "no value chosen for the render setting volphoton:%s (SETTING_CASES)" % name
    line, context, expect = SETTING_CASES[name]
    hyd, cli, hlog, clog = settings_renders[name]
    rhyd, rcli, _, _ = settings_renders["ref:" + setting_context_key(context)]
    problems = []
    for door, img, ref, log in (("CLI", cli, rcli, clog), ("delegate", hyd, rhyd, hlog)):
        bad = complaints(log, name)
        if bad:
            problems.append("%s complains about %s: %s" % (door, line, bad))
        ratio = img.mean() / max(ref.mean(), 1e-12)
        if expect == "same" and not np.array_equal(img, ref):
            problems.append("%s: %s changes the picture (max difference %g)" % (door, line, np.abs(img - ref).max()))
        if expect == "pixels" and np.array_equal(img, ref):
            problems.append("%s: %s leaves the picture bit-identical" % (door, line))
        if expect == "darker" and not ratio < 0.95:
            problems.append("%s: %s does not darken the picture (mean ratio %.3f, needs < 0.95)" % (door, line, ratio))
        if expect == "changes" and not abs(ratio - 1) > 0.05:
            problems.append("%s: %s does not change the picture (mean ratio %.3f, needs |1 - ratio| > 0.05)"
                            % (door, line, ratio))
    check(not problems, "volphoton:%s (context %s; %d renders in %.0f s):\n  %s" % (
        name, context, 2 * (len(settings_renders) - 1), settings_renders["seconds"], "\n  ".join(problems)))


def test_an_unknown_render_setting_is_named_by_both_doors(settings_renders):
    """The negative control of the test above: a misspelt volphoton:* setting is named in a warning
    by both doors.  Measured 2026-12-02: the CLI warns ("unknown render setting"), the delegate says
    nothing."""
    _, _, hlog, clog = settings_renders["unknown"]
    for door, log in (("CLI", clog), ("delegate (usdrecord)", hlog)):
        check(complaints(log, "noSuchSetting"), "%s does not name volphoton:noSuchSetting:\n%s" % (door, log[-3000:]))


# --------------------------------------------------------------------------------------------------
# Lights at infinity: every one an escaping ray meets
# --------------------------------------------------------------------------------------------------

# A sun of angular diameter 8 degrees straight ahead (its light travels +Z, towards the camera: the
# disk's radius is about 7 pixels around the image centre) and a dim sky.  "sky" sorts before "sun",
# so both doors list the dome first.
SUN_AND_SKY = '''    def DomeLight "sky"
    {
        float inputs:intensity = 0.2
    }
    def DistantLight "sun"
    {
        float inputs:intensity = 1
        float inputs:angle = 8
        bool inputs:normalize = 1
        float3 xformOp:rotateXYZ = (0, 180, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }'''


def test_a_wide_sun_is_seen_in_front_of_the_sky_in_both_doors(tmp_path, hydra_env):
    """Camera rays that escape see every light at infinity (Integrator::lightsAtInfinity).  The sun's
    radiance is its irradiance 1 / (pi sin^2(4 deg)) = 65.5 (normalize), the sky's 0.2.  Measured
    2026-12-05 before the fix: both doors saw the sky alone (0.2) inside the sun's disk."""
    hydra, cli, _, _ = render_both(hydra_env, tmp_path, "sun_and_sky", lambda s: stage_text(SUN_AND_SKY, s))
    centre = (slice(H // 2 - 2, H // 2 + 2), slice(W // 2 - 2, W // 2 + 2))
    corner = (slice(0, 4), slice(0, 4))
    sun = 1 / (math.pi * math.sin(math.radians(4)) ** 2)
    for door, img in (("delegate", hydra), ("CLI", cli)):
        c, k = img[:, centre[0], centre[1]].mean(), img[:, corner[0], corner[1]].mean()
        check(abs(c / (sun + 0.2) - 1) < 0.01, "%s: the sun's disk reads %.3f (sun %.3f + sky 0.2)" % (door, c, sun))
        check(abs(k / 0.2 - 1) < 0.01, "%s: the sky reads %.4f (0.2)" % (door, k))
    assert_doors_agree(hydra, cli, "sun and sky")
