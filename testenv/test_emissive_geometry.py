"""Emissive geometry is a light (issue 14, part 3): a mesh whose UsdPreviewSurface has an
emissiveColor is sampled by next-event estimation in both integrators (uniform over its area,
chosen by power with the other lights) and emits photons, through the usd-core front end (the
delegate's side is testenv/hydra/test_parity.py).

Scenes (all at default settings but resolution and passes):
  * enclosure vs dome: a 1-unit slab of fog (albedo 0.8) over a black ground, seen from just below
    it, lit either by a dome of radiance 1 or by an inward-facing emissive sphere of radiance 1
    around everything.  Inside such a sphere every direction meets radiance 1, exactly as under
    the dome, so the two pictures are equal; both integrators, against each other too.
  * white furnace: fog of albedo 1 filling an inward-facing emissive sphere (radiance 1, albedo
    0): the radiance is 1 everywhere inside, whatever the fog.
  * slab under an emissive plane: the same slab under a downward-facing emissive square instead of
    the dome; the path tracer and the photon map must agree.  Before emissive meshes were lights,
    the photon map returned only the unscattered part here.
  * UsdLux MeshLightAPI: the same panel as a mesh light (intensity normalized by its area) renders
    as the emissiveColor panel.
  * light sampling does not change the answer: a small emissive sphere in fog, rendered with its
    mesh light (next-event estimation + MIS) and with hits only (SceneDesc.emissive_mesh_lights
    False, the old way): equal means.  The equal-time error of the two is measured by
    tools/bench_emissive.py, not here.

Tolerance: the image mean of each (seed, pass) is one sample; sigma is the standard error of the
mean over the seeds x passes; two renders agree when they differ by less than K = 5 combined sigma
(9 comparisons: a Gaussian exceeds 5 sigma with probability 6e-7 each), and the furnace is within
K sigma of 1 plus the photon map's kernel allowance stated there.
"""

import math
import textwrap

import pytest

import slab_scene

K = 5.0
RES = 8
SEEDS = (1, 2, 3)
PASSES = 16
INTEGRATORS = ("pathTracer", "photonMap")


def sphere_mesh(name, radius, inward, material, segments=24, rings=12, center=(0.0, 0.0, 0.0)):
    """A UV sphere Mesh prim (usda text) whose front side (counter-clockwise winding, right-handed)
    faces out, or in when `inward`."""
    pts, faces = [], []
    for r in range(rings + 1):
        th = math.pi * r / rings
        for s in range(segments):
            ph = 2 * math.pi * s / segments
            pts.append((center[0] + radius * math.sin(th) * math.cos(ph), center[1] + radius * math.cos(th),
                        center[2] + radius * math.sin(th) * math.sin(ph)))
    for r in range(rings):
        for s in range(segments):
            a, b = r * segments + s, r * segments + (s + 1) % segments
            c, d = a + segments, b + segments
            quad = [a, b, d, c]  # normal (b - a) x (c - a) points outwards
            faces.append(quad[::-1] if inward else quad)
    return textwrap.dedent('''\
        def Mesh "%s" (
            prepend apiSchemas = ["MaterialBindingAPI"]
        )
        {
            int[] faceVertexCounts = [%s]
            int[] faceVertexIndices = [%s]
            point3f[] points = [%s]
            rel material:binding = <%s>
        }
        ''') % (name, ", ".join("4" for _ in faces), ", ".join(str(i) for f in faces for i in f),
                ", ".join("(%.9g, %.9g, %.9g)" % p for p in pts), material)


def emissive_material(name, emission, diffuse=0.0):
    return textwrap.dedent('''\
        def Material "%(n)s"
        {
            token outputs:surface.connect = </World/%(n)s/shader.outputs:surface>
            def Shader "shader"
            {
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = (%(d)g, %(d)g, %(d)g)
                color3f inputs:emissiveColor = (%(e)g, %(e)g, %(e)g)
                token outputs:surface
            }
        }
        ''') % {"n": name, "e": emission, "d": diffuse}


# A square at y = 3 facing down (-Y), half-width 8.
PLANE = '''def Mesh "panel" (
    prepend apiSchemas = ["MaterialBindingAPI"]
)
{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    point3f[] points = [(-8, 3, -8), (8, 3, -8), (8, 3, 8), (-8, 3, 8)]
    rel material:binding = </World/glow>
}
'''


# The same square as a UsdLux mesh light: intensity 256 normalized by its area (16 x 16) is radiance
# 1; its material has no glow (materialGlowTintsLight then leaves the light's colour alone).
MESH_LIGHT_PLANE = PLANE.replace('''prepend apiSchemas = ["MaterialBindingAPI"]''',
                                 '''prepend apiSchemas = ["MaterialBindingAPI", "MeshLightAPI"]''').replace(
    "rel material:binding", "float inputs:intensity = 256\n    bool inputs:normalize = 1\n    rel material:binding")


def stage_file(tmp_path, name, body):
    path = tmp_path / (name + ".usda")
    path.write_text(slab_scene.stage_text(body))
    return str(path)


def pass_means(path, integrator, emissive_mesh_lights=True, seeds=SEEDS, passes=PASSES):
    """(mean, standard error) of the per-pass image means over the seeds, at default settings."""
    return slab_scene.mean_and_error(slab_scene.pass_means(path, integrator, RES, seeds, passes,
                                                           emissive_mesh_lights=emissive_mesh_lights))


def assert_agree(a, b, what):
    (ma, sa), (mb, sb) = a, b
    tol = K * math.hypot(sa, sb)
    print("%s: %.5f +- %.5f vs %.5f +- %.5f" % (what, ma, sa, mb, sb))
    assert abs(ma - mb) <= tol, "%s: %.5f +- %.5f vs %.5f +- %.5f (tolerance %.5f)" % (what, ma, sa, mb, sb, tol)


BELOW = slab_scene.camera("below")  # 1e-3 under the slab, looking up
GROUND = slab_scene.ground(3)


@pytest.fixture(scope="module")
def slab_renders(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("emissive")
    slab = BELOW + slab_scene.SLAB + GROUND
    dome = stage_file(tmp, "dome", slab + slab_scene.DOME)
    enclosure = stage_file(tmp, "enclosure", slab + emissive_material("glow", 1.0) +
                           sphere_mesh("enclosure", 6.0, True, "/World/glow"))
    plane = stage_file(tmp, "plane", slab + emissive_material("glow", 1.0) + PLANE)
    mesh_light = stage_file(tmp, "mesh_light", slab + emissive_material("glow", 0.0) + MESH_LIGHT_PLANE)
    out = {}
    for integrator in INTEGRATORS:
        out["dome", integrator] = pass_means(dome, integrator)
        out["enclosure", integrator] = pass_means(enclosure, integrator)
        out["plane", integrator] = pass_means(plane, integrator)
        out["mesh_light", integrator] = pass_means(mesh_light, integrator)
    return out


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_an_emissive_enclosure_lights_a_slab_as_a_dome_of_equal_radiance(slab_renders, integrator):
    m, _ = slab_renders["dome", integrator]
    assert 0.3 < m < 0.95, m  # e^-1 of the sky plus the light the slab scatters forward
    assert_agree(slab_renders["enclosure", integrator], slab_renders["dome", integrator],
                 "%s: emissive enclosure vs dome" % integrator)


@pytest.mark.parametrize("scene", ("enclosure", "plane"))
def test_both_integrators_agree_under_emissive_geometry(slab_renders, scene):
    # Under the plane the slab sees radiance 1 over most of its upper hemisphere (the square's edges
    # are 2 to 3 units above it, 8 across): far more than the e^-1 = 0.37 of the bare panel, which
    # is all the photon map returned when emissive meshes were no lights.
    m, _ = slab_renders[scene, "pathTracer"]
    assert m > 0.45, m
    assert_agree(slab_renders[scene, "photonMap"], slab_renders[scene, "pathTracer"],
                 "%s: photon map vs path tracer" % scene)


CENTRE = slab_scene.CAMERA.format(cam_y=0, cam_rx=0)  # at the origin, looking down -Z

@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_mesh_light_is_its_surface_emission(slab_renders, integrator):
    """UsdLux MeshLightAPI on the panel (intensity 256, normalize, area 256) renders as the panel
    with emissiveColor 1 (core/translate/light.h, kind "mesh")."""
    assert_agree(slab_renders["mesh_light", integrator], slab_renders["plane", integrator],
                 "%s: MeshLightAPI panel vs emissiveColor panel" % integrator)


@pytest.mark.parametrize("bad,severity,attribute", [
    ("float inputs:intensity = nan", "error", "inputs:intensity"),
    ('float inputs:intensity = 256\n    uniform token light:materialSyncMode = "glow"', "warning",
     "light:materialSyncMode"),
])
def test_a_mesh_light_with_unusable_values_is_named_and_the_render_goes_on(tmp_path, bad, severity, attribute):
    """inputs:intensity = nan on a MeshLightAPI mesh: an error naming the prim and the attribute, and
    the mesh stays plain geometry; an unknown materialSyncMode: a warning, the default used.  The
    render goes on, finite."""
    from pxr import Usd

    from volphoton import usdscene

    panel = MESH_LIGHT_PLANE.replace("float inputs:intensity = 256", bad)
    path = stage_file(tmp_path, "bad_mesh_light", BELOW + slab_scene.SLAB + GROUND + emissive_material("glow", 0.0) + panel)
    sc = usdscene.translate(Usd.Stage.Open(path), Usd.TimeCode.Default(), RES, RES, "/World/cam")
    named = [d for d in sc.diagnostics if d.prim_path == "/World/panel"]
    assert any(d.severity == severity and d.attribute == attribute for d in named), sc.diagnostics
    assert any(m.prim_path == "/World/panel" for m in sc.meshes)  # still geometry
    m, _ = slab_scene.mean_and_error(slab_scene.pass_means(path, "pathTracer", RES, (1,), 4, allow_errors=True))
    if severity == "error":
        assert m < 0.05, m  # no light left in the scene
    else:
        assert 0.3 < m < 1, m  # lit by the panel, as with the default mode


def fog_cube(size, density, albedo):
    """An index-matched Cube of fog centred on the origin (usda text)."""
    return textwrap.dedent('''\
        def Cube "fog" (
            prepend apiSchemas = ["VolPhotonMediumAPI"]
        )
        {
            double size = %g
            float volphoton:ior = 1
            float volphoton:density = %g
            color3f volphoton:albedo = (%g, %g, %g)
        }
        ''') % (size, density, albedo, albedo, albedo)


FURNACE = CENTRE + fog_cube(5, 4, 1)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_white_furnace_inside_an_emissive_enclosure(tmp_path, integrator):
    """Fog of albedo 1 (mean free path 0.25) filling an emissive sphere of radius 2 (radiance 1,
    albedo 0) that faces in: radiance 1 everywhere inside.  The photon map's kernel (radius 1/100 of
    the media's diameter, 0.087 here) misses photons where it reaches past the enclosure's wall, but
    the camera sees into the fog no deeper than a few mean free paths, about 1.5 units from the wall:
    an allowance of 0.005 on top of K sigma for the photon map (measured 1.024 +- 0.012), none for
    the path tracer (measured 1.0011 +- 0.0013)."""
    path = stage_file(tmp_path, "furnace", FURNACE + emissive_material("glow", 1.0) +
                      sphere_mesh("enclosure", 2.0, True, "/World/glow"))
    m, se = pass_means(path, integrator)
    allowance = 0.005 if integrator == "photonMap" else 0.0
    print("%s furnace: %.5f +- %.5f" % (integrator, m, se))
    assert abs(m - 1.0) <= K * se + allowance, (m, se)


SMALL_SPHERE = CENTRE + fog_cube(6, 0.3, 0.9) + '''def Mesh "floor"
{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 3, 2, 1]
    point3f[] points = [(-3, -1, -3), (3, -1, -3), (3, -1, 3), (-3, -1, 3)]
    color3f[] primvars:displayColor = [(0.5, 0.5, 0.5)]
}
'''


def test_light_sampling_of_an_emissive_sphere_keeps_the_mean(tmp_path):
    """A small emissive sphere (radius 0.1, radiance 50) in fog over a grey floor, behind the camera
    (every pixel is scattered light), path tracer: with the sphere sampled as a light (next-event
    estimation, MIS with hits) and with hits only, the same mean (a wrong MIS weight or light
    density shifts it)."""
    body = SMALL_SPHERE + emissive_material("glow", 50.0) + sphere_mesh("bulb", 0.1, False, "/World/glow",
                                                                         center=(0.2, 0.3, 0.6))
    path = stage_file(tmp_path, "bulb", body)
    nee = pass_means(path, "pathTracer", True, seeds=(1, 2, 3, 4), passes=32)
    hits = pass_means(path, "pathTracer", False, seeds=(1, 2, 3, 4), passes=32)
    assert nee[0] > 0.01, nee
    assert_agree(nee, hits, "emissive sphere: light sampling vs hits only")
    # Light sampling is the point: at equal samples its error is well below hit-only's.
    assert nee[1] < 0.5 * hits[1], (nee, hits)
