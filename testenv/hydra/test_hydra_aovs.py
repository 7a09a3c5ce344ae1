"""The id AOVs (primId, instanceId, elementId) and the denoiser guides (albedo, normal) through
UsdImagingGLEngine, read back by the small C++ tool build/hdVolPhoton/hd/hdVolPhotonIdImages
(OpenUSD 24.08's Python cannot map a render buffer)."""

import json
import math
import os
import subprocess

import pytest

from hydra_util import BUILD

TOOL = os.path.join(BUILD, "hdVolPhoton", "hd", "hdVolPhotonIdImages")

# Camera at z = 10 looking down -Z, 2:1 aperture (no window conforming at 32x16): two meshes side by
# side (/World/left has two faces, left and right), and a PointInstancer with two copies of a tile
# below them. World x = +-2.0955 and y = +-1.04775 at the image borders.
SCENE = """#usda 1.0
(
    upAxis = "Y"
)
def Xform "World"
{
    def Camera "camera"
    {
        float focalLength = 50
        float horizontalAperture = 20.955
        float verticalAperture = 10.4775
        double3 xformOp:translate = (0, 0, 10)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
    def Mesh "left"
    {
        int[] faceVertexCounts = [4, 4]
        int[] faceVertexIndices = [0, 1, 4, 3, 1, 2, 5, 4]
        point3f[] points = [(-1.6, 0.1, 0), (-1.2, 0.1, 0), (-0.8, 0.1, 0), (-1.6, 0.7, 0), (-1.2, 0.7, 0), (-0.8, 0.7, 0)]
        uniform token subdivisionScheme = "none"
    }
    def Mesh "right"
    {
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(0.8, 0.1, 0), (1.6, 0.1, 0), (1.6, 0.7, 0), (0.8, 0.7, 0)]
        uniform token subdivisionScheme = "none"
    }
    def PointInstancer "instancer"
    {
        point3f[] positions = [(-0.6, -0.5, 0), (0.6, -0.5, 0)]
        int[] protoIndices = [0, 0]
        rel prototypes = </World/instancer/prototypes/tile>
        def Scope "prototypes"
        {
            def Mesh "tile"
            {
                int[] faceVertexCounts = [4]
                int[] faceVertexIndices = [0, 1, 2, 3]
                point3f[] points = [(-0.25, -0.25, 0), (0.25, -0.25, 0), (0.25, 0.25, 0), (-0.25, 0.25, 0)]
                uniform token subdivisionScheme = "none"
            }
        }
    }
    def DomeLight "sky"
    {
        float inputs:intensity = 1
    }
}
"""
W, H = 32, 16


def pixel(x, y):
    """The pixel (column, row from the top) whose centre sees world point (x, y, 0)."""
    return int((x / 2.0955 + 1) / 2 * W), int((1 - y / 1.04775) / 2 * H)


def test_id_aovs_name_the_prims_the_pixels_see(tmp_path, hydra_env):
    assert os.path.exists(TOOL), "the id-image tool was not built (usdImagingGL and OpenGL::GL are needed)"
    scene = tmp_path / "ids.usda"
    scene.write_text(SCENE)
    p = subprocess.run([TOOL, str(scene), "/World/camera", str(W), str(H)], capture_output=True, text=True,
                       env=hydra_env["env"], timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    d = json.loads(p.stdout)

    def at(aov, x, y):
        c, r = pixel(x, y)
        return d[aov][r * W + c]

    hits = {(h["primId"], h["instanceId"]): h for h in d["hits"]}
    assert all(h["decoded"] for h in hits.values()), hits

    left, right, tile0, tile1 = at("primId", -1.2, 0.4), at("primId", 1.2, 0.4), at("primId", -0.6, -0.5), at("primId", 0.6, -0.5)
    assert min(left, right, tile0) >= 0 and len({left, right, tile0}) == 3
    assert tile1 == tile0  # one rprim, two instances
    assert hits[(left, 0)]["path"] == "/World/left"
    assert hits[(right, 0)]["path"] == "/World/right"
    assert at("instanceId", -1.2, 0.4) == 0 and at("instanceId", 1.2, 0.4) == 0  # not instanced: 0, as hdEmbree
    for x, index in ((-0.6, 0), (0.6, 1)):
        h = hits[(tile0, at("instanceId", x, -0.5))]
        assert h["path"] == "/World/instancer/prototypes/tile"
        assert h["instancer"] == "/World/instancer" and h["instanceIndex"] == index, h
    # elementId: the authored face (the left mesh's two quads are four triangles).
    assert at("elementId", -1.45, 0.4) == 0 and at("elementId", -0.95, 0.4) == 1
    assert at("elementId", 1.2, 0.4) == 0
    # Background: nothing in any id image.
    for aov in ("primId", "instanceId", "elementId"):
        assert at(aov, -2.0, 1.0) == -1 and at(aov, 0.0, 0.4) == -1 and at(aov, 2.0, -1.0) == -1
        assert d[aov].count(-1) > W * H // 2


# The id scene's stage header and camera, then one coloured wall and the dome.
GUIDE_SCENE = SCENE[:SCENE.index('    def Mesh "left"')] + """    def Mesh "wall"
    {
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(-3, -2, 0), (0, -2, 0), (0, 2, 0), (-3, 2, 0)]
        color3f[] primvars:displayColor = [(0.2, 0.4, 0.6)]
        uniform token subdivisionScheme = "none"
    }
    def DomeLight "sky"
    {
        float inputs:intensity = 1
    }
}
"""


def test_denoiser_guide_aovs_albedo_and_normal(tmp_path, hydra_env):
    """The albedo and normal AOVs (the denoiser guides, core Integrator::firstVertexGuides) through
    the delegate: bound, they are traced; the wall's pixels hold its displayColor and its normal +z
    (facing the camera), the same for every sample (a lambertian first vertex: no noise)."""
    assert os.path.exists(TOOL), "the id-image tool was not built (usdImagingGL and OpenGL::GL are needed)"
    scene = tmp_path / "guides.usda"
    scene.write_text(GUIDE_SCENE)
    p = subprocess.run([TOOL, str(scene), "/World/camera", str(W), str(H), "albedo", "normal"], capture_output=True,
                       text=True, env=hydra_env["env"], timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    d = json.loads(p.stdout)
    c, r = pixel(-1.5, 0.0)
    i = 3 * (r * W + c)
    assert d["albedo"][i:i + 3] == pytest.approx([0.2, 0.4, 0.6], abs=1e-5)
    assert d["normal"][i:i + 3] == pytest.approx([0.0, 0.0, 1.0], abs=1e-5)
    assert all(math.isfinite(v) for v in d["albedo"] + d["normal"])
