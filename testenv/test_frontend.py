"""Tests of the usd-core front end: the bindings (volphoton._core), the USD -> core translation
(volphoton.usdscene), the OCIO/EXR output and the ``volphoton`` command's behaviour on good and bad
input.  Pictures and statistics of renders are in test_render.py.

Run:  cd /work/main && . .venv/bin/activate && pip install --no-build-isolation -e . \
      && python -m pytest testenv -q
"""

import json
import math
import os
import textwrap

import numpy as np
import pytest

from conftest import REPO, TESTENV, run_cli, usda, volphoton_exe

from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux  # noqa: E402  (after conftest set the plug-in path)

import volphoton  # noqa: E402
from volphoton import _core, cli, output, usdscene  # noqa: E402


HEADER = '#usda 1.0\n(\n    metersPerUnit = 1\n    upAxis = "Y"\n)\n'


def stage_from(tmp_path, body, name="scene.usda", header=HEADER):
    path = tmp_path / name
    path.write_text(header + usda(textwrap.dedent(body)))
    stage = Usd.Stage.Open(str(path))
    assert stage, path
    return stage, path


def world_points(scene_desc, mesh_index):
    """World-space points of every instance of a core mesh."""
    m = scene_desc.mesh(mesh_index)
    out = []
    for inst in scene_desc.instances:
        if inst.mesh == mesh_index:
            t = inst.transform
            out.append(m.points @ t[:3, :3].T + t[:3, 3])
    return out


def diag_text(diags):
    return "\n".join(str(d) for d in diags)


# ------------------------------------------------------------------------------------------------
# Package and bindings
# ------------------------------------------------------------------------------------------------


def test_console_script_and_version():
    exe = volphoton_exe()
    assert os.access(exe, os.X_OK)
    r = run_cli("--version")
    assert r.returncode == 0 and volphoton.__version__ in r.stdout
    r = run_cli("render", "--help")
    assert r.returncode == 0
    for opt in ("--camera", "--resolution", "--spp", "--integrator", "--frames", "--seed", "--stats", "--png",
                "--threads", "--photons", "--max-depth", "--quiet", "OpenCue", "Deadline", "Tractor"):
        assert opt in r.stdout, opt


def test_schema_plugin_is_found_and_registered():
    assert volphoton.find_usd_plugin_dir(include_source_tree=True) is not None
    assert volphoton.plugin_dirs_on_path(), os.environ.get("PXR_PLUGINPATH_NAME")
    assert Usd.SchemaRegistry().FindAppliedAPIPrimDefinition("VolPhotonMediumAPI") is not None


def test_installed_package_registers_plugin_without_env(tmp_path):
    """A fresh interpreter with no PXR_PLUGINPATH_NAME: `volphoton render` still knows the schema
    (the packaged or source-tree plug-in is registered before pxr is imported)."""
    stage, path = stage_from(tmp_path, """
        def Volume "fog" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            float volphoton:density = 0.5
        }
        def DomeLight "d" {}
    """)
    r = run_cli("check", path, drop_env=("PXR_PLUGINPATH_NAME",))
    assert "PXR_PLUGINPATH_NAME" not in r.stdout + r.stderr, r.stdout + r.stderr
    assert "is not registered" not in r.stdout + r.stderr


def test_bindings_types_and_errors():
    hg = _core.henyey_greenstein_phase(0.5)
    assert hg.mean_cosine() == pytest.approx(0.5, abs=1e-9)
    mix = _core.mixture_phase([(1.0, hg), (1.0, _core.isotropic_phase())])
    assert mix.mean_cosine() == pytest.approx(0.25, abs=1e-6)
    c = _core.MediumCoefficients.fromAlbedo(2.0, (1, 0.5, 0.25), (0.5, 0.5, 1.0), (0, 0, 0), hg)
    assert c.sigma_t == pytest.approx((2.0, 1.0, 0.5))
    assert c.sigma_s == pytest.approx((1.0, 0.5, 0.5))
    med = _core.HomogeneousMedium(c, ((0, 0, 0), (1, 1, 1)))
    assert med.properties((0.5, 0.5, 0.5))["sigma_t"] == pytest.approx((2.0, 1.0, 0.5))
    assert med.properties((2, 2, 2))["sigma_t"] == (0.0, 0.0, 0.0)
    assert med.bounds() == ((0, 0, 0), (1, 1, 1))
    assert _core.HomogeneousMedium(c).bounds() is None
    with pytest.raises(ValueError):
        _core.henyey_greenstein_phase(float("nan"))
    with pytest.raises(RuntimeError) as e:
        d = _core.GridMediumDesc()
        d.file_path = "/nonexistent/cloud.vdb"
        _core.load_grid_medium(d)
    assert "/nonexistent/cloud.vdb" in str(e.value)
    # a Gf (row-vector) matrix is refused instead of being misread
    with pytest.raises(TypeError):
        _core.rect_light(np.array(Gf.Matrix4d().SetTranslate(Gf.Vec3d(1, 2, 3))), 1, 1, (1, 1, 1))
    m = _core.MeshDesc()
    m.points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    m.indices = np.array([[0, 1, 2]])
    assert m.triangle_count == 1 and m.points.shape == (3, 3) and list(m.indices) == [0, 1, 2]


def test_render_callbacks_cancel_and_exceptions():
    desc = _core.SceneDesc()
    desc.add_light(_core.dome_light((1, 1, 1)))
    cam = _core.CameraDesc()
    desc.camera = cam
    scene = _core.Scene(desc)
    s = _core.RenderSettings()
    s.width, s.height, s.samples_per_pixel = 8, 8, 4
    seen = []
    r = _core.Renderer(scene, s)
    stats = r.render(progress=lambda done, total: seen.append((done, total)))
    assert seen == [(1, 4), (2, 4), (3, 4), (4, 4)] and stats["passes"] == 4 and not stats["cancelled"]
    assert r.film.beauty.shape == (8, 8, 3) and r.film.beauty.dtype == np.float32
    np.testing.assert_allclose(r.film.beauty, 1.0, rtol=0, atol=1e-6)  # camera sees the dome directly
    assert r.film.depth().shape == (8, 8) and np.all(np.isinf(r.film.depth()))
    r2 = _core.Renderer(scene, s)
    assert r2.render(cancel=lambda: True)["cancelled"]

    def boom(done, total):
        raise ZeroDivisionError("from progress")

    with pytest.raises(ZeroDivisionError):
        _core.Renderer(scene, s).render(progress=boom)
    r3 = _core.Renderer(scene, s)
    assert r3.render_pass() and r3.stats["passes"] == 1


def test_diagnostic_sink_receives_core_messages():
    got = []
    _core.set_diagnostic_sink(lambda sev, msg: got.append((sev, msg)))
    try:
        _core.report("warning", "hello from the test")
    finally:
        _core.set_diagnostic_sink(None)
    assert got == [("warning", "hello from the test")]


def test_exr_round_trip(tmp_path):
    h, w = 3, 5
    planes = {"R": np.arange(15, dtype=np.float32).reshape(h, w), "depth.Z": np.full((h, w), np.inf, np.float32)}
    path = str(tmp_path / "a.exr")
    output.write_exr(path, planes, {"volphoton:test": "yes"})
    channels, attrs = output.read_exr(path)
    assert set(channels) == {"R", "depth.Z"}
    np.testing.assert_array_equal(channels["R"], planes["R"])
    assert np.all(np.isinf(channels["depth.Z"]))
    assert attrs["volphoton:test"] == "yes"
    assert not [f for f in os.listdir(tmp_path) if f.startswith(".")], "temporary file left behind"


def _srgb(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def test_builtin_ocio_display_is_the_srgb_curve():
    t = output.display_transform("", "", config="")
    assert (t.display, t.view, t.input_colorspace) == ("sRGB", "Standard", "Linear Rec.709 (sRGB)")
    x = np.linspace(0, 1.2, 241, dtype=np.float32)
    rgb = np.stack([x, x, x], axis=-1)[None]
    disp = t.apply(rgb)[0, :, 0]
    # OCIO's ExponentWithLinear(2.4, 0.055) is the continuous form of the IEC curve: < 0.1% apart
    np.testing.assert_allclose(np.clip(disp, 0, 1), _srgb(x), atol=1e-3)
    u8 = t.to_uint8(rgb)[0, :, 0].astype(int)
    assert np.max(np.abs(u8 - np.round(_srgb(x) * 255))) <= 1
    assert t.to_uint8(np.array([[[0.18, np.nan, 5.0]]], np.float32)).tolist() == [[[118, 0, 255]]]
    raw = _core.DisplayTransform("", "sRGB", "Raw")
    np.testing.assert_allclose(raw.apply(rgb)[0, :, 0], x, atol=1e-6)
    with pytest.raises(ValueError):
        _core.DisplayTransform("", "NoSuchDisplay", "")


OCIO_CONFIG = """\
ocio_profile_version: 2

roles:
  scene_linear: lin
  default: lin
  reference: lin

displays:
  TestDisplay:
    - !<View> {name: Square, colorspace: sq}
    - !<View> {name: Linear, colorspace: lin}

colorspaces:
  - !<ColorSpace>
    name: lin
    isdata: false
  - !<ColorSpace>
    name: sq
    isdata: false
    from_scene_reference: !<ExponentTransform> {value: [2, 2, 2, 1], direction: inverse}
"""


def test_ocio_env_config_display_and_view(tmp_path):
    cfg = tmp_path / "config.ocio"
    cfg.write_text(OCIO_CONFIG)
    t = _core.DisplayTransform(str(cfg), "TestDisplay", "Square")
    out = t.apply(np.array([[[0.25, 0.5, 1.0]]], np.float32))
    np.testing.assert_allclose(out[0, 0], np.sqrt([0.25, 0.5, 1.0]), atol=1e-5)
    assert _core.ocio_views(str(cfg), "TestDisplay") == ["Square", "Linear"]
    # through the command: $OCIO with --display/--view, and a bad view is a usage error (2)
    scene = os.path.join(TESTENV, "furnace.usda")
    r = run_cli("render", scene, "-o", tmp_path / "f.exr", "--resolution", "16", "16", "--spp", "1", "--quiet",
                "--display", "TestDisplay", "--view", "Linear", env_updates={"OCIO": str(cfg)})
    assert r.returncode == 0, r.stderr
    from PIL import Image

    # The corner pixel sees the dome (radiance 1) past the medium sphere: its rays leave the camera at
    # tan >= 0.297 off the axis, the sphere's silhouette is at tan(asin(1/5)) = 0.204. (At 4x4 the
    # corner pixel reached the sphere, whose 1-sample estimate is not exactly 1.)
    px = np.asarray(Image.open(tmp_path / "f.png"))
    assert px.shape == (16, 16, 3) and abs(int(px[0, 0, 0]) - 255) <= 1  # dome radiance 1, linear view
    r = run_cli("render", scene, "-o", tmp_path / "g.exr", "--resolution", "4", "4", "--spp", "1", "--quiet",
                "--display", "TestDisplay", "--view", "Nope", env_updates={"OCIO": str(cfg)})
    assert r.returncode == 2 and "unknown view 'Nope'" in r.stderr and "Square" in r.stderr
    assert "Traceback" not in r.stderr


# ------------------------------------------------------------------------------------------------
# Round trip: every value read from USD arrives intact in the core scene
# ------------------------------------------------------------------------------------------------


def test_mesh_points_triangulation_and_xform_round_trip(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Xform "World" {
            double3 xformOp:translate.timeSamples = {1: (0, 0, 0), 2: (10, 0, 0)}
            float3 xformOp:rotateXYZ = (10, 20, 30)
            float3 xformOp:scale = (1, 2, 3)
            uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ", "xformOp:scale"]
            def Mesh "m" {
                point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0), (2,0,0)]
                int[] faceVertexCounts = [4, 3, 2]
                int[] faceVertexIndices = [0, 1, 2, 3, 1, 4, 2, 0, 1]
                double3 xformOp:translate = (0, 0, 1)
                uniform token[] xformOpOrder = ["xformOp:translate"]
            }
            def Mesh "left" {
                uniform token orientation = "leftHanded"
                point3f[] points = [(0,0,0), (1,0,0), (0,1,0)]
                int[] faceVertexCounts = [3]
                int[] faceVertexIndices = [0, 1, 2]
            }
        }
    """)
    sc = usdscene.translate(stage, 2.0, 64, 64)
    assert "fewer than 3 vertices" in diag_text(sc.diagnostics)
    recs = {m.prim_path: m for m in sc.meshes}
    m = recs["/World/m"]
    assert m.triangles == 3  # quad -> 2 fan triangles, triangle -> 1, 2-gon dropped
    mesh = sc.desc.mesh(m.mesh_index)
    pts = mesh.points
    tris = pts[mesh.indices.reshape(-1, 3)]
    authored = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0)], float)
    expected_tris = authored[[[0, 1, 2], [0, 2, 3], [1, 4, 2]]]
    np.testing.assert_array_equal(tris, expected_tris)
    # world positions against USD's own transform at time 2
    xf = UsdGeom.XformCache(Usd.TimeCode(2.0)).GetLocalToWorldTransform(stage.GetPrimAtPath("/World/m"))
    (world,) = world_points(sc.desc, m.mesh_index)
    for p, q in zip(pts, world):
        np.testing.assert_allclose(q, np.array(xf.Transform(Gf.Vec3d(*p))), rtol=0, atol=1e-9)
    # leftHanded: winding flipped so the geometric normal is the authored front (-Z here)
    left = sc.desc.mesh(recs["/World/left"].mesh_index)
    a, b, c = left.points[left.indices]
    assert np.cross(b - a, c - a)[2] < 0
    # time samples are evaluated at the requested time
    sc1 = usdscene.translate(stage, 1.0, 64, 64)
    (world1,) = world_points(sc1.desc, [r for r in sc1.meshes if r.prim_path == "/World/m"][0].mesh_index)
    assert np.allclose(world - world1, [10, 0, 0])


def test_normals_vertex_facevarying_and_hard_edges(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Mesh "smooth" {
            point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0)]
            int[] faceVertexCounts = [3, 3]
            int[] faceVertexIndices = [0, 1, 2, 0, 2, 3]
            normal3f[] primvars:normals = [(0,0,1), (0,0,1), (0,0,1), (0,0,1), (0,0,1), (0,0,1)] (interpolation = "faceVarying")
        }
        def Mesh "hard" {
            point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0)]
            int[] faceVertexCounts = [3, 3]
            int[] faceVertexIndices = [0, 1, 2, 0, 2, 3]
            normal3f[] primvars:normals = [(0,0,1), (0,0,1), (0,0,1), (1,0,0), (1,0,0), (1,0,0)] (interpolation = "faceVarying")
        }
        def Mesh "vertex" {
            point3f[] points = [(0,0,0), (1,0,0), (0,1,0)]
            int[] faceVertexCounts = [3]
            int[] faceVertexIndices = [0, 1, 2]
            normal3f[] normals = [(0,0,1), (0,1,0), (1,0,0)] (interpolation = "vertex")
        }
        def DomeLight "d" {}
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 16, 16)
    recs = {m.prim_path: sc.desc.mesh(m.mesh_index) for m in sc.meshes}
    assert recs["/smooth"].points.shape == (4, 3) and np.allclose(recs["/smooth"].normals, [0, 0, 1])
    assert recs["/hard"].points.shape == (6, 3)  # unwelded per corner
    n = recs["/hard"].normals
    assert np.allclose(n[:3], [0, 0, 1]) and np.allclose(n[3:], [1, 0, 0])
    assert np.allclose(recs["/vertex"].normals, [[0, 0, 1], [0, 1, 0], [1, 0, 0]])


def test_implicit_prims_are_closed_and_sized(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Sphere "s" { double radius = 2 }
        def Cube "c" { double size = 3 }
        def Cylinder "y" { double radius = 0.5
                           double height = 4
                           uniform token axis = "X" }
        def Cone "k" { double radius = 1
                       double height = 2 }
        def Plane "p" { double width = 4
                        double length = 2
                        uniform token axis = "Y" }
        def DomeLight "d" {}
    """)
    t = Usd.TimeCode.Default()
    for path, (lo, hi) in {"/s": ((-2, -2, -2), (2, 2, 2)), "/c": ((-1.5,) * 3, (1.5,) * 3),
                           "/y": ((-2, -0.5, -0.5), (2, 0.5, 0.5)), "/k": ((-1, -1, -1), (1, 1, 1)),
                           "/p": ((-2, 0, -1), (2, 0, 1))}.items():
        pts, tris, normals = usdscene.tessellate(stage.GetPrimAtPath(path), t)
        np.testing.assert_allclose(pts.min(axis=0), lo, atol=1e-9, err_msg=path)
        np.testing.assert_allclose(pts.max(axis=0), hi, atol=1e-9, err_msg=path)
        if path != "/p":
            assert usdscene._closed_edges_report(tris) == 0, path
            # outward winding: positive signed volume
            a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
            assert np.einsum("ij,ij->i", a, np.cross(b, c)).sum() > 0, path
    pts, tris, _ = usdscene.tessellate(stage.GetPrimAtPath("/p"), t)
    a, b, c = pts[tris[0]]
    assert np.cross(b - a, c - a)[1] > 0  # plane faces +axis


def test_light_emission_round_trip(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def RectLight "rect" {
            float inputs:width = 2
            float inputs:height = 0.5
            float inputs:intensity = 3
            float inputs:exposure = 1
            color3f inputs:color = (1, 0.5, 0.25)
            bool inputs:normalize = 1
            double3 xformOp:translate = (0, 5, 0)
            float3 xformOp:scale = (2, 1, 1)
            uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
        }
        def RectLight "rectRaw" {
            float inputs:width = 2
            float inputs:height = 0.5
            float inputs:intensity = 3
        }
        def DiskLight "disk" {
            float inputs:radius = 0.5
            float inputs:intensity = 2
            bool inputs:normalize = 1
        }
        def SphereLight "sphere" {
            float inputs:radius = 0.25
            float inputs:intensity = 10
            float inputs:exposure = -1
            bool inputs:normalize = 1
            double3 xformOp:translate = (1, 2, 3)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def SphereLight "point" {
            float inputs:radius = 0.5
            bool treatAsPoint = 1
            float inputs:intensity = 4
        }
        def SphereLight "spot" (prepend apiSchemas = ["ShapingAPI"]) {
            float inputs:radius = 0
            float inputs:intensity = 7
            float inputs:shaping:cone:angle = 30
            float inputs:shaping:cone:softness = 0.25
            float3 xformOp:rotateXYZ = (-90, 0, 0)
            uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
        }
        def DistantLight "sunNorm" {
            float inputs:intensity = 5
            bool inputs:normalize = 1
            float inputs:angle = 2
        }
        def DistantLight "sunRaw" {
            float inputs:intensity = 5
            float inputs:angle = 2
        }
        def DomeLight "dome" {
            float inputs:intensity = 0.5
            color3f inputs:color = (0.2, 0.4, 0.8)
        }
        def DomeLight "warm" {
            bool inputs:enableColorTemperature = 1
            float inputs:colorTemperature = 3000
        }
        def CylinderLight "tube" {}
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 16, 16)
    L = {l.prim_path: l for l in sc.lights}
    assert "/tube" not in L and "CylinderLight lights are not supported" in diag_text(sc.diagnostics)
    # rect: s = 3 * 2^1 * color, normalize divides by the world area 2 * 0.5 * (x scale 2) = 2
    rect = L["/rect"]
    assert rect.kind == "rect" and rect.quantity == "radiance" and rect.params["area"] == pytest.approx(2.0)
    assert rect.emission == pytest.approx((3.0, 1.5, 0.75))
    assert rect.light.power() == pytest.approx(tuple(math.pi * 2.0 * e for e in rect.emission))
    assert L["/rectRaw"].emission == pytest.approx((3, 3, 3))  # not normalized
    assert L["/disk"].emission == pytest.approx((2 / (math.pi * 0.25),) * 3)
    sph = L["/sphere"]
    area = 4 * math.pi * 0.25 ** 2
    assert sph.kind == "sphere" and sph.emission == pytest.approx((5 / area,) * 3)
    assert sph.params["position"] == pytest.approx((1, 2, 3))
    # sphere power = L * pi * area
    assert sph.light.power()[0] == pytest.approx(5 / area * math.pi * area)
    pt = L["/point"]
    assert pt.kind == "point" and pt.quantity == "intensity" and pt.emission == pytest.approx((4 * math.pi * 0.25,) * 3)
    spot = L["/spot"]
    assert spot.kind == "spot" and spot.emission == pytest.approx((7, 7, 7))
    assert spot.params["cone_angle"] == pytest.approx(math.radians(30))
    assert spot.params["cone_softness"] == pytest.approx(0.25)
    assert spot.params["axis"] == pytest.approx((0, -1, 0), abs=1e-6)
    half = math.radians(1.0)
    assert L["/sunNorm"].emission == pytest.approx((5, 5, 5)) and L["/sunNorm"].params["half_angle"] == pytest.approx(half)
    assert L["/sunRaw"].emission == pytest.approx((5 * math.pi * math.sin(half) ** 2,) * 3)
    assert L["/sunNorm"].params["direction"] == pytest.approx((0, 0, -1))
    assert L["/dome"].emission == pytest.approx((0.1, 0.2, 0.4))
    bb = UsdLux.BlackbodyTemperatureAsRgb(3000)
    assert L["/warm"].emission == pytest.approx(tuple(bb), rel=1e-6)
    assert L["/warm"].emission[0] > L["/warm"].emission[2]


def test_camera_round_trip_and_aperture_conform(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Camera "cam" {
            float focalLength = 35
            float horizontalAperture = 36
            float verticalAperture = 24
            float fStop = 2.8
            float focusDistance = 5
            float2 clippingRange = (0.5, 200)
            double3 xformOp:translate = (1, 2, 3)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def Camera "ortho" {
            token projection = "orthographic"
            float horizontalAperture = 40
            float verticalAperture = 20
        }
        def Sphere "far" {
            double3 xformOp:translate = (0, 0, -500)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def DomeLight "d" {}
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 300, 200, "/cam")
    cam = sc.camera
    assert cam.prim_path == "/cam"
    assert sc.desc.camera.tan_half_fov_x == pytest.approx(18 / 35)
    # lensRadius = focal length in scene units (35 tenths = 3.5) / (2 * fStop)
    assert sc.desc.camera.lens_radius == pytest.approx(3.5 / 5.6)
    assert sc.desc.camera.focus_distance == pytest.approx(5)
    # the far plane clips /far (500 units away), so it is kept
    assert (sc.desc.camera.near_clip, sc.desc.camera.far_clip) == pytest.approx((0.5, 200))
    assert sc.desc.camera.camera_to_world[:3, 3] == pytest.approx((1, 2, 3))
    # the core camera spans exactly that field of view: the ray through the right image edge
    pinhole = sc.desc.camera
    pinhole.lens_radius = 0.0
    c = _core.Camera(pinhole, 300, 200)
    _, d, _, _ = c.generate_ray(300, 100)
    assert -d[0] / d[2] == pytest.approx(18 / 35, rel=1e-9)
    # expandAperture: a wider image widens the horizontal aperture to 24 * 3 = 72
    wide = usdscene.translate(stage, Usd.TimeCode.Default(), 600, 200, "/cam")
    assert wide.desc.camera.tan_half_fov_x == pytest.approx(36 / 35)
    narrow = usdscene.translate(stage, Usd.TimeCode.Default(), 200, 200, "/cam")
    assert narrow.desc.camera.tan_half_fov_x == pytest.approx(18 / 35)
    ortho = usdscene.translate(stage, Usd.TimeCode.Default(), 200, 100, "/ortho")
    # the clipping range is kept as authored (the core shows the dome past the far plane)
    assert ortho.desc.camera.far_clip == pytest.approx(1e6) and ortho.desc.camera.near_clip == pytest.approx(1)
    assert ortho.desc.camera.projection == _core.CameraDesc.Projection.Orthographic
    assert ortho.desc.camera.ortho_width == pytest.approx(4.0)  # 40 tenths of a unit
    # without cameras: a default framing camera, with a warning
    stage2, _ = stage_from(tmp_path, 'def Sphere "s" {}\ndef DomeLight "d" {}\n', name="nocam.usda")
    sc2 = usdscene.translate(stage2, Usd.TimeCode.Default(), 64, 64)
    assert sc2.camera.prim_path is None and "no camera" in diag_text(sc2.diagnostics)
    eye = np.array(sc2.camera.params["eye"])
    hit = _core.Scene(sc2.desc).intersect(tuple(eye), tuple(-eye))
    assert hit is not None  # it looks at the sphere


def test_medium_coefficients_round_trip(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Volume "fog" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            float volphoton:density = 2
            color3f volphoton:albedo = (0.5, 0.25, 1)
            color3f volphoton:extinctionColor = (1, 2, 0.5)
            color3f volphoton:emission = (0.1, 0.2, 0.3)
            float volphoton:emissionScale = 2
            point3f volphoton:bounds:min = (-1, -1, -1)
            point3f volphoton:bounds:max = (1, 1, 1)
            double3 xformOp:translate = (10, 0, 0)
            float3 xformOp:scale = (2, 1, 1)
            uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
        }
        def Volume "air" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            float volphoton:density = 0.5
            uniform token volphoton:densityMode = "exponential"
            float volphoton:exponential:a = 2
            float volphoton:exponential:b = 0.5
            point3f volphoton:exponential:origin = (0, 1, 0)
            float3 xformOp:scale = (1, 2, 1)
            uniform token[] xformOpOrder = ["xformOp:scale"]
        }
        def Cube "jelly" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            float volphoton:density = 3
            float volphoton:ior = 1.33
            uniform token volphoton:phase = "rayleigh"
        }
        def Sphere "clear" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            float volphoton:density = 1
            double3 xformOp:translate = (0, 0, 10)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def DomeLight "d" {}
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 16, 16)
    assert not sc.errors, diag_text(sc.errors)
    M = {m.prim_path: m for m in sc.media}
    fog = M["/fog"]
    assert fog.kind == "homogeneous" and fog.unbounded and fog.index in list(sc.desc.unbounded_media)
    # bounds: prim-space box (-1..1) through scale (2,1,1) and translate (10,0,0)
    lo, hi = fog.medium.bounds()
    assert lo == pytest.approx((8, -1, -1)) and hi == pytest.approx((12, 1, 1))
    p = fog.medium.properties((10, 0, 0))
    assert p["sigma_t"] == pytest.approx((2, 4, 1))
    assert p["sigma_s"] == pytest.approx((1, 1, 1))
    assert p["emission"] == pytest.approx((0.2, 0.4, 0.6))
    assert fog.medium.properties((13, 0, 0))["sigma_t"] == (0, 0, 0)
    air = M["/air"]
    assert air.kind == "exponential"
    # origin (0,1,0) in prim space is (0,2,0) in world; b = 0.5 per prim unit = 0.25 per world unit
    for y in (2.0, 4.0, 10.0):
        expected = 0.5 * 2 * math.exp(-0.25 * (y - 2.0))
        assert air.medium.properties((0, y, 0))["sigma_t"][1] == pytest.approx(expected, rel=1e-9)
    jelly = M["/jelly"]
    assert not jelly.unbounded and jelly.mesh_index >= 0
    mesh = sc.desc.mesh(jelly.mesh_index)
    assert mesh.interior_medium == jelly.index
    assert mesh.material.kind == _core.SurfaceMaterial.Kind.Dielectric and mesh.material.ior == pytest.approx(1.33, rel=1e-6)
    assert jelly.medium.properties((0, 0, 0))["sigma_t"] == pytest.approx((3, 3, 3))
    clear = sc.desc.mesh(M["/clear"].mesh_index)
    assert clear.material.kind == _core.SurfaceMaterial.Kind.Boundary


def test_preset_replaces_coefficients(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Sphere "ball" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            uniform token volphoton:preset = "marble"
            float volphoton:sceneUnitsPerMm = 0.1
        }
        def Sphere "odd" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            uniform token volphoton:preset = "unobtainium"
            double3 xformOp:translate = (5, 0, 0)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def DomeLight "d" {}
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 16, 16)
    ball = [m for m in sc.media if m.prim_path == "/ball"][0]
    ss, sa = usdscene.PRESETS["marble"]
    p = ball.medium.properties((0, 0, 0))
    assert p["sigma_t"] == pytest.approx(tuple((a + b) / 0.1 for a, b in zip(ss, sa)), rel=1e-6)
    assert p["sigma_s"] == pytest.approx(tuple(a / 0.1 for a in ss), rel=1e-6)
    assert "/odd.volphoton:preset: unknown preset 'unobtainium'" in diag_text(sc.diagnostics)


def test_phase_mapping_including_tabulated_and_mixture(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Volume "mix" (prepend apiSchemas = ["VolPhotonMediumAPI", "VolPhotonPhaseLobeAPI:fwd", "VolPhotonPhaseLobeAPI:back"]) {
            uniform token volphoton:phase = "mixture"
            float volphoton:lobe:fwd:weight = 3
            float volphoton:lobe:fwd:g = 0.8
            float volphoton:lobe:back:weight = 1
            uniform token volphoton:lobe:back:phase = "tabulated"
            float[] volphoton:lobe:back:table = [2, 0]
        }
    """)
    md, diags = volphoton.schema.read_medium(stage.GetPrimAtPath("/mix"), Usd.TimeCode.Default())
    assert not diags
    ph = _core.build_phase(md.core.phase)
    # tabulated [2, 0]: p ~ (1 - cos)/... has mean cosine -1/3; HG mean cosine 0.8
    assert ph.mean_cosine() == pytest.approx(0.75 * 0.8 + 0.25 * (-1 / 3), abs=1e-3)


def test_scene_graph_and_point_instancing(tmp_path):
    stage, _ = stage_from(tmp_path, """
        class Xform "proto" {
            def Mesh "tri" {
                point3f[] points = [(0,0,0), (1,0,0), (0,1,0)]
                int[] faceVertexCounts = [3]
                int[] faceVertexIndices = [0, 1, 2]
            }
        }
        def Xform "a" (
            instanceable = true
            references = </proto>
        ) {
            double3 xformOp:translate = (5, 0, 0)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def Xform "b" (
            instanceable = true
            references = </proto>
        ) {
            double3 xformOp:translate = (0, 5, 0)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def PointInstancer "pi" {
            rel prototypes = [</pi/protos/cube>, </pi/protos/ball>]
            int[] protoIndices = [0, 1, 0, 1, 0]
            point3f[] positions = [(0,0,0), (2,0,0), (4,0,0), (6,0,0), (8,0,0)]
            int64[] invisibleIds = [4]
            double3 xformOp:translate = (0, 0, -10)
            uniform token[] xformOpOrder = ["xformOp:translate"]
            def Scope "protos" {
                def Cube "cube" {
                    double size = 1
                    double3 xformOp:translate = (0, 1, 0)
                    uniform token[] xformOpOrder = ["xformOp:translate"]
                }
                def Sphere "ball" { double radius = 0.5 }
            }
        }
        def DomeLight "d" {}
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 16, 16)
    tri = [m for m in sc.meshes if m.prim_path.endswith("/tri")]
    assert len(tri) == 1, "one mesh for the prototype, shared by both instances"
    worlds = sorted(tuple(w[0]) for w in world_points(sc.desc, tri[0].mesh_index))
    assert worlds == [(0.0, 5.0, 0.0), (5.0, 0.0, 0.0)]
    cube = [m for m in sc.meshes if m.prim_path == "/pi/protos/cube"]
    ball = [m for m in sc.meshes if m.prim_path == "/pi/protos/ball"]
    assert len(cube) == 1 and len(ball) == 1
    assert len(cube[0].instance_indices) == 2  # instance 4 is invisible (masked)
    assert len(ball[0].instance_indices) == 2
    centers = sorted(tuple(np.round(w.mean(axis=0), 6)) for w in world_points(sc.desc, cube[0].mesh_index))
    # prototype root transform (y + 1) is included, then the instance position, then the instancer
    assert centers == [(0.0, 1.0, -10.0), (4.0, 1.0, -10.0)]


def test_materials_preview_surface_subsets_and_display_color(tmp_path):
    stage, _ = stage_from(tmp_path, """
        def Material "red" {
            token outputs:surface.connect = </red/pbs.outputs:surface>
            def Shader "pbs" {
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = (0.8, 0.1, 0.1)
                color3f inputs:emissiveColor = (0, 0, 2)
                token outputs:surface
            }
        }
        def Material "glass" {
            token outputs:surface.connect = </glass/pbs.outputs:surface>
            def Shader "pbs" {
                uniform token info:id = "UsdPreviewSurface"
                float inputs:opacity = 0
                float inputs:ior = 1.45
                token outputs:surface
            }
        }
        def Material "invisible" {
            token outputs:surface.connect = </invisible/pbs.outputs:surface>
            def Shader "pbs" {
                uniform token info:id = "UsdPreviewSurface"
                float inputs:opacity = 0
                token outputs:surface
            }
        }
        def Mesh "two" (prepend apiSchemas = ["MaterialBindingAPI"]) {
            point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0), (2,0,0), (2,1,0)]
            int[] faceVertexCounts = [4, 4]
            int[] faceVertexIndices = [0, 1, 2, 3, 1, 4, 5, 2]
            rel material:binding = </red>
            def GeomSubset "right" (prepend apiSchemas = ["MaterialBindingAPI"]) {
                uniform token elementType = "face"
                uniform token familyName = "materialBind"
                int[] indices = [1]
                rel material:binding = </glass>
            }
        }
        def Sphere "ghost" (prepend apiSchemas = ["MaterialBindingAPI"]) { rel material:binding = </invisible> }
        def Sphere "painted" { color3f[] primvars:displayColor = [(0.2, 0.6, 0.4)] }
        def Sphere "plain" {}
        def DomeLight "d" {}
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 16, 16)
    by = {}
    for m in sc.meshes:
        by.setdefault(m.prim_path, []).append(sc.desc.mesh(m.mesh_index))
    two = sorted(by["/two"], key=lambda m: m.material.kind.value)
    assert len(two) == 2
    assert two[0].material.kind == _core.SurfaceMaterial.Kind.Lambertian
    assert two[0].material.albedo == pytest.approx((0.8, 0.1, 0.1), rel=1e-6)
    assert two[0].material.emission == pytest.approx((0, 0, 2))
    assert two[1].material.kind == _core.SurfaceMaterial.Kind.Dielectric
    assert two[1].material.ior == pytest.approx(1.45, rel=1e-6)
    assert "/ghost" not in by  # opacity 0 without an ior: not rendered
    assert by["/painted"][0].material.albedo == pytest.approx((0.2, 0.6, 0.4), rel=1e-6)
    assert by["/plain"][0].material.albedo == pytest.approx(usdscene.DEFAULT_ALBEDO)


def test_render_settings_prim_and_priority(tmp_path):
    stage, path = stage_from(tmp_path, """
        def Scope "Render" {
            def RenderSettings "rs" {
                int2 resolution = (20, 10)
                rel camera = </cam2>
                int volphoton:samplesPerPixel = 3
                int volphoton:maxDepth = 7
                token volphoton:integrator = "photonMap"
                float volphoton:bogus = 1
            }
        }
        def Camera "cam1" {}
        def Camera "cam2" { double3 xformOp:translate = (0, 0, 9)
                            uniform token[] xformOpOrder = ["xformOp:translate"] }
        def DomeLight "d" {}
    """)
    info = usdscene.read_render_settings(stage)
    assert info.prim_path == "/Render/rs" and info.resolution == (20, 10) and info.camera_path == "/cam2"
    assert info.overrides == {"samplesPerPixel": 3, "maxDepth": 7, "integrator": "photonMap"}
    assert "/Render/rs.volphoton:bogus: unknown render setting" in diag_text(info.diagnostics)
    stats = tmp_path / "s.json"
    r = run_cli("render", path, "-o", tmp_path / "o.exr", "--quiet", "--stats", stats)
    assert r.returncode == 0, r.stderr
    st = json.loads(stats.read_text())["frames"][0]
    assert st["settings"]["width"] == 20 and st["settings"]["height"] == 10
    assert st["settings"]["samplesPerPixel"] == 3 and st["settings"]["maxDepth"] == 7
    assert st["settings"]["integrator"] == "photonMap" and st["camera"] == "/cam2"
    # the command line wins
    r = run_cli("render", path, "-o", tmp_path / "o.exr", "--quiet", "--stats", stats, "--resolution", "8", "6",
                "--spp", "2", "--camera", "/cam1", "--integrator", "pathtracer", "--max-depth", "5", "--seed", "9")
    assert r.returncode == 0, r.stderr
    st = json.loads(stats.read_text())["frames"][0]
    assert (st["settings"]["width"], st["settings"]["height"], st["settings"]["samplesPerPixel"]) == (8, 6, 2)
    assert st["settings"]["integrator"] == "pathTracer" and st["camera"] == "/cam1"
    assert st["settings"]["maxDepth"] == 5 and st["settings"]["seed"] == 9


# A cube of dense medium filling the middle of the view under a sphere light; %s: its ior (1.3: a
# translucent object behind a refracting surface, 1: an open medium).
MEDIUM_CUBE = """
        def Cube "marble" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            double size = 1.6
            float volphoton:density = 8
            float volphoton:ior = %s
        }
        def SphereLight "lamp" { float inputs:radius = 0.3
                                 double3 xformOp:translate = (1.5, 2, 1.5)
                                 uniform token[] xformOpOrder = ["xformOp:translate"] }
        def Camera "cam" { double3 xformOp:translate = (0, 0, 6)
                           uniform token[] xformOpOrder = ["xformOp:translate"] }
"""


@pytest.mark.parametrize("ior,density,chosen,prefix", [("1.3", 8, "combined", ""), ("1", 8, "pathTracer", ""),
                                                       ("1", 0.2, "combined", "open media by the photon map (beams): ")])
def test_integrator_auto_reports_its_choice(tmp_path, ior, density, chosen, prefix):
    """--integrator auto: a cube of dense medium filling the middle of the view, translucent behind an
    n = 1.3 surface (the combined integrator) or an open medium (ior 1: the path tracer), or a cube of
    thin fog lit by the sphere light alone (combined, whose camera segments in the fog are the photon
    map's with beams); the stats and the log line say which integrator rendered and why (core
    chooseIntegrator)."""
    stage, path = stage_from(tmp_path, (MEDIUM_CUBE % ior).replace("density = 8", "density = %g" % density))
    stats = tmp_path / "s.json"
    r = run_cli("render", path, "-o", tmp_path / "o.exr", "--stats", stats, "--resolution", "16", "12", "--spp", "1",
                "--integrator", "auto", "--photons", "2000")
    assert r.returncode == 0, r.stderr
    st = json.loads(stats.read_text())["frames"][0]
    assert st["settings"]["integrator"] == "auto"
    assert st["render"]["integrator_used"] == chosen
    reason = st["render"]["integrator_reason"]
    assert reason.startswith(prefix + "translucent objects cover") and "of the view, open media" in reason, reason
    assert "auto: %s (%s)" % (chosen, reason) in r.stderr + r.stdout
    assert (st["render"]["photons_traced"] > 0) == (chosen == "combined"), st["render"]


def test_integrator_combined_renders_through_the_cli(tmp_path):
    """--integrator combined: path-traced camera paths, and inside a translucent object (a dielectric
    with a medium inside, where no shadow ray reaches a light) the photon map's multiple scattering;
    the stats say so, with the photons traced and the open-media share (default -1: automatic, here 0)."""
    stage, path = stage_from(tmp_path, MEDIUM_CUBE % "1.3")
    stats = tmp_path / "s.json"
    r = run_cli("render", path, "-o", tmp_path / "o.exr", "--stats", stats, "--resolution", "16", "12", "--spp", "2",
                "--integrator", "combined", "--photons", "2000")
    assert r.returncode == 0, r.stderr
    st = json.loads(stats.read_text())["frames"][0]
    assert st["settings"]["integrator"] == "combined" and st["settings"]["combinedPhotonShare"] == -1.0
    assert st["render"]["integrator_used"] == "combined"
    # The automatic share asks auto's pilot, which keeps open media to the path tracer here, and says so.
    assert st["render"]["integrator_reason"].startswith("open media by the path tracer: translucent objects cover")
    assert "combined (open media by the path tracer: " in r.stderr + r.stdout, r.stderr
    assert st["render"]["photons_traced"] > 0 and st["render"]["photons_stored"] > 0
    assert "single scattering (path-traced: combined)" in st["render"]["passes_run"]
    assert "multiple scattering (photons)" in st["render"]["passes_run"]


def test_the_measured_choice_through_the_cli(tmp_path):
    """--integrator combined at 16 passes with the automatic photon count: passes 1-2 use the photons
    inside the translucent cube, 3-4 the path tracer, and the cheaper renders the rest (core
    Renderer::decideTrial); the stats carry both costs and the reason says what was kept. Short renders
    and explicit photon counts are not measured (choose_integrator: at 16 passes auto tries the photons
    on the open cube too, at 1 pass its size rule keeps the path tracer)."""
    stage, path = stage_from(tmp_path, MEDIUM_CUBE % "1.3")
    stats = tmp_path / "s.json"
    r = run_cli("render", path, "-o", tmp_path / "o.exr", "--stats", stats, "--resolution", "16", "12", "--spp", "16",
                "--integrator", "combined")
    assert r.returncode == 0, r.stderr
    st = json.loads(stats.read_text())["frames"][0]["render"]
    photons, paths = st["measured_photon_cost"], st["measured_path_tracer_cost"]
    assert photons > 0, st
    reason = st["integrator_reason"]
    assert "measured on passes 1-4" in reason, reason
    if st["integrator_used"] == "pathTracer":
        assert 0 < paths < photons and reason.endswith("the path tracer renders the rest"), reason
    else:
        assert st["integrator_used"] == "combined" and reason.endswith("combined kept"), reason
        assert paths >= photons or "darker than the photons'" in reason, reason
    r = run_cli("render", path, "-o", tmp_path / "o.exr", "--stats", stats, "--resolution", "16", "12", "--spp", "16",
                "--integrator", "combined", "--photons", "2000")
    assert r.returncode == 0, r.stderr
    st = json.loads(stats.read_text())["frames"][0]["render"]
    assert st["measured_photon_cost"] == 0 and st["integrator_used"] == "combined"
    # What auto tries on an open medium of albedo 0.97: the photons when the render will measure them,
    # else the size rule (the path tracer below 128 x 128).
    bright = (MEDIUM_CUBE % "1").replace("float volphoton:density = 8",
                                         "float volphoton:density = 8\n    color3f volphoton:albedo = (0.97, 0.97, 0.97)")
    translated = usdscene.translate(stage_from(tmp_path, bright, name="open.usda")[0], Usd.TimeCode.Default(), 16, 12)
    scene = _core.Scene(translated.desc)
    settings = _core.RenderSettings()
    settings.width, settings.height, settings.integrator = 16, 12, _core.RenderSettings.Integrator.Auto
    for spp, photons_tried in ((1, False), (16, True)):
        settings.samples_per_pixel = spp
        choice = _core.choose_integrator(scene, settings)
        assert choice["open_media_by_photons"] == photons_tried, choice
        assert choice["integrator"] == ("combined" if photons_tried else "pathTracer"), choice
        assert ("kept if they measure cheaper" in choice["reason"]) == photons_tried, choice


# ------------------------------------------------------------------------------------------------
# Frames, stats and the command's errors
# ------------------------------------------------------------------------------------------------


def test_frame_placeholders_and_ranges():
    assert cli.expand_frame("out.####.exr", 7) == "out.0007.exr"
    assert cli.expand_frame("out.#.exr", 12) == "out.12.exr"
    assert cli.expand_frame("out.%04d.exr", 3) == "out.0003.exr"
    assert cli.expand_frame("out.%d.exr", 3) == "out.3.exr"
    assert cli.expand_frame("out.####.exr", -5) == "out.-005.exr"
    assert cli.parse_frames("1:3") == [1, 2, 3]
    assert cli.parse_frames("1:9:4,20") == [1, 5, 9, 20]
    assert cli.parse_frames("-2:-1") == [-2, -1]
    for bad in ("3:1", "a:b", "1:5:0", ""):
        with pytest.raises(cli.UsageError):
            cli.parse_frames(bad)


ANIMATED = """
    def Camera "cam" { double3 xformOp:translate = (0, 0, 4)
                       uniform token[] xformOpOrder = ["xformOp:translate"] }
    def Sphere "ball" { double radius = 1 }
    def DistantLight "sun" {
        float inputs:intensity.timeSamples = {1: 1, 2: 4}
        bool inputs:normalize = 1
    }
"""


def test_frames_render_each_time_code(tmp_path):
    _, path = stage_from(tmp_path, ANIMATED)
    r = run_cli("render", path, "-o", tmp_path / "out.####.exr", "--frames", "1:2", "--resolution", "8", "8",
                "--spp", "2", "--stats", tmp_path / "stats.json", "--quiet")
    assert r.returncode == 0, r.stderr
    means = []
    for f in (1, 2):
        assert (tmp_path / ("out.%04d.png" % f)).exists()
        ch, attrs = output.read_exr(str(tmp_path / ("out.%04d.exr" % f)))
        assert attrs["volphoton:frame"] == str(f)
        means.append(ch["R"].mean())
    assert means[1] == pytest.approx(4 * means[0], rel=1e-5)  # same seed, 4x the light
    stats = json.loads((tmp_path / "stats.json").read_text())
    assert [fr["frame"] for fr in stats["frames"]] == [1, 2]
    assert stats["exit_status"] == 0 and stats["peak_rss_bytes"] > 10 << 20
    fr = stats["frames"][0]
    assert len(fr["passes"]) == 2 and all(p["seconds"] >= 0 for p in fr["passes"])
    assert fr["render"]["camera_samples"] == 8 * 8 * 2
    assert any("no media" in s for s in fr["render"]["passes_skipped"])
    assert fr["render"]["photons_thinned"] == 0 and fr["render"]["photons_radius_capped"] == 0
    assert fr["timings"]["wall_seconds"] > 0 and fr["scene"]["lights"] == 1
    # several frames without a placeholder: usage error
    r = run_cli("render", path, "-o", tmp_path / "out.exr", "--frames", "1:2")
    assert r.returncode == 2 and "placeholder" in r.stderr and "Traceback" not in r.stderr


FOG_SHOT = """
    def Cube "fog" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
        double size = 2
        float volphoton:density = 1.5
        color3f volphoton:albedo = (0.9, 0.8, 0.7)
        rel material:binding = </Fog>
    }
    def Material "Fog" {}
    def SphereLight "lamp" {
        float inputs:radius = 0.1
        float inputs:intensity = 40
        double3 xformOp:translate%(light)s
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
    def Xform "rig" {
        double3 xformOp:translate.timeSamples = {1: (0, 0, 0), 2: (0.4, 0.2, 0), 3: (-0.3, 0.1, 0.2)}
        uniform token[] xformOpOrder = ["xformOp:translate"]
        def Camera "cam" {
            double3 xformOp:translate = (0.2, 0.3, 4)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
    }
"""


def _render_frames(tmp_path, name, light, frames):
    _, path = stage_from(tmp_path, FOG_SHOT % {"light": light}, name=name + ".usda")
    out = tmp_path / name
    r = run_cli("render", path, "-o", out / "f.####.exr", "--frames", frames, "--resolution", "12", "12",
                "--spp", "3", "--integrator", "photonmap", "--camera", "/rig/cam", "--photons", "3000",
                "--stats", out / "stats.json")
    assert r.returncode == 0, r.stderr
    stats = json.loads((out / "stats.json").read_text())
    images = {fr["frame"]: output.read_exr(fr["output"]["exr"])[0]["R"] for fr in stats["frames"]}
    return r, {fr["frame"]: fr["render"] for fr in stats["frames"]}, images


def test_frames_with_only_the_camera_animated_trace_photons_once(tmp_path):
    """--frames over a shot where only the camera moves: frames after the first reuse every photon
    pass (core PhotonCache) and are bit-identical to frames rendered on their own; an animated light
    makes every frame trace its photons, and says why."""
    r, shot, images = _render_frames(tmp_path, "shot", " = (1.5, 0.5, 0.5)", "1:3")
    assert shot[1]["photons_traced"] == 3 * 3000 and shot[1]["photon_passes_reused"] == 0
    for f in (2, 3):
        assert shot[f]["photons_traced"] == 0 and shot[f]["photon_passes_reused"] == 3, shot[f]
        assert shot[f]["photons_reused"] == shot[1]["photons_stored"]
    assert "photon maps of 3 passes reused" in r.stderr
    _, alone, alone_images = _render_frames(tmp_path, "alone", " = (1.5, 0.5, 0.5)", "3")
    assert alone[3]["photons_traced"] == 3 * 3000
    assert np.array_equal(images[3], alone_images[3])
    assert not np.array_equal(images[2], images[3])  # the camera did move

    r, lit, _ = _render_frames(tmp_path, "lit", ".timeSamples = {1: (1.5, 0.5, 0.5), 3: (1.5, -0.5, 0.5)}", "1:2")
    assert all(lit[f]["photons_traced"] == 3 * 3000 and lit[f]["photon_passes_reused"] == 0 for f in (1, 2))
    assert "/lamp.xformOp:translate may vary in time" in r.stderr


def test_only_camera_animation_is_static_content(tmp_path):
    stage, _ = stage_from(tmp_path, FOG_SHOT % {"light": " = (1, 1, 1)"})
    assert usdscene.first_time_varying_content(stage) is None
    # the rig's transform above the camera and geometry: content moves
    stage.DefinePrim("/rig/prop", "Sphere")
    assert usdscene.first_time_varying_content(stage) == "/rig.xformOp:translate"


def one_line_error(r):
    """The command failed with a one-line message and no traceback."""
    assert "Traceback" not in r.stderr, r.stderr
    errors = [l for l in r.stderr.splitlines() if "error" in l]
    assert errors, r.stderr
    return r.stderr


def test_missing_scene_and_bad_options(tmp_path):
    r = run_cli("render", tmp_path / "nope.usda", "-o", tmp_path / "o.exr")
    assert r.returncode == 2
    assert "nope.usda' does not exist" in one_line_error(r)
    assert len(r.stderr.strip().splitlines()) == 1
    r = run_cli("render", os.path.join(TESTENV, "furnace.usda"), "-o", tmp_path / "o.png")
    assert r.returncode == 2 and ".exr" in r.stderr
    r = run_cli("render", os.path.join(TESTENV, "furnace.usda"), "-o", tmp_path / "o.exr", "--spp", "0")
    assert r.returncode == 2
    r = run_cli("render", os.path.join(TESTENV, "furnace.usda"), "-o", tmp_path / "o.exr", "--integrator", "magic")
    assert r.returncode == 2
    bad = tmp_path / "broken.usda"
    bad.write_text("#usda 1.0\ndef Xform \"x\" {\n  this is not usd\n")
    r = run_cli("render", bad, "-o", tmp_path / "o.exr")
    assert r.returncode == 1 and "cannot open scene" in one_line_error(r)
    # A missing output folder is created (farm tasks often write the first frame into a new one) ...
    r = run_cli("render", os.path.join(TESTENV, "furnace.usda"), "-o", tmp_path / "missing_dir" / "o.exr",
                "--resolution", "4", "4", "--spp", "1")
    assert r.returncode == 0 and (tmp_path / "missing_dir" / "o.exr").exists()
    # ... and one that cannot be created is a clear error naming it.
    (tmp_path / "a_file").write_text("x")
    r = run_cli("render", os.path.join(TESTENV, "furnace.usda"), "-o", tmp_path / "a_file" / "o.exr",
                "--resolution", "4", "4", "--spp", "1")
    assert r.returncode == 1 and "a_file" in one_line_error(r)


def render_bad(tmp_path, body, *extra):
    _, path = stage_from(tmp_path, body)
    out = tmp_path / "bad.exr"
    r = run_cli("render", path, "-o", out, "--resolution", "12", "8", "--spp", "2", "--quiet", *extra)
    return r, out


def assert_clean_image(out):
    ch, _ = output.read_exr(str(out))
    for name, plane in ch.items():
        if name != "depth.Z":
            assert np.all(np.isfinite(plane)), name
        else:
            assert not np.any(np.isnan(plane))
    return ch


VOLUME_SCENE = """
    def Camera "cam" { double3 xformOp:translate = (0.5, 0.5, 4)
                       uniform token[] xformOpOrder = ["xformOp:translate"] }
    def DomeLight "d" {}
    def Volume "cloud" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
        float volphoton:density = 2
        rel field:density = </cloud/density>
        def OpenVDBAsset "density" {
            asset filePath = @%s@
            token fieldName = "%s"
        }
    }
"""


def test_missing_vdb_file_names_prim_attribute_and_file(tmp_path):
    r, out = render_bad(tmp_path, VOLUME_SCENE % ("./no_such_cloud.vdb", "density"))
    assert r.returncode == 1
    err = one_line_error(r)
    assert "/cloud/density.filePath" in err and "no_such_cloud.vdb" in err
    assert_clean_image(out)  # the rest of the scene still rendered


def test_wrong_field_name_and_wrong_grid_type(tmp_path, cloud_vdb):
    r, out = render_bad(tmp_path, VOLUME_SCENE % (str(cloud_vdb), "smoke"))
    assert r.returncode == 1
    err = one_line_error(r)
    assert "/cloud/density.fieldName" in err and "smoke" in err and "density" in err  # lists the grids there
    assert_clean_image(out)
    vdb = tmp_path / "typed.vdb"
    _core.write_test_vdb(str(vdb), {"vel": "vec3s", "density": "float"})
    r, out = render_bad(tmp_path, VOLUME_SCENE % (str(vdb), "vel"))
    assert r.returncode == 1
    err = one_line_error(r)
    assert "/cloud/density.fieldName" in err and "vel" in err and "vec3s" in err.lower().replace("vec3<float>", "vec3s")
    assert_clean_image(out)
    # the float grid of the same file loads fine
    r, out = render_bad(tmp_path, VOLUME_SCENE % (str(vdb), "density"))
    assert r.returncode == 0, r.stderr


def test_grid_size_cap_refuses_large_grids_by_option_and_by_render_settings(tmp_path, cloud_vdb):
    """The grid-size cap (issue #6): a grid with more active voxels than the cap is an error naming the
    field's prim, the file, the count and the cap; the rest of the scene renders. The cloud has ~1e5
    active voxels."""
    r, out = render_bad(tmp_path, VOLUME_SCENE % (str(cloud_vdb), "density"), "--max-grid-voxels", "1000")
    assert r.returncode == 1
    err = one_line_error(r)
    assert "/cloud/density" in err and "grid-size cap of 1000" in err and "active voxels" in err, err
    assert_clean_image(out)
    capped = VOLUME_SCENE + """
    def RenderSettings "rs" { int64 volphoton:maxGridVoxels = 1000 }
"""
    r, out = render_bad(tmp_path, capped % (str(cloud_vdb), "density"))
    assert r.returncode == 1 and "grid-size cap of 1000" in r.stderr, r.stderr
    r, out = render_bad(tmp_path, capped % (str(cloud_vdb), "density"), "--max-grid-voxels", "0")  # 0: no cap
    assert r.returncode == 0, r.stderr
    r, out = render_bad(tmp_path, VOLUME_SCENE % (str(cloud_vdb), "density"))  # the default cap: 2^30
    assert r.returncode == 0, r.stderr


def test_nan_xform_negative_density_and_unknown_token(tmp_path):
    r, out = render_bad(tmp_path, """
        def Camera "cam" { double3 xformOp:translate = (0, 0, 5)
                           uniform token[] xformOpOrder = ["xformOp:translate"] }
        def DomeLight "d" {}
        def Sphere "broken" {
            double3 xformOp:translate = (nan, 0, 0)
            uniform token[] xformOpOrder = ["xformOp:translate"]
        }
        def Sphere "ok" {}
    """)
    assert r.returncode == 1
    assert "/broken.xformOp:translate" in one_line_error(r) and "not finite" in r.stderr
    ch = assert_clean_image(out)
    assert ch["A"].max() > 0  # /ok rendered
    r, out = render_bad(tmp_path, """
        def Camera "cam" { double3 xformOp:translate = (0, 0, 5)
                           uniform token[] xformOpOrder = ["xformOp:translate"] }
        def DomeLight "d" {}
        def Cube "fog" (prepend apiSchemas = ["VolPhotonMediumAPI"]) { float volphoton:density = -4 }
    """)
    assert r.returncode == 0, r.stderr  # a warning: clamped to 0
    assert "warning: /fog.volphoton:density: density = -4 is negative; clamped to 0" in r.stderr
    ch = assert_clean_image(out)
    np.testing.assert_allclose(ch["R"], 1.0, atol=1e-6)  # an empty medium: the dome unchanged
    r, out = render_bad(tmp_path, """
        def Camera "cam" { double3 xformOp:translate = (0, 0, 5)
                           uniform token[] xformOpOrder = ["xformOp:translate"] }
        def DomeLight "d" {}
        def Cube "fog" (prepend apiSchemas = ["VolPhotonMediumAPI"]) { uniform token volphoton:phase = "fancy" }
    """)
    assert r.returncode == 1
    assert "error: /fog.volphoton:phase: unknown phase 'fancy'" in one_line_error(r)
    assert_clean_image(out)


def test_nothing_to_render_is_a_failure(tmp_path):
    r, out = render_bad(tmp_path, 'def Xform "empty" {}\n')
    assert r.returncode == 1 and "nothing to render" in one_line_error(r)
    assert not out.exists()


def test_check_command_reports_errors(tmp_path):
    _, path = stage_from(tmp_path, VOLUME_SCENE % ("./no_such_cloud.vdb", "density"))
    r = run_cli("check", path, "-v")
    assert r.returncode == 1 and "/cloud/density.filePath" in r.stdout
    r = run_cli("check", os.path.join(TESTENV, "fog_spotlight.usda"), "-v")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "medium /World/fogBox" in r.stdout and "light /World/spot: spot" in r.stdout


@pytest.mark.parametrize("name", ["fog_spotlight.usda", "vdb_cloud.usda", "atmosphere_sunset.usda",
                                  "emissive_smoke.usda", "marble.usda", "furnace.usda"])
def test_example_scenes_translate_cleanly(scene_copy, name):
    path = scene_copy(name)
    stage = Usd.Stage.Open(str(path))
    info = usdscene.read_render_settings(stage)
    assert not info.diagnostics and info.resolution and info.camera_path
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), *info.resolution, info.camera_path, info.conform_policy)
    assert not [d for d in sc.diagnostics if d.severity != "info"], diag_text(sc.diagnostics)
    assert sc.media and sc.lights and sc.camera.prim_path == info.camera_path
    _core.Scene(sc.desc)  # the core accepts it


def test_dome_light_texture_and_missing_texture(tmp_path):
    h, w = 4, 8
    planes = {"R": np.full((h, w), 0.5, np.float32), "G": np.full((h, w), 0.25, np.float32),
              "B": np.full((h, w), 1.0, np.float32)}
    output.write_exr(str(tmp_path / "sky.exr"), planes)
    stage, path = stage_from(tmp_path, """
        def Camera "cam" {}
        def DomeLight "sky" {
            float inputs:intensity = 2
            asset inputs:texture:file = @./sky.exr@
        }
    """)
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), 8, 8, "/cam")
    assert not sc.errors, diag_text(sc.errors)
    (dome,) = sc.lights
    assert dome.params["texture"].endswith("sky.exr") and dome.emission == pytest.approx((2, 2, 2))
    s = _core.RenderSettings()
    s.width, s.height, s.samples_per_pixel = 8, 8, 1
    r = _core.Renderer(_core.Scene(sc.desc), s)
    r.render()
    np.testing.assert_allclose(r.film.beauty.reshape(-1, 3), [[1.0, 0.5, 2.0]] * 64, rtol=1e-3)
    (tmp_path / "sky.exr").unlink()
    r = run_cli("render", path, "-o", tmp_path / "o.exr", "--resolution", "4", "4", "--spp", "1", "--quiet")
    assert r.returncode == 1
    assert "/sky.inputs:texture:file" in one_line_error(r) and "sky.exr" in r.stderr
    ch = assert_clean_image(tmp_path / "o.exr")
    np.testing.assert_allclose(ch["R"], 2.0, rtol=1e-6)  # the constant dome it fell back to
