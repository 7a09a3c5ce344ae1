"""usd-core stage -> volphoton core scene (``_core.SceneDesc``), one time code at a time.

``translate(stage, time, width, height, camera_path=None)`` returns a ``TranslatedScene``: the core
``SceneDesc`` plus plain records of what was read (``meshes``, ``lights``, ``media``, ``camera``) and
``Diagnostic``s naming prim and attribute.  Errors never raise: a prim that cannot be used is skipped
(or falls back to a default) with an ``error`` diagnostic; the caller decides the exit status.

Geometry (UsdGeom)
    * Traversal: ``Usd.TraverseInstanceProxies`` (scene-graph instances are read through their
      instance proxies; a prototype's mesh is translated once and every instance adds an
      ``InstanceDesc``).  Invisible prims (``ComputeVisibility``) and purpose ``guide``/``proxy`` are
      skipped.  Transforms are ``ComputeLocalToWorldTransform`` at the frame's time code.
    * Mesh: polygons are triangulated as fans (vertex 0, k, k+1); faces with < 3 vertices and
      ``holeIndices`` are dropped; ``orientation = leftHanded`` flips the winding.  Normals
      (``primvars:normals`` first, else ``normals``): vertex/varying are used per vertex;
      faceVarying are used per vertex where every corner of a vertex agrees (within 1e-4), else
      the mesh is unwelded per corner (hard edges kept); constant/uniform normals are dropped (face
      normals).  Subdivision surfaces render their control cage.  GeomSubsets of family
      ``materialBind`` with a bound material split the mesh per material.
    * Implicit prims are tessellated in object space: Sphere 48 segments x 24 rings (smooth normals),
      Cube 12 triangles, Cylinder and Cone 48 segments with caps, Plane 2 triangles (``axis``:
      width along X for Z/Y, along Z for X; length along Y for Z/X, along Z for Y).  Capsule is not
      supported (warning).
    * PointInstancer: ``ComputeInstanceTransformsAtTime`` (prototype root transform included, mask
      applied through ``ComputeMaskAtTime``); each prototype Gprim is translated once and gets one
      ``InstanceDesc`` per instance.  Lights, media and nested instancers inside prototypes are
      ignored with a warning.

Materials (UsdShade UsdPreviewSurface, purpose "full")
    * ``diffuseColor`` -> lambertian albedo (clamped to [0, 1]), ``emissiveColor`` -> emission
      (radiance leaving the front side).  Inputs connected to textures use the input's authored value
      or the UsdPreviewSurface default, with a warning (no texturing).
    * ``opacity`` 0 (<= 1e-3) with an authored ``ior`` > 1 -> smooth dielectric with that ior (clear
      glass); ``opacity`` 0 without an authored ior (or ior 1) -> not rendered (a fully transparent
      card); ``opacityThreshold`` > 0 and ``opacity`` below it -> not rendered (cutout);
      0 < opacity < 1 -> rendered opaque, warning (no partial transparency).  ``metallic`` > 0 is
      rendered diffuse with a warning.
    * No material: ``primvars:displayColor`` (mean of its values) as albedo, else 0.18 grey (the
      UsdPreviewSurface ``diffuseColor`` fallback).
    * A Gprim with VolPhotonMediumAPI bounds a medium (it must be closed; open edges are warned):
      ``volphoton:ior`` == 1 -> an invisible Boundary, > 1 -> Dielectric with that ior; bound
      materials are ignored (warning).

Media (volphoton.schema.read_medium, documented in schemas/README.md)
    * UsdVol Volume with densityMode ``field``: ``GridMedium`` from the OpenVDBAsset of
      ``field:density`` (grid ``fieldName``, default "density"); ``field:emission``,
      ``field:temperature`` and ``field:albedo`` must be grids of the same file.  objectToWorld is
      the Volume's world transform.  Load failures (missing file, unknown grid, wrong grid type)
      are errors naming the asset prim, its attribute and the file; the Volume is skipped.
    * densityMode ``constant`` / ``exponential`` on a Volume: Homogeneous / Exponential medium,
      bounded by ``volphoton:bounds:min/max`` (prim space, transformed to a world axis-aligned box)
      or unbounded.  Exponential ``origin``/``up`` are transformed to world; ``b`` is divided by the
      world length of ``up`` so the profile follows the prim's scale.
    * A Gprim with the API: the medium (constant or exponential) fills the Gprim's mesh
      (``MeshDesc.interior_medium``).
    * ``volphoton:preset`` (measured coefficients in 1/mm, Jensen et al. 2001, as reduced
      scattering + absorption) replaces density, albedo and extinctionColor:
      sigma_s = sigma_s' / (1 - g) / sceneUnitsPerMm, sigma_a = sigma_a / sceneUnitsPerMm, with g the
      mean cosine of the prim's phase.  Table and mapping: ``volphoton.presets`` (``PRESETS`` here is
      the same dict).  An unknown preset is an error; the authored coefficients are used.
    * Phase: isotropic, linear(x), rayleigh, lambertianSphere, henyeyGreenstein(g), schlick(k),
      tabulated(table), mixture(lobes) -> the core factories.

Lights (UsdLux).  With s = intensity * 2^exposure * color (* the UsdLux blackbody colour of
colorTemperature when enableColorTemperature is on):
    * DistantLight: propagation direction = world -Z; halfAngle = angle / 2.  ``normalize`` on, or
      angle 0: irradiance E = s (perpendicular to the light).  Off: s is the radiance of the sun disk,
      E = s * pi * sin^2(halfAngle), so a larger angle gives more light (UsdLux semantics).
    * SphereLight: radiance L = s, divided by the world surface area 4 pi r^2 with ``normalize``.
      ``treatAsPoint`` or radius 0: a point light of intensity I = L * pi r^2 (the sphere's
      far field; I = s when radius is 0).  radius is scaled by the transform (cube root of |det|).
    * ShapingAPI (applied): spot with cone angle ``shaping:cone:angle`` (degrees) and softness
      ``shaping:cone:softness``, axis world -Z; angles >= 180 are no cone.  focus/IES: warning.
    * RectLight width x height, DiskLight radius, emitting towards local -Z: radiance L = s,
      divided by the world-space area with ``normalize``.  ``texture:file`` on a RectLight: warning.
    * DomeLight: radiance L = s, times ``texture:file`` when set (a lat-long OpenEXR, read with the
      core's loader; +Y up in light space, -Z at the image centre); oriented by the prim's transform.
      A texture that cannot be read is an error and the dome becomes constant.
    * CylinderLight, GeometryLight, PortalLight, light filters, ``diffuse``/``specular`` != 1:
      warnings (not supported).
    Units: radiance, irradiance and intensity are in the renderer's linear RGB; with intensity 1 a
    lambertian white surface facing a normalized distant light renders at 1/pi.

Camera (UsdGeomCamera; apertures and focal length in tenths of a scene unit)
    * perspective: tanHalfFovX = (horizontalAperture' / 2) / focalLength, where horizontalAperture'
      is conformed to the image aspect by the RenderSettings ``aspectRatioConformPolicy`` (default
      expandAperture; adjustApertureWidth, adjustApertureHeight, cropAperture also supported).
    * orthographic: orthoWidth = horizontalAperture' / 10 scene units.
    * depth of field: fStop > 0 -> lensRadius = (focalLength / 10) / (2 fStop) scene units,
      focusDistance in scene units; clippingRange -> near/far (the far plane clips geometry and media;
      rays that pass it still see distant and dome lights).  Aperture offsets: warning.
    * no camera: a default camera looking at the stage's bounds (warning).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdRender, UsdShade, UsdVol

from . import _core
from . import presets as vpresets
from . import schema as vschema
from .schema import Diagnostic

__all__ = [
    "Diagnostic",
    "PRESETS",
    "SETTINGS_ATTRIBUTES",
    "MeshRecord",
    "LightRecord",
    "MediumRecord",
    "CameraRecord",
    "RenderSettingsInfo",
    "TranslatedScene",
    "affine_from_gf",
    "read_render_settings",
    "translate",
    "tessellate",
]

# Measured subsurface coefficients (volphoton:preset): the table lives in volphoton/presets.py.
PRESETS = vpresets.PRESETS

# Renderer settings read from a UsdRender Settings prim as ``volphoton:<name>`` attributes: the C++
# table (core/translate/settings.h) the CLI flags and the Hydra delegate share.
SETTINGS_ATTRIBUTES = tuple(e["name"] for e in _core.render_settings_table())

# The UsdLux attributes the translation layer reads, and the UsdLux schemas -> its light kinds
# (anything else: "not supported").
_LIGHT_ATTRIBUTES = tuple(_core.light_attribute_names())
_LIGHT_KINDS = (("distant", UsdLux.DistantLight), ("sphere", UsdLux.SphereLight), ("rect", UsdLux.RectLight),
                ("disk", UsdLux.DiskLight), ("dome", UsdLux.DomeLight))
SPHERE_SEGMENTS, SPHERE_RINGS = 48, 24
CYLINDER_SEGMENTS = 48
DEFAULT_ALBEDO = (0.18, 0.18, 0.18)
CONFORM_POLICIES = ("expandAperture", "cropAperture", "adjustApertureWidth", "adjustApertureHeight",
                    "adjustPixelAspectRatio")

Vec3 = Tuple[float, float, float]


# --------------------------------------------------------------------------------------------------
# Records
# --------------------------------------------------------------------------------------------------


@dataclass
class MeshRecord:
    """One core mesh: the Gprim (or prototype Gprim) it came from and its instances."""

    prim_path: str
    mesh_index: int
    instance_indices: List[int] = field(default_factory=list)
    triangles: int = 0
    material: str = ""  # material prim path, 'displayColor', 'default' or 'medium'
    subset: str = ""  # GeomSubset path when the mesh is one material's part of a prim


@dataclass
class LightRecord:
    """A light as translated: ``emission`` is the radiance (area, sphere, dome lights), irradiance
    (distant) or intensity (point, spot with radius 0) given to the core; ``params`` holds the
    world-space geometry (position, direction, radius, width, height, half_angle, area, ...)."""

    prim_path: str
    kind: str
    emission: Vec3
    quantity: str
    params: dict
    light: object  # _core.Light


@dataclass
class MediumRecord:
    prim_path: str
    kind: str  # homogeneous | exponential | grid
    index: int  # into SceneDesc.media
    desc: vschema.MediumDesc
    medium: object  # _core.Medium
    unbounded: bool  # in SceneDesc.unbounded_media (else inside a mesh)
    mesh_index: int = -1


@dataclass
class CameraRecord:
    prim_path: Optional[str]  # None: the default framing camera
    desc: object  # _core.CameraDesc
    projection: str
    params: dict


@dataclass
class RenderSettingsInfo:
    prim_path: Optional[str] = None
    resolution: Optional[Tuple[int, int]] = None
    camera_path: Optional[str] = None
    conform_policy: str = "expandAperture"
    overrides: Dict[str, object] = field(default_factory=dict)  # setting name -> validated value
    settings: object = field(default_factory=lambda: _core.RenderSettings())  # defaults + overrides
    max_grid_voxels: Optional[int] = None  # volphoton:maxGridVoxels when authored (grid-size cap; 0 = none)
    diagnostics: List[Diagnostic] = field(default_factory=list)


@dataclass
class TranslatedScene:
    desc: object  # _core.SceneDesc
    time: Usd.TimeCode
    meshes: List[MeshRecord] = field(default_factory=list)
    lights: List[LightRecord] = field(default_factory=list)
    media: List[MediumRecord] = field(default_factory=list)
    camera: Optional[CameraRecord] = None
    diagnostics: List[Diagnostic] = field(default_factory=list)
    bounds: Optional[Tuple[Vec3, Vec3]] = None

    @property
    def errors(self) -> List[Diagnostic]:
        return [d for d in self.diagnostics if d.severity == "error"]

    @property
    def triangle_count(self) -> int:
        return sum(m.triangles for m in self.meshes)

    def is_empty(self) -> bool:
        """Nothing that could put light on the film: no surfaces, no media, no lights."""
        return not self.meshes and not self.media and not self.lights

    def summary(self) -> dict:
        return {
            "meshes": len(self.meshes),
            "instances": int(self.desc.instance_count),
            "triangles": self.triangle_count,
            "lights": len(self.lights),
            "media": len(self.media),
            "camera": self.camera.prim_path if self.camera and self.camera.prim_path else "default",
            "bounds": [list(self.bounds[0]), list(self.bounds[1])] if self.bounds else None,
        }


# --------------------------------------------------------------------------------------------------
# Small helpers
# --------------------------------------------------------------------------------------------------


def affine_from_gf(m) -> np.ndarray:
    """Gf.Matrix4d (row vectors, translation in the last row) -> (4, 4) column-vector affine."""
    return np.array(m, dtype=np.float64).T.copy()


def _point(a: np.ndarray, p) -> np.ndarray:
    return a[:3, :3] @ np.asarray(p, dtype=np.float64) + a[:3, 3]


def _vector(a: np.ndarray, v) -> np.ndarray:
    return a[:3, :3] @ np.asarray(v, dtype=np.float64)


def _tuple3(v) -> Vec3:
    return (float(v[0]), float(v[1]), float(v[2]))


def _finite(x) -> bool:
    return bool(np.all(np.isfinite(np.asarray(x, dtype=np.float64))))


def _world_box(a: np.ndarray, lo: Sequence[float], hi: Sequence[float]) -> Tuple[Vec3, Vec3]:
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    w = corners @ a[:3, :3].T + a[:3, 3]
    return _tuple3(w.min(axis=0)), _tuple3(w.max(axis=0))


class _Diags:
    def __init__(self, out: List[Diagnostic]):
        self.out = out

    def error(self, prim, attr: str, msg: str) -> None:
        self.out.append(Diagnostic("error", str(prim), attr, msg))

    def warn(self, prim, attr: str, msg: str) -> None:
        self.out.append(Diagnostic("warning", str(prim), attr, msg))

    def info(self, prim, attr: str, msg: str) -> None:
        self.out.append(Diagnostic("info", str(prim), attr, msg))


# --------------------------------------------------------------------------------------------------
# Tessellation of implicit prims (object space)
# --------------------------------------------------------------------------------------------------


def _orient_outwards(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Flips triangles of a convex shape centred at the origin so their normals point outwards."""
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    n = np.cross(b - a, c - a)
    inward = np.einsum("ij,ij->i", n, (a + b + c) / 3.0) < 0
    tris = tris.copy()
    tris[inward] = tris[inward][:, [0, 2, 1]]
    return tris


def _axis_permutation(axis: str) -> List[int]:
    # Shapes are built along Z; a cyclic permutation puts that axis on X or Y (handedness kept).
    return {"X": [2, 0, 1], "Y": [1, 2, 0]}.get(axis, [0, 1, 2])


def _revolve(profile: List[Tuple[float, float]], segments: int, axis: str):
    """Points and triangles of a closed surface of revolution around Z from (radius, z) profile
    points; radius-0 profile points are single vertices (poles/apexes/cap centres)."""
    pts: List[Tuple[float, float, float]] = []
    rings: List[List[int]] = []
    for r, z in profile:
        if r == 0.0:
            rings.append([len(pts)] * segments)
            pts.append((0.0, 0.0, z))
        else:
            ring = []
            for j in range(segments):
                phi = 2.0 * math.pi * j / segments
                ring.append(len(pts))
                pts.append((r * math.cos(phi), r * math.sin(phi), z))
            rings.append(ring)
    tris = []
    for i in range(len(rings) - 1):
        r0, r1 = rings[i], rings[i + 1]
        for j in range(segments):
            k = (j + 1) % segments
            a, b, c, d = r0[j], r0[k], r1[j], r1[k]
            if a != b:
                tris.append((a, b, d))
            if c != d:
                tris.append((a, d, c))
    points = np.array(pts, dtype=np.float64)[:, _axis_permutation(axis)]
    # permuting columns maps the Z-built shape onto the requested axis: new[:, i] = old[:, perm[i]]
    return points, np.array(tris, dtype=np.int64)


def tessellate(prim: Usd.Prim, time) -> Optional[Tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]]:
    """(points (N,3), triangles (M,3), normals (N,3) or None) of an implicit UsdGeom prim in object
    space, or None when the prim type is not an implicit shape."""
    if prim.IsA(UsdGeom.Sphere):
        r = float(UsdGeom.Sphere(prim).GetRadiusAttr().Get(time))
        profile = [(0.0, r)] + [(r * math.sin(math.pi * i / SPHERE_RINGS), r * math.cos(math.pi * i / SPHERE_RINGS))
                                for i in range(1, SPHERE_RINGS)] + [(0.0, -r)]
        pts, tris = _revolve(profile, SPHERE_SEGMENTS, "Z")
        tris = _orient_outwards(pts, tris)
        normals = pts / max(abs(r), 1e-300)
        return pts, tris, normals
    if prim.IsA(UsdGeom.Cube):
        h = 0.5 * float(UsdGeom.Cube(prim).GetSizeAttr().Get(time))
        pts = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)], dtype=np.float64)
        quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        tris = np.array([t for q in quads for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))], dtype=np.int64)
        return pts, _orient_outwards(pts, tris), None
    if prim.IsA(UsdGeom.Cylinder) or prim.IsA(UsdGeom.Cone):
        is_cone = prim.IsA(UsdGeom.Cone)
        g = UsdGeom.Cone(prim) if is_cone else UsdGeom.Cylinder(prim)
        r = float(g.GetRadiusAttr().Get(time))
        hh = 0.5 * float(g.GetHeightAttr().Get(time))
        axis = str(g.GetAxisAttr().Get(time))
        profile = [(0.0, -hh), (r, -hh)] + ([(0.0, hh)] if is_cone else [(r, hh), (0.0, hh)])
        pts, tris = _revolve(profile, CYLINDER_SEGMENTS, axis)
        return pts, _orient_outwards(pts, tris), None
    if prim.IsA(UsdGeom.Plane):
        p = UsdGeom.Plane(prim)
        w = 0.5 * float(p.GetWidthAttr().Get(time))
        ln = 0.5 * float(p.GetLengthAttr().Get(time))
        axis = str(p.GetAxisAttr().Get(time))
        # (width axis, length axis, normal axis) per the UsdGeomPlane documentation
        u, v, n = {"X": (2, 1, 0), "Y": (0, 2, 1)}.get(axis, (0, 1, 2))
        pts = np.zeros((4, 3))
        for i, (su, sv) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
            pts[i, u], pts[i, v] = su * w, sv * ln
        tris = np.array([(0, 1, 2), (0, 2, 3)], dtype=np.int64)
        normal = np.cross(pts[1] - pts[0], pts[2] - pts[0])
        if normal[n] < 0:
            tris = tris[:, [0, 2, 1]]
        return pts, tris, None
    return None


# --------------------------------------------------------------------------------------------------
# Meshes
# --------------------------------------------------------------------------------------------------


def _fan_triangulate(counts: np.ndarray, indices: np.ndarray):
    """Fan triangulation.  Returns (triangles (T,3) of point indices, corners (T,3) of face-vertex
    positions, face index per triangle)."""
    counts = counts.astype(np.int64)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]) if len(counts) else np.zeros(0, np.int64)
    ntri = np.maximum(counts - 2, 0)
    total = int(ntri.sum())
    face = np.repeat(np.arange(len(counts)), ntri)
    first = np.concatenate([[0], np.cumsum(ntri)[:-1]]) if len(ntri) else np.zeros(0, np.int64)
    k = np.arange(total) - np.repeat(first, ntri) + 1
    a = starts[face]
    corners = np.stack([a, a + k, a + k + 1], axis=1) if total else np.zeros((0, 3), np.int64)
    return indices[corners] if total else np.zeros((0, 3), np.int64), corners, face


def _closed_edges_report(tris: np.ndarray) -> int:
    """Number of edges not shared by exactly two triangles (0 for a closed manifold mesh)."""
    if len(tris) == 0:
        return 0
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e.sort(axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return int(np.count_nonzero(counts != 2))


class _MeshData:
    """Object-space triangles of one Gprim, with an optional per-triangle group (material) id."""

    def __init__(self, points, tris, normals=None, corner_normals=None, corners=None, face=None):
        self.points = points
        self.tris = tris
        self.normals = normals  # per point
        self.corner_normals = corner_normals  # per face-vertex (faceVarying)
        self.corners = corners  # (T,3) face-vertex positions of each triangle corner
        self.face = face  # (T,) authored face of each triangle


def _read_mesh(prim: Usd.Prim, time, d: _Diags) -> Optional[_MeshData]:
    mesh = UsdGeom.Mesh(prim)
    path = prim.GetPath()
    pts = mesh.GetPointsAttr().Get(time)
    counts = mesh.GetFaceVertexCountsAttr().Get(time)
    idx = mesh.GetFaceVertexIndicesAttr().Get(time)
    if pts is None or counts is None or idx is None or len(pts) == 0 or len(counts) == 0:
        d.warn(path, "points" if not pts else "faceVertexCounts", "mesh has no points or faces; skipped")
        return None
    points = np.array(pts, dtype=np.float64).reshape(-1, 3)
    counts = np.array(counts, dtype=np.int64)
    idx = np.array(idx, dtype=np.int64)
    if not _finite(points):
        d.error(path, "points", "points contain NaN or infinite values; mesh skipped")
        return None
    if counts.sum() != len(idx) or np.any(counts < 0):
        d.error(path, "faceVertexCounts", "faceVertexCounts sum to %d but there are %d faceVertexIndices; "
                "mesh skipped" % (int(counts.sum()), len(idx)))
        return None
    if len(idx) and (idx.min() < 0 or idx.max() >= len(points)):
        d.error(path, "faceVertexIndices", "faceVertexIndices out of range [0, %d); mesh skipped" % len(points))
        return None
    small = int(np.count_nonzero(counts < 3))
    if small:
        d.warn(path, "faceVertexCounts", "%d faces with fewer than 3 vertices ignored" % small)
    tris, corners, face = _fan_triangulate(counts, idx)
    holes = mesh.GetHoleIndicesAttr().Get(time)
    if holes is not None and len(holes):
        keep = ~np.isin(face, np.array(holes, dtype=np.int64))
        tris, corners, face = tris[keep], corners[keep], face[keep]
    if str(mesh.GetOrientationAttr().Get(time)) == UsdGeom.Tokens.leftHanded:
        tris, corners = tris[:, [0, 2, 1]], corners[:, [0, 2, 1]]
    data = _MeshData(points, tris, corners=corners, face=face)

    # normals: primvars:normals wins over the normals attribute (UsdGeomPointBased)
    values, interp, attr_name = None, None, "normals"
    pv = UsdGeom.PrimvarsAPI(prim).GetPrimvar("normals")
    if pv and pv.HasAuthoredValue():
        values, interp, attr_name = pv.ComputeFlattened(time), pv.GetInterpolation(), "primvars:normals"
    elif mesh.GetNormalsAttr().HasAuthoredValue():
        values, interp = mesh.GetNormalsAttr().Get(time), mesh.GetNormalsInterpolation()
    if values is not None and len(values):
        n = np.array(values, dtype=np.float64).reshape(-1, 3)
        if not _finite(n):
            d.warn(path, attr_name, "normals contain NaN or infinite values; using face normals")
        elif interp in (UsdGeom.Tokens.vertex, UsdGeom.Tokens.varying):
            if len(n) == len(points):
                data.normals = n
            else:
                d.warn(path, attr_name, "%d %s normals for %d points; using face normals" % (len(n), interp, len(points)))
        elif interp == UsdGeom.Tokens.faceVarying:
            if len(n) == len(idx):
                data.corner_normals = n
            else:
                d.warn(path, attr_name, "%d faceVarying normals for %d face-vertices; using face normals"
                       % (len(n), len(idx)))
        # constant / uniform normals: the face normals are the same thing
    return data


def _submesh(data: _MeshData, tri_mask: np.ndarray, prim_path: str, d: _Diags):
    """Compacted (points, indices, normals) for the selected triangles."""
    tris = data.tris[tri_mask]
    corners = data.corners[tri_mask] if data.corners is not None else None
    if data.corner_normals is not None and corners is not None:
        n = data.corner_normals[corners.reshape(-1)]
        n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        verts = tris.reshape(-1)
        # per-vertex if every corner of a vertex has (nearly) the same normal
        order = np.argsort(verts, kind="stable")
        sv, sn = verts[order], n[order]
        firsts = np.concatenate([[True], sv[1:] != sv[:-1]])
        ref = sn[np.maximum.accumulate(np.where(firsts, np.arange(len(sv)), 0))]
        if np.all(np.abs(sn - ref) <= 1e-4):
            normals_full = np.zeros_like(data.points)
            normals_full[sv] = sn
            used, inverse = np.unique(tris, return_inverse=True)
            return data.points[used], inverse.reshape(-1, 3), normals_full[used]
        # hard edges: one vertex per corner
        pts = data.points[verts]
        return pts, np.arange(len(verts)).reshape(-1, 3), n
    used, inverse = np.unique(tris, return_inverse=True)
    normals = data.normals[used] if data.normals is not None else None
    return data.points[used], inverse.reshape(-1, 3), normals


# --------------------------------------------------------------------------------------------------
# Materials
# --------------------------------------------------------------------------------------------------

_PREVIEW_DEFAULTS = {
    "diffuseColor": (0.18, 0.18, 0.18),
    "emissiveColor": (0.0, 0.0, 0.0),
    "opacity": 1.0,
    "opacityThreshold": 0.0,
    "ior": 1.5,
    "metallic": 0.0,
}


def _shader_input(shader: UsdShade.Shader, name: str, time, d: _Diags):
    """(value, authored) of a UsdPreviewSurface input, following connections to Material interface
    inputs; a connection to another shader's output (a texture) gives the default with a warning."""
    inp = shader.GetInput(name)
    default = _PREVIEW_DEFAULTS[name]
    if not inp:
        return default, False
    attrs = inp.GetValueProducingAttributes()
    if attrs:
        a = attrs[0]
        if UsdShade.Utils.GetType(a.GetName()) == UsdShade.AttributeType.Output:
            d.warn(shader.GetPath(), "inputs:" + name, "connected to %s (textures are not supported); using %s"
                   % (a.GetPath(), "the authored value" if inp.GetAttr().HasAuthoredValue() else "the default"))
            v = inp.GetAttr().Get(time)
            return (default if v is None else v), v is not None
        v = a.Get(time)
        if v is not None:
            return v, True
    return default, False


def _preview_material(material: UsdShade.Material, time, d: _Diags):
    """SurfaceMaterial for a bound UsdShade Material, or None = do not render the surface."""
    mpath = material.GetPath()
    surface = material.ComputeSurfaceSource()
    shader = surface[0] if isinstance(surface, tuple) else surface
    if not shader:
        d.warn(mpath, "outputs:surface", "material has no surface shader; using the default grey")
        return _core.SurfaceMaterial(albedo=DEFAULT_ALBEDO)
    sid = shader.GetShaderId()
    if sid != "UsdPreviewSurface":
        d.warn(shader.GetPath(), "info:id", "shader '%s' is not supported (only UsdPreviewSurface); using the "
               "default grey" % sid)
        return _core.SurfaceMaterial(albedo=DEFAULT_ALBEDO)
    spath = shader.GetPath()
    diffuse, _ = _shader_input(shader, "diffuseColor", time, d)
    emissive, _ = _shader_input(shader, "emissiveColor", time, d)
    opacity, _ = _shader_input(shader, "opacity", time, d)
    threshold, _ = _shader_input(shader, "opacityThreshold", time, d)
    ior, ior_authored = _shader_input(shader, "ior", time, d)
    metallic, _ = _shader_input(shader, "metallic", time, d)
    # The rules are the core's (core/previewSurface.h), shared with the Hydra delegate.
    material, notes = _core.preview_surface_material(_tuple3(diffuse), _tuple3(emissive), float(opacity),
                                                     float(threshold), float(ior), bool(ior_authored),
                                                     float(metallic))
    for severity, name, message in notes:
        (d.error if severity == "error" else d.warn)(spath, "inputs:" + name, message)
    return material


def _display_color(prim: Usd.Prim, time):
    pv = UsdGeom.Gprim(prim).GetDisplayColorPrimvar()
    if pv and pv.HasAuthoredValue():
        v = pv.ComputeFlattened(time)
        if v is not None and len(v):
            c = np.array(v, dtype=np.float64).reshape(-1, 3).mean(axis=0)
            if _finite(c):
                return tuple(float(min(max(x, 0.0), 1.0)) for x in c)
    return None


# --------------------------------------------------------------------------------------------------
# Media
# --------------------------------------------------------------------------------------------------


class _Translator:
    def __init__(self, stage: Usd.Stage, time: Usd.TimeCode):
        self.stage = stage
        self.time = time
        self.diags: List[Diagnostic] = []
        self.d = _Diags(self.diags)
        self.xf = UsdGeom.XformCache(time)
        self.max_grid_voxels = int(_core.DEFAULT_MAX_GRID_VOXELS)
        self.desc = _core.SceneDesc()
        self.meshes: List[MeshRecord] = []
        self.lights: List[LightRecord] = []
        self.media: List[MediumRecord] = []
        self.mesh_cache: Dict[tuple, List[MeshRecord]] = {}
        self.lo = np.full(3, np.inf)
        self.hi = np.full(3, -np.inf)

    # -- transforms ------------------------------------------------------------------------------
    def world(self, prim: Usd.Prim) -> Optional[np.ndarray]:
        """Column-vector world transform, or None (error reported) when it is not finite."""
        a = affine_from_gf(self.xf.GetLocalToWorldTransform(prim))
        if _finite(a):
            return a
        where, attr = self._bad_xform_op(prim)
        self.d.error(where, attr, "transform is not finite (NaN or infinite); %s skipped" % prim.GetPath())
        return None

    def _bad_xform_op(self, prim: Usd.Prim):
        p = prim
        while p and not p.IsPseudoRoot():
            x = UsdGeom.Xformable(p)
            if x:
                for op in x.GetOrderedXformOps():
                    try:
                        m = op.GetOpTransform(self.time)
                    except Exception:  # noqa: BLE001 - malformed op values
                        return p.GetPath(), op.GetName()
                    if not _finite(np.array(m)):
                        return p.GetPath(), op.GetName()
            p = p.GetParent()
        return prim.GetPath(), "xformOpOrder"

    def extend_bounds(self, pts_world: np.ndarray) -> None:
        if len(pts_world):
            self.lo = np.minimum(self.lo, pts_world.min(axis=0))
            self.hi = np.maximum(self.hi, pts_world.max(axis=0))

    # -- traversal --------------------------------------------------------------------------------
    def run(self) -> None:
        it = iter(Usd.PrimRange(self.stage.GetPseudoRoot(), Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)))
        for prim in it:
            if prim.IsPseudoRoot():
                continue
            img = UsdGeom.Imageable(prim)
            if img:
                purpose = img.GetPurposeAttr().Get()
                if purpose in (UsdGeom.Tokens.guide, UsdGeom.Tokens.proxy):
                    it.PruneChildren()
                    continue
                if img.ComputeVisibility(self.time) == UsdGeom.Tokens.invisible:
                    it.PruneChildren()
                    continue
            if prim.IsA(UsdGeom.PointInstancer):
                self.point_instancer(prim)
                it.PruneChildren()
                continue
            if prim.IsA(UsdVol.Volume):
                self.volume(prim)
                continue
            if prim.IsA(UsdGeom.Gprim):  # with MeshLightAPI (LightAPI) too: an emissive surface
                self.gprim(prim)
                continue
            if prim.HasAPI(UsdLux.LightAPI) or prim.IsA(UsdLux.BoundableLightBase) or prim.IsA(UsdLux.NonboundableLightBase):
                self.light(prim)

    # -- gprims ------------------------------------------------------------------------------------
    def gprim(self, prim: Usd.Prim, instance_xforms: Optional[List[np.ndarray]] = None,
              relative: Optional[np.ndarray] = None) -> None:
        """Translates a Gprim.  instance_xforms: PointInstancer world transforms of the prototype
        root; relative: the Gprim's transform relative to the prototype root."""
        path = prim.GetPath()
        is_medium_prim = instance_xforms is None and vschema.MEDIUM_API in vschema._applied_schemas(prim)
        if instance_xforms is None:
            w = self.world(prim)
            if w is None:
                return
            xforms = [w]
        else:
            xforms = [x @ relative for x in instance_xforms]
            xforms = [x for x in xforms if _finite(x)]

        # mesh data (shared by instances of the same prototype prim with the same materials)
        key_prim = prim.GetPrimInPrototype() if prim.IsInstanceProxy() else prim
        if is_medium_prim:
            records = self._medium_gprim(prim, xforms[0])
            return
        groups = self._material_groups(prim)
        key = (str(key_prim.GetPath()), tuple(label for label, _, _ in groups))
        records = self.mesh_cache.get(key)
        if records is None:
            data = self._gprim_data(prim)
            if data is None:
                return
            mesh_light = self._mesh_light(prim, data, xforms[0]) if prim.HasAPI(UsdLux.LightAPI) else None
            records = []
            for label, material, face_mask in groups:
                if material is None:
                    continue  # transparent / cutout: nothing to render
                if mesh_light is not None:
                    material = _core.mesh_light_surface(mesh_light[0], mesh_light[1], material)
                tri_mask = np.ones(len(data.tris), bool) if face_mask is None else face_mask(data)
                if not np.any(tri_mask):
                    continue
                pts, tris, normals = _submesh(data, tri_mask, str(path), self.d)
                m = _core.MeshDesc()
                m.name = str(path) + ("" if face_mask is None else ":" + label)
                m.points = pts
                m.indices = tris.reshape(-1)
                if normals is not None:
                    m.normals = normals
                m.material = material
                idx = self.desc.add_mesh(m)
                rec = MeshRecord(str(path), idx, triangles=len(tris), material=label,
                                 subset="" if face_mask is None else label)
                rec._points = pts  # for bounds
                records.append(rec)
                self.meshes.append(rec)
            self.mesh_cache[key] = records
        for rec in records:
            for x in xforms:
                rec.instance_indices.append(self.desc.add_instance(rec.mesh_index, x))
                self.extend_bounds(rec._points @ x[:3, :3].T + x[:3, 3])

    def _mesh_light(self, prim: Usd.Prim, data: _MeshData, world: np.ndarray):
        """(radiance, materialSyncMode) of a Gprim with MeshLightAPI (the translation layer's rules,
        core/translate/light.h), or None when its light attributes are unusable (reported). The
        area for inputs:normalize is the world area under the first transform."""
        values, _ = vschema.read_attributes(prim, self.time, prefix="", names=_LIGHT_ATTRIBUTES)
        area = _core.mesh_world_area(data.points, data.tris.reshape(-1), world)
        has_filters = bool(UsdLux.LightAPI(prim).GetFiltersRel().GetForwardedTargets())
        _, kind, emission, _, params, diags = _core.translate_light(
            str(prim.GetPath()), values, "mesh", str(prim.GetTypeName()), world, has_filters, "", area)
        self.diags.extend(vschema.diagnostics_from_core(diags))
        if kind != "mesh":
            return None
        return emission, params["material_sync_mode"]

    def _gprim_data(self, prim: Usd.Prim) -> Optional[_MeshData]:
        if prim.IsA(UsdGeom.Mesh):
            return _read_mesh(prim, self.time, self.d)
        try:
            t = tessellate(prim, self.time)
        except Exception as e:  # noqa: BLE001 - bad attribute values
            self.d.error(prim.GetPath(), "", "cannot tessellate %s: %s; skipped" % (prim.GetTypeName(), e))
            return None
        if t is None:
            self.d.warn(prim.GetPath(), "", "%s prims are not supported; skipped" % prim.GetTypeName())
            return None
        pts, tris, normals = t
        if not _finite(pts):
            self.d.error(prim.GetPath(), "", "size attributes are not finite; skipped")
            return None
        if str(UsdGeom.Gprim(prim).GetOrientationAttr().Get(self.time)) == UsdGeom.Tokens.leftHanded:
            tris = tris[:, [0, 2, 1]]
        corners = np.arange(tris.size).reshape(-1, 3)
        return _MeshData(pts, tris, normals=normals, corners=corners, face=np.arange(len(tris)))

    def _material_groups(self, prim: Usd.Prim):
        """[(label, SurfaceMaterial or None, face mask fn or None)]: the prim's own material for the
        faces not in a materialBind subset, and one group per subset with a bound material."""
        groups = []
        subset_faces = []
        if prim.IsA(UsdGeom.Mesh):
            subsets = UsdGeom.Subset.GetGeomSubsets(UsdGeom.Imageable(prim), UsdGeom.Tokens.face,
                                                    UsdShade.Tokens.materialBind)
            for s in subsets:
                mat, _ = UsdShade.MaterialBindingAPI(s.GetPrim()).ComputeBoundMaterial()
                if not mat:
                    continue
                faces = np.array(s.GetIndicesAttr().Get(self.time) or [], dtype=np.int64)
                subset_faces.append(faces)
                sm = _preview_material(mat, self.time, self.d)
                groups.append((str(s.GetPath()), sm, (lambda data, f=faces: np.isin(data.face, f))))
        label, material = self._prim_material(prim)
        if subset_faces:
            allf = np.concatenate(subset_faces)
            groups.insert(0, (label, material, (lambda data, f=allf: ~np.isin(data.face, f))))
        else:
            groups.insert(0, (label, material, None))
        return groups

    def _prim_material(self, prim: Usd.Prim):
        mat, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        if mat:
            return str(mat.GetPath()), _preview_material(mat, self.time, self.d)
        color = _display_color(prim, self.time)
        if color is not None:
            return "displayColor", _core.SurfaceMaterial(albedo=color)
        return "default", _core.SurfaceMaterial(albedo=DEFAULT_ALBEDO)

    def _medium_gprim(self, prim: Usd.Prim, world: np.ndarray) -> None:
        path = prim.GetPath()
        md, diags = vschema.read_medium(prim, self.time)
        self.diags.extend(diags)
        if md is None:
            return
        mat, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
        if mat:
            self.d.warn(path, "material:binding", "a material is bound to a prim with %s; it is ignored (the "
                        "surface is %s)" % (vschema.MEDIUM_API, "index-matched" if md.ior == 1 else
                                            "a dielectric with volphoton:ior"))
        data = self._gprim_data(prim)
        if data is None:
            return
        open_edges = _closed_edges_report(data.tris)
        if open_edges:
            self.d.warn(path, "", "the mesh bounding the medium is not closed (%d edges are not shared by "
                        "exactly two triangles); light may leak" % open_edges)
        medium, kind = self._procedural_medium(prim, md, world, use_bounds=False)
        if medium is None:
            return
        midx = self.desc.add_medium(medium, False)
        pts, tris, normals = _submesh(data, np.ones(len(data.tris), bool), str(path), self.d)
        m = _core.MeshDesc()
        m.name = str(path)
        m.points = pts
        m.indices = tris.reshape(-1)
        if normals is not None:
            m.normals = normals
        if md.ior > 1.0:
            m.material = _core.SurfaceMaterial(kind=_core.SurfaceMaterial.Kind.Dielectric, ior=md.ior)
        else:
            m.material = _core.SurfaceMaterial(kind=_core.SurfaceMaterial.Kind.Boundary)
        m.interior_medium = midx
        idx = self.desc.add_mesh(m)
        rec = MeshRecord(str(path), idx, triangles=len(tris), material="medium")
        rec.instance_indices.append(self.desc.add_instance(idx, world))
        self.meshes.append(rec)
        self.extend_bounds(pts @ world[:3, :3].T + world[:3, 3])
        self.media.append(MediumRecord(str(path), kind, midx, md, medium, False, idx))

    # -- media -------------------------------------------------------------------------------------
    def _procedural_medium(self, prim, md: vschema.MediumDesc, world: np.ndarray, use_bounds: bool):
        medium, kind, diags = _core.build_procedural_medium(md.core, world, use_bounds)
        self.diags.extend(vschema.diagnostics_from_core(diags))
        return medium, kind

    def volume(self, prim: Usd.Prim) -> None:
        path = prim.GetPath()
        md, diags = vschema.read_medium(prim, self.time)
        self.diags.extend(diags)
        if md is None:
            return
        world = self.world(prim)
        if world is None:
            return
        if md.density_mode == "field":
            medium = self._grid_medium(prim, md, world)
            kind = "grid"
        else:
            medium, kind = self._procedural_medium(prim, md, world, use_bounds=True)
        if medium is None:
            return
        idx = self.desc.add_medium(medium, True)
        self.media.append(MediumRecord(str(path), kind, idx, md, medium, True))
        b = medium.bounds()
        if b is not None and all(math.isfinite(c) for c in b[0] + b[1]):
            self.extend_bounds(np.array(b))

    def _grid_medium(self, prim: Usd.Prim, md: vschema.MediumDesc, world: np.ndarray):
        """The grid medium from the volume's OpenVDBAsset fields: which grid of which file each slot
        names, and the guarded load, are the translation layer's (core/translate/volume.h)."""
        path = str(prim.GetPath())
        fields = [_core.GridFieldInput(slot, f.prim_path, f.file_path, f.field_name, f.field_index)
                  for slot, f in md.fields.items()]
        gd, diags = _core.grid_medium_from_fields(path, md.core, world, fields, self.max_grid_voxels)
        self.diags.extend(vschema.diagnostics_from_core(diags))
        if gd is None:
            return None  # read_medium reported why there is no density file
        medium, diags = _core.load_grid_medium_reported(path, md.fields["density"].prim_path, gd)
        self.diags.extend(vschema.diagnostics_from_core(diags))
        return medium

    # -- point instancers --------------------------------------------------------------------------
    def point_instancer(self, prim: Usd.Prim) -> None:
        path = prim.GetPath()
        pi = UsdGeom.PointInstancer(prim)
        world = self.world(prim)
        if world is None:
            return
        protos = pi.GetPrototypesRel().GetForwardedTargets()
        ids = pi.GetProtoIndicesAttr().Get(self.time)
        if not protos or ids is None or len(ids) == 0:
            self.d.warn(path, "protoIndices" if protos else "prototypes", "point instancer has no instances; skipped")
            return
        xforms = pi.ComputeInstanceTransformsAtTime(self.time, self.time, UsdGeom.PointInstancer.IncludeProtoXform,
                                                    UsdGeom.PointInstancer.IgnoreMask)
        if len(xforms) != len(ids):
            self.d.error(path, "protoIndices", "cannot compute instance transforms (positions/orientations/scales "
                         "do not match protoIndices); skipped")
            return
        mask = pi.ComputeMaskAtTime(self.time)
        ids = np.array(ids, dtype=np.int64)
        bad = int(np.count_nonzero((ids < 0) | (ids >= len(protos))))
        if bad:
            self.d.error(path, "protoIndices", "%d protoIndices are out of range [0, %d); those instances are "
                         "skipped" % (bad, len(protos)))
        inst_world = [world @ affine_from_gf(m) for m in xforms]
        for pidx, proto_path in enumerate(protos):
            proto = self.stage.GetPrimAtPath(proto_path)
            if not proto:
                self.d.error(path, "prototypes", "prototype %s does not exist" % proto_path)
                continue
            sel = [inst_world[i] for i in range(len(ids)) if ids[i] == pidx and (mask is None or len(mask) == 0 or mask[i])]
            bad_x = [x for x in sel if not _finite(x)]
            if bad_x:
                self.d.error(path, "positions", "%d instances of %s have non-finite transforms; skipped"
                             % (len(bad_x), proto_path))
                sel = [x for x in sel if _finite(x)]
            if not sel:
                continue
            root_inv = np.linalg.inv(affine_from_gf(self.xf.GetLocalToWorldTransform(proto)))
            pit = iter(Usd.PrimRange(proto, Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)))
            for p in pit:
                img = UsdGeom.Imageable(p)
                if img and (img.GetPurposeAttr().Get() in (UsdGeom.Tokens.guide, UsdGeom.Tokens.proxy)
                            or img.ComputeVisibility(self.time) == UsdGeom.Tokens.invisible):
                    pit.PruneChildren()
                    continue
                if p.IsA(UsdGeom.PointInstancer):
                    self.d.warn(p.GetPath(), "", "nested point instancers are not supported; ignored")
                    pit.PruneChildren()
                elif p.IsA(UsdVol.Volume) or p.HasAPI(UsdLux.LightAPI) or \
                        vschema.MEDIUM_API in vschema._applied_schemas(p):
                    self.d.warn(p.GetPath(), "", "lights and media inside point instancer prototypes are not "
                                "supported; ignored")
                elif p.IsA(UsdGeom.Gprim):
                    rel = root_inv @ affine_from_gf(self.xf.GetLocalToWorldTransform(p))
                    self.gprim(p, instance_xforms=sel, relative=rel)

    # -- lights ------------------------------------------------------------------------------------
    def light(self, prim: Usd.Prim) -> None:
        """Reads the UsdLux attributes the translation layer uses (core/translate/light.h has the
        rules) and adds the light it builds."""
        path = prim.GetPath()
        world = self.world(prim)
        if world is None:
            return
        kind = next((k for k, t in _LIGHT_KINDS if prim.IsA(t)), "")
        values, _ = vschema.read_attributes(prim, self.time, prefix="", names=_LIGHT_ATTRIBUTES)
        tex = prim.GetAttribute("inputs:texture:file").Get(self.time) if kind == "dome" else None
        asset = tex.path if tex is not None else ""
        if kind == "dome":
            values["inputs:texture:file"] = tex.resolvedPath if tex is not None else ""
        has_filters = bool(UsdLux.LightAPI(prim).GetFiltersRel().GetForwardedTargets())
        light, kind, emission, quantity, params, diags = _core.translate_light(
            str(path), values, kind, str(prim.GetTypeName()), world, has_filters, asset)
        self.diags.extend(vschema.diagnostics_from_core(diags))
        if light is not None:
            self._add_light(prim, kind, emission, quantity, params, light)

    def _add_light(self, prim, kind, emission, quantity, params, light) -> None:
        self.desc.add_light(light)
        self.lights.append(LightRecord(str(prim.GetPath()), kind, _tuple3(emission), quantity, params, light))


# --------------------------------------------------------------------------------------------------
# Render settings and camera
# --------------------------------------------------------------------------------------------------


def read_render_settings(stage: Usd.Stage) -> RenderSettingsInfo:
    """The stage's UsdRender Settings prim (stage metadata ``renderSettingsPrimPath``, else the first
    one in traversal order): resolution and camera when authored, the aspect ratio conform policy and
    ``volphoton:<setting>`` attributes (see SETTINGS_ATTRIBUTES)."""
    info = RenderSettingsInfo()
    d = _Diags(info.diagnostics)
    path = stage.GetMetadata("renderSettingsPrimPath") if stage.HasAuthoredMetadata("renderSettingsPrimPath") else ""
    prim = None
    if path:
        prim = stage.GetPrimAtPath(path)
        if not prim or not prim.IsA(UsdRender.Settings):
            d.error(stage.GetRootLayer().identifier, "renderSettingsPrimPath",
                    "renderSettingsPrimPath %s is not a RenderSettings prim; ignored" % path)
            prim = None
    if prim is None:
        for p in stage.Traverse():
            if p.IsA(UsdRender.Settings):
                prim = p
                break
    if prim is None:
        return info
    info.prim_path = str(prim.GetPath())
    s = UsdRender.Settings(prim)
    res_attr = s.GetResolutionAttr()
    if res_attr.HasAuthoredValue():
        res = res_attr.Get()
        if res[0] > 0 and res[1] > 0:
            info.resolution = (int(res[0]), int(res[1]))
        else:
            d.error(prim.GetPath(), "resolution", "resolution %s is not positive; ignored" % (tuple(res),))
    targets = s.GetCameraRel().GetForwardedTargets()
    if targets:
        info.camera_path = str(targets[0])
    policy = str(s.GetAspectRatioConformPolicyAttr().Get() or "expandAperture")
    if policy not in CONFORM_POLICIES:
        d.error(prim.GetPath(), "aspectRatioConformPolicy", "unknown policy '%s'; using expandAperture" % policy)
        policy = "expandAperture"
    elif policy == "adjustPixelAspectRatio":
        d.warn(prim.GetPath(), "aspectRatioConformPolicy", "adjustPixelAspectRatio is not supported (square "
               "pixels); using adjustApertureHeight")
        policy = "adjustApertureHeight"
    info.conform_policy = policy
    par = s.GetPixelAspectRatioAttr().Get()
    if par is not None and abs(float(par) - 1.0) > 1e-6:
        d.warn(prim.GetPath(), "pixelAspectRatio", "pixelAspectRatio %g is not supported; square pixels are "
               "rendered" % par)
    for attr in prim.GetAuthoredAttributes():
        n = attr.GetName()
        if not n.startswith("volphoton:") or not attr.HasAuthoredValue():
            continue
        name = n[len("volphoton:"):]
        ok, diags = _core.apply_setting(info.settings, name, vschema.plain_value(attr.Get()), str(prim.GetPath()))
        info.diagnostics.extend(vschema.diagnostics_from_core(diags))
        if ok:
            info.overrides[name] = _core.get_setting(info.settings, name)
    if "maxGridVoxels" in info.overrides:
        info.max_grid_voxels = int(info.overrides["maxGridVoxels"])
    return info


def _look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray) -> np.ndarray:
    f = target - eye
    f = f / np.linalg.norm(f)
    r = np.cross(f, up)
    if np.linalg.norm(r) < 1e-9:
        r = np.cross(f, np.array([1.0, 0.0, 0.0]))
    r = r / np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, eye
    return m


def _default_camera(stage: Usd.Stage, time, bounds, width: int, height: int) -> CameraRecord:
    z_up = UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    up = np.array([0.0, 0.0, 1.0]) if z_up else np.array([0.0, 1.0, 0.0])
    if bounds is None:
        center, radius = np.zeros(3), 1.0
    else:
        lo, hi = np.array(bounds[0]), np.array(bounds[1])
        center, radius = (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
    tan_x = math.tan(math.radians(27.0))
    tan_min = min(tan_x, tan_x * height / width)
    dist = radius / math.sin(math.atan(tan_min)) * 1.05
    view = np.array([0.35, -1.0, 0.3]) if z_up else np.array([0.35, 0.3, 1.0])
    eye = center + dist * view / np.linalg.norm(view)
    desc = _core.CameraDesc()
    desc.camera_to_world = _look_at(eye, center, up)
    desc.tan_half_fov_x = tan_x
    return CameraRecord(None, desc, "perspective", {"tan_half_fov_x": tan_x, "eye": _tuple3(eye),
                                                    "target": _tuple3(center)})


def _camera(prim: Usd.Prim, time, xf: UsdGeom.XformCache, width: int, height: int, policy: str,
            d: _Diags, bounds=None) -> Optional[CameraRecord]:
    path = prim.GetPath()
    cam = UsdGeom.Camera(prim)
    world = affine_from_gf(xf.GetLocalToWorldTransform(prim))
    if not _finite(world):
        d.error(path, "xformOpOrder", "camera transform is not finite; using the default camera")
        return None
    g = lambda a, default: (lambda v: default if v is None else v)(a.Get(time))  # noqa: E731
    projection = str(g(cam.GetProjectionAttr(), "perspective"))
    hap = float(g(cam.GetHorizontalApertureAttr(), 20.955))
    vap = float(g(cam.GetVerticalApertureAttr(), 15.2908))
    focal = float(g(cam.GetFocalLengthAttr(), 50.0))
    fstop = float(g(cam.GetFStopAttr(), 0.0))
    focus = float(g(cam.GetFocusDistanceAttr(), 0.0))
    clip = g(cam.GetClippingRangeAttr(), Gf.Vec2f(1, 1000000))
    for name, v in (("horizontalAperture", hap), ("verticalAperture", vap), ("focalLength", focal)):
        if not (math.isfinite(v) and v > 0):
            d.error(path, name, "%s = %g must be positive; using the default camera" % (name, v))
            return None
    for name in ("horizontalApertureOffset", "verticalApertureOffset"):
        v = prim.GetAttribute(name).Get(time)
        if v:
            d.warn(path, name, "aperture offsets are not supported; ignored")
    aspect = width / height
    if policy == "adjustApertureWidth":
        hap_eff = vap * aspect
    elif policy == "adjustApertureHeight":
        hap_eff = hap
    elif policy == "cropAperture":
        hap_eff = min(hap, vap * aspect)
    else:  # expandAperture
        hap_eff = max(hap, vap * aspect)
    desc = _core.CameraDesc()
    desc.camera_to_world = world
    params = {"horizontal_aperture": hap, "vertical_aperture": vap, "focal_length": focal,
              "conformed_horizontal_aperture": hap_eff, "conform_policy": policy}
    if projection == "orthographic":
        desc.projection = _core.CameraDesc.Projection.Orthographic
        desc.ortho_width = hap_eff / 10.0
        params["ortho_width"] = desc.ortho_width
    else:
        if projection != "perspective":
            d.error(path, "projection", "unknown projection '%s'; using perspective" % projection)
            projection = "perspective"
        desc.tan_half_fov_x = (hap_eff / 2.0) / focal
        params["tan_half_fov_x"] = desc.tan_half_fov_x
    near, far = float(clip[0]), float(clip[1])
    if not (0 <= near < far):
        d.error(path, "clippingRange", "clippingRange %s is not 0 <= near < far; ignored" % ((near, far),))
        near, far = 0.0, math.inf
    desc.near_clip, desc.far_clip = near, far
    if fstop > 0 and projection == "perspective":
        if not (focus > 0 and math.isfinite(focus)):
            d.warn(path, "focusDistance", "fStop is set but focusDistance = %g is not positive; depth of field "
                   "disabled" % focus)
        else:
            desc.lens_radius = (focal / 10.0) / (2.0 * fstop)
            desc.focus_distance = focus
            params.update(lens_radius=desc.lens_radius, focus_distance=focus)
    elif fstop < 0:
        d.warn(path, "fStop", "negative fStop ignored")
    params.update(near_clip=near, far_clip=far)
    return CameraRecord(str(path), desc, projection, params)


_CAMERA_RIG_TYPES = ("Camera", "Xform", "Scope", "")


def first_time_varying_content(stage: Usd.Stage) -> Optional[str]:
    """The first attribute (``/prim.attr``) that may vary in time and reaches more than cameras, or None
    when only cameras (and transforms above nothing but cameras) can change from frame to frame.

    Photons do not see the camera, so a --frames range over such a stage keeps one PhotonCache: every
    frame after the first reuses the photon maps (core/photonCache.h). Any other animated attribute
    (a light, a medium, a mesh, a material, a transform above them, an asset path, a render setting)
    makes each frame trace its own photons."""
    rig_only = {}

    def only_cameras_below(prim: Usd.Prim) -> bool:
        path = prim.GetPath()
        if path not in rig_only:
            rig_only[path] = all(p.GetTypeName() in _CAMERA_RIG_TYPES
                                 for p in Usd.PrimRange(prim, Usd.TraverseInstanceProxies()))
        return rig_only[path]

    for prim in stage.Traverse(Usd.TraverseInstanceProxies()):
        for attr in prim.GetAttributes():
            if attr.ValueMightBeTimeVarying() and not only_cameras_below(prim):
                return "%s.%s" % (prim.GetPath(), attr.GetName())
    return None


def translate(stage: Usd.Stage, time=Usd.TimeCode.Default(), width: int = 640, height: int = 360,
              camera_path: Optional[str] = None, conform_policy: str = "expandAperture",
              max_grid_voxels: Optional[int] = None) -> TranslatedScene:
    """Reads the stage at ``time`` into a core SceneDesc; see the module docstring.  max_grid_voxels:
    the grid-size cap (None: the core's default, 2^30 active voxels; 0: none)."""
    if not isinstance(time, Usd.TimeCode):
        time = Usd.TimeCode(time)
    tr = _Translator(stage, time)
    if max_grid_voxels is not None:
        tr.max_grid_voxels = int(max_grid_voxels)
    tr.run()
    bounds = None
    if np.all(np.isfinite(tr.lo)) and np.all(np.isfinite(tr.hi)):
        bounds = (_tuple3(tr.lo), _tuple3(tr.hi))
    camera = None
    if camera_path:
        prim = stage.GetPrimAtPath(camera_path) if Sdf.Path.IsValidPathString(camera_path) else None
        if not prim or not prim.IsA(UsdGeom.Camera):
            tr.d.error(camera_path, "", "no UsdGeomCamera at %s; using the default camera" % camera_path)
        else:
            camera = _camera(prim, time, tr.xf, width, height, conform_policy, tr.d, bounds)
    else:
        for prim in stage.Traverse(Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)):
            if prim.IsA(UsdGeom.Camera):
                camera = _camera(prim, time, tr.xf, width, height, conform_policy, tr.d, bounds)
                break
        if camera is None:
            tr.d.warn(stage.GetRootLayer().identifier, "", "the stage has no camera; using a default camera "
                      "looking at the scene bounds")
    if camera is None:
        camera = _default_camera(stage, time, bounds, width, height)
    tr.desc.camera = camera.desc
    return TranslatedScene(tr.desc, time, tr.meshes, tr.lights, tr.media, camera, tr.diags, bounds)
