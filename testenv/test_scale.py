"""Right at any scale (issue 14, part 1): ray offsets follow the local float precision of each hit,
not the scene's extent.

A 1-unit slab of fog (x, z in [-2, 2], y in [0, 1]) under a dome of radiance 1, with a black ground
plane 0.02 below it whose half-width W is the only thing that changes (1e2, 1e4, 1e5, 1e6: the
scene's extent follows W).  Two cameras 1e-3 from the medium's boundary: one below the slab looking
up through it at the sky (the ground behind it), one above looking down into it (the ground 0.02
past its far side).  Nothing near the slab changes with W, so every W must give the same picture.

With offsets of 1e-5 x the scene's extent (the old Scene::epsilon) a W = 1e5 ground made the ray
entering the slab from below skip its far side (0.1 .. 10 units of offset against 1 unit of
slab), and the ray leaving its bottom skip the ground 0.02 below (the sky came through): both
views changed by far more than the noise.

Through the standalone front end: the .usda files are translated by volphoton.usdscene (as
`volphoton render` does) and rendered by the core, one image per pass.  The photon map runs its
single-scattering march and camera paths only (multipleScattering off, march step and radius set):
its dome photons are emitted over the scene's bounding disk, so with W = 1e6 almost none of them
reach a 4-unit slab, a separate matter from ray offsets (the multiple part would be pure noise).

Tolerance: the image mean of each (W, seed, pass) is one sample; sigma is the standard error of
the mean over 2 seeds x 16 passes.  The difference to W = 1e2 must stay within 5 sigma of the
combined standard errors (k = 5: 3 W values x 2 views x 2 integrators = 12 comparisons, a Gaussian
exceeds 5 sigma with probability 6e-7 each).  The old code misses by tens to hundreds of sigma.
"""

import math
import textwrap

import numpy as np
import pytest

from conftest import usda

from pxr import Usd  # noqa: E402

from volphoton import _core, usdscene  # noqa: E402

HALF_WIDTHS = (1e2, 1e4, 1e5, 1e6)
INTEGRATORS = ("pathTracer", "photonMap")
SEEDS = (1, 2)
PASSES = 16
RES = 8
K = 5.0

SCENE = """\
def Xform "World"
{{
    def Camera "cam"
    {{
        float focalLength = 50
        float horizontalAperture = 20
        float verticalAperture = 20
        float2 clippingRange = (1e-5, 1e8)
        double3 xformOp:translate = (0, {cam_y}, 0)
        float3 xformOp:rotateXYZ = ({cam_rx}, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }}
    def Cube "fog" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {{
        double size = 1
        float volphoton:ior = 1
        float volphoton:density = 1
        color3f volphoton:albedo = (0.8, 0.8, 0.8)
        double3 xformOp:translate = (0, 0.5, 0)
        float3 xformOp:scale = (4, 1, 4)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
    }}
    def Mesh "ground"
    {{
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 3, 2, 1]
        point3f[] points = [(-{w}, -0.02, -{w}), ({w}, -0.02, -{w}), ({w}, -0.02, {w}), (-{w}, -0.02, {w})]
        color3f[] primvars:displayColor = [(0, 0, 0)]
    }}
    def DomeLight "sky"
    {{
        float inputs:intensity = 1
    }}
}}
"""

# Camera 1e-3 below the slab looking up (+Y), or 1e-3 above it looking down (-Y).
VIEWS = {"below": dict(cam_y=-1e-3, cam_rx=90), "above": dict(cam_y=1 + 1e-3, cam_rx=-90)}


def pass_means(tmp_path, view, w, integrator):
    """Image mean of every pass, over SEEDS: (len(SEEDS) * PASSES,) float64."""
    path = tmp_path / ("%s_%g.usda" % (view, w))
    path.write_text('#usda 1.0\n(\n    upAxis = "Y"\n)\n' + usda(textwrap.dedent(SCENE.format(w=repr(float(w)), **VIEWS[view]))))
    stage = Usd.Stage.Open(str(path))
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), RES, RES, "/World/cam")
    assert not sc.errors, "\n".join(map(str, sc.errors))
    scene = _core.Scene(sc.desc)
    out = []
    for seed in SEEDS:
        s = _core.RenderSettings()  # the defaults (maxDepth included)
        s.width = s.height = RES
        s.samples_per_pixel = PASSES
        s.seed = seed
        if integrator == "photonMap":
            s.integrator = _core.RenderSettings.Integrator.PhotonMap
            s.multiple_scattering = False
            s.march_step = 0.01
            s.initial_radius = 0.05
        r = _core.Renderer(scene, s)
        prev = 0.0
        for k in range(1, PASSES + 1):
            assert r.render_pass()
            cum = float(r.film.beauty.astype(np.float64).mean()) * k
            out.append(cum - prev)
            prev = cum
    return np.array(out)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("view", sorted(VIEWS))
def test_thin_slab_is_the_same_whatever_the_ground_plane_size(tmp_path, view, integrator):
    stats = {}
    for w in HALF_WIDTHS:
        v = pass_means(tmp_path, view, w, integrator)
        stats[w] = (v.mean(), v.std(ddof=1) / math.sqrt(len(v)))
    ref, ref_se = stats[HALF_WIDTHS[0]]
    # The layer is there at all (not black, not the bare sky): 1 unit of optical depth, albedo 0.8.
    if view == "below":
        assert 0.3 < ref < 0.95, ref  # e^-1 of the sky plus the light it scatters forward
    else:
        assert 0.05 < ref < 0.45, ref  # only the light the slab scatters back (ground black)
    for w in HALF_WIDTHS[1:]:
        m, se = stats[w]
        tol = K * math.hypot(se, ref_se)
        print("%s %s W=%g: %.5f +- %.5f (W=1e2: %.5f +- %.5f)" % (integrator, view, w, m, se, ref, ref_se))
        assert abs(m - ref) <= tol, (integrator, view, w, m, se, ref, ref_se)
