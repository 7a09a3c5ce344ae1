#!/usr/bin/env python3
"""Writes the subsurface-scattering example scenes of testenv/ with their procedural meshes.

    python tools/make_subsurface_meshes.py            # rewrites the four scenes below in testenv/
    python tools/make_subsurface_meshes.py OUT_DIR    # writes them into OUT_DIR instead

Scenes (each a self-contained, commented .usda; the comments live in the templates below, so edit
this file and re-run it rather than editing the generated scenes):

    subsurface_bunny.usda     marble (preset) bunny-like figurine lit from behind
    subsurface_hand.usda      skin1 (preset) hand lit from behind
    subsurface_milk.usda      wholemilk (preset) in a clear glass (two closed meshes)
    translucent_furnace.usda  a non-absorbing translucent blob in a white furnace (energy test)

Meshes are smooth, closed and procedural (no scanned or copyrighted models): iso-surfaces of
smooth unions of ellipsoids and capsules, polygonised by marching tetrahedra (Kuhn's six-tetrahedron
split of each grid cube, which makes neighbouring cubes agree, so the surface is watertight), with
vertices projected onto the iso-surface by Newton steps and normals from the field's gradient.
Glass and milk are surfaces of revolution.  Only numpy is needed.  Output is deterministic.
"""

from __future__ import annotations

import math
import os
import sys
from itertools import permutations

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# --------------------------------------------------------------------------------------------------
# Signed fields (negative inside) and their smooth union
# --------------------------------------------------------------------------------------------------


def _rot(axis, degrees):
    a = math.radians(degrees)
    x, y, z = np.asarray(axis, float) / np.linalg.norm(axis)
    c, s, t = math.cos(a), math.sin(a), 1 - math.cos(a)
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


def ellipsoid(center, radii, rotation=None):
    """Approximate signed distance of an ellipsoid (exact on the surface, a bound elsewhere)."""
    c, r = np.asarray(center, float), np.asarray(radii, float)
    inv = np.eye(3) if rotation is None else rotation.T

    def f(p):
        q = (p - c) @ inv.T
        k0 = np.linalg.norm(q / r, axis=-1)
        k1 = np.linalg.norm(q / (r * r), axis=-1)
        return k0 * (k0 - 1.0) / np.maximum(k1, 1e-12)
    return f


def capsule(a, b, radius):
    a, b = np.asarray(a, float), np.asarray(b, float)
    ab = b - a

    def f(p):
        h = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
        return np.linalg.norm(p - a - h[..., None] * ab, axis=-1) - radius
    return f


def smooth_union(parts, k):
    """Polynomial smooth minimum of the parts' fields with blend width k."""

    def f(p):
        d = parts[0](p)
        for part in parts[1:]:
            e = part(p)
            h = np.clip(0.5 + 0.5 * (e - d) / k, 0.0, 1.0)
            d = e * (1 - h) + d * h - k * h * (1 - h)
        return d
    return f


# --------------------------------------------------------------------------------------------------
# Marching tetrahedra
# --------------------------------------------------------------------------------------------------

_CORNERS = np.array([[(i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)])
# Kuhn split: the six paths 0 -> a -> a+b -> 7 along the cube's main diagonal.
_TETS = [(0, a, a + b, 7) for a, b, _ in permutations((1, 2, 4))]


def polygonize(field, lo, hi, cell, decimate_below=0.6):
    """Closed triangle mesh of {field < 0} inside the box [lo, hi] (the set must not touch the box).

    Returns (points (N, 3), triangles (M, 3) wound counter-clockwise seen from outside, unit
    normals (N, 3) from the field's gradient)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    n = np.maximum(np.ceil((hi - lo) / cell).astype(int), 1) + 1
    axes = [lo[i] + np.arange(n[i]) * cell for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1)
    values = field(grid.reshape(-1, 3)).reshape(tuple(n))
    values[values == 0] = 1e-9  # no grid value exactly on the surface: the topology is unambiguous
    if (values[0] < 0).any() or (values[-1] < 0).any() or (values[:, 0] < 0).any() or (values[:, -1] < 0).any() \
            or (values[:, :, 0] < 0).any() or (values[:, :, -1] < 0).any():
        raise ValueError("the shape touches the polygonisation box")
    flat_points = grid.reshape(-1, 3)
    flat_values = values.reshape(-1)
    ii, jj, kk = np.meshgrid(np.arange(n[0] - 1), np.arange(n[1] - 1), np.arange(n[2] - 1), indexing="ij")
    base = np.stack([ii.ravel(), jj.ravel(), kk.ravel()], -1)
    corner_ids = []
    for c in _CORNERS:
        g = base + c
        corner_ids.append((g[:, 0] * n[1] + g[:, 1]) * n[2] + g[:, 2])
    corner_ids = np.stack(corner_ids, -1)  # (cubes, 8) grid point ids
    keep = (flat_values[corner_ids] < 0).any(1) & (flat_values[corner_ids] >= 0).any(1)
    corner_ids = corner_ids[keep]

    tri_edges = []  # per triangle: its 3 tetrahedron edges (pairs of grid point ids)
    for tet in _TETS:
        ids = corner_ids[:, tet]  # (cubes, 4)
        inside = flat_values[ids] < 0
        code = inside @ np.array([1, 2, 4, 8])
        for case in range(1, 15):
            sel = ids[code == case]
            if not len(sel):
                continue
            ins = [v for v in range(4) if case >> v & 1]
            outs = [v for v in range(4) if not case >> v & 1]
            if len(ins) == 1 or len(outs) == 1:
                lone, others = (ins[0], outs) if len(ins) == 1 else (outs[0], ins)
                quads = [[(lone, others[0]), (lone, others[1]), (lone, others[2])]]
            else:
                (a, b), (c, d) = ins, outs
                quads = [[(a, c), (a, d), (b, d)], [(a, c), (b, d), (b, c)]]
            hint = flat_points[sel[:, outs]].mean(1) - flat_points[sel[:, ins]].mean(1)
            for tri in quads:
                e = np.stack([np.sort(np.stack([sel[:, u], sel[:, v]], -1), axis=1) for u, v in tri], 1)
                # Orientation from the edge midpoints (a non-degenerate triangle in a non-degenerate
                # tetrahedron), not from the interpolated vertices, which may coincide.
                mid = 0.5 * (flat_points[e[..., 0]] + flat_points[e[..., 1]])
                nrm = np.cross(mid[:, 1] - mid[:, 0], mid[:, 2] - mid[:, 0])
                flip = (nrm * hint).sum(1) < 0
                e[flip] = e[flip][:, ::-1]
                tri_edges.append(e)
    tri_edges = np.concatenate(tri_edges)  # (T, 3, 2), counter-clockwise seen from outside
    keys = tri_edges[..., 0].astype(np.int64) * flat_values.size + tri_edges[..., 1]
    unique, inverse = np.unique(keys.ravel(), return_inverse=True)
    tris = inverse.reshape(-1, 3)
    a, b = unique // flat_values.size, unique % flat_values.size
    fa, fb = flat_values[a], flat_values[b]
    t = (fa / (fa - fb))[:, None]
    points = flat_points[a] + t * (flat_points[b] - flat_points[a])
    points = _project(field, points, cell)
    # Drop triangles that collapsed to a point or a line (both their vertices on one grid point);
    # the remaining ones still close the surface because collapsed edges join equal vertices.
    points, tris = _weld(points, tris, cell * 1e-4)
    if decimate_below > 0:
        points = relax(field, points, tris, cell, 3)
        points, tris = decimate(field, points, tris, decimate_below * cell, cell)
    points = unfold(relax(field, points, tris, cell), tris)
    normals = _gradient(field, points, cell * 1e-3)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return points, tris, normals


def _gradient(field, p, h):
    g = np.zeros_like(p)
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        g[:, i] = (field(p + e) - field(p - e)) / (2 * h)
    return g


def _project(field, p, cell):
    for _ in range(4):
        f = field(p)
        g = _gradient(field, p, cell * 1e-3)
        step = (f / np.maximum((g * g).sum(1), 1e-12))[:, None] * g
        length = np.linalg.norm(step, axis=1, keepdims=True)
        step *= np.minimum(1.0, 0.25 * cell / np.maximum(length, 1e-30))
        p = p - step
    return p


def _weld(points, tris, tol):
    """Merges vertices closer than tol and drops degenerate triangles."""
    q = np.round(points / tol).astype(np.int64)
    _, first, inverse = np.unique(q, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    tris = inverse[tris]
    good = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    tris = tris[good]
    used = np.unique(tris)
    remap = -np.ones(len(first), np.int64)
    remap[used] = np.arange(len(used))
    return points[first][used], remap[tris]


def decimate(field, points, tris, min_length, cell):
    """Collapses edges shorter than min_length, shortest first, into their midpoint (marching
    tetrahedra leave many slivers); the vertices are projected onto the iso-surface at the end.  A collapse is skipped when it would
    break the manifold (link condition: the edge's endpoints share exactly two neighbours) or turn
    a neighbouring triangle by more than about 60 degrees, so the mesh stays closed and oriented."""
    import heapq

    pts = [np.array(p) for p in points]
    faces = [list(map(int, t)) for t in tris]
    alive = [True] * len(faces)
    vf = [set() for _ in pts]
    for i, (a, b, c) in enumerate(faces):
        vf[a].add(i), vf[b].add(i), vf[c].add(i)
    gone = [False] * len(pts)

    def length(a, b):
        return float(np.linalg.norm(pts[a] - pts[b]))

    heap = []
    for a, b, c in faces:
        for u, v in ((a, b), (b, c), (c, a)):
            if u < v:
                heap.append((length(u, v), u, v))
    heapq.heapify(heap)

    def neighbours(v):
        return {w for f in vf[v] for w in faces[f]} - {v}

    def normal(f, moved, where):
        q = [where if w in moved else pts[w] for w in faces[f]]
        return np.cross(q[1] - q[0], q[2] - q[0])

    while heap:
        l, a, b = heapq.heappop(heap)
        if l >= min_length:
            break
        if gone[a] or gone[b] or b not in neighbours(a) or abs(length(a, b) - l) > 1e-12:
            continue
        shared = vf[a] & vf[b]
        if len(shared) != 2 or len(neighbours(a) & neighbours(b)) != 2 or len(neighbours(a) | neighbours(b)) <= 4:
            continue
        m = (pts[a] + pts[b]) / 2  # projected onto the surface with every vertex at the end
        ok = True
        for f in (vf[a] | vf[b]) - shared:
            n0, n1 = normal(f, (), None), normal(f, (a, b), m)
            if n0 @ n1 <= 0.5 * np.linalg.norm(n0) * np.linalg.norm(n1):
                ok = False
                break
        if not ok:
            continue
        pts[a] = m
        for f in shared:
            alive[f] = False
            for w in faces[f]:
                vf[w].discard(f)
        for f in list(vf[b]):
            faces[f] = [a if w == b else w for w in faces[f]]
            vf[a].add(f)
        vf[b] = set()
        gone[b] = True
        for w in neighbours(a):
            heapq.heappush(heap, (length(a, w), min(a, w), max(a, w)))
    keep = [f for f, ok in zip(faces, alive) if ok]
    used = sorted({w for f in keep for w in f})
    remap = {w: i for i, w in enumerate(used)}
    return _project(field, np.array([pts[w] for w in used]), cell), np.array([[remap[w] for w in f] for f in keep])


def relax(field, points, tris, cell, iterations=6):
    """Tangential Laplacian smoothing with re-projection onto the iso-surface: evens out the
    triangles and unfolds the slivers that marching tetrahedra and edge collapses leave."""
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    count = np.bincount(e[:, 0], minlength=len(points)).astype(float)[:, None]
    p = points.copy()
    for _ in range(iterations):
        centroid = np.zeros_like(p)
        np.add.at(centroid, e[:, 0], p[e[:, 1]])
        centroid /= count
        n = _gradient(field, p, cell * 1e-3)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        move = centroid - p
        move -= (move * n).sum(1, keepdims=True) * n
        p = _project(field, p + 0.5 * move, cell)
    return p


def unfold(points, tris, min_cos=0.2, rounds=50):
    """Plain Laplacian smoothing of the vertices around folded edges (neighbour normals at cos
    below min_cos), round after round, until none is left: features below the grid size (paw
    tips, the webbing between fingers) come out a little rounder instead of crumpled."""
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    count = np.bincount(e[:, 0], minlength=len(points)).astype(float)[:, None]
    p = points.copy()
    for _ in range(rounds):
        bad = _folded_faces(p, tris, min_cos)
        if not len(bad):
            break
        sel = np.zeros(len(p), bool)
        sel[tris[bad].ravel()] = True
        sel[e[sel[e[:, 0]], 1]] = True  # and their one-ring
        centroid = np.zeros_like(p)
        np.add.at(centroid, e[:, 0], p[e[:, 1]])
        centroid /= count
        p[sel] = 0.5 * p[sel] + 0.5 * centroid[sel]
    return p


def _folded_faces(points, tris, min_cos):
    n = np.cross(points[tris[:, 1]] - points[tris[:, 0]], points[tris[:, 2]] - points[tris[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    key = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    face = np.tile(np.arange(len(tris)), 3)
    order = np.lexsort((key[:, 1], key[:, 0]))
    pairs = face[order].reshape(-1, 2)
    return np.unique(pairs[(n[pairs[:, 0]] * n[pairs[:, 1]]).sum(1) < min_cos].ravel())


def sharpest_fold(points, tris):
    """Smallest cosine between the face normals of two triangles sharing an edge (< 0: a fold)."""
    n = np.cross(points[tris[:, 1]] - points[tris[:, 0]], points[tris[:, 2]] - points[tris[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    key = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    face = np.tile(np.arange(len(tris)), 3)
    order = np.lexsort((key[:, 1], key[:, 0]))
    pairs = face[order].reshape(-1, 2)  # closed mesh: every edge has exactly two faces
    return float((n[pairs[:, 0]] * n[pairs[:, 1]]).sum(1).min())


def open_edges(tris):
    """Number of edges not shared by exactly two triangles with opposite orientation (0: closed)."""
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    directed, counts = np.unique(e, axis=0, return_counts=True)
    bad = int((counts != 1).sum())
    s = set(map(tuple, directed))
    bad += sum(1 for a, b in directed if (b, a) not in s)
    return bad


def revolve(profile, segments):
    """Closed surface of revolution about +Y of a polyline profile [(r, y), ...] that starts and
    ends on the axis (r = 0); the winding is made outward whatever the profile's direction.
    Returns points and outward-wound triangles (no normals: faceted, 48 segments look round)."""
    prof = np.asarray(profile, float)
    assert prof[0, 0] == 0 and prof[-1, 0] == 0
    ring = prof[1:-1]
    ang = 2 * np.pi * np.arange(segments) / segments
    pts = [np.array([0.0, prof[0, 1], 0.0])]
    for r, y in ring:
        pts.extend(np.stack([r * np.cos(ang), np.full(segments, y), -r * np.sin(ang)], -1))
    pts.append(np.array([0.0, prof[-1, 1], 0.0]))
    pts = np.vstack(pts)
    top = len(pts) - 1
    tris = []
    for s in range(segments):
        s1 = (s + 1) % segments
        tris.append((0, 1 + s1, 1 + s))
        for k in range(len(ring) - 1):
            a, b = 1 + k * segments, 1 + (k + 1) * segments
            tris.append((a + s, a + s1, b + s1))
            tris.append((a + s, b + s1, b + s))
        last = 1 + (len(ring) - 1) * segments
        tris.append((last + s, last + s1, top))
    tris = np.array(tris)
    # Make the winding outward whatever the profile's direction: the signed volume must be > 0.
    v = np.einsum("ij,ij->i", pts[tris[:, 0]], np.cross(pts[tris[:, 1]], pts[tris[:, 2]])).sum()
    if v < 0:
        tris = tris[:, ::-1]
    return pts, tris


# --------------------------------------------------------------------------------------------------
# Shapes
# --------------------------------------------------------------------------------------------------


def bunny_field():
    """A sitting bunny-like figurine, about 3.4 cm tall, facing +X, in centimetres."""
    ear_l = _rot((0, 0, 1), 18) @ _rot((1, 0, 0), 14)
    ear_r = _rot((0, 0, 1), 18) @ _rot((1, 0, 0), -14)
    parts = [
        ellipsoid((0.0, 0.85, 0.0), (1.15, 0.85, 0.8)),                 # body
        ellipsoid((0.95, 1.65, 0.0), (0.55, 0.48, 0.46)),               # head
        ellipsoid((0.72, 2.45, 0.27), (0.2, 0.62, 0.13), ear_l),        # ears: thin, so they glow
        ellipsoid((0.72, 2.45, -0.27), (0.2, 0.62, 0.13), ear_r),
        ellipsoid((-1.15, 0.95, 0.0), (0.3, 0.3, 0.3)),                 # tail
        ellipsoid((0.75, 0.14, 0.3), (0.38, 0.14, 0.16)),               # front paws
        ellipsoid((0.75, 0.14, -0.3), (0.38, 0.14, 0.16)),
        ellipsoid((-0.4, 0.3, 0.55), (0.62, 0.3, 0.22)),                # hind legs
        ellipsoid((-0.4, 0.3, -0.55), (0.62, 0.3, 0.22)),
    ]
    return smooth_union(parts, 0.18)


def hand_field():
    """An open left hand, palm towards -Z, fingers up (+Y), about 18 cm long, in centimetres."""
    parts = [ellipsoid((0.0, 4.0, 0.0), (4.1, 4.6, 1.35))]              # palm
    parts.append(ellipsoid((0.0, -1.8, 0.0), (2.9, 3.6, 1.7)))          # wrist
    fingers = [(-3.0, 7.6, 5.0, 0.72, -14), (-1.0, 8.4, 6.6, 0.78, -5), (1.0, 8.5, 7.3, 0.8, 4),
               (3.0, 8.0, 6.4, 0.75, 12)]                               # x, base y, length, radius, splay
    for x, y, length, r, splay in fingers:
        d = np.array([math.sin(math.radians(splay)), math.cos(math.radians(splay)), 0.0])
        parts.append(capsule((x, y, 0.0), np.array([x, y, 0.0]) + d * length, r))
    parts.append(capsule((3.6, 3.2, -0.3), (6.2, 6.4, -0.9), 1.0))      # thumb
    return smooth_union(parts, 0.6)


def furnace_field():
    """A blob with a concave waist (so light re-enters the object), about 2 units across."""
    return smooth_union([ellipsoid((-0.45, 0, 0), (0.6, 0.55, 0.5)), ellipsoid((0.5, 0.1, 0), (0.5, 0.6, 0.55)),
                         capsule((-0.2, -0.2, 0), (0.4, -0.3, 0.3), 0.25)], 0.15)


# --------------------------------------------------------------------------------------------------
# USD text
# --------------------------------------------------------------------------------------------------


def _fmt(v):
    s = "%.3f" % v
    s = s.rstrip("0").rstrip(".") if "." in s else s
    return "0" if s in ("-0", "") else s


def mesh_usda(name, points, tris, normals, indent, extra=""):
    pad = " " * indent
    pts = ", ".join("(%s, %s, %s)" % tuple(_fmt(c) for c in p) for p in points)
    counts = ", ".join("3" for _ in range(len(tris)))
    idx = ", ".join(str(int(i)) for i in tris.ravel())
    lo, hi = points.min(0), points.max(0)
    schemas = ['"VolPhotonMediumAPI"'] if "volphoton:" in extra else []
    if "material:binding" in extra:
        schemas.append('"MaterialBindingAPI"')
    lines = [
        '%sdef Mesh "%s" (' % (pad, name),
        '%s    prepend apiSchemas = [%s]' % (pad, ", ".join(schemas)) if schemas else None,
        "%s)" % pad,
        "%s{" % pad,
        "%s    # %d triangles, closed; generated by tools/make_subsurface_meshes.py" % (pad, len(tris)),
        "%s    float3[] extent = [(%s, %s, %s), (%s, %s, %s)]" % ((pad,) + tuple(_fmt(c) for c in lo) + tuple(_fmt(c) for c in hi)),
        "%s    int[] faceVertexCounts = [%s]" % (pad, counts),
        "%s    int[] faceVertexIndices = [%s]" % (pad, idx),
        "%s    point3f[] points = [%s]" % (pad, pts),
    ]
    if normals is not None:
        nrm = ", ".join("(%s, %s, %s)" % tuple(_fmt(c) for c in p) for p in normals)
        lines.append("%s    normal3f[] primvars:normals = [%s] (\n%s        interpolation = \"vertex\"\n%s    )"
                     % (pad, nrm, pad, pad))
    lines.append('%s    uniform token subdivisionScheme = "none"' % pad)
    for line in extra.strip("\n").splitlines():
        lines.append(pad + line if line.strip() else "")
    lines.append("%s}" % pad)
    return "\n".join(l for l in lines if l is not None)


def _check(name, points, tris, min_fold=0.1):
    bad = open_edges(tris)
    if bad:
        raise RuntimeError("%s: %d open or inconsistently wound edges" % (name, bad))
    v = np.einsum("ij,ij->i", points[tris[:, 0]], np.cross(points[tris[:, 1]], points[tris[:, 2]])).sum() / 6
    if v <= 0:
        raise RuntimeError("%s: negative volume (inward winding)" % name)
    fold = sharpest_fold(points, tris)
    if fold < min_fold:
        # A fold (neighbours turned by more than 90 degrees, or crumpled slivers) is where the
        # renderer's ray offsets can step through the surface and light leaks.
        raise RuntimeError("%s: folded triangles (neighbour normals at cos = %.2f)" % (name, fold))
    return v


RENDER_SETTINGS = """def Scope "Render"
{{
    def RenderSettings "settings"
    {{
        int2 resolution = (160, 90)
        rel camera = </World/camera>
        int volphoton:samplesPerPixel = 16
        # Dense measured media scatter hundreds of times per path: a higher maxDepth than the
        # default 64 keeps paths from being cut (which would darken the object).
        int volphoton:maxDepth = {max_depth}
        # Every photon is stored at each event inside a translucent object: few photons suffice.
        int volphoton:photonsPerPass = {photons}
    }}
}}
"""


def bunny_scene():
    points, tris, normals = polygonize(bunny_field(), (-1.7, -0.2, -1.1), (1.8, 3.3, 1.1), 0.07, 0.9)
    vol = _check("bunny", points, tris)
    medium = """
# Measured marble (Jensen et al. 2001); sizes are in centimetres.
uniform token volphoton:preset = "marble"
float volphoton:sceneUnitsPerMm = 0.1
# The index the coefficients were measured with (the preset does not set it).
float volphoton:ior = 1.3
uniform token volphoton:phase = "isotropic"
"""
    mesh = mesh_usda("bunny", points, tris, normals, 4, medium)
    return ("""#usda 1.0
(
    doc = \"\"\"A marble figurine (a procedural bunny-like shape, about 3.4 cm tall) lit from behind.

    Generated by tools/make_subsurface_meshes.py (edit that file, not this one).
    Render:  volphoton render testenv/subsurface_bunny.usda -o bunny.exr
             volphoton render testenv/subsurface_bunny.usda -o bunny_pm.exr --integrator photonmap

    What to look at
      * volphoton:preset = "marble" replaces density/albedo/extinctionColor with Jensen et al.'s
        measured coefficients (1/mm), divided by volphoton:sceneUnitsPerMm = 0.1 (1 unit = 1 cm):
        sigma_t is about 22-30 per cm, a mean free path of 0.3-0.45 mm, albedo 0.998-0.999;
      * the thin ears (about 1.8 mm) glow with light from the rect light behind; the thick body
        does not, except at its rim;
      * inside the object everything comes from the photon map (photonMap) or from paths leaving the
        surface and hitting a light (pathTracer): no shadow ray crosses the refracting surface.
    \"\"\"
    defaultPrim = "World"
    metersPerUnit = 0.01
    upAxis = "Y"
    renderSettingsPrimPath = "/Render/settings"
)

""" + RENDER_SETTINGS.format(max_depth=100000, photons=4000) + """
def Xform "World"
{
    def Camera "camera"
    {
        float focalLength = 50
        float horizontalAperture = 36
        float verticalAperture = 20.25
        float2 clippingRange = (1, 1000)
        double3 xformOp:translate = (0.4, 1.7, 9.5)
        float3 xformOp:rotateXYZ = (-2, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }

    # %(volume).1f cm^3 of marble.
%(mesh)s

    def RectLight "backlight"
    {
        # Behind and above the figurine, out of the picture, shining down towards the camera
        # (rect lights emit along their local -Z).
        float inputs:width = 14
        float inputs:height = 8
        float inputs:intensity = 3
        color3f inputs:color = (1, 0.92, 0.8)
        double3 xformOp:translate = (0.3, 7, -4)
        float3 xformOp:rotateXYZ = (-125, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }

    def DomeLight "fill"
    {
        float inputs:intensity = 0.15
    }
}
""") % {"mesh": mesh, "volume": vol}


def hand_scene():
    points, tris, normals = polygonize(hand_field(), (-5.8, -5.7, -2.3), (8.6, 17.2, 2.3), 0.3, 0.9)
    vol = _check("hand", points, tris)
    medium = """
# Measured skin (Jensen et al. 2001, skin1); sizes are in centimetres.
uniform token volphoton:preset = "skin1"
float volphoton:sceneUnitsPerMm = 0.1
float volphoton:ior = 1.3
uniform token volphoton:phase = "isotropic"
"""
    mesh = mesh_usda("hand", points, tris, normals, 4, medium)
    return ("""#usda 1.0
(
    doc = \"\"\"A hand (procedural: palm, wrist, four fingers and a thumb; about 18 cm long) of measured
    skin, held in front of a bright window-like light.

    Generated by tools/make_subsurface_meshes.py (edit that file, not this one).
    Render:  volphoton render testenv/subsurface_hand.usda -o hand.exr

    What to look at
      * volphoton:preset = "skin1": blue and green are absorbed within a few millimetres
        (reduced albedo 0.84 and 0.68), red travels about 3 mm (albedo 0.96), so light through the
        fingers comes out red and the palm's thick centre stays dark;
      * skin absorbs enough that paths are short (about 25 events in red): this scene is cheap even
        at full size, unlike milk or marble.
    \"\"\"
    defaultPrim = "World"
    metersPerUnit = 0.01
    upAxis = "Y"
    renderSettingsPrimPath = "/Render/settings"
)

""" + RENDER_SETTINGS.format(max_depth=10000, photons=20000) + """
def Xform "World"
{
    def Camera "camera"
    {
        float focalLength = 35
        float horizontalAperture = 36
        float verticalAperture = 20.25
        float2 clippingRange = (1, 1000)
        double3 xformOp:translate = (1.2, 6, 48)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }

    # %(volume).0f cm^3 of skin.
%(mesh)s

    def RectLight "window"
    {
        # Behind the hand, facing the camera.
        float inputs:width = 30
        float inputs:height = 30
        float inputs:intensity = 2
        double3 xformOp:translate = (1, 6, -15)
        float3 xformOp:rotateXYZ = (0, 180, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }

    def DomeLight "fill"
    {
        float inputs:intensity = 0.2
    }
}
""") % {"mesh": mesh, "volume": vol}


def milk_scene():
    # A tumbler: outer radius 2.6 cm, 8 cm tall, 0.25 cm walls, 0.5 cm base (centimetres).
    R, H, wall, base, segments = 2.6, 8.0, 0.25, 0.5, 48
    fillet = [(R - 0.15 + 0.15 * math.sin(a), 0.15 - 0.15 * math.cos(a)) for a in np.linspace(0, math.pi / 2, 4)]
    glass_profile = [(0.0, 0.0)] + fillet[1:] + [(R, H - 0.05), (R - wall / 2, H), (R - wall, H - 0.05),
                                                  (R - wall, base + 0.1), (R - wall - 0.1, base), (0.0, base)]
    g_pts, g_tris = revolve(glass_profile, segments)
    g_vol = _check("glass", g_pts, g_tris, -1e-6)  # right-angled edges by design
    gap, level = 0.02, 6.0  # milk stays 0.2 mm off the glass: the two surfaces must not touch
    r = R - wall - gap
    milk_profile = [(0.0, base + gap), (r - 0.1, base + gap), (r, base + 0.1 + gap), (r, level), (0.0, level)]
    m_pts, m_tris = revolve(milk_profile, segments)
    m_vol = _check("milk", m_pts, m_tris, -1e-6)
    glass_extra = """
# Clear glass: a closed shell (outside wall, rim, inside wall, base); a UsdPreviewSurface with
# opacity 0 and an ior is a smooth dielectric with a clear (medium-free) interior.
rel material:binding = </World/Looks/clearGlass>
"""
    milk_extra = """
# Measured whole milk (Jensen et al. 2001); sizes are in centimetres.
uniform token volphoton:preset = "wholemilk"
float volphoton:sceneUnitsPerMm = 0.1
float volphoton:ior = 1.33
uniform token volphoton:phase = "isotropic"
"""
    glass = mesh_usda("glass", g_pts, g_tris, None, 4, glass_extra)
    milk = mesh_usda("milk", m_pts, m_tris, None, 4, milk_extra)
    return ("""#usda 1.0
(
    doc = \"\"\"A glass of milk: a clear glass tumbler (closed shell, ior 1.5, no medium) holding whole
    milk (a closed mesh with volphoton:preset = "wholemilk").

    Generated by tools/make_subsurface_meshes.py (edit that file, not this one).
    Render:  volphoton render testenv/subsurface_milk.usda -o milk.exr

    What to look at
      * Nesting: closed meshes nest and the innermost medium wins.  Here the glass is modelled as
        a real shell (its solid is the wall and the base), so the milk sits in the glass's cavity,
        outside the glass's solid; a solid glass cylinder with the milk mesh inside it would work
        too (the milk, innermost, replaces the glass's clear interior), but then the glass would
        also fill the space above the milk.  Every surface is seen as material-to-air (each mesh's
        ior is relative to vacuum), so surfaces must not touch: the milk keeps a 0.2 mm gap.
      * Milk is nearly non-absorbing (albedo 0.996-0.9996): light wanders far, the milk glows
        evenly and its edges soften; the rect light's reflection shows on the glass.
      * The glass is a UsdPreviewSurface with opacity 0 and ior 1.5 (no VolPhotonMediumAPI: a
        clear dielectric); the milk is a Gprim with VolPhotonMediumAPI and volphoton:ior.
    \"\"\"
    defaultPrim = "World"
    metersPerUnit = 0.01
    upAxis = "Y"
    renderSettingsPrimPath = "/Render/settings"
)

""" + RENDER_SETTINGS.format(max_depth=100000, photons=4000) + """
def Xform "World"
{
    def Camera "camera"
    {
        float focalLength = 50
        float horizontalAperture = 36
        float verticalAperture = 20.25
        float2 clippingRange = (1, 1000)
        double3 xformOp:translate = (0, 7.5, 30)
        float3 xformOp:rotateXYZ = (-7, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }

    def Scope "Looks"
    {
        def Material "clearGlass"
        {
            token outputs:surface.connect = </World/Looks/clearGlass/surface.outputs:surface>

            def Shader "surface"
            {
                uniform token info:id = "UsdPreviewSurface"
                float inputs:opacity = 0
                float inputs:ior = 1.5
                token outputs:surface
            }
        }
    }

    # %(gvol).1f cm^3 of glass.
%(glass)s

    # %(mvol).1f cm^3 of milk.
%(milk)s

    def RectLight "key"
    {
        # To the left of and behind the glass, facing it.
        float inputs:width = 12
        float inputs:height = 12
        float inputs:intensity = 3
        double3 xformOp:translate = (-14, 8, -10)
        float3 xformOp:rotateXYZ = (0, -125, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateXYZ"]
    }

    def DomeLight "sky"
    {
        float inputs:intensity = 0.3
        color3f inputs:color = (0.9, 0.95, 1)
    }
}
""") % {"glass": glass, "milk": milk, "gvol": g_vol, "mvol": m_vol}


def furnace_scene():
    points, tris, normals = polygonize(furnace_field(), (-1.3, -1.0, -0.9), (1.3, 1.0, 0.9), 0.08, 0.9)
    _check("blob", points, tris)
    medium = """
# Non-absorbing (albedo 1) forward-scattering medium behind an ior 1.5 surface.
float volphoton:ior = 1.5
float volphoton:density = 4
color3f volphoton:albedo = (1, 1, 1)
float volphoton:phase:g = 0.3
"""
    mesh = mesh_usda("blob", points, tris, normals, 4, medium)
    return ("""#usda 1.0
(
    doc = \"\"\"White furnace for translucent objects: a non-absorbing medium (albedo 1) inside a closed
    refracting mesh (ior 1.5) under a uniform dome of radiance 1.  Energy conservation makes the
    object invisible: every pixel renders 1 (up to noise), in both integrators.  A darker object
    means energy lost at the dielectric (Fresnel, total internal reflection, the 1/eta^2 radiance
    scaling) or in the medium; a brighter one means energy created.

    Generated by tools/make_subsurface_meshes.py (edit that file, not this one).
    Checked by testenv/test_subsurface.py.
    \"\"\"
    defaultPrim = "World"
    metersPerUnit = 1
    upAxis = "Y"
    renderSettingsPrimPath = "/Render/settings"
)

""" + RENDER_SETTINGS.format(max_depth=100000, photons=20000).replace("(160, 90)", "(48, 32)") + """
def Xform "World"
{
    def Camera "camera"
    {
        float focalLength = 50
        float horizontalAperture = 30
        float verticalAperture = 20
        double3 xformOp:translate = (0, 0, 5)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }

%(mesh)s

    def DomeLight "furnace"
    {
        float inputs:intensity = 1
    }
}
""") % {"mesh": mesh}


SCENES = {
    "subsurface_bunny.usda": bunny_scene,
    "subsurface_hand.usda": hand_scene,
    "subsurface_milk.usda": milk_scene,
    "translucent_furnace.usda": furnace_scene,
}


def main(argv):
    out = argv[1] if len(argv) > 1 else os.path.join(REPO, "testenv")
    os.makedirs(out, exist_ok=True)
    for name, make in SCENES.items():
        text = make()
        with open(os.path.join(out, name), "w") as f:
            f.write(text)
        print("%s: %d bytes" % (os.path.join(out, name), len(text)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
