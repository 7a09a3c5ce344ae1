"""Tests of the volPhoton codeless USD schemas (schemas/, plugInfo/) and of the Python
reader/validator hdVolPhoton/python/volphoton/schema.py.

Run:  cd /work/main && . .venv/bin/activate && python -m pytest testenv/test_schema.py -q
"""

import ast
import math
import os
import random
import shutil
import subprocess
import sys
import textwrap

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PLUGIN_DIR = os.path.join(REPO, "plugInfo")
SCHEMA_DIR = os.path.join(REPO, "schemas")
PY_DIR = os.path.join(REPO, "hdVolPhoton", "python")

# USD reads plug-ins once, when pxr is first used: register ours before importing pxr.
_paths = [p for p in os.environ.get("PXR_PLUGINPATH_NAME", "").split(os.pathsep) if p]
if PLUGIN_DIR not in _paths:
    os.environ["PXR_PLUGINPATH_NAME"] = os.pathsep.join([PLUGIN_DIR] + _paths)
if PY_DIR not in sys.path:
    sys.path.insert(0, PY_DIR)

import numpy as np  # noqa: E402
from pxr import Gf, Sdf, Usd, UsdGeom, UsdVol, Vt  # noqa: E402

from volphoton import schema as vs  # noqa: E402

MEDIUM = "VolPhotonMediumAPI"
LOBE = "VolPhotonPhaseLobeAPI"
PHASES = ["isotropic", "linear", "rayleigh", "lambertianSphere", "henyeyGreenstein", "schlick",
          "tabulated", "mixture"]

# The documented schema (schemas/README.md): name -> (type, fallback or None, uniform?)
EXPECTED_MEDIUM = {
    "volphoton:density": ("float", 1.0, False),
    "volphoton:albedo": ("color3f", (0.8, 0.8, 0.8), False),
    "volphoton:extinctionColor": ("color3f", (1.0, 1.0, 1.0), False),
    "volphoton:emission": ("color3f", (0.0, 0.0, 0.0), False),
    "volphoton:emissionScale": ("float", 1.0, False),
    "volphoton:temperatureScale": ("float", 1.0, False),
    "volphoton:phase": ("token", "henyeyGreenstein", True),
    "volphoton:phase:g": ("float", 0.0, False),
    "volphoton:phase:k": ("float", None, False),
    "volphoton:phase:x": ("float", 0.0, False),
    "volphoton:phase:table": ("float[]", None, False),
    "volphoton:densityMode": ("token", None, True),
    "volphoton:exponential:a": ("float", 1.0, False),
    "volphoton:exponential:b": ("float", 1.0, False),
    "volphoton:exponential:up": ("vector3f", None, False),
    "volphoton:exponential:origin": ("point3f", (0.0, 0.0, 0.0), False),
    "volphoton:ior": ("float", 1.0, False),
    "volphoton:preset": ("token", "", True),
    "volphoton:sceneUnitsPerMm": ("float", 1.0, False),
    "volphoton:bounds:min": ("point3f", None, False),
    "volphoton:bounds:max": ("point3f", None, False),
}
EXPECTED_LOBE = {
    "weight": ("float", 1.0, False),
    "phase": ("token", "henyeyGreenstein", True),
    "g": ("float", 0.0, False),
    "k": ("float", None, False),
    "x": ("float", 0.0, False),
    "table": ("float[]", None, False),
}
ALLOWED = {
    "volphoton:phase": PHASES,
    "volphoton:densityMode": ["field", "constant", "exponential"],
}


def f32(v):
    """Round a float or a sequence through float32 (what a float/color3f attribute stores)."""
    if isinstance(v, (list, tuple)):
        return tuple(float(np.float32(c)) for c in v)
    return float(np.float32(v))


def same_value(a, b):
    if a is None or b is None:
        return a is None and b is None
    if isinstance(b, str):
        return str(a) == b
    if isinstance(b, tuple):
        return len(a) == 3 and all(math.isclose(float(x), y, abs_tol=1e-7) for x, y in zip(a, b))
    return math.isclose(float(a), b, abs_tol=1e-7)


@pytest.fixture(scope="module", autouse=True)
def registered():
    assert vs.is_schema_registered(), (
        "VolPhotonMediumAPI is not registered: pxr was imported before PXR_PLUGINPATH_NAME "
        "included %s" % PLUGIN_DIR)


def touch(path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(b"placeholder; the reader does not parse VDB files")
    return path


def new_stage(tmp_path, name="scene.usda", up="Y"):
    stage = Usd.Stage.CreateNew(str(tmp_path / name))
    UsdGeom.SetStageUpAxis(stage, up)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    return stage


def volume(stage, path="/World/fog", api=True):
    prim = UsdVol.Volume.Define(stage, path).GetPrim()
    if api:
        assert prim.ApplyAPI(MEDIUM)
    return prim


def cube(stage, path="/World/box", api=True):
    prim = UsdGeom.Cube.Define(stage, path).GetPrim()
    if api:
        assert prim.ApplyAPI(MEDIUM)
    return prim


def vdb_asset(stage, path, file_path=None, field_name="density", field_index=None):
    asset = UsdVol.OpenVDBAsset.Define(stage, path)
    if file_path is not None:
        asset.GetFilePathAttr().Set(Sdf.AssetPath(file_path))
    if field_name is not None:
        asset.GetFieldNameAttr().Set(field_name)
    if field_index is not None:
        asset.GetFieldIndexAttr().Set(field_index)
    return asset


def bind_field(vol_prim, name, target):
    vol_prim.CreateRelationship("field:" + name).SetTargets([Sdf.Path(target)])


def author(prim, name, value):
    """Sets ``value`` on attribute ``name``, creating it with the schema's type when needed."""
    attr = prim.GetAttribute(name)
    if not attr:
        base = name.split(":")[-1] if name.startswith("volphoton:lobe:") else name
        spec = EXPECTED_LOBE[base] if name.startswith("volphoton:lobe:") else EXPECTED_MEDIUM[name]
        attr = prim.CreateAttribute(name, Sdf.ValueTypeNames.Find(spec[0]))
    assert attr.Set(value), name
    return attr


# ------------------------------------------------------------------------------------------
# Registration
# ------------------------------------------------------------------------------------------


def check_definition(defn, expected, name_of):
    assert defn is not None
    names = set(defn.GetPropertyNames())
    assert names == {name_of(n) for n in expected}
    for base, (type_name, fallback, uniform) in expected.items():
        name = name_of(base)
        attr = defn.GetAttributeDefinition(name)
        assert attr, name
        assert str(attr.GetTypeName()) == type_name, name
        assert same_value(attr.GetFallbackValue(), fallback), (name, attr.GetFallbackValue())
        variability = Sdf.VariabilityUniform if uniform else Sdf.VariabilityVarying
        assert attr.GetVariability() == variability, name
        assert defn.GetPropertyDocumentation(name).strip(), "no doc on " + name


def test_medium_api_registered_with_documented_defaults():
    reg = Usd.SchemaRegistry()
    defn = reg.FindAppliedAPIPrimDefinition(MEDIUM)
    check_definition(defn, EXPECTED_MEDIUM, lambda n: n)
    assert defn.GetDocumentation().strip()
    for name, tokens in ALLOWED.items():
        assert list(defn.GetPropertyMetadata(name, "allowedTokens")) == tokens
    assert defn.GetPropertyMetadata("volphoton:preset", "allowedTokens") is None  # open list
    assert Usd.SchemaRegistry.GetSchemaKind(MEDIUM) == Usd.SchemaKind.SingleApplyAPI
    assert set(Usd.SchemaRegistry.GetAPISchemaCanOnlyApplyToTypeNames(MEDIUM)) == {"Volume", "Gprim"}
    assert tuple(vs.PHASE_KINDS) == tuple(PHASES)
    assert tuple(vs.DENSITY_MODES) == ("field", "constant", "exponential")


def test_lobe_api_registered_with_documented_defaults():
    reg = Usd.SchemaRegistry()
    defn = reg.FindAppliedAPIPrimDefinition(LOBE)
    check_definition(defn, EXPECTED_LOBE, lambda n: "volphoton:lobe:__INSTANCE_NAME__:" + n)
    assert defn.GetDocumentation().strip()
    assert list(defn.GetPropertyMetadata("volphoton:lobe:__INSTANCE_NAME__:phase", "allowedTokens")) \
        == PHASES[:-1]
    assert Usd.SchemaRegistry.GetSchemaKind(LOBE) == Usd.SchemaKind.MultipleApplyAPI


def test_module_defaults_table_matches_registered_fallbacks():
    reg = Usd.SchemaRegistry()
    medium = reg.FindAppliedAPIPrimDefinition(MEDIUM)
    assert set(vs.DEFAULTS) == set(EXPECTED_MEDIUM)
    for name, value in vs.DEFAULTS.items():
        assert same_value(medium.GetAttributeFallbackValue(name), value), name
    lobe = reg.FindAppliedAPIPrimDefinition(LOBE)
    assert set(vs.LOBE_DEFAULTS) == set(EXPECTED_LOBE)
    for name, value in vs.LOBE_DEFAULTS.items():
        fallback = lobe.GetAttributeFallbackValue("volphoton:lobe:__INSTANCE_NAME__:" + name)
        assert same_value(fallback, value), name


def test_generated_files_are_up_to_date(tmp_path):
    """generatedSchema.usda and plugInfo.json are what usdGenSchema makes of schema.usda."""
    pytest.importorskip("jinja2", reason="usdGenSchema needs jinja2 (pip install jinja2)")
    shutil.copy(os.path.join(PLUGIN_DIR, "plugInfo.json"), tmp_path / "plugInfo.json")
    env = dict(os.environ)
    env.pop("PXR_PLUGINPATH_NAME", None)
    subprocess.run([sys.executable, "-m", "pxr.Usd.usdGenSchema", "-q",
                    os.path.join(SCHEMA_DIR, "schema.usda"), str(tmp_path)],
                   check=True, env=env, capture_output=True)
    for produced, committed in ((tmp_path / "generatedSchema.usda", os.path.join(SCHEMA_DIR, "generatedSchema.usda")),
                                (tmp_path / "plugInfo.json", os.path.join(PLUGIN_DIR, "plugInfo.json"))):
        with open(produced) as a, open(committed) as b:
            assert a.read() == b.read(), "%s is stale: run sh schemas/generate.sh" % committed


def test_plugin_is_a_relative_resource_plugin():
    import json
    with open(os.path.join(PLUGIN_DIR, "plugInfo.json")) as f:
        info = json.loads("".join(l for l in f if not l.strip().startswith("#")))
    (plugin,) = info["Plugins"]
    assert plugin["Name"] == "volPhoton" and plugin["Type"] == "resource"
    assert not os.path.isabs(plugin["Root"]) and not os.path.isabs(plugin["ResourcePath"])
    resources = os.path.normpath(os.path.join(PLUGIN_DIR, plugin["Root"], plugin["ResourcePath"]))
    assert os.path.isfile(os.path.join(resources, "generatedSchema.usda"))
    assert set(plugin["Info"]["Types"]) == {MEDIUM, LOBE}


def test_readme_documents_every_attribute():
    with open(os.path.join(SCHEMA_DIR, "README.md")) as f:
        text = f.read()
    for name in EXPECTED_MEDIUM:
        assert "| `%s` |" % name in text, name
    for name in EXPECTED_LOBE:
        assert "| `volphoton:lobe:<name>:%s` |" % name in text, name


# ------------------------------------------------------------------------------------------
# Applying the schemas
# ------------------------------------------------------------------------------------------


def test_apply_medium_api_to_volume_and_gprims():
    stage = Usd.Stage.CreateInMemory()
    for prim in (UsdVol.Volume.Define(stage, "/v").GetPrim(), UsdGeom.Cube.Define(stage, "/c").GetPrim(),
                 UsdGeom.Sphere.Define(stage, "/s").GetPrim(), UsdGeom.Mesh.Define(stage, "/m").GetPrim()):
        assert prim.CanApplyAPI(MEDIUM), prim.GetPath()
        assert prim.ApplyAPI(MEDIUM)
        assert prim.HasAPI(MEDIUM)
        assert MEDIUM in prim.GetAppliedSchemas()
        # Fallbacks come through the schema without authoring anything.
        assert prim.GetAttribute("volphoton:density").Get() == 1.0
        assert prim.GetAttribute("volphoton:phase").Get() == "henyeyGreenstein"
        assert not prim.GetAttribute("volphoton:density").HasAuthoredValue()
    for prim in (UsdGeom.Xform.Define(stage, "/x").GetPrim(), stage.DefinePrim("/untyped")):
        assert not prim.CanApplyAPI(MEDIUM), prim.GetPath()
        assert not prim.CanApplyAPI(LOBE, "a")


def test_multiple_apply_lobes():
    stage = Usd.Stage.CreateInMemory()
    prim = UsdVol.Volume.Define(stage, "/v").GetPrim()
    prim.ApplyAPI(MEDIUM)
    assert prim.CanApplyAPI(LOBE, "forward")
    assert prim.ApplyAPI(LOBE, "forward")
    assert prim.ApplyAPI(LOBE, "back")
    assert prim.HasAPI(LOBE, "forward") and prim.HasAPI(LOBE, "back")
    assert not prim.HasAPI(LOBE, "side")
    assert prim.GetAppliedSchemas() == [MEDIUM, LOBE + ":forward", LOBE + ":back"]
    for lobe in ("forward", "back"):
        for base, (type_name, fallback, _) in EXPECTED_LOBE.items():
            attr = prim.GetAttribute(vs.lobe_attr(lobe, base))
            assert attr, (lobe, base)
            assert str(attr.GetTypeName()) == type_name
            assert same_value(attr.Get(), fallback)
    prim.GetAttribute("volphoton:phase").Set("mixture")
    prim.GetAttribute(vs.lobe_attr("forward", "weight")).Set(3.0)
    prim.GetAttribute(vs.lobe_attr("forward", "g")).Set(0.8)
    prim.GetAttribute(vs.lobe_attr("back", "phase")).Set("schlick")
    prim.GetAttribute(vs.lobe_attr("back", "g")).Set(-0.5)
    desc, diags = vs.read_medium(prim)
    assert diags == []
    assert desc.phase.kind == "mixture"
    assert [w for w, _ in desc.phase.lobes] == [3.0, 1.0]
    fwd, back = (p for _, p in desc.phase.lobes)
    assert (fwd.kind, fwd.g) == ("henyeyGreenstein", f32(0.8))
    assert back.kind == "schlick"
    assert back.k == pytest.approx(vs.schlick_k_from_g(-0.5), abs=1e-7)
    prim.RemoveAPI(LOBE, "back")
    desc, _ = vs.read_medium(prim)
    assert len(desc.phase.lobes) == 1


# ------------------------------------------------------------------------------------------
# Round trip
# ------------------------------------------------------------------------------------------


def random_phase(rng, allow_mixture):
    kinds = PHASES if allow_mixture else PHASES[:-1]
    kind = rng.choice(kinds)
    values = {"phase": kind, "g": rng.uniform(-0.99, 0.99), "x": rng.uniform(-1, 1),
              "table": [rng.uniform(0, 5) for _ in range(rng.randint(2, 40))]}
    if rng.random() < 0.5:
        values["k"] = rng.uniform(-0.99, 0.99)
    return values


def expected_phase(values, lobes=()):
    g = f32(values["g"])
    # Derived k is clamped: 1.55 g - 0.55 g^3 exceeds 1 in magnitude for |g| > ~0.93.
    k = f32(values["k"]) if "k" in values else min(max(vs.schlick_k_from_g(g), -vs.G_LIMIT), vs.G_LIMIT)
    return dict(kind=values["phase"], g=g, k=k, x=f32(values["x"]),
                table=[f32(v) for v in values["table"]], lobes=list(lobes))


def author_phase(prim, values, name_of):
    for key in ("phase", "g", "k", "x"):
        if key in values:
            author(prim, name_of(key), values[key])
    author(prim, name_of("table"), Vt.FloatArray(values["table"]))


def compare_phase(got, want):
    assert got.kind == want["kind"]
    assert got.g == want["g"] and got.x == want["x"]
    assert got.k == pytest.approx(want["k"], abs=1e-12)
    assert got.table == want["table"]
    assert len(got.lobes) == len(want["lobes"])
    for (w, lobe), (ww, wlobe) in zip(got.lobes, want["lobes"]):
        assert w == ww
        compare_phase(lobe, wlobe)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("kind", ["volume", "cube"])
def test_round_trip_of_every_authored_value(tmp_path, seed, kind):
    rng = random.Random(seed * 7919 + (kind == "cube"))
    stage = new_stage(tmp_path, up=rng.choice(["Y", "Z"]))
    prim = volume(stage) if kind == "volume" else cube(stage)

    color = lambda lo, hi: tuple(rng.uniform(lo, hi) for _ in range(3))  # noqa: E731
    values = {
        "volphoton:density": rng.uniform(0, 100),
        "volphoton:albedo": color(0, 1),
        "volphoton:extinctionColor": color(0, 4),
        "volphoton:emission": color(0, 20),
        "volphoton:emissionScale": rng.uniform(0, 10),
        "volphoton:temperatureScale": rng.uniform(0, 3000),
        "volphoton:exponential:a": rng.uniform(0, 5),
        "volphoton:exponential:b": rng.uniform(0, 5),
        "volphoton:exponential:origin": color(-100, 100),
        "volphoton:preset": rng.choice(["", "marble", "skimmilk", "someStudioMaterial"]),
        "volphoton:sceneUnitsPerMm": rng.uniform(0.001, 1000),
    }
    if kind == "cube":
        values["volphoton:ior"] = rng.uniform(1, 2.5)
    for name, value in values.items():
        author(prim, name, Gf.Vec3f(*value) if isinstance(value, tuple) else value)
    up = np.array([rng.gauss(0, 1) for _ in range(3)])
    up = tuple(float(c) for c in up / np.linalg.norm(up))
    author(prim, "volphoton:exponential:up", Gf.Vec3f(*up))
    lo = color(-50, 0)
    hi = tuple(c + rng.uniform(0.1, 50) for c in lo)
    if kind == "volume":
        author(prim, "volphoton:bounds:min", Gf.Vec3f(*lo))
        author(prim, "volphoton:bounds:max", Gf.Vec3f(*hi))

    # Phase, with lobes when it is a mixture.
    phase = random_phase(rng, allow_mixture=True)
    if seed == 0:
        phase["phase"] = "mixture"
    author_phase(prim, phase, lambda k: "volphoton:phase" if k == "phase" else "volphoton:phase:" + k)
    lobes = []
    for i in range(rng.randint(1, 4) if phase["phase"] == "mixture" else 0):
        name = "lobe%d" % i
        assert prim.ApplyAPI(LOBE, name)
        weight = rng.uniform(0.01, 5)
        author(prim, vs.lobe_attr(name, "weight"), weight)
        lv = random_phase(rng, allow_mixture=False)
        author_phase(prim, lv, lambda k, n=name: vs.lobe_attr(n, k))
        lobes.append((f32(weight), expected_phase(lv)))

    # Fields (volume): every field name, with fieldName/fieldIndex, density mode random.
    fields = {}
    if kind == "volume":
        for fname in vs.FIELD_NAMES:
            path = touch(str(tmp_path / "vdb" / ("%s_%d.vdb" % (fname, seed))))
            index = rng.randint(0, 3)
            vdb_asset(stage, "/World/fog/" + fname, "./vdb/" + os.path.basename(path), fname + "Grid", index)
            bind_field(prim, fname, "/World/fog/" + fname)
            fields[fname] = vs.FieldDesc(path, fname + "Grid", index, "/World/fog/" + fname)
    mode = rng.choice(vs.DENSITY_MODES if kind == "volume" else ("constant", "exponential"))
    author(prim, "volphoton:densityMode", mode)

    stage.GetRootLayer().Save()
    stage = Usd.Stage.Open(str(tmp_path / "scene.usda"))  # read back from disk
    desc, diags = vs.read_medium(stage.GetPrimAtPath(prim.GetPath()))
    assert diags == [], [str(d) for d in diags]

    assert desc.prim_path == str(prim.GetPath())
    assert desc.density == f32(values["volphoton:density"])
    assert desc.albedo == f32(values["volphoton:albedo"])
    assert desc.extinction_color == f32(values["volphoton:extinctionColor"])
    assert desc.emission == f32(values["volphoton:emission"])
    assert desc.emission_scale == f32(values["volphoton:emissionScale"])
    assert desc.temperature_scale == f32(values["volphoton:temperatureScale"])
    assert desc.exp_a == f32(values["volphoton:exponential:a"])
    assert desc.exp_b == f32(values["volphoton:exponential:b"])
    assert desc.exp_origin == f32(values["volphoton:exponential:origin"])
    assert desc.exp_up == pytest.approx(up, abs=1e-6)
    assert math.isclose(sum(c * c for c in desc.exp_up), 1.0, abs_tol=1e-12)
    assert desc.preset == values["volphoton:preset"]
    assert desc.scene_units_per_mm == f32(values["volphoton:sceneUnitsPerMm"])
    assert desc.ior == (f32(values["volphoton:ior"]) if kind == "cube" else 1.0)
    assert desc.bounds == ((f32(lo), f32(hi)) if kind == "volume" else None)
    assert desc.density_mode == mode
    assert desc.fields == fields
    compare_phase(desc.phase, expected_phase(phase, lobes if phase["phase"] == "mixture" else ()))


def test_time_varying_values_are_read_at_the_given_time(tmp_path):
    stage = new_stage(tmp_path)
    prim = volume(stage)
    attr = author(prim, "volphoton:density", 1.0)
    attr.Set(2.0, 1)
    attr.Set(4.0, 3)
    author(prim, "volphoton:albedo", Gf.Vec3f(0.1, 0.2, 0.3)).Set(Gf.Vec3f(0.5, 0.5, 0.5), 10)
    assert vs.read_medium(prim)[0].density == 1.0
    assert vs.read_medium(prim, Usd.TimeCode(1))[0].density == 2.0
    assert vs.read_medium(prim, 2)[0].density == 3.0  # linear interpolation
    assert vs.read_medium(prim, 3)[0].density == 4.0
    assert vs.read_medium(prim, 10)[0].albedo == (0.5, 0.5, 0.5)


# ------------------------------------------------------------------------------------------
# Defaults
# ------------------------------------------------------------------------------------------

DEFAULT_DESC = dict(density=1.0, albedo=(0.8, 0.8, 0.8), extinction_color=(1.0, 1.0, 1.0),
                    emission=(0.0, 0.0, 0.0), emission_scale=1.0, temperature_scale=1.0,
                    density_mode="constant", exp_a=1.0, exp_b=1.0, exp_origin=(0.0, 0.0, 0.0), ior=1.0,
                    preset="", scene_units_per_mm=1.0, bounds=None, fields={})


def check_defaults(desc, up):
    for key, value in DEFAULT_DESC.items():
        got = getattr(desc, key)
        if isinstance(value, tuple):
            assert got == pytest.approx(value, abs=1e-7), key
        else:
            assert got == value, key
    assert desc.exp_up == up
    p = desc.phase
    assert (p.kind, p.g, p.k, p.x, p.table, p.lobes) == ("henyeyGreenstein", 0.0, 0.0, 0.0, [], [])


@pytest.mark.parametrize("up", ["Y", "Z"])
def test_defaults_when_nothing_is_authored(tmp_path, up):
    stage = new_stage(tmp_path, up=up)
    up_vec = (0.0, 1.0, 0.0) if up == "Y" else (0.0, 0.0, 1.0)
    for prim in (volume(stage, "/World/withApi"), volume(stage, "/World/noApi", api=False),
                 cube(stage, "/World/box")):
        desc, diags = vs.read_medium(prim)
        assert diags == [], [str(d) for d in diags]
        assert desc.prim_path == str(prim.GetPath())
        check_defaults(desc, up_vec)


def test_non_media_give_none(tmp_path):
    stage = new_stage(tmp_path)
    assert vs.read_medium(cube(stage, "/World/plainCube", api=False)) == (None, [])
    assert vs.read_medium(stage.GetPrimAtPath("/World")) == (None, [])
    assert vs.read_medium(Usd.Prim()) == (None, [])
    # Medium attributes without the API: not a medium, but the TD is told.
    prim = cube(stage, "/World/forgot", api=False)
    author(prim, "volphoton:density", 2.0)
    desc, diags = vs.read_medium(prim)
    assert desc is None
    assert len(diags) == 1 and diags[0].severity == "warning" and MEDIUM in diags[0].message
    assert diags[0].prim_path == "/World/forgot"


def test_density_mode_defaults_to_field_when_a_density_field_is_bound(tmp_path):
    stage = new_stage(tmp_path)
    path = touch(str(tmp_path / "smoke.vdb"))
    for api in (True, False):
        prim = volume(stage, "/World/smoke%d" % api, api=api)
        vdb_asset(stage, str(prim.GetPath()) + "/density", "./smoke.vdb")
        bind_field(prim, "density", str(prim.GetPath()) + "/density")
        desc, diags = vs.read_medium(prim)
        assert diags == []
        assert desc.density_mode == "field"
        assert desc.fields["density"] == vs.FieldDesc(path, "density", -1, str(prim.GetPath()) + "/density")
    # Other fields alone do not make it a field-density medium.
    prim = volume(stage, "/World/glow")
    vdb_asset(stage, "/World/glow/t", "./smoke.vdb", "temperature")
    bind_field(prim, "temperature", "/World/glow/t")
    desc, diags = vs.read_medium(prim)
    assert diags == [] and desc.density_mode == "constant" and set(desc.fields) == {"temperature"}


def test_schlick_k_derived_from_g_only_when_not_authored(tmp_path):
    stage = new_stage(tmp_path)
    prim = volume(stage)
    author(prim, "volphoton:phase", "schlick")
    author(prim, "volphoton:phase:g", 0.6)
    desc, _ = vs.read_medium(prim)
    g = f32(0.6)
    assert desc.phase.k == pytest.approx(1.55 * g - 0.55 * g ** 3, abs=1e-12)
    author(prim, "volphoton:phase:k", -0.25)
    desc, _ = vs.read_medium(prim)
    assert desc.phase.k == -0.25
    # k derived from a g near 1 stays inside (-1, 1).
    author(prim, "volphoton:phase:g", 0.999999)
    prim.GetAttribute("volphoton:phase:k").Clear()
    desc, _ = vs.read_medium(prim)
    assert abs(desc.phase.k) < 1


# ------------------------------------------------------------------------------------------
# Diagnostics
# ------------------------------------------------------------------------------------------

NAN = float("nan")

# (id, prim kind, {attribute: value}, lobes, severity, attribute named, check(desc))
BAD_INPUTS = [
    ("g_above", "volume", {"volphoton:phase:g": 1.5}, None, "warning", "volphoton:phase:g",
     lambda d: d.phase.g == vs.G_LIMIT),
    ("g_below", "volume", {"volphoton:phase:g": -1.0}, None, "warning", "volphoton:phase:g",
     lambda d: d.phase.g == -vs.G_LIMIT),
    ("g_nan", "volume", {"volphoton:phase:g": NAN}, None, "error", "volphoton:phase:g",
     lambda d: d.phase.g == 0.0),
    ("k_range", "cube", {"volphoton:phase": "schlick", "volphoton:phase:k": 1.2}, None, "warning",
     "volphoton:phase:k", lambda d: d.phase.k == vs.G_LIMIT),
    ("x_range", "volume", {"volphoton:phase": "linear", "volphoton:phase:x": -3.0}, None, "warning",
     "volphoton:phase:x", lambda d: d.phase.x == -1.0),
    ("density_negative", "volume", {"volphoton:density": -2.0}, None, "warning", "volphoton:density",
     lambda d: d.density == 0.0),
    ("density_nan", "cube", {"volphoton:density": NAN}, None, "error", "volphoton:density",
     lambda d: d.density == 1.0),
    ("density_inf", "volume", {"volphoton:density": float("inf")}, None, "error", "volphoton:density",
     lambda d: d.density == 1.0),
    ("albedo_range", "volume", {"volphoton:albedo": Gf.Vec3f(1.5, 0.5, -0.25)}, None, "warning",
     "volphoton:albedo", lambda d: d.albedo == (1.0, 0.5, 0.0)),
    ("albedo_nan", "volume", {"volphoton:albedo": Gf.Vec3f(NAN, 0.5, 0.5)}, None, "error",
     "volphoton:albedo", lambda d: d.albedo == (0.8, 0.5, 0.5)),
    ("extinction_negative", "cube", {"volphoton:extinctionColor": Gf.Vec3f(-1, 2, 1)}, None, "warning",
     "volphoton:extinctionColor", lambda d: d.extinction_color == (0.0, 2.0, 1.0)),
    ("emission_negative", "volume", {"volphoton:emission": Gf.Vec3f(0, -3, 1)}, None, "warning",
     "volphoton:emission", lambda d: d.emission == (0.0, 0.0, 1.0)),
    ("emission_scale_negative", "volume", {"volphoton:emissionScale": -1.0}, None, "warning",
     "volphoton:emissionScale", lambda d: d.emission_scale == 0.0),
    ("temperature_scale_nan", "volume", {"volphoton:temperatureScale": NAN}, None, "error",
     "volphoton:temperatureScale", lambda d: d.temperature_scale == 1.0),
    ("phase_unknown", "volume", {"volphoton:phase": "cardioid"}, None, "error", "volphoton:phase",
     lambda d: d.phase.kind == "henyeyGreenstein"),
    ("density_mode_unknown", "volume", {"volphoton:densityMode": "procedural"}, None, "error",
     "volphoton:densityMode", lambda d: d.density_mode == "constant"),
    ("density_mode_field_on_cube", "cube", {"volphoton:densityMode": "field"}, None, "error",
     "volphoton:densityMode", lambda d: d.density_mode == "constant"),
    ("density_mode_field_without_field", "volume", {"volphoton:densityMode": "field"}, None, "error",
     "volphoton:densityMode", lambda d: d.density_mode == "constant"),
    ("mixture_without_lobes", "volume", {"volphoton:phase": "mixture"}, None, "error", "volphoton:phase",
     lambda d: d.phase.kind == "isotropic" and d.phase.lobes == []),
    ("mixture_zero_weights", "cube", {"volphoton:phase": "mixture"}, {"a": {"weight": 0.0}, "b": {"weight": 0.0}},
     "error", "volphoton:phase", lambda d: d.phase.kind == "isotropic" and d.phase.lobes == []),
    ("lobe_weight_negative", "volume", {"volphoton:phase": "mixture"},
     {"a": {"weight": -1.0}, "b": {"weight": 2.0}}, "warning", "volphoton:lobe:a:weight",
     lambda d: [w for w, _ in d.phase.lobes] == [0.0, 2.0]),
    ("lobe_phase_mixture", "volume", {"volphoton:phase": "mixture"}, {"a": {"phase": "mixture"}}, "error",
     "volphoton:lobe:a:phase", lambda d: d.phase.lobes[0][1].kind == "henyeyGreenstein"),
    ("lobe_phase_unknown", "volume", {"volphoton:phase": "mixture"}, {"a": {"phase": "mie"}}, "error",
     "volphoton:lobe:a:phase", lambda d: d.phase.lobes[0][1].kind == "henyeyGreenstein"),
    ("lobe_g_range", "volume", {"volphoton:phase": "mixture"}, {"a": {"g": 2.0}}, "warning",
     "volphoton:lobe:a:g", lambda d: d.phase.lobes[0][1].g == vs.G_LIMIT),
    ("lobe_table_short", "volume", {"volphoton:phase": "mixture"},
     {"a": {"phase": "tabulated", "table": Vt.FloatArray([1.0])}}, "error", "volphoton:lobe:a:table",
     lambda d: d.phase.lobes[0][1].kind == "isotropic"),
    ("lobes_without_mixture", "volume", {"volphoton:phase": "isotropic"}, {"a": {}}, "warning",
     "volphoton:phase", lambda d: d.phase.kind == "isotropic" and d.phase.lobes == []),
    ("table_short", "volume", {"volphoton:phase": "tabulated", "volphoton:phase:table": Vt.FloatArray([2.0])},
     None, "error", "volphoton:phase:table", lambda d: d.phase.kind == "isotropic"),
    ("table_missing", "volume", {"volphoton:phase": "tabulated"}, None, "error", "volphoton:phase:table",
     lambda d: d.phase.kind == "isotropic"),
    ("table_negative", "volume", {"volphoton:phase": "tabulated",
                                  "volphoton:phase:table": Vt.FloatArray([1.0, -0.5, 2.0])},
     None, "warning", "volphoton:phase:table",
     lambda d: d.phase.kind == "tabulated" and d.phase.table == [1.0, 0.0, 2.0]),
    ("table_zero", "volume", {"volphoton:phase": "tabulated", "volphoton:phase:table": Vt.FloatArray([0.0, 0.0])},
     None, "error", "volphoton:phase:table", lambda d: d.phase.kind == "isotropic"),
    ("table_nan", "volume", {"volphoton:phase": "tabulated",
                             "volphoton:phase:table": Vt.FloatArray([1.0, NAN, 1.0])},
     None, "error", "volphoton:phase:table", lambda d: d.phase.table == [1.0, 0.0, 1.0]),
    ("exp_b_negative", "volume", {"volphoton:exponential:b": -0.5}, None, "warning", "volphoton:exponential:b",
     lambda d: d.exp_b == 0.0),
    ("exp_a_negative", "volume", {"volphoton:exponential:a": -0.5}, None, "warning", "volphoton:exponential:a",
     lambda d: d.exp_a == 0.0),
    ("exp_up_zero", "volume", {"volphoton:exponential:up": Gf.Vec3f(0, 0, 0)}, None, "error",
     "volphoton:exponential:up", lambda d: d.exp_up == (0.0, 1.0, 0.0)),
    ("exp_origin_nan", "volume", {"volphoton:exponential:origin": Gf.Vec3f(0, NAN, 0)}, None, "error",
     "volphoton:exponential:origin", lambda d: d.exp_origin == (0.0, 0.0, 0.0)),
    ("ior_below_one", "cube", {"volphoton:ior": 0.5}, None, "warning", "volphoton:ior", lambda d: d.ior == 1.0),
    ("ior_nan", "cube", {"volphoton:ior": NAN}, None, "error", "volphoton:ior", lambda d: d.ior == 1.0),
    ("ior_on_volume", "volume", {"volphoton:ior": 1.5}, None, "warning", "volphoton:ior", lambda d: True),
    ("scene_units_zero", "cube", {"volphoton:sceneUnitsPerMm": 0.0}, None, "error", "volphoton:sceneUnitsPerMm",
     lambda d: d.scene_units_per_mm == 1.0),
    ("bounds_inverted", "volume", {"volphoton:bounds:min": Gf.Vec3f(0, 0, 0), "volphoton:bounds:max": Gf.Vec3f(1, -1, 1)},
     None, "error", "volphoton:bounds:min", lambda d: d.bounds is None),
    ("bounds_half", "volume", {"volphoton:bounds:max": Gf.Vec3f(1, 1, 1)}, None, "warning", "volphoton:bounds:max",
     lambda d: d.bounds is None),
    ("wrong_value_type", "volume", {}, None, "error", "volphoton:density", lambda d: d.density == 1.0),
]


@pytest.mark.parametrize("case", BAD_INPUTS, ids=[c[0] for c in BAD_INPUTS])
def test_bad_input_gives_diagnostic_naming_prim_and_attribute(tmp_path, case):
    cid, kind, attrs, lobes, severity, attr_name, check = case
    stage = new_stage(tmp_path)
    path = "/World/medium_" + cid
    prim = volume(stage, path) if kind == "volume" else cube(stage, path)
    for name, value in attrs.items():
        author(prim, name, value)
    for lobe, lvalues in (lobes or {}).items():
        assert prim.ApplyAPI(LOBE, lobe)
        for key, value in lvalues.items():
            author(prim, vs.lobe_attr(lobe, key), value)
    if cid == "wrong_value_type":
        # A Volume without the API may carry a mistyped opinion; the reader must not crash.
        prim.RemoveAPI(MEDIUM)
        prim.CreateAttribute("volphoton:density", Sdf.ValueTypeNames.String).Set("thick")
    desc, diags = vs.read_medium(prim)
    assert desc is not None
    hits = [d for d in diags if d.prim_path == path and d.attribute == attr_name]
    assert hits, "no diagnostic for %s.%s in %s" % (path, attr_name, [str(d) for d in diags])
    assert hits[0].severity == severity, str(hits[0])
    text = str(hits[0])
    assert text.startswith("%s: %s.%s: " % (severity, path, attr_name)), text
    assert check(desc), (cid, desc)


def test_diagnostic_text():
    d = vs.Diagnostic("error", "/World/fog", "volphoton:phase:g", "g = 1.5 is outside (-1, 1); clamped to 0.99999")
    assert str(d) == "error: /World/fog.volphoton:phase:g: g = 1.5 is outside (-1, 1); clamped to 0.99999"
    assert str(vs.Diagnostic("warning", "/World/fog", "", "hello")) == "warning: /World/fog: hello"
    stage = Usd.Stage.CreateInMemory()
    prim = UsdVol.Volume.Define(stage, "/World/fog").GetPrim()
    prim.ApplyAPI(MEDIUM)
    prim.GetAttribute("volphoton:phase:g").Set(1.5)
    _, diags = vs.read_medium(prim)
    assert [str(x) for x in diags] == [
        "warning: /World/fog.volphoton:phase:g: g = 1.5 is outside (-1, 1); clamped to 0.99999"]


def test_field_relationship_errors(tmp_path):
    stage = new_stage(tmp_path)
    touch(str(tmp_path / "ok.vdb"))
    prim = volume(stage)
    UsdGeom.Xform.Define(stage, "/World/notAField")
    UsdVol.Field3DAsset.Define(stage, "/World/f3d").GetFilePathAttr().Set(Sdf.AssetPath("./ok.vdb"))
    vdb_asset(stage, "/World/noPath", None)
    vdb_asset(stage, "/World/badPath", "./missing/smoke.0042.vdb")
    vdb_asset(stage, "/World/ok", "./ok.vdb")
    bind_field(prim, "density", "/World/notAField")
    bind_field(prim, "emission", "/World/f3d")
    bind_field(prim, "temperature", "/World/nothingHere")
    bind_field(prim, "albedo", "/World/noPath")
    prim.CreateRelationship("field:velocity").SetTargets([Sdf.Path("/World/ok")])  # not ours: ignored
    desc, diags = vs.read_medium(prim)
    by_attr = {(d.prim_path, d.attribute): d for d in diags}
    for rel, target in (("field:density", "/World/notAField"), ("field:emission", "/World/f3d"),
                        ("field:temperature", "/World/nothingHere")):
        d = by_attr[("/World/fog", rel)]
        assert d.severity == "error" and target in d.message
    d = by_attr[("/World/noPath", "filePath")]
    assert d.severity == "error" and "field:albedo" in d.message and "/World/fog" in d.message
    assert set(desc.fields) == {"albedo"} and desc.fields["albedo"].file_path == ""
    assert desc.density_mode == "constant"

    bind_field(prim, "albedo", "/World/badPath")
    desc, diags = vs.read_medium(prim)
    d = [x for x in diags if x.prim_path == "/World/badPath"]
    assert len(d) == 1 and d[0].severity == "error" and d[0].attribute == "filePath"
    assert "./missing/smoke.0042.vdb" in d[0].message
    assert desc.fields["albedo"].file_path == ""

    # Several targets: the first is used, with a warning.
    prim.GetRelationship("field:albedo").SetTargets([Sdf.Path("/World/ok"), Sdf.Path("/World/badPath")])
    desc, diags = vs.read_medium(prim)
    assert desc.fields["albedo"].file_path == str(tmp_path / "ok.vdb")
    assert any(x.attribute == "field:albedo" and x.severity == "warning" for x in diags)


def test_time_sampled_file_path_resolves_per_frame(tmp_path):
    stage = new_stage(tmp_path)
    prim = volume(stage)
    asset = vdb_asset(stage, "/World/fog/density", None)
    frames = {}
    for frame in (1, 2, 3, 5):
        frames[frame] = touch(str(tmp_path / "seq" / ("fog.%04d.vdb" % frame)))
        asset.GetFilePathAttr().Set(Sdf.AssetPath("./seq/fog.%04d.vdb" % frame), frame)
    asset.GetFilePathAttr().Set(Sdf.AssetPath("./seq/fog.0004.vdb"), 4)  # not on disk
    asset.GetFieldIndexAttr().Set(0, 1)
    asset.GetFieldIndexAttr().Set(7, 5)
    bind_field(prim, "density", "/World/fog/density")
    stage.GetRootLayer().Save()
    stage = Usd.Stage.Open(str(tmp_path / "scene.usda"))
    prim = stage.GetPrimAtPath("/World/fog")

    for frame, path in frames.items():
        desc, diags = vs.read_medium(prim, Usd.TimeCode(frame))
        assert diags == [], [str(d) for d in diags]
        assert desc.fields["density"].file_path == path
        assert os.path.isabs(desc.fields["density"].file_path)
        assert desc.density_mode == "field"
    assert vs.read_medium(prim, 5)[0].fields["density"].field_index == 7
    assert vs.read_medium(prim, 1)[0].fields["density"].field_index == 0
    # Asset paths are held, not interpolated: time 2.5 uses frame 2.
    assert vs.read_medium(prim, 2.5)[0].fields["density"].file_path == frames[2]

    desc, diags = vs.read_medium(prim, 4)
    assert desc.fields["density"].file_path == ""
    assert [(d.severity, d.prim_path, d.attribute) for d in diags] == [
        ("error", "/World/fog/density", "filePath")]
    assert "fog.0004.vdb" in diags[0].message

    # No time given for a sequence: the first sample is used, with a warning.
    desc, diags = vs.read_medium(prim)
    assert desc.fields["density"].file_path == frames[1]
    assert [(d.severity, d.attribute) for d in diags] == [("warning", "filePath")]


# ------------------------------------------------------------------------------------------
# Example stage, usdchecker, CLI, plug-in missing, imports
# ------------------------------------------------------------------------------------------

EXAMPLE = """\
#usda 1.0
(
    defaultPrim = "World"
    metersPerUnit = 1
    upAxis = "Y"
)

def Xform "World"
{
    def Volume "fog" (
        prepend apiSchemas = ["VolPhotonMediumAPI", "VolPhotonPhaseLobeAPI:forward", "VolPhotonPhaseLobeAPI:back"]
    )
    {
        float3[] extent = [(-1, -1, -1), (1, 1, 1)]
        float volphoton:density = 0.5
        color3f volphoton:albedo = (0.9, 0.9, 0.9)
        uniform token volphoton:phase = "mixture"
        float volphoton:lobe:forward:weight = 0.8
        float volphoton:lobe:forward:g = 0.7
        float volphoton:lobe:back:weight = 0.2
        float volphoton:lobe:back:g = -0.3
        rel field:density = </World/fog/density>

        def OpenVDBAsset "density"
        {
            asset filePath.timeSamples = {
                1: @./fog.0001.vdb@,
                2: @./fog.0002.vdb@,
            }
            token fieldName = "density"
        }
    }

    def Volume "haze" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        uniform token volphoton:densityMode = "exponential"
        float volphoton:exponential:b = 0.2
        point3f volphoton:bounds:min = (-100, 0, -100)
        point3f volphoton:bounds:max = (100, 20, 100)
        uniform token volphoton:phase = "rayleigh"
    }

    def Cube "jade" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {
        double size = 2
        float volphoton:density = 3
        color3f volphoton:albedo = (0.6, 0.95, 0.7)
        float volphoton:ior = 1.6
        uniform token volphoton:preset = "marble"
        float volphoton:sceneUnitsPerMm = 0.1
    }
}
"""


@pytest.fixture
def example_stage(tmp_path):
    path = tmp_path / "example.usda"
    path.write_text(EXAMPLE)
    touch(str(tmp_path / "fog.0001.vdb"))
    touch(str(tmp_path / "fog.0002.vdb"))
    return str(path)


def find_usdchecker():
    for cand in (os.path.join(os.path.dirname(sys.executable), "usdchecker"), shutil.which("usdchecker")):
        if cand and os.path.exists(cand):
            return cand
    return None


def test_example_stage_passes_usdchecker(example_stage):
    checker = find_usdchecker()
    if checker is not None:
        r = subprocess.run([checker, example_stage], capture_output=True, text=True, env=dict(os.environ))
        assert r.returncode == 0, r.stdout + r.stderr
        return
    # usd-core ships no usdchecker binary: run what it runs, every registered UsdValidation validator.
    from pxr import UsdValidation
    stage = Usd.Stage.Open(example_stage)
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    assert validators
    errors = UsdValidation.ValidationContext(validators).Validate(stage)
    bad = [e.GetErrorAsString() for e in errors
           if e.GetType() in (UsdValidation.ValidationErrorType.Error, UsdValidation.ValidationErrorType.Warn)]
    assert bad == []


def test_validator_catches_mistyped_schema_attribute(tmp_path):
    """The UsdValidation attribute-type check sees our schema: a double authored where the schema
    says float is reported (so the previous test would notice a broken example)."""
    from pxr import UsdValidation
    path = tmp_path / "bad.usda"
    path.write_text(EXAMPLE.replace("float volphoton:density = 3", "double volphoton:density = 3"))
    validator = UsdValidation.ValidationRegistry().GetOrLoadValidatorByName("usdValidation:AttributeTypeMismatch")
    stage = Usd.Stage.Open(str(path))
    errors = validator.Validate(stage.GetPrimAtPath("/World/jade"))
    assert any("volphoton:density" in e.GetMessage() for e in errors), [e.GetMessage() for e in errors]


def test_example_stage_reads_cleanly(example_stage):
    stage = Usd.Stage.Open(example_stage)
    media = {str(p.GetPath()): (d, diags) for p, d, diags in vs.read_stage(stage, 1)}
    assert set(media) == {"/World/fog", "/World/haze", "/World/jade"}
    assert all(diags == [] for _, diags in media.values())
    fog = media["/World/fog"][0]
    assert fog.density_mode == "field" and fog.phase.kind == "mixture" and len(fog.phase.lobes) == 2
    assert fog.fields["density"].file_path.endswith("fog.0001.vdb")
    haze = media["/World/haze"][0]
    assert haze.density_mode == "exponential" and haze.bounds == ((-100, 0, -100), (100, 20, 100))
    jade = media["/World/jade"][0]
    assert jade.preset == "marble" and jade.ior == f32(1.6) and jade.scene_units_per_mm == f32(0.1)


def run_py(code, *args, env_updates=None, drop_plugin=False):
    env = dict(os.environ)
    # The installed package: the reader's rules are the compiled core's (core/translate/medium.h).
    if drop_plugin:
        env.pop("PXR_PLUGINPATH_NAME", None)
    env.update(env_updates or {})
    return subprocess.run([sys.executable] + (["-c", code] if code else []) + list(args),
                          capture_output=True, text=True, env=env)


def test_cli_exit_status(example_stage, tmp_path):
    r = run_py(None, "-m", "volphoton.schema", example_stage, "--time", "1")
    assert r.returncode == 0, r.stdout + r.stderr
    bad = tmp_path / "bad.usda"
    bad.write_text(EXAMPLE.replace("float volphoton:density = 3", "float volphoton:density = -3")
                   .replace('"rayleigh"', '"fancy"'))
    r = run_py(None, "-m", "volphoton.schema", str(bad), "--time", "1")
    assert r.returncode == 1
    assert "error: /World/haze.volphoton:phase: unknown phase 'fancy'" in r.stdout
    assert "warning: /World/jade.volphoton:density: density = -3 is negative; clamped to 0" in r.stdout


def test_reader_without_registered_plugin(example_stage):
    code = textwrap.dedent("""
        import sys
        from pxr import Usd
        from volphoton import schema as vs
        assert not vs.is_schema_registered()
        stage = Usd.Stage.Open(sys.argv[1])
        desc, diags = vs.read_medium(stage.GetPrimAtPath('/World/haze'), 1)
        assert desc.density_mode == 'exponential' and desc.exp_b == 0.2 - (0.2 - float(__import__('numpy').float32(0.2)))
        assert desc.density == 1.0 and desc.albedo == (0.8, 0.8, 0.8), desc
        assert [d.severity for d in diags] == ['warning'] and 'PXR_PLUGINPATH_NAME' in diags[0].message
        desc, diags = vs.read_medium(stage.GetPrimAtPath('/World/fog'), 1)
        assert desc.phase.kind == 'mixture' and len(desc.phase.lobes) == 2
        print('ok')
    """)
    r = run_py(code, example_stage, drop_plugin=True)
    assert r.returncode == 0 and "ok" in r.stdout, r.stdout + r.stderr


def test_module_imports_only_pxr_stdlib_and_the_core():
    """schema.py reads values off the stage; its rules are the C++ translation layer's (_core)."""
    with open(os.path.join(PY_DIR, "volphoton", "schema.py")) as f:
        tree = ast.parse(f.read())
    allowed = set(sys.stdlib_module_names) | {"pxr", "numpy"}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            mods = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level == 1:
                assert [a.name for a in node.names] == ["_core"], "relative import of %s" % node.names
                continue
            assert node.level == 0, "relative import"
            mods = [node.module]
        else:
            continue
        for mod in mods:
            assert mod.split(".")[0] in allowed, mod
