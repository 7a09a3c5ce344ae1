"""The thin fog slab the scale and emissive-geometry tests share (testenv/test_scale.py,
testenv/hydra/test_hydra_scale.py, testenv/test_emissive_geometry.py), and their per-pass image
statistics.

The slab: a Cube of fog (density 1, albedo 0.8, index-matched) with x, z in [-2, 2] and y in [0, 1];
a black ground square of half-width w at y = -0.02; cameras (20 x 20 aperture, focal length 50,
clipping range 1e-5 .. 1e8) 1e-3 below it looking up or 1e-3 above it looking down.
"""

import math
import textwrap

import numpy as np

from pxr import Usd  # noqa: E402

from volphoton import _core, usdscene  # noqa: E402

CAMERA = '''def Camera "cam"
{{
    float focalLength = 50
    float horizontalAperture = 20
    float verticalAperture = 20
    float2 clippingRange = (1e-5, 1e8)
    double3 xformOp:translate = (0, {cam_y}, 0)
    float3 xformOp:rotateXYZ = ({cam_rx}, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
}}
'''

# Camera 1e-3 below the slab looking up (+Y), or 1e-3 above it looking down (-Y).
VIEWS = {"below": dict(cam_y=-1e-3, cam_rx=90), "above": dict(cam_y=1 + 1e-3, cam_rx=-90)}

SLAB = '''def Cube "fog" (
    prepend apiSchemas = ["VolPhotonMediumAPI"]
)
{
    double size = 1
    float volphoton:ior = 1
    float volphoton:density = 1
    color3f volphoton:albedo = (0.8, 0.8, 0.8)
    double3 xformOp:translate = (0, 0.5, 0)
    float3 xformOp:scale = (4, 1, 4)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
}
'''

GROUND = '''def Mesh "ground"
{{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 3, 2, 1]
    point3f[] points = [(-{w}, -0.02, -{w}), ({w}, -0.02, -{w}), ({w}, -0.02, {w}), (-{w}, -0.02, {w})]
    color3f[] primvars:displayColor = [(0, 0, 0)]
}}
'''

DOME = '''def DomeLight "sky"
{
    float inputs:intensity = 1
}
'''

RENDER_SETTINGS = '''def Scope "Render"
{{
    def RenderSettings "settings"
    {{
        int2 resolution = ({size}, {size})
        rel camera = </World/cam>
        int volphoton:samplesPerPixel = {spp}
        int volphoton:seed = {seed}
        token volphoton:integrator = "{integrator}"
{extra}    }}
}}
'''


def camera(view):
    return CAMERA.format(**VIEWS[view])


def ground(w):
    return GROUND.format(w=repr(float(w)))


def stage_text(body, settings=None):
    """A Y-up stage whose /World holds body (prims as text); with settings (a dict of size, spp,
    seed and integrator, and optionally more volphoton: settings, e.g. noiseTarget=0.05) a
    RenderSettings prim /Render/settings too."""
    if settings:
        fixed = ("size", "spp", "seed", "integrator")
        extra = "".join("        %s volphoton:%s = %r\n" % ("int" if isinstance(v, int) else "double", k, v)
                        for k, v in settings.items() if k not in fixed)
        settings = dict({k: settings[k] for k in fixed}, extra=extra)
    header = '#usda 1.0\n(\n    upAxis = "Y"\n%s)\n' % ('    renderSettingsPrimPath = "/Render/settings"\n' if settings else "")
    return (header + (RENDER_SETTINGS.format(**settings) if settings else "") +
            'def Xform "World"\n{\n' + textwrap.indent(body, "    ") + "}\n")


def pass_means(path, integrator, res, seeds, passes, configure=None, emissive_mesh_lights=True, allow_errors=False):
    """Image mean (all pixels and channels) of every pass of every seed, through the standalone
    front end (volphoton.usdscene, as `volphoton render` translates) at RenderSettings' defaults but
    resolution, seed, passes and the integrator; configure(settings) may change more.  Every
    pixel must be finite; the translation must have no errors unless allow_errors.
    -> (len(seeds) * passes,) float64."""
    stage = Usd.Stage.Open(str(path))
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), res, res, "/World/cam")
    assert allow_errors or not sc.errors, "\n".join(map(str, sc.errors))
    sc.desc.emissive_mesh_lights = emissive_mesh_lights
    scene = _core.Scene(sc.desc)
    out = []
    for seed in seeds:
        s = _core.RenderSettings()
        s.width = s.height = res
        s.samples_per_pixel = passes
        s.seed = seed
        if integrator == "photonMap":
            s.integrator = _core.RenderSettings.Integrator.PhotonMap
        if configure:
            configure(s)
        r = _core.Renderer(scene, s)
        prev = 0.0
        for k in range(1, passes + 1):
            assert r.render_pass()
            img = r.film.beauty.astype(np.float64)
            assert np.isfinite(img).all()
            cum = float(img.mean()) * k
            out.append(cum - prev)
            prev = cum
    return np.array(out)


def mean_and_error(values):
    """(mean, standard error of the mean) of independent samples."""
    v = np.asarray(values, np.float64)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v)))
