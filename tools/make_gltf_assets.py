#!/usr/bin/env python3
"""Writes the glTF asset of testenv/gltf_statue.usda and converts it to USD.

    python tools/make_gltf_assets.py [OUT_DIR]     # default testenv/gltf

writes OUT_DIR/statue.glb (glTF 2.0 binary, metres, +Y up) and OUT_DIR/statue.usdc (through
`volphoton gltf2usd`, the path a TD takes).  The asset: the procedural bunny-like figurine of
tools/make_subsurface_meshes.py (3.4 cm tall, closed, with normals) and, 2 cm behind it, a
6 x 1.5 x 2 cm block whose top and sides are two primitives with two materials (-> GeomSubsets).
Node tree: Statue -> {figure (TRS), pedestal (matrix)}.  (The block is not under the figure: a
surface within a few millimetres of a medium's mesh can confuse the photon tracer's medium
bookkeeping.)  Deterministic output.

    python tools/make_gltf_assets.py --triangles 1000000 OUT.glb
writes a single-mesh asset of about that many triangles (a displaced sphere) for the conversion
benchmark (tools/bench_gltf.py).
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import gltf_writer as gw  # noqa: E402


def box(lo, hi):
    """A closed box as (points, top triangles, side+bottom triangles), outward counter-clockwise."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    p = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], np.float32)
    top = [[3, 7, 6], [3, 6, 2]]
    rest = [[0, 1, 5], [0, 5, 4], [0, 4, 7], [0, 7, 3], [1, 2, 6], [1, 6, 5],
            [0, 3, 2], [0, 2, 1], [4, 5, 6], [4, 6, 7]]
    return p, np.array(top), np.array(rest)


def statue_asset() -> gw.GltfWriter:
    import make_subsurface_meshes as ms
    points, tris, normals = ms.polygonize(ms.bunny_field(), (-1.7, -0.2, -1.1), (1.8, 3.3, 1.1), 0.07, 0.9)
    w = gw.GltfWriter()
    pos = w.accessor(np.asarray(points, np.float32) * np.float32(0.01), gw.FLOAT, minmax=True)  # cm -> m
    nrm = w.accessor(np.asarray(normals, np.float32), gw.FLOAT)
    idx = w.accessor(np.asarray(tris).reshape(-1), gw.UNSIGNED_SHORT if len(points) < 65536 else gw.UNSIGNED_INT)
    marble = w.material((0.9, 0.88, 0.85, 1), metallic=0.0, roughness=0.3, name="marble")
    figure = w.mesh([{"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx, "material": marble}],
                    name="figure")
    bp, top, rest = box((-0.03, 0.0, -0.01), (0.03, 0.015, 0.01))
    bpos = w.accessor(bp, gw.FLOAT, minmax=True)
    slate = w.material((0.12, 0.12, 0.14, 1), metallic=0.0, roughness=0.8, name="slate top")
    wood = w.material((0.35, 0.2, 0.1, 1), metallic=0.0, roughness=0.9, name="wood")
    pedestal = w.mesh([{"attributes": {"POSITION": bpos}, "indices": w.accessor(top.reshape(-1), gw.UNSIGNED_BYTE),
                        "material": slate},
                       {"attributes": {"POSITION": bpos}, "indices": w.accessor(rest.reshape(-1), gw.UNSIGNED_BYTE),
                        "material": wood}], name="pedestal")
    fig_node = w.node(name="figure", mesh=figure, translation=[0.0, 0.0, 0.0],
                      rotation=[0.0, 0.2588190451025207, 0.0, 0.9659258262890683])  # 30 degrees about +Y
    ped_node = w.node(name="pedestal", mesh=pedestal, matrix=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -0.035, 1])
    w.scene([w.node(name="Statue", children=[fig_node, ped_node])], name="statue", default=True)
    return w


def sphere_asset(triangles: int) -> gw.GltfWriter:
    """A bumpy UV sphere of about `triangles` triangles (positions, normals, UVs; uint indices)."""
    n = max(4, int(round(np.sqrt(triangles / 2))))
    theta = np.linspace(0, np.pi, n + 1)
    phi = np.linspace(0, 2 * np.pi, n + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    r = 1 + 0.05 * np.sin(7 * t) * np.cos(5 * p)
    pts = np.stack([r * np.sin(t) * np.cos(p), r * np.cos(t), r * np.sin(t) * np.sin(p)], -1).reshape(-1, 3)
    nrm = pts / np.linalg.norm(pts, axis=1, keepdims=True)
    uv = np.stack([p / (2 * np.pi), t / np.pi], -1).reshape(-1, 2)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).reshape(-1)
    b, c, d = a + n + 1, a + 1, a + n + 2
    tris = np.concatenate([np.stack([a, c, b], 1), np.stack([c, d, b], 1)]).reshape(-1)
    w = gw.GltfWriter()
    prim = {"attributes": {"POSITION": w.accessor(pts.astype(np.float32), gw.FLOAT, minmax=True),
                           "NORMAL": w.accessor(nrm.astype(np.float32), gw.FLOAT),
                           "TEXCOORD_0": w.accessor(uv.astype(np.float32), gw.FLOAT)},
            "indices": w.accessor(tris, gw.UNSIGNED_INT)}
    w.scene([w.node(name="sphere", mesh=w.mesh([prim], name="sphere"))], default=True)
    return w


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", nargs="?", default=os.path.join(REPO, "testenv", "gltf"))
    ap.add_argument("--triangles", type=int, help="write a benchmark sphere of about N triangles to OUT (.glb)")
    args = ap.parse_args(argv)
    if args.triangles:
        sphere_asset(args.triangles).write_glb(args.out)
        return 0
    os.makedirs(args.out, exist_ok=True)
    glb = os.path.join(args.out, "statue.glb")
    statue_asset().write_glb(glb)
    from volphoton import gltf
    result = gltf.convert(glb, os.path.join(args.out, "statue.usdc"))
    for d in result.diagnostics:
        print(gltf.format_diagnostic(glb, d))
    print("wrote %s and %s (%d triangles)" % (glb, result.output, result.stats["triangles"]))
    return 1 if result.errors else 0


if __name__ == "__main__":
    sys.exit(main())
