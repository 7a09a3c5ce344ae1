"""glTF 2.0 -> USD (`volphoton gltf2usd`, volphoton/gltf.py, hdVolPhoton/gltf/gltfToUsda.cpp).

Every asset is generated here with tools/gltf_writer.py, which stores exactly the numbers it is given
in the requested component types; the expected USD values are computed from those numbers with
numpy (normalized integers per the glTF 2.0 formulas, UV t = 1 - v), independently of the translator,
and compared exactly (vertex data, indices, authored transform ops).  Composed world transforms are
compared against numpy's T*R*S products to 1e-12 (floating-point composition order differs).
"""

import json
import os
import random
import struct
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO, volphoton_exe

sys.path.insert(0, os.path.join(REPO, "tools"))
import gltf_writer as gw  # noqa: E402

from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade  # noqa: E402

from volphoton import gltf  # noqa: E402

TRI = np.array([[0, 1, 2], [2, 1, 3]])


def convert(src, dst, *extra):
    p = subprocess.run([volphoton_exe(), "gltf2usd", str(src), str(dst)] + list(extra), capture_output=True,
                       text=True, timeout=120)
    return p.returncode, p.stdout + p.stderr


def arr(values, dtype=np.float32):
    return np.array(values, dtype=dtype)


def mesh_prims(stage):
    return [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]


# ---- vertex data -------------------------------------------------------------------------------

# (attribute, component type, normalized, components): the combinations glTF 2.0 and
# KHR_mesh_quantization allow for the attributes the translator reads.
ATTRIBUTE_CASES = [
    ("POSITION", gw.FLOAT, False, 3), ("POSITION", gw.BYTE, False, 3), ("POSITION", gw.BYTE, True, 3),
    ("POSITION", gw.UNSIGNED_BYTE, False, 3), ("POSITION", gw.UNSIGNED_BYTE, True, 3),
    ("POSITION", gw.SHORT, False, 3), ("POSITION", gw.SHORT, True, 3),
    ("POSITION", gw.UNSIGNED_SHORT, False, 3), ("POSITION", gw.UNSIGNED_SHORT, True, 3),
    ("NORMAL", gw.FLOAT, False, 3), ("NORMAL", gw.BYTE, True, 3), ("NORMAL", gw.SHORT, True, 3),
    ("TEXCOORD_0", gw.FLOAT, False, 2), ("TEXCOORD_0", gw.UNSIGNED_BYTE, True, 2),
    ("TEXCOORD_0", gw.UNSIGNED_SHORT, True, 2), ("TEXCOORD_0", gw.BYTE, True, 2), ("TEXCOORD_0", gw.SHORT, False, 2),
    ("COLOR_0", gw.FLOAT, False, 3), ("COLOR_0", gw.FLOAT, False, 4), ("COLOR_0", gw.UNSIGNED_BYTE, True, 4),
    ("COLOR_0", gw.UNSIGNED_SHORT, True, 3),
]
INDEX_TYPES = [gw.UNSIGNED_BYTE, gw.UNSIGNED_SHORT, gw.UNSIGNED_INT]


def sample_values(component_type, n, rng, count=4):
    """Values spanning the type's range, extremes included (-128 -> -1 after normalization)."""
    if component_type == gw.FLOAT:
        return rng.uniform(-3, 3, (count, n)).astype(np.float32)
    info = np.iinfo(gw.DTYPES[component_type])
    v = rng.integers(info.min, info.max, (count, n), endpoint=True)
    v[0, 0], v[-1, -1] = info.min, info.max
    return v.astype(gw.DTYPES[component_type])


def expected_floats(values, component_type, normalized):
    return gw.normalized_to_float(values, component_type) if normalized else np.asarray(values).astype(np.float32)


def build_attribute_asset():
    """One mesh + node per attribute case; strides, offsets and index types vary across cases."""
    rng = np.random.default_rng(7)
    w = gw.GltfWriter()
    expected = []
    for i, (attr, ctype, normalized, n) in enumerate(ATTRIBUTE_CASES):
        values = sample_values(ctype, n, rng)
        element = np.dtype(gw.DTYPES[ctype]).itemsize * n
        stride = (element + 7) // 4 * 4 if i % 2 else None  # every other case interleaved with padding
        acc = w.accessor(values, ctype, normalized=normalized, stride=stride, byte_offset=4 * (i % 3))
        attrs = {attr: acc}
        positions = values if attr == "POSITION" else rng.uniform(-1, 1, (4, 3)).astype(np.float32)
        if attr != "POSITION":
            attrs["POSITION"] = w.accessor(positions, gw.FLOAT)
        itype = INDEX_TYPES[i % 3]
        prim = {"attributes": attrs, "indices": w.accessor(TRI.reshape(-1), itype, target=gw.ELEMENT_ARRAY_BUFFER)}
        mesh = w.mesh([prim], name="case_%d" % i)
        w.node(name="node_%d" % i, mesh=mesh)
        pos_float = expected_floats(positions, ctype, normalized) if attr == "POSITION" else positions
        expected.append((attr, expected_floats(values, ctype, normalized), pos_float))
    w.scene(list(range(len(ATTRIBUTE_CASES))), name="all", default=True)
    return w, expected


def check_attribute_stage(stage, expected):
    for i, (attr, values, positions) in enumerate(expected):
        mesh = UsdGeom.Mesh(stage.GetPrimAtPath("/asset/node_%d/case_%d" % (i, i)))
        assert mesh, "node_%d" % i
        assert np.array_equal(arr(mesh.GetPointsAttr().Get()), positions), attr
        assert list(mesh.GetFaceVertexIndicesAttr().Get()) == TRI.reshape(-1).tolist()
        assert list(mesh.GetFaceVertexCountsAttr().Get()) == [3, 3]
        if attr == "NORMAL":
            assert np.array_equal(arr(mesh.GetNormalsAttr().Get()), values)
            assert mesh.GetNormalsInterpolation() == UsdGeom.Tokens.vertex
        elif attr == "TEXCOORD_0":
            st = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st")
            assert st.GetInterpolation() == UsdGeom.Tokens.vertex
            want = np.stack([values[:, 0], np.float32(1) - values[:, 1]], axis=1)
            assert np.array_equal(arr(st.Get()), want)
        elif attr == "COLOR_0":
            pv = UsdGeom.PrimvarsAPI(mesh)
            assert np.array_equal(arr(pv.GetPrimvar("displayColor").Get()), values[:, :3])
            opacity = pv.GetPrimvar("displayOpacity")
            if values.shape[1] == 4:
                assert np.array_equal(arr(opacity.Get()), values[:, 3])
            else:
                assert not opacity.HasAuthoredValue()


@pytest.mark.parametrize("container", ["glb", "gltf+bin", "gltf+datauri"])
def test_every_component_type_round_trips_exactly(tmp_path, container):
    w, expected = build_attribute_asset()
    src = tmp_path / ("asset.glb" if container == "glb" else "asset.gltf")
    if container == "glb":
        w.write_glb(str(src))
    else:
        w.write_gltf(str(src), "asset.bin" if container == "gltf+bin" else None)
    code, out = convert(src, tmp_path / "asset.usda")
    assert code == 0, out
    stage = Usd.Stage.Open(str(tmp_path / "asset.usda"))
    check_attribute_stage(stage, expected)
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    assert UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetDefaultPrim().GetPath() == Sdf.Path("/asset")


def test_containers_and_output_formats_agree(tmp_path):
    w, expected = build_attribute_asset()
    w.write_glb(str(tmp_path / "asset.glb"))
    w.write_gltf(str(tmp_path / "asset.gltf"), "asset.bin")
    texts = [gltf.translate(str(tmp_path / n))[0] for n in ("asset.glb", "asset.gltf")]
    assert texts[0] == texts[1]
    for ext in (".usdc", ".usd", ".usda"):
        out = tmp_path / ("out" + ext)
        gltf.convert(str(tmp_path / "asset.glb"), str(out))
        check_attribute_stage(Usd.Stage.Open(str(out)), expected)
    assert Sdf.Layer.FindOrOpen(str(tmp_path / "out.usdc")).GetFileFormat().formatId == "usdc"


def test_sparse_accessors(tmp_path):
    w = gw.GltfWriter()
    base = np.arange(12, dtype=np.float32).reshape(4, 3)
    dense = w.sparse_accessor(base, 4, 3, gw.FLOAT, indices=[1, 3], values=[[9, 9, 9], [-1, -2, -3]],
                              index_type=gw.UNSIGNED_BYTE)
    zeros = w.sparse_accessor(None, 4, 3, gw.SHORT, indices=[2], values=[[32767, -32768, 5]],
                              index_type=gw.UNSIGNED_INT, normalized=True)
    idx = w.accessor(TRI.reshape(-1), gw.UNSIGNED_SHORT)
    w.node(name="a", mesh=w.mesh([{"attributes": {"POSITION": dense}, "indices": idx}], name="dense"))
    w.node(name="b", mesh=w.mesh([{"attributes": {"POSITION": zeros}, "indices": idx}], name="zeros"))
    w.scene([0, 1], default=True)
    w.write_glb(str(tmp_path / "s.glb"))
    assert convert(tmp_path / "s.glb", tmp_path / "s.usda")[0] == 0
    stage = Usd.Stage.Open(str(tmp_path / "s.usda"))
    want = base.copy()
    want[1], want[3] = 9, [-1, -2, -3]
    assert np.array_equal(arr(UsdGeom.Mesh.Get(stage, "/s/a/dense").GetPointsAttr().Get()), want)
    want = np.zeros((4, 3), np.float32)
    want[2] = gw.normalized_to_float(np.array([32767, -32768, 5], np.int16), gw.SHORT)
    assert want[2, 1] == -1.0  # the spec clamps -32768 / 32767 to -1
    assert np.array_equal(arr(UsdGeom.Mesh.Get(stage, "/s/b/zeros").GetPointsAttr().Get()), want)


def test_strips_fans_and_primitives_with_materials_become_subsets(tmp_path):
    w = gw.GltfWriter()
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0, 2, 0]], np.float32)
    pos = w.accessor(pts, gw.FLOAT)
    red = w.material((1, 0, 0, 1), name="red", metallic=0.25, roughness=0.5, emissive=(0.5, 0, 0))
    blue = w.material((0, 0, 1, 0.5), name="blue", alpha_mode="MASK", alpha_cutoff=0.3)
    prims = [{"attributes": {"POSITION": pos}, "mode": gw.TRIANGLE_STRIP, "material": red,
              "indices": w.accessor([0, 1, 2, 3, 4], gw.UNSIGNED_BYTE)},
             {"attributes": {"POSITION": pos}, "mode": gw.TRIANGLE_FAN, "material": blue,
              "indices": w.accessor([0, 1, 3, 4], gw.UNSIGNED_INT)},
             {"attributes": {"POSITION": pos}, "material": red}]  # no indices: 0..4, last 2 ignored
    w.node(name="n", mesh=w.mesh(prims, name="m"))
    w.scene([0], default=True)
    w.write_glb(str(tmp_path / "p.glb"))
    code, out = convert(tmp_path / "p.glb", tmp_path / "p.usda")
    assert code == 0 and "not a multiple of 3" in out, out
    stage = Usd.Stage.Open(str(tmp_path / "p.usda"))
    mesh = UsdGeom.Mesh.Get(stage, "/p/n/m")
    # glTF 2.0 3.7.2.1: strip i -> (v_i, v_{i+1+i%2}, v_{i+2-i%2}); fan i -> (v_{i+1}, v_{i+2}, v_0)
    strip = [[0, 1, 2], [1, 3, 2], [2, 3, 4]]
    fan = [[1, 3, 0], [3, 4, 0]]
    plain = [[0, 1, 2]]
    want = np.array(strip + (np.array(fan) + 5).tolist() + (np.array(plain) + 10).tolist()).reshape(-1)
    assert list(mesh.GetFaceVertexIndicesAttr().Get()) == want.tolist()
    assert np.array_equal(arr(mesh.GetPointsAttr().Get()), np.concatenate([pts, pts, pts]))
    subsets = UsdGeom.Subset.GetGeomSubsets(mesh, UsdGeom.Tokens.face, "materialBind")
    faces = {s.GetPrim().GetName(): list(s.GetIndicesAttr().Get()) for s in subsets}
    assert faces == {"red": [0, 1, 2, 5], "blue": [3, 4]}
    valid, why = UsdGeom.Subset.ValidateFamily(mesh, UsdGeom.Tokens.face, "materialBind")
    assert valid, why
    for s in subsets:
        material, _ = UsdShade.MaterialBindingAPI(s.GetPrim()).ComputeBoundMaterial()
        assert material.GetPath() == Sdf.Path("/p/Materials/" + s.GetPrim().GetName())
    shader = UsdShade.Shader.Get(stage, "/p/Materials/red/PreviewSurface")
    assert shader.GetIdAttr().Get() == "UsdPreviewSurface"
    assert shader.GetInput("diffuseColor").Get() == Gf.Vec3f(1, 0, 0)
    assert shader.GetInput("metallic").Get() == 0.25 and shader.GetInput("roughness").Get() == 0.5
    assert shader.GetInput("emissiveColor").Get() == Gf.Vec3f(0.5, 0, 0)
    assert not shader.GetInput("opacity")  # OPAQUE ignores alpha
    blue_shader = UsdShade.Shader.Get(stage, "/p/Materials/blue/PreviewSurface")
    assert blue_shader.GetInput("opacity").Get() == 0.5
    assert blue_shader.GetInput("opacityThreshold").Get() == pytest.approx(0.3)
    colors = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("displayColor")
    assert colors.GetInterpolation() == UsdGeom.Tokens.uniform
    assert [tuple(c) for c in colors.Get()] == [(1, 0, 0)] * 3 + [(0, 0, 1)] * 2 + [(1, 0, 0)]


# ---- hierarchy, transforms, scenes --------------------------------------------------------------

def trs_matrix(t, q, s):
    """Column-vector 4x4 T * R * S from glTF translation, rotation (x, y, z, w), scale."""
    x, y, z, w = q
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * np.array(s)[None, :]
    m[:3, 3] = t
    return m


def test_node_hierarchy_transforms_and_scenes(tmp_path):
    rng = np.random.default_rng(3)
    w = gw.GltfWriter()
    pos = w.accessor(rng.uniform(-1, 1, (3, 3)), gw.FLOAT)
    mesh = w.mesh([{"attributes": {"POSITION": pos}}], name="tri")
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    t, s = rng.uniform(-5, 5, 3), rng.uniform(0.5, 2, 3)
    leaf = w.node(name="leaf", mesh=mesh, translation=t.tolist(), rotation=q.tolist(), scale=s.tolist())
    mat = trs_matrix(rng.uniform(-1, 1, 3), [0, 0.6, 0, 0.8], [1, 2, 3])
    mid = w.node(name="mid", children=[leaf], matrix=mat.T.reshape(-1).tolist())  # glTF: column-major
    only_t = w.node(name="1 odd/name", mesh=mesh, translation=[1e-300, 0.1, 3.0000000000000004])
    other = w.node(mesh=mesh)
    w.scene([mid, only_t], name="main")
    w.scene([other], name="second", default=True)
    w.write_gltf(str(tmp_path / "h.gltf"))
    code, out = convert(tmp_path / "h.gltf", tmp_path / "h.usda", "--root-name", "Asset")
    assert code == 0, out

    stage = Usd.Stage.Open(str(tmp_path / "h.usda"))
    root = stage.GetPrimAtPath("/Asset")
    vset = root.GetVariantSets().GetVariantSet("scene")
    assert vset.GetVariantNames() == ["main", "second"]
    assert vset.GetVariantSelection() == "second"  # glTF "scene": the default scene
    assert [p.GetName() for p in root.GetChildren() if p.GetName() not in ("Prototypes",)] == ["node_3"]
    vset.SetVariantSelection("main")

    leaf_prim = stage.GetPrimAtPath("/Asset/mid/leaf")
    ops = {op.GetOpName(): op.Get() for op in UsdGeom.Xformable(leaf_prim).GetOrderedXformOps()}
    assert list(ops) == ["xformOp:translate", "xformOp:orient", "xformOp:scale"]
    assert tuple(ops["xformOp:translate"]) == tuple(t)
    assert (ops["xformOp:orient"].GetReal(),) + tuple(ops["xformOp:orient"].GetImaginary()) == (q[3], q[0], q[1], q[2])
    assert tuple(ops["xformOp:scale"]) == tuple(s)
    mid_op = UsdGeom.Xformable(stage.GetPrimAtPath("/Asset/mid")).GetOrderedXformOps()
    assert [o.GetOpName() for o in mid_op] == ["xformOp:transform"]
    assert np.array_equal(np.array(mid_op[0].Get()), mat.T)  # USD's row-vector matrix = transposed
    odd = stage.GetPrimAtPath("/Asset/_1_odd_name")
    assert odd.GetCustomDataByKey("gltfName") == "1 odd/name"
    assert tuple(UsdGeom.Xformable(odd).GetOrderedXformOps()[0].Get()) == (1e-300, 0.1, 3.0000000000000004)

    cache = UsdGeom.XformCache()
    world = np.array(cache.GetLocalToWorldTransform(stage.GetPrimAtPath("/Asset/mid/leaf/tri"))).T
    assert np.allclose(world, mat @ trs_matrix(t, q, s), rtol=0, atol=1e-12)
    # The mesh used by three nodes is written once, as a class prototype, and referenced.
    proto = stage.GetPrimAtPath("/Asset/Prototypes/tri")
    assert proto.IsAbstract() and len(mesh_prims(stage)) == 2
    assert UsdGeom.Mesh(stage.GetPrimAtPath("/Asset/mid/leaf/tri")).GetPointsAttr().Get() == \
        UsdGeom.Mesh(proto).GetPointsAttr().Get()


# ---- validation ----------------------------------------------------------------------------------

def small_asset():
    w = gw.GltfWriter()
    pos = w.accessor(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), gw.FLOAT, minmax=True)
    idx = w.accessor([0, 1, 2], gw.UNSIGNED_SHORT)
    w.node(name="n", mesh=w.mesh([{"attributes": {"POSITION": pos}, "indices": idx}], name="m"))
    w.scene([0], default=True)
    return w


def write_json(path, doc, blob=None):
    if blob is not None:
        with open(str(path) + ".bin", "wb") as f:
            f.write(blob)
        doc["buffers"] = [{"byteLength": len(blob), "uri": os.path.basename(str(path)) + ".bin"}]
    with open(path, "w") as f:
        json.dump(doc, f)


def mutated(w, edit):
    doc = json.loads(json.dumps(w._json({"byteLength": len(w.blob)})))
    edit(doc)
    return doc


@pytest.mark.parametrize("name,edit,code,expect", [
    ("out_of_range_index", lambda d: None, 1, "index 7 (at 2) is out of range"),
    ("points_mode", lambda d: d["meshes"][0]["primitives"][0].update(mode=0), 1,
     "meshes[0].primitives[0]: mode POINTS is not a triangle mode"),
    ("lines_mode", lambda d: d["meshes"][0]["primitives"][0].update(mode=1), 1, "mode LINES"),
    ("view_past_buffer", lambda d: d["bufferViews"][0].update(byteLength=4000), 2, "bufferView"),
    ("accessor_past_view", lambda d: d["accessors"][0].update(count=50), 1, "accessors[0]: reads bytes"),
    ("missing_accessor", lambda d: d["meshes"][0]["primitives"][0]["attributes"].update(POSITION=9), 2,
     "accessor"),
    ("node_cycle", lambda d: d["nodes"][0].update(children=[0]), 1, "nodes[0]: is its own ancestor"),
    ("huge_transform", lambda d: d["nodes"][0].update(translation=[0, 1e999, 0]), 1,
     "nodes[0]: has a non-finite transform"),  # JSON has no NaN; 1e999 overflows to inf or is refused
    ("missing_material", lambda d: d["meshes"][0]["primitives"][0].update(material=5), 1,
     "material 5 does not exist"),
    ("draco", lambda d: d.update(extensionsRequired=["KHR_draco_mesh_compression"],
                                 extensionsUsed=["KHR_draco_mesh_compression"]), 1, "KHR_draco_mesh_compression"),
    ("no_position", lambda d: d["meshes"][0]["primitives"][0]["attributes"].pop("POSITION"), 2, ""),
])
def test_malformed_elements_are_named(tmp_path, name, edit, code, expect):
    w = small_asset()
    blob = bytes(w.blob)
    if name == "out_of_range_index":
        blob = blob[:-6] + struct.pack("<3H", 0, 1, 7)  # the index accessor is the last buffer view
    src = tmp_path / (name + ".gltf")
    write_json(src, mutated(w, edit), blob)
    got, out = convert(src, tmp_path / "o.usda")
    assert str(src) in out, out
    # A failed element is an error (exit 1, the rest written) unless tinygltf refuses the file (exit 2).
    assert got in (1, 2), out
    if got == 1:
        assert os.path.exists(tmp_path / "o.usda")
        assert expect in out, out
    else:
        assert not os.path.exists(tmp_path / "o.usda")
    if name not in ("view_past_buffer", "missing_accessor", "no_position", "huge_transform", "missing_material"):
        assert got == code, out


def test_unreadable_files_exit_2_naming_the_file(tmp_path):
    w = small_asset()
    glb = w.glb_bytes()
    cases = {"truncated.glb": glb[: len(glb) // 2], "empty.gltf": b"", "garbage.glb": b"glTF\x02\0\0\0" + b"\xff" * 40,
             "not_json.gltf": b"{ this is not json"}
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
        code, out = convert(tmp_path / name, tmp_path / "o.usda")
        assert code == 2 and name in out, (name, out)
    write_json(tmp_path / "nobin.gltf", mutated(w, lambda d: d["buffers"][0].update(uri="missing.bin")))
    code, out = convert(tmp_path / "nobin.gltf", tmp_path / "o.usda")
    assert code == 2 and "missing.bin" in out, out
    code, out = convert(tmp_path / "absent.glb", tmp_path / "o.usda")
    assert code == 2 and "absent.glb" in out
    (tmp_path / "ok.glb").write_bytes(glb)
    code, out = convert(tmp_path / "ok.glb", tmp_path / "o.obj")
    assert code == 2 and "must end in" in out
    assert not os.path.exists(tmp_path / "o.usda")


FUZZ_CHILD = r"""
import random, sys
from volphoton import gltf
data = open(sys.argv[1], "rb").read()
rng = random.Random(int(sys.argv[3]))
outcomes = {"ok": 0, "errors": 0, "unreadable": 0}
for i in range(int(sys.argv[4])):
    b = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        op = rng.random()
        k = rng.randrange(len(b))
        if op < 0.5:
            b[k] = rng.randrange(256)
        elif op < 0.7:
            del b[k:k + rng.randint(1, 64)]
        elif op < 0.85:
            b[k:k] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        else:
            b = b[:k]
        if not b:
            b = bytearray(b"{")
    path = "%s.%d%s" % (sys.argv[2], i, sys.argv[1][-5:])
    open(path, "wb").write(bytes(b))
    try:
        text, diags, stats = gltf.translate(path)
        outcomes["errors" if any(d[0] == "error" for d in diags) else "ok"] += 1
    except gltf.GltfError:
        outcomes["unreadable"] += 1
print(outcomes)
"""


@pytest.mark.parametrize("container", ["glb", "gltf"])
def test_mutated_files_never_crash(tmp_path, container):
    """300 random byte mutations (deterministic seed) of a valid file, in one child process: every
    case must end in a translation or a GltfError; a crash or hang fails the test."""
    w = small_asset()
    src = tmp_path / ("valid." + container)
    if container == "glb":
        w.write_glb(str(src))
    else:
        w.write_gltf(str(src))  # data URI: mutations hit the JSON and the base64 payload
    p = subprocess.run([sys.executable, "-c", FUZZ_CHILD, str(src), str(tmp_path / "m"), "11", "300"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    outcomes = eval(p.stdout.strip().splitlines()[-1])
    assert sum(outcomes.values()) == 300
    assert outcomes["unreadable"] > 0 and outcomes["ok"] + outcomes["errors"] > 0, outcomes


# ---- a converted asset in a media scene ----------------------------------------------------------

def test_statue_scene_renders_from_a_freshly_converted_gltf(tmp_path):
    """testenv/gltf_statue.usda references gltf/statue.usdc (converted from statue.glb) and applies
    VolPhotonMediumAPI to the figure with an `over`: the asset is regenerated and converted here, so
    the scene is rendered from this build's translation, and the medium must reach the render."""
    import shutil
    from volphoton import output
    shutil.copy(os.path.join(REPO, "testenv", "gltf_statue.usda"), tmp_path / "gltf_statue.usda")
    p = subprocess.run([sys.executable, os.path.join(REPO, "tools", "make_gltf_assets.py"), str(tmp_path / "gltf")],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    scene = str(tmp_path / "gltf_statue.usda")
    check = subprocess.run([volphoton_exe(), "check", "-v", scene], capture_output=True, text=True, timeout=120)
    assert check.returncode == 0, check.stdout + check.stderr
    assert "medium /World/Statue/Statue/figure/figure: homogeneous" in check.stdout, check.stdout
    assert "pedestal/pedestal/slate_top" in check.stdout and "pedestal/pedestal/wood" in check.stdout
    # The same scene with a black (absorbing) medium: the figure's pixels must then be much darker.
    text = open(scene).read()
    assert "color3f volphoton:albedo = (0.99, 0.97, 0.93)" in text
    dark = str(tmp_path / "gltf_statue_dark.usda")
    with open(dark, "w") as f:
        f.write(text.replace("color3f volphoton:albedo = (0.99, 0.97, 0.93)", "color3f volphoton:albedo = (0, 0, 0)"))
    for integrator in ("pathtracer", "photonmap"):
        images = []
        for name, path in (("lit", scene), ("dark", dark)):
            exr = tmp_path / ("statue_%s_%s.exr" % (name, integrator))
            r = subprocess.run([volphoton_exe(), "render", path, "-o", str(exr), "--no-png", "--resolution", "64", "36",
                                "--spp", "4", "--integrator", integrator, "-q"], capture_output=True, text=True,
                               timeout=300)
            assert r.returncode == 0, r.stderr
            channels, _ = output.read_exr(str(exr))
            images.append(np.stack([channels[c] for c in "RGB"]).sum(axis=0))
            assert np.isfinite(images[-1]).all()
        lit, absorbing = images
        figure = np.abs(lit - absorbing) > 1e-6  # only the figure's medium differs
        # Measured at 64x36, 4 spp: 10-14 % of the pixels; mean 0.80-0.95 lit against 0.13-0.14.
        assert figure.mean() > 0.05, (integrator, figure.mean())
        assert lit[figure].mean() > 3 * absorbing[figure].mean(), (integrator, lit[figure].mean(),
                                                                  absorbing[figure].mean())


def test_conversion_benchmark_runs():
    """tools/bench_gltf.py on a small asset (the 1M-triangle figures are in the issue notes)."""
    p = subprocess.run([sys.executable, os.path.join(REPO, "tools", "bench_gltf.py"), "--triangles", "2000",
                        "--repeat", "1"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    rows = [l for l in p.stdout.splitlines() if l.startswith("| ") and "step" not in l]
    assert [r.split("|")[1].strip() for r in rows] == ["translate (C++ only)", "-> .usdc", "-> .usda"], p.stdout
