"""Subsurface scattering through photon maps: measured presets, a thick-slab reflectance against the
exact transport solution, a translucent white furnace and the example scenes.

Statistics and their tolerances
    Every render here is split into its passes (``Renderer.render_pass``; a pass adds one sample per
    pixel and, for photonMap, traces a fresh photon map), over several seeds.  Passes are
    independent, so the quantity of interest (an image mean, a masked mean, a pixel) is estimated by
    the mean over passes with standard error sigma = std(pass values) / sqrt(passes).  The passes of
    a progressive photon map shrink its radius, so their spread also carries the change of bias
    between passes, which only makes sigma conservative.  A check passes within k sigma (k = 4 for a
    few numbers, 6 for one z-score per pixel) plus, for the biased photon map, a stated allowance
    measured as described next to each test.  Seeds are fixed, so results are deterministic.

    ``python testenv/test_subsurface.py`` reruns the measurements behind the allowances with many
    more passes and prints them.

Run:  cd /work/main && . .venv/bin/activate && python -m pytest testenv/test_subsurface.py -q
"""

import math
import os
import re
import sys

import numpy as np
import pytest

from conftest import REPO, TESTENV

from pxr import Usd  # noqa: E402  (after conftest set the plug-in path)

from volphoton import _core, presets, usdscene  # noqa: E402

INTEGRATORS = ("pathTracer", "photonMap")

# ------------------------------------------------------------------------------------------------
# Helpers
# ------------------------------------------------------------------------------------------------


def pass_images(scene, settings, seeds):
    """(passes * len(seeds), H, W, 3) float64: each pass's own image, recovered from the running
    average the film keeps (film_k = mean of passes 1..k)."""
    out = []
    for seed in seeds:
        s = _core.RenderSettings()
        for k in ("integrator", "width", "height", "samples_per_pixel", "max_depth", "photons_per_pass",
                  "initial_radius", "radius_alpha"):
            setattr(s, k, getattr(settings, k))
        s.seed = seed
        r = _core.Renderer(scene, s)
        prev = 0.0
        for k in range(1, s.samples_per_pixel + 1):
            assert r.render_pass()
            cum = r.film.beauty.astype(np.float64) * k
            out.append(cum - prev)
            prev = cum
    out = np.array(out)
    assert np.all(np.isfinite(out))
    return out


def mean_sigma(values):
    """Mean over axis 0 and its standard error."""
    v = np.asarray(values, dtype=np.float64)
    return v.mean(axis=0), v.std(axis=0, ddof=1) / math.sqrt(len(v))


def integrator_enum(name):
    return _core.RenderSettings.Integrator.PathTracer if name == "pathTracer" else _core.RenderSettings.Integrator.PhotonMap


def load_usd(path, width, height):
    """(core Scene, RenderSettings with the stage's volphoton:* settings, TranslatedScene)."""
    stage = Usd.Stage.Open(str(path))
    info = usdscene.read_render_settings(stage)
    assert not info.diagnostics, "\n".join(map(str, info.diagnostics))
    sc = usdscene.translate(stage, Usd.TimeCode.Default(), width, height, info.camera_path, info.conform_policy)
    problems = [d for d in sc.diagnostics if d.severity != "info"]
    assert not problems, "\n".join(map(str, problems))
    s = info.settings
    s.width, s.height = width, height
    return _core.Scene(sc.desc), s, sc


# ------------------------------------------------------------------------------------------------
# 1. Presets: one table, its source, its mapping, its errors
# ------------------------------------------------------------------------------------------------

# Spot values copied from pbrt-v4 src/pbrt/media.cpp (SubsurfaceParameterTable, the Jensen et al.
# 2001 block), independently of presets.PRESETS.
PBRT_SPOT_VALUES = {
    "apple": ((2.29, 2.39, 1.97), (0.0030, 0.0034, 0.046)),
    "ketchup": ((0.18, 0.07, 0.03), (0.061, 0.97, 1.45)),
    "marble": ((2.19, 2.62, 3.00), (0.0021, 0.0041, 0.0071)),
    "skin1": ((0.74, 0.88, 1.01), (0.032, 0.17, 0.48)),
    "spectralon": ((11.6, 20.4, 14.9), (0.00, 0.00, 0.00)),
    "wholemilk": ((2.55, 3.21, 3.77), (0.0011, 0.0024, 0.014)),
}


def test_preset_table_is_jensen_2001_table_2():
    assert presets.names() == ["apple", "chicken1", "chicken2", "cream", "ketchup", "marble", "potato",
                               "skimmilk", "skin1", "skin2", "spectralon", "wholemilk"]
    for name, values in PBRT_SPOT_VALUES.items():
        assert presets.PRESETS[name] == values, name
    assert presets.MEASURED_IOR == 1.3
    assert usdscene.PRESETS is presets.PRESETS  # the front end uses this one table


def _doc_rows(text, pattern):
    rows = {}
    for m in re.finditer(pattern, text, re.M):
        nums = [float(x) for x in m.group(2).replace("|", " ").split()]
        rows[m.group(1)] = (tuple(nums[0:3]), tuple(nums[3:6]))
    return rows


def test_preset_docs_match_the_table():
    doc = _doc_rows(presets.__doc__, r"^\s{4}([a-z0-9]+)\s+((?:[0-9.]+\s+){6})")
    assert doc == presets.PRESETS
    with open(os.path.join(REPO, "schemas", "README.md")) as f:
        readme = f.read()
    rows = _doc_rows(readme, r"^\| `([a-z0-9]+)` \| ((?:[0-9.]+ ){2}[0-9.]+ \| (?:[0-9.]+ ){2}[0-9.]+) \|")
    assert rows == presets.PRESETS


def test_preset_mapping_uses_g_and_units():
    c = presets.preset_coefficients("skin1", 0.1, 0.5)
    np.testing.assert_allclose(c.sigma_s, [0.74 / 0.5 / 0.1, 0.88 / 0.5 / 0.1, 1.01 / 0.5 / 0.1])
    np.testing.assert_allclose(c.sigma_a, [0.32, 1.7, 4.8])
    np.testing.assert_allclose(np.array(c.extinction_color) * c.density, c.sigma_t)
    np.testing.assert_allclose(np.array(c.albedo) * c.sigma_t, c.sigma_s)
    assert presets.reduced_albedo("spectralon") == (1.0, 1.0, 1.0)
    with pytest.raises(presets.UnknownPresetError) as e:
        presets.preset_coefficients("jade")
    assert "unknown preset 'jade'" in str(e.value) and "marble" in str(e.value)
    with pytest.raises(ValueError):
        presets.preset_coefficients("marble", 0.0)


def test_preset_through_usd_with_g_units_and_unknown_name(tmp_path):
    path = tmp_path / "p.usda"
    path.write_text("""#usda 1.0
(
    upAxis = "Y"
)
def Sphere "forward" (prepend apiSchemas = ["VolPhotonMediumAPI"])
{
    uniform token volphoton:preset = "marble"
    float volphoton:sceneUnitsPerMm = 0.1
    float volphoton:phase:g = 0.5
    float volphoton:density = 99
}
def Sphere "odd" (prepend apiSchemas = ["VolPhotonMediumAPI"])
{
    uniform token volphoton:preset = "jade"
    float volphoton:density = 2
    double3 xformOp:translate = (5, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]
}
""")
    sc = usdscene.translate(Usd.Stage.Open(str(path)), Usd.TimeCode.Default(), 8, 8)
    media = {m.prim_path: m.medium.properties((0, 0, 0)) for m in sc.media}
    ssp, sa = presets.PRESETS["marble"]
    np.testing.assert_allclose(media["/forward"]["sigma_s"], [s / 0.5 / 0.1 for s in ssp], rtol=1e-6)
    np.testing.assert_allclose(media["/forward"]["sigma_a"], [a / 0.1 for a in sa], rtol=1e-5, atol=1e-9)
    errors = [str(d) for d in sc.errors]
    assert len(errors) == 1 and errors[0].startswith("error: /odd.volphoton:preset: unknown preset 'jade' (valid: apple, "), errors
    assert media["/odd"]["sigma_t"] == pytest.approx((2, 2, 2))  # the authored coefficients are kept


# ------------------------------------------------------------------------------------------------
# 2. Total diffuse reflectance of a thick slab against the exact transport solution
# ------------------------------------------------------------------------------------------------

# Semi-infinite isotropic (g = 0) slab of index 1.3 in air (no glass slides), collimated normal
# incidence: total reflectance UR1 from the adding-doubling solver of iadpython 0.5.3 (quad_pts=16)
# minus the specular Fresnel term ((n - 1) / (n + 1))^2.  test_iadpython_reproduces_the_references
# recomputes them; 32 quadrature points move them by 1.5e-4.
IOR = 1.3
SPECULAR = ((IOR - 1) / (IOR + 1)) ** 2
DIFFUSE_REFLECTANCE = {0.9: 0.28596, 0.99: 0.64557}


def test_iadpython_reproduces_the_references():
    try:
        import iadpython
    except ImportError as e:  # iadpython imports scipy without declaring it
        pytest.fail("iadpython is needed for the slab references (pip install iadpython scipy): %s" % e)
    for a, expected in DIFFUSE_REFLECTANCE.items():
        s = iadpython.Sample(a=a, b=float("inf"), g=0.0, n=IOR, n_above=1.0, n_below=1.0, quad_pts=16)
        ur1, ut1, _, _ = s.rt()
        assert ur1 - SPECULAR == pytest.approx(expected, abs=5e-5), a
        assert ut1 < 1e-9
    sigma_t, albedo = marble_coefficients()
    for c, expected in enumerate(MARBLE_REFLECTANCE):
        s = iadpython.Sample(a=albedo[c], b=sigma_t[c] * MARBLE_D, g=0.0, n=IOR, n_above=1.0, n_below=1.0,
                             quad_pts=16)
        ur1, ut1, _, _ = s.rt()
        assert ur1 - SPECULAR == pytest.approx(expected, abs=5e-5), c
        assert ut1 < 1e-7


# Geometry, in mean free paths (sigma_t = 1): a box 2H x 2H x D with its top face at z = 0, seen
# straight down by an orthographic camera VIEW wide at its centre, under a constant dome of radiance 1.
# By reciprocity the radiance leaving along the normal equals the directional-hemispherical
# reflectance for normal incidence; light leaving through the sides or the bottom is negligible
# (the diffusion length 1/sqrt(3 (1 - a)) is 1.8 and 5.8 mfp; D = 100 mfp transmits < 1e-7 and the
# camera looks 240 mfp from the sides).  D is 100 rather than 1000 mfp and H only 250 mfp because the
# core skips the first 1e-5 * scene extent of medium behind a refracting surface (see
# test_wide_slab_skips_a_layer_behind_the_surface): here that is 0.0036 mfp, a -0.2 % effect; a
# 1000 mfp deep slab that is wider than deep would make it several times larger.  A flat slab also
# sends most dome photons into the top face.
SLAB_D, SLAB_H, SLAB_VIEW = 100.0, 250.0, 20.0
# The path tracer is unbiased up to that skipped layer: allowance 0.3 % of the reference.
PT_ALLOWANCE = 0.003
# Photon map: radius 200 mfp (shrinking per pass; the kernel is lateral to the camera ray and the
# slab is laterally uniform for 250 mfp, so lateral blur adds no bias), photons per pass as below.
# Measured (calibrate(): 64 passes x 4 seeds for 0.9, 32 x 4 for 0.99): +1.45 % +- 0.74 % and
# -0.11 % +- 0.86 % of the reference (an earlier 8 x 8 pixel run: +0.57 % +- 0.52 % for 0.9); the
# path tracer: -0.13 % +- 0.19 % and -0.20 % +- 0.12 %.  Allowance 2 % of the reference.
PM_ALLOWANCE = 0.02
PM_PHOTONS = {0.9: 20000, 0.99: 8000}  # a = 0.99 walks are ~5x longer
PM_PASSES = {0.9: 64, 0.99: 32}  # per seed; the photon map's noise falls with passes x photons
PM_SEEDS = {0.9: (0, 1, 2), 0.99: (0, 1, 2, 3)}


def box_mesh(lo, hi, material, medium):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    m = _core.MeshDesc()
    m.name = "slab"
    m.points = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                         [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], dtype=np.float64)
    m.indices = np.array([0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                          1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7])
    m.material = material
    m.interior_medium = medium
    return m


def slab_scene(albedo, depth=SLAB_D, half=SLAB_H, view=SLAB_VIEW, sigma_t=(1, 1, 1)):
    """albedo: grey (a number) or per channel; sigma_t per channel, in the slab's length units."""
    d = _core.SceneDesc()
    albedo = tuple(albedo) if np.ndim(albedo) else (albedo,) * 3
    coeffs = _core.MediumCoefficients.from_albedo(1.0, tuple(sigma_t), albedo, (0, 0, 0), _core.isotropic_phase())
    medium = d.add_medium(_core.HomogeneousMedium(coeffs), False)
    glass = _core.SurfaceMaterial(kind=_core.SurfaceMaterial.Kind.Dielectric, ior=IOR)
    mesh = d.add_mesh(box_mesh((-half, -half, -depth), (half, half, 0.0), glass, medium))
    d.add_instance(mesh, np.eye(4))
    d.add_light(_core.dome_light((1, 1, 1)))
    cam = _core.CameraDesc()
    cam.projection = _core.CameraDesc.Projection.Orthographic
    cam.ortho_width = view
    to_world = np.eye(4)
    to_world[2, 3] = 10.0  # looking down -Z from above the slab
    cam.camera_to_world = to_world
    d.camera = cam
    return _core.Scene(d)


def slab_settings(integrator, albedo, photons_scale=1.0):
    s = _core.RenderSettings()
    s.integrator = integrator_enum(integrator)
    # The default maxDepth: a = 0.99 walks have hundreds of events, and the default must not cut
    # them (issue 14: the old default of 64 reflected ~4 % too little at a = 0.99).
    assert s.max_depth >= 100000
    if integrator == "pathTracer":
        s.width = s.height = 64
        s.samples_per_pixel = 16
    else:
        s.width = s.height = 4  # the view is 20 mfp wide, inside one 200 mfp kernel: pixels agree
        s.samples_per_pixel = PM_PASSES[albedo]
        s.photons_per_pass = int(PM_PHOTONS[albedo] * photons_scale)
        s.initial_radius = 200.0
    return s


def slab_reflectance(integrator, albedo, seeds=None, passes=None, photons_scale=1.0, **geometry):
    if seeds is None:
        seeds = (0, 1, 2) if integrator == "pathTracer" else PM_SEEDS[albedo]
    s = slab_settings(integrator, albedo, photons_scale)
    if passes:
        s.samples_per_pixel = passes
    images = pass_images(slab_scene(albedo, **geometry), s, seeds)
    return mean_sigma(images.mean(axis=(1, 2, 3)) - SPECULAR)


@pytest.mark.parametrize("albedo", sorted(DIFFUSE_REFLECTANCE))
@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_slab_reflectance_matches_the_transport_solution(integrator, albedo):
    ref = DIFFUSE_REFLECTANCE[albedo]
    r, sigma = slab_reflectance(integrator, albedo)
    allowance = (PT_ALLOWANCE if integrator == "pathTracer" else PM_ALLOWANCE) * ref
    assert abs(r - ref) <= 4 * sigma + allowance, (integrator, albedo, r, sigma, ref)
    # The test has teeth: the tolerance stays below 6 % of the reference (leaving out the 1/eta^2
    # radiance scaling, or Fresnel at the exit, changes R by far more).
    assert 4 * sigma + allowance < 0.06 * ref, sigma


# The marble of benchmark scene 9 (Jensen et al. 2001, Table 2, g = 0; the "marble" preset): strongly
# chromatic extinction (red 0.73 of blue) and albedo 0.998-0.999, so walks take hundreds of events and
# the per-channel weights of chromatic distance sampling matter.  Lengths in blue mean free paths; a
# slab MARBLE_D deep (the red channel's diffusion length is 26 of them: T < 4e-8).  Per channel, total
# reflectance for normal incidence minus the specular term, iadpython 0.5.3 (quad_pts=16; 32 points
# move them by 1e-4).  This is the independent check of issue 16 part 4: the figurine's mean differed
# from Mitsuba's by 2.2 %; measured here: path tracer 0.87611 +- 0.00106, 0.84552 +- 0.00092,
# 0.81441 +- 0.00136 with the specular term (64 x 64 px, 16 seeds x 16 passes) against iadpython's
# 0.87632, 0.84550, 0.81440.  (`python tools/bench/check_marble_slab.py` puts Mitsuba beside it.)
MARBLE_D = 400.0
MARBLE_REFLECTANCE = (0.85930, 0.82849, 0.79738)


def marble_coefficients():
    """(sigma_t relative to the largest channel, albedo) of the marble preset with g = 0."""
    ssp, sa = presets.PRESETS["marble"]
    st = np.array(ssp) + np.array(sa)
    return st / st.max(), np.array(ssp) / st


def test_marble_slab_matches_the_transport_solution_per_channel():
    sigma_t, albedo = marble_coefficients()
    scene = slab_scene(albedo, depth=MARBLE_D, sigma_t=sigma_t)
    s = _core.RenderSettings()  # the defaults: in particular maxDepth and roulette
    s.integrator = integrator_enum("pathTracer")
    s.width = s.height = 64
    s.samples_per_pixel = 16
    images = pass_images(scene, s, tuple(range(6)))
    r, sigma = mean_sigma(images.mean(axis=(1, 2)) - SPECULAR)
    ref = np.array(MARBLE_REFLECTANCE)
    tol = 4 * sigma + PT_ALLOWANCE * ref
    assert np.all(np.abs(r - ref) <= tol), (r, sigma, ref)
    # Teeth: the tolerance stays below the 2.2 % by which Mitsuba's volpath differed on the figurine.
    assert np.all(tol < 0.02 * ref), tol


def test_wide_slab_tracks_the_medium_from_the_surface():
    # The same slab 100 times wider: nothing physical changes, but the core's self-intersection
    # offset grows with the scene's extent (here to 0.35 mean free paths).  Rays refracted into the
    # medium must start at the surface itself, or that layer is skipped (it was: -18 %).
    r, sigma = slab_reflectance("pathTracer", 0.9, seeds=(0,), half=100 * SLAB_H)
    ref = DIFFUSE_REFLECTANCE[0.9]
    assert abs(r - ref) <= 4 * sigma + PT_ALLOWANCE * ref, (r, sigma, ref)


# ------------------------------------------------------------------------------------------------
# 3. A non-absorbing translucent object disappears in a white furnace (through USD)
# ------------------------------------------------------------------------------------------------

FURNACE = os.path.join(TESTENV, "translucent_furnace.usda")
# Photon map: the beam estimate only gathers photons of the region the camera ray is in, so near
# the silhouette part of its disc lies outside the object and is lost (a slightly dark rim).
# Measured (calibrate(), 64 passes x 4 seeds): image mean 0.9978 +- 0.0005 (path tracer 1.0022 +-
# 0.0010), every pixel within 4 sigma + 0.001 of 1.  Allowances: 0.005 on the mean, 0.02 per pixel.
FURNACE_PIXEL_ALLOWANCE = {"pathTracer": 0.0, "photonMap": 0.02}
FURNACE_MEAN_ALLOWANCE = {"pathTracer": 0.0, "photonMap": 0.005}


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_translucent_object_disappears_in_a_white_furnace(integrator):
    scene, s, sc = load_usd(FURNACE, 48, 32)
    (medium,) = sc.media
    assert medium.desc.ior == pytest.approx(1.5) and medium.desc.albedo == pytest.approx((1, 1, 1))
    (dome,) = sc.lights
    assert dome.kind == "dome" and dome.emission == pytest.approx((1, 1, 1))
    s.integrator = integrator_enum(integrator)
    images = pass_images(scene, s, seeds=(0, 1))
    assert images.shape[0] == 32
    pixel, sigma = mean_sigma(images)
    allowance = FURNACE_PIXEL_ALLOWANCE[integrator]
    z = np.abs(pixel - 1.0) / np.maximum(sigma, 1e-12)
    bad = (np.abs(pixel - 1.0) > 6 * sigma + allowance + 1e-4)
    assert not bad.any(), (integrator, int(bad.sum()), float(z.max()), pixel[bad][:5], sigma[bad][:5])
    m, sm = mean_sigma(images.mean(axis=(1, 2, 3)))
    assert abs(m - 1.0) <= 4 * sm + FURNACE_MEAN_ALLOWANCE[integrator] + 1e-4, (integrator, m, sm)
    covered = np.isfinite(np.array(_depth(scene, s)))
    assert covered.mean() > 0.3  # the object fills a good part of the frame


def _depth(scene, settings):
    s = _core.RenderSettings()
    s.width, s.height, s.samples_per_pixel = settings.width, settings.height, 1
    r = _core.Renderer(scene, s)
    r.render()
    return r.film.depth()


# ------------------------------------------------------------------------------------------------
# 4-5. Example scenes: generated, clean, and both integrators agree on them
# ------------------------------------------------------------------------------------------------

EXAMPLES = ("subsurface_bunny.usda", "subsurface_hand.usda", "subsurface_milk.usda")
# Photon map relative to path tracer over the pixels that see the object, per channel (R, G, B),
# measured with 64 passes x 32 seeds per integrator (calibrate(), other seeds than the test's):
#   bunny (marble)   -1.9 %, -2.1 %, -6.1 %  (+- 2 %)
#   hand (skin1)     -1.4 %, -1.3 %, -1.1 %  (+- 0.5 %)
#   milk (wholemilk) -4.2 %, -6.1 %, -6.8 %  (+- 1.2 %)
# The photon map is darker: its beam estimate gathers only photons of the camera ray's region, so
# where the ray enters obliquely part of the kernel disc lies outside the object and is lost (the
# difference grows with the radius: -11 % for the milk with a 3x larger initialRadius).  Milk and
# marble have mean free paths (0.26-0.45 mm) below the automatic radius (1 and 0.45 mm).
# Allowances: the measured difference + 3 of its sigma, rounded up.
AGREEMENT_ALLOWANCE = {"subsurface_bunny.usda": 0.12, "subsurface_hand.usda": 0.03, "subsurface_milk.usda": 0.11}
EXAMPLE_RES = (32, 18)  # the photon map's noise falls with passes, not pixels: few pixels, many passes
EXAMPLE_PASSES, EXAMPLE_SEEDS = 64, tuple(range(8))


def example_object_means(name, integrator, seeds, passes=16):
    """Per-pass means over the pixels whose camera rays hit geometry, per channel: (passes, 3)."""
    scene, s, _ = load_usd(os.path.join(TESTENV, name), *EXAMPLE_RES)
    mask = np.isfinite(np.array(_depth(scene, s)))
    s.integrator = integrator_enum(integrator)
    s.samples_per_pixel = passes
    images = pass_images(scene, s, seeds)
    return images[:, mask].mean(axis=1)


@pytest.mark.parametrize("name", EXAMPLES + ("translucent_furnace.usda",))
def test_subsurface_scene_is_generated_closed_and_clean(name):
    path = os.path.join(TESTENV, name)
    with open(path) as f:
        text = f.read()
    assert "Generated by tools/make_subsurface_meshes.py" in text
    assert os.path.getsize(path) < 400 << 10
    scene, s, sc = load_usd(path, 160, 90)  # no warnings: in particular every medium mesh is closed
    assert s.samples_per_pixel == 16 and s.max_depth >= 10000
    assert sc.media and sc.lights and sc.camera.prim_path == "/World/camera"
    for m in sc.media:
        if name != "translucent_furnace.usda":
            assert m.desc.preset in presets.PRESETS and m.desc.scene_units_per_mm == pytest.approx(0.1)
        assert sc.desc.mesh(m.mesh_index).material.kind == _core.SurfaceMaterial.Kind.Dielectric


def test_generator_reproduces_the_milk_scene():
    sys.path.insert(0, os.path.join(REPO, "tools"))
    try:
        import make_subsurface_meshes as tool
    finally:
        sys.path.pop(0)
    with open(os.path.join(TESTENV, "subsurface_milk.usda")) as f:
        assert f.read() == tool.milk_scene()


@pytest.mark.parametrize("name", EXAMPLES)
def test_photon_map_and_path_tracer_agree_on_example_scenes(name):
    pt, spt = mean_sigma(example_object_means(name, "pathTracer", EXAMPLE_SEEDS, EXAMPLE_PASSES))
    pm, spm = mean_sigma(example_object_means(name, "photonMap", EXAMPLE_SEEDS, EXAMPLE_PASSES))
    tol = 4 * np.sqrt(spt ** 2 + spm ** 2) + AGREEMENT_ALLOWANCE[name] * pt
    assert np.all(np.abs(pm - pt) <= tol), (name, pm, pt, spm, spt, tol)
    assert np.all(pt > 0.01)


# ------------------------------------------------------------------------------------------------
# Calibration: the measurements behind the allowances (not a test)
# ------------------------------------------------------------------------------------------------


def calibrate(parts=("slab", "furnace", "examples")):
    for a in sorted(DIFFUSE_REFLECTANCE) if "slab" in parts else ():
        for integ in INTEGRATORS:
            r, s = slab_reflectance(integ, a, seeds=(10, 11, 12, 13), passes=64 if a == 0.9 or integ == "pathTracer" else 32)
            print("slab a=%g %-10s R-R0 = %.5f +- %.5f  ref %.5f  (%+.2f %% +- %.2f %%)"
                  % (a, integ, r, s, DIFFUSE_REFLECTANCE[a], 100 * (r / DIFFUSE_REFLECTANCE[a] - 1),
                     100 * s / DIFFUSE_REFLECTANCE[a]), flush=True)
    for integ in INTEGRATORS if "furnace" in parts else ():
        scene, st, _ = load_usd(FURNACE, 48, 32)
        st.integrator = integrator_enum(integ)
        st.samples_per_pixel = 64
        images = pass_images(scene, st, (0, 1, 2, 3))
        pixel, sigma = mean_sigma(images)
        m, sm = mean_sigma(images.mean(axis=(1, 2, 3)))
        worst = np.abs(pixel - 1) - 4 * sigma
        print("furnace %-10s mean %.4f +- %.4f; worst pixel |p - 1| - 4 sigma = %.3f" % (integ, m, sm, worst.max()),
              flush=True)
    for name in EXAMPLES if "examples" in parts else ():
        seeds = tuple(range(100, 132))  # other seeds than the test's
        pt, spt = mean_sigma(example_object_means(name, "pathTracer", seeds, 64))
        pm, spm = mean_sigma(example_object_means(name, "photonMap", seeds, 64))
        print("%s: pathTracer %s +- %s, photonMap %s +- %s, relative difference %s" % (
            name, np.round(pt, 4), np.round(spt, 4), np.round(pm, 4), np.round(spm, 4), np.round(pm / pt - 1, 4)),
            flush=True)


if __name__ == "__main__":
    calibrate(sys.argv[1:] or ("slab", "furnace", "examples"))
