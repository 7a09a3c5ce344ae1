"""The benchmark scenes: ONE renderer-neutral description per scene.

Every renderer's input is generated from these descriptions, so the peers see the same scene:
    export_usd.py   -> testenv/bench/<name>.usda   (volphoton reads it through the usd-core front end)
    peer_mitsuba.py -> a Mitsuba 3 scene dict
    peer_cycles.py  -> a Blender (bpy) scene rendered with Cycles
Nothing here imports pxr, mitsuba or bpy (each of them runs in its own process).

Conventions (the USD ones, which the exporters convert to each peer):
    * right-handed world, +Y up; transforms are 4x4 float64 numpy arrays acting on column vectors
      (p' = M p);
    * the camera looks down its local -Z with +Y up; fov_x is the full horizontal angle; pixels are
      square and sampled uniformly inside each pixel (a 1-pixel box filter) in every renderer;
    * colours are linear RGB (Rec.709 primaries) and every quantity is physical radiometry in them:
      radiance for the dome, irradiance (perpendicular to the light) for distant lights, intensity
      (W/sr) for spot lights, extinction and emission per scene unit;
    * surfaces are lambertian triangle meshes; media fill closed outward-wound boxes, a VDB grid's
      support, or an exponential slab;
    * max_depth counts scattering and bounce events per path as volphoton's maxDepth does (each peer
      converts: Mitsuba max_depth = N + 1, Cycles bounces = N - 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

import numpy as np

RGB = Tuple[float, float, float]


# --------------------------------------------------------------------------------------------------
# Small transform helpers (column-vector convention)
# --------------------------------------------------------------------------------------------------


def translate(t) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = t
    return m


def scale(s) -> np.ndarray:
    s = np.broadcast_to(np.asarray(s, float), (3,))
    return np.diag([s[0], s[1], s[2], 1.0])


def rotate_y(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    m = np.eye(4)
    m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    return m


def normalize(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def look_at(eye, target, up) -> np.ndarray:
    """Camera-to-world: the camera at eye looks down its -Z at target, +Y towards up."""
    eye = np.asarray(eye, float)
    f = normalize(np.asarray(target, float) - eye)
    r = normalize(np.cross(f, up))
    u = np.cross(r, f)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, eye
    return m


def frame_z_to(direction) -> np.ndarray:
    """A rotation whose local -Z is `direction` (lights emit along their local -Z)."""
    d = normalize(direction)
    helper = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    z = -d
    x = normalize(np.cross(helper, z))
    y = np.cross(z, x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = x, y, z
    return m


# --------------------------------------------------------------------------------------------------
# Geometry
# --------------------------------------------------------------------------------------------------

# The canonical box [-1, 1]^3: 8 points, 12 triangles wound counter-clockwise seen from outside.
BOX_POINTS = np.array([[x, y, z] for z in (-1.0, 1.0) for y in (-1.0, 1.0) for x in (-1.0, 1.0)])
BOX_TRIS = np.array([
    [0, 2, 3], [0, 3, 1],  # z = -1 (normal -Z)
    [4, 5, 7], [4, 7, 6],  # z = +1
    [0, 1, 5], [0, 5, 4],  # y = -1
    [2, 6, 7], [2, 7, 3],  # y = +1
    [0, 4, 6], [0, 6, 2],  # x = -1
    [1, 3, 7], [1, 7, 5],  # x = +1
], dtype=np.int64)
# The canonical quad [-1, 1]^2 in the XZ plane, facing +Y.
QUAD_POINTS = np.array([[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]])
QUAD_TRIS = np.array([[0, 2, 1], [0, 3, 2]], dtype=np.int64)


def box_to_world(lo, hi) -> np.ndarray:
    """Transform of the canonical box onto the axis-aligned box [lo, hi]."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return translate((lo + hi) / 2) @ scale((hi - lo) / 2)


def _check_outward(points: np.ndarray, tris: np.ndarray) -> None:
    c = points.mean(axis=0)
    for t in tris:
        a, b, d = points[t]
        n = np.cross(b - a, d - a)
        assert np.dot(n, (a + b + d) / 3 - c) > 0, "box triangles must be wound outwards"


_check_outward(BOX_POINTS, BOX_TRIS)


# --------------------------------------------------------------------------------------------------
# Scene elements
# --------------------------------------------------------------------------------------------------


@dataclass
class Camera:
    eye: Tuple[float, float, float]
    target: Tuple[float, float, float]
    up: Tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov_x_deg: float = 40.0
    near: float = 0.01
    far: float = 1.0e4

    def to_world(self) -> np.ndarray:
        return look_at(self.eye, self.target, self.up)


@dataclass
class Phase:
    kind: str = "isotropic"  # isotropic | hg | rayleigh
    g: float = 0.0


@dataclass
class Surface:
    """A lambertian triangle mesh (object-space points, outward-wound triangles, object-to-world)."""

    name: str
    points: np.ndarray
    tris: np.ndarray
    to_world: np.ndarray
    albedo: RGB


@dataclass
class BoxMedium:
    """A homogeneous medium filling the canonical box under to_world (an index-matched boundary)."""

    name: str
    to_world: np.ndarray
    sigma_t: float
    albedo: float
    phase: Phase


@dataclass
class GridMedium:
    """The procedural VDB cloud (volphoton's write_procedural_cloud_vdb) scaled by density_scale.

    The grid has `resolution`^3 voxels of size 1/resolution: voxel (i, j, k) sits at (i, j, k) /
    resolution in grid space (OpenVDB's cell-centred convention) and values are trilinearly
    interpolated; to_world maps grid space to the world. Emission (when not None) is the radiance
    added per unit length at density 1, proportional to the interpolated density."""

    name: str
    to_world: np.ndarray
    density_scale: float
    albedo: float
    phase: Phase
    emission: Optional[RGB] = None
    resolution: int = 64
    seed: int = 1
    file: str = "cloud.vdb"

    @property
    def voxel_size(self) -> float:
        return 1.0 / self.resolution


@dataclass
class ExponentialMedium:
    """sigma_t(h) = density * a * exp(-b h) * extinction_color, h = world y, inside the world box
    [lo, hi]; sigma_s = albedo * sigma_t."""

    name: str
    lo: Tuple[float, float, float]
    hi: Tuple[float, float, float]
    density: float
    extinction_color: RGB
    albedo: float
    a: float
    b: float
    phase: Phase


@dataclass
class TranslucentMesh:
    """A closed, outward-wound mesh with a smooth dielectric surface (index `ior`, Fresnel reflection
    and refraction both ways) around a homogeneous medium with per-channel sigma_t (per scene unit)
    and albedo: subsurface scattering (issue #7). volphoton: VolPhotonMediumAPI + volphoton:ior;
    Mitsuba: dielectric BSDF + interior homogeneous medium."""

    name: str
    points: np.ndarray
    tris: np.ndarray
    to_world: np.ndarray
    ior: float
    sigma_t: RGB
    albedo: RGB
    phase: Phase


@dataclass
class Dome:
    radiance: RGB


@dataclass
class Distant:
    direction: Tuple[float, float, float]  # propagation direction
    irradiance: RGB  # perpendicular to the light


@dataclass
class Spot:
    position: Tuple[float, float, float]
    direction: Tuple[float, float, float]
    intensity: RGB  # W/sr inside the cone
    cone_deg: float  # half angle; hard edge


@dataclass
class SphereLight:
    """A spherical area light of uniform radiance (visible; rays can hit it, so paths that refract
    out of a translucent object can reach it, unlike a delta light)."""
    position: Tuple[float, float, float]
    radius: float
    radiance: RGB


@dataclass
class BenchScene:
    name: str
    title: str
    camera: Camera
    surfaces: List[Surface] = field(default_factory=list)
    media: list = field(default_factory=list)
    lights: list = field(default_factory=list)
    max_depth: int = 64
    # volphoton photon-map settings for this scene (RenderSettings names, Python spelling)
    photon_settings: Dict[str, float] = field(default_factory=dict)
    meters_per_unit: float = 1.0
    notes: str = ""

    def features(self) -> set:
        """What a peer must support to render the scene exactly."""
        f = set()
        for m in self.media:
            f.add(type(m).__name__)
            f.add("phase:" + m.phase.kind)
            if isinstance(m, GridMedium) and m.emission is not None:
                f.add("volume_emission")
        for l in self.lights:
            f.add(type(l).__name__)
        if self.surfaces:
            f.add("Surface")
        return f

    def grid_media(self) -> List[GridMedium]:
        return [m for m in self.media if isinstance(m, GridMedium)]


# --------------------------------------------------------------------------------------------------
# The seven scenes
# --------------------------------------------------------------------------------------------------

CLOUD_TO_WORLD = translate((-1.2, -0.8, -1.2)) @ scale((2.4, 1.6, 2.4))


def _homogeneous_cube() -> BenchScene:
    return BenchScene(
        name="homogeneous_cube",
        title="(1) homogeneous cube in a constant environment",
        camera=Camera(eye=(3.0, 2.2, 4.4), target=(0.0, -0.1, 0.0), fov_x_deg=40.0),
        media=[BoxMedium("cube", box_to_world((-1, -1, -1), (1, 1, 1)), sigma_t=2.0, albedo=0.8,
                         phase=Phase("hg", 0.5))],
        lights=[Dome((1.0, 1.0, 1.0))],
        max_depth=64,
        notes="sigma_t = 2, albedo 0.8, HG g = 0.5, unit-radiance dome; the calibration scene for the peers.",
    )


def _vdb_cloud() -> BenchScene:
    return BenchScene(
        name="vdb_cloud",
        title="(2) heterogeneous VDB cloud under a directional light",
        camera=Camera(eye=(0.0, 0.5, 4.6), target=(0.0, 0.0, 0.0), fov_x_deg=42.0),
        media=[GridMedium("cloud", CLOUD_TO_WORLD, density_scale=8.0, albedo=0.9, phase=Phase("hg", 0.6))],
        lights=[Distant(direction=tuple(normalize((0.35, -0.6, 0.72))), irradiance=(3.0, 2.9, 2.7)),
                Dome((0.08, 0.1, 0.14))],
        max_depth=64,
        notes="procedural 64^3 cloud, density scale 8 (optical depth ~5 through the core), albedo 0.9, HG g = 0.6, "
              "sun from behind the cloud plus a faint sky.",
    )


def _dense_cloud() -> BenchScene:
    return BenchScene(
        name="dense_cloud",
        title="(3) dense high-albedo cloud (multiple scattering dominates)",
        camera=Camera(eye=(0.0, 0.5, 4.6), target=(0.0, 0.0, 0.0), fov_x_deg=42.0),
        media=[GridMedium("cloud", CLOUD_TO_WORLD, density_scale=40.0, albedo=0.99, phase=Phase("hg", 0.3))],
        lights=[Distant(direction=tuple(normalize((-0.5, -0.7, -0.3))), irradiance=(3.0, 3.0, 3.0)),
                Dome((0.05, 0.05, 0.05))],
        max_depth=1000,
        notes="the same cloud at density scale 40 (optical depth > 20 through the core), albedo 0.99, HG g = 0.3, "
              "lit from the camera's side.",
    )


def _fog_spotlight() -> BenchScene:
    return BenchScene(
        name="fog_spotlight",
        title="(4) thin fog with a spot-light beam (single scattering dominates)",
        camera=Camera(eye=(0.0, 1.6, 6.5), target=(0.0, 1.3, 0.0), fov_x_deg=50.0),
        media=[BoxMedium("fog", box_to_world((-2.5, 0.0, -2.5), (2.5, 3.0, 2.5)), sigma_t=0.08, albedo=0.9,
                         phase=Phase("hg", 0.3))],
        lights=[Spot(position=(0.0, 2.8, 0.0), direction=tuple(normalize((0.25, -1.0, 0.1))),
                     intensity=(60.0, 55.0, 48.0), cone_deg=15.0)],
        max_depth=32,
        notes="sigma_t = 0.08 (optical depth 0.4 across), albedo 0.9, HG g = 0.3; a hard-edged point spot of 60 W/sr "
              "inside the fog, nothing else.",
    )


def _atmosphere_sunset() -> BenchScene:
    return BenchScene(
        name="atmosphere_sunset",
        title="(5) exponential Rayleigh atmosphere at sunset",
        camera=Camera(eye=(0.0, 0.05, 0.0), target=(0.0, math.sin(math.radians(9.0)), -1.0), fov_x_deg=70.0,
                      near=0.001, far=5000.0),
        surfaces=[Surface("ground", QUAD_POINTS, QUAD_TRIS, scale((150.0, 1.0, 150.0)), (0.2, 0.18, 0.15))],
        media=[ExponentialMedium("air", lo=(-150.0, -1.0, -150.0), hi=(150.0, 40.0, 150.0), density=0.0331,
                                 extinction_color=(0.175, 0.408, 1.0), albedo=1.0, a=1.0, b=0.125,
                                 phase=Phase("rayleigh"))],
        lights=[Distant(direction=(0.0, -math.sin(math.radians(4.0)), math.cos(math.radians(4.0))),
                        irradiance=(20.0, 20.0, 20.0))],
        max_depth=32,
        meters_per_unit=1000.0,
        notes="km units; sigma_t(h) = 0.0331 exp(-h/8) (0.175, 0.408, 1) per km, albedo 1, Rayleigh phase, in a "
              "300 x 41 x 300 km slab over a dark ground; the sun 4 degrees above the horizon in front of the camera.",
    )


def _emissive_smoke() -> BenchScene:
    return BenchScene(
        name="emissive_smoke",
        title="(6) emissive smoke",
        camera=Camera(eye=(0.0, 0.3, 4.6), target=(0.0, 0.0, 0.0), fov_x_deg=42.0),
        media=[GridMedium("smoke", CLOUD_TO_WORLD, density_scale=6.0, albedo=0.25, phase=Phase("isotropic"),
                          emission=(3.0, 0.9, 0.2))],
        lights=[Dome((0.05, 0.06, 0.08))],
        max_depth=32,
        notes="the cloud as sooty smoke (density scale 6, albedo 0.25, isotropic) emitting (3, 0.9, 0.2) x density "
              "per unit length, under a faint sky.",
    )


def _surfaces_only() -> BenchScene:
    box = (BOX_POINTS, BOX_TRIS)
    return BenchScene(
        name="surfaces_only",
        title="(7) surfaces only, no media",
        camera=Camera(eye=(0.5, 3.0, 6.5), target=(0.0, 0.5, 0.0), fov_x_deg=50.0),
        surfaces=[
            Surface("floor", QUAD_POINTS, QUAD_TRIS, scale((5.0, 1.0, 5.0)), (0.5, 0.5, 0.5)),
            Surface("red", *box, box_to_world((-2.0, 0.0, -0.6), (-0.8, 1.2, 0.6)), (0.8, 0.3, 0.2)),
            Surface("blue", *box, translate((1.1, 1.0, -0.4)) @ rotate_y(30.0) @ scale((0.5, 1.0, 0.5)), (0.2, 0.45, 0.8)),
            Surface("white", *box, translate((0.0, 0.35, 1.3)) @ rotate_y(-20.0) @ scale(0.35), (0.85, 0.85, 0.85)),
        ],
        lights=[Distant(direction=tuple(normalize((-0.4, -0.8, -0.3))), irradiance=(3.0, 2.9, 2.7)),
                Dome((0.35, 0.45, 0.6))],
        max_depth=8,
        notes="a floor and three lambertian boxes under a sun and a blue sky; no medium anywhere.",
    )


def icosphere(subdivisions: int):
    """Unit sphere: an icosahedron split `subdivisions` times (20 * 4^n triangles, outward-wound)."""
    t = (1 + 5 ** 0.5) / 2
    pts = [normalize(p) for p in ((-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                                  (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1))]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
            (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
            (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache: Dict[Tuple[int, int], int] = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                pts.append(normalize((pts[a] + pts[b]) / 2))
                cache[key] = len(pts) - 1
            return cache[key]
        new = []
        for a, b, c in tris:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = new
    return np.array(pts), np.array(tris, dtype=np.int64)


def _subsurface_ball() -> BenchScene:
    points, tris = icosphere(4)
    return BenchScene(
        name="subsurface_ball",
        title="(8) translucent ball lit from behind (subsurface scattering)",
        camera=Camera(eye=(0.0, 0.4, 4.2), target=(0.0, 0.0, 0.0), fov_x_deg=40.0),
        media=[TranslucentMesh("ball", points, tris, np.eye(4), ior=1.3, sigma_t=(6.0, 8.0, 10.0),
                               albedo=(0.99, 0.97, 0.95), phase=Phase("isotropic"))],
        # An area light, not a sun: a path tracer cannot reach a delta light through a refracting
        # surface (shadow rays stop there, sampled directions never hit it), so with a sun the
        # reference would miss the sunlight inside the ball that the photon map carries.
        lights=[SphereLight(position=(-1.0, 2.5, -4.0), radius=1.0, radiance=(12.0, 11.4, 10.5)),
                Dome((0.1, 0.1, 0.12))],
        max_depth=1000,
        notes="a radius-1 ball (5120 triangles) of a chromatic medium, sigma_t = (6, 8, 10), albedo (0.99, 0.97, "
              "0.95), isotropic, behind a smooth n = 1.3 surface; a spherical area light behind the ball and a "
              "faint sky.",
    )


# Jensen et al. 2001, Table 2, marble: sigma_s' = (2.19, 2.62, 3.00) /mm, sigma_a = (0.0021, 0.0041,
# 0.0071) /mm (the coefficients of volphoton's "marble" preset), with g = 0: sigma_s = sigma_s'.
MARBLE_PER_CM = tuple(10 * (s + a) for s, a in zip((2.19, 2.62, 3.00), (0.0021, 0.0041, 0.0071)))
MARBLE_ALBEDO = tuple(s / (s + a) for s, a in zip((2.19, 2.62, 3.00), (0.0021, 0.0041, 0.0071)))


def _subsurface_bunny() -> BenchScene:
    import os
    import sys
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    import make_subsurface_meshes as ms  # the figurine of testenv/subsurface_bunny.usda
    points, tris, _ = ms.polygonize(ms.bunny_field(), (-1.7, -0.2, -1.1), (1.8, 3.3, 1.1), 0.07, 0.9)
    return BenchScene(
        name="subsurface_bunny",
        title="(9) measured marble figurine lit from behind (dense subsurface scattering)",
        camera=Camera(eye=(0.4, 1.7, 9.5), target=(0.4, 1.4, 0.0), fov_x_deg=32.0, near=0.1),
        media=[TranslucentMesh("bunny", np.asarray(points, float), np.asarray(tris, np.int64), np.eye(4), ior=1.3,
                               sigma_t=MARBLE_PER_CM, albedo=MARBLE_ALBEDO, phase=Phase("isotropic"))],
        lights=[SphereLight(position=(1.0, 7.0, -8.0), radius=2.0, radiance=(14.0, 13.0, 11.5)),
                Dome((0.15, 0.15, 0.15))],
        max_depth=100000,
        meters_per_unit=0.01,
        notes="the 3.4 cm figurine of testenv/subsurface_bunny.usda (4666 triangles) in Jensen et al. 2001's marble "
              "(sigma_t 22-30 per cm, albedo 0.998-0.999, n = 1.3), a spherical area light from behind and a grey sky; paths "
              "scatter hundreds of times.",
    )


def _ball_behind_fog() -> BenchScene:
    ball = _subsurface_ball()
    return BenchScene(
        name="ball_behind_fog",
        title="(10) translucent ball seen through a fog bank (open and translucent media together)",
        camera=ball.camera,
        media=ball.media + [BoxMedium("fog", box_to_world((-3.0, -2.0, 1.3), (3.0, 2.0, 2.5)), sigma_t=0.6, albedo=0.9,
                                      phase=Phase("hg", 0.3))],
        lights=ball.lights,
        max_depth=1000,
        photon_settings=dict(ball.photon_settings),
        notes="scene 8's ball and lights with a slab of fog between the ball and the camera (sigma_t 0.6, albedo 0.9, "
              "HG g = 0.3, 1.2 deep): neither integrator alone suits both media (issue 15's combined integrator).",
    )


SCENES: List[BenchScene] = [_homogeneous_cube(), _vdb_cloud(), _dense_cloud(), _fog_spotlight(),
                            _atmosphere_sunset(), _emissive_smoke(), _surfaces_only(), _subsurface_ball(),
                            _subsurface_bunny(), _ball_behind_fog()]
BY_NAME: Dict[str, BenchScene] = {s.name: s for s in SCENES}
# The quick set's default: the seven scenes of issue #6 (about 14 min on 2 cores). The subsurface
# scenes (8, 9; issue #7) add about 3 min: in the full set by default, in the quick set by --scenes.
QUICK_DEFAULT: List[str] = [s.name for s in SCENES[:7]]


def get(name: str) -> BenchScene:
    return BY_NAME[name]
