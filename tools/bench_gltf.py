#!/usr/bin/env python3
"""Conversion speed of `volphoton gltf2usd` on a large glTF asset.

    python tools/bench_gltf.py [--triangles 1000000] [--repeat 3]

Writes a single-mesh .glb of about N triangles (a bumpy sphere with positions, normals and UVs:
tools/make_gltf_assets.py --triangles), then times, in separate processes so each starts cold:
  * translate  tinygltf read + usda text (the C++ translator alone, volphoton.gltf.translate)
  * -> .usdc   the full command to a crate file (translate + usd-core parse + crate write)
  * -> .usda   the full command to a text file
and reports the best of --repeat runs with the peak resident memory of that process, as a
Markdown table.  Run it on an otherwise idle machine; the figures in the issue notes say which.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))

CHILD = r"""
import resource, sys, time
from volphoton import gltf
t0 = time.perf_counter()
if sys.argv[2] == "translate":
    text, diags, stats = gltf.translate(sys.argv[1])
else:
    stats = gltf.convert(sys.argv[1], sys.argv[2]).stats
print(time.perf_counter() - t0, stats["triangles"], resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def run(glb: str, target: str):
    p = subprocess.run([sys.executable, "-c", CHILD, glb, target], capture_output=True, text=True, check=True)
    seconds, triangles, rss_kb = p.stdout.split()
    return float(seconds), int(triangles), int(rss_kb)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        glb = os.path.join(tmp, "big.glb")
        subprocess.run([sys.executable, os.path.join(HERE, "make_gltf_assets.py"), "--triangles",
                        str(args.triangles), glb], check=True)
        size_mb = os.path.getsize(glb) / 2**20
        rows = []
        for label, target in (("translate (C++ only)", "translate"), ("-> .usdc", os.path.join(tmp, "big.usdc")),
                              ("-> .usda", os.path.join(tmp, "big.usda"))):
            runs = [run(glb, target) for _ in range(args.repeat)]
            seconds, triangles, rss = min(runs)
            out_mb = os.path.getsize(target) / 2**20 if target != "translate" else float("nan")
            rows.append((label, seconds, triangles, rss, out_mb))
    print("glTF conversion, %d triangles (%.1f MiB .glb), best of %d, %s, %d cores"
          % (rows[0][2], size_mb, args.repeat, platform.processor() or platform.machine(), os.cpu_count()))
    print()
    print("| step | seconds | Mtriangles/s | peak RSS MiB | output MiB |")
    print("|---|---:|---:|---:|---:|")
    for label, seconds, triangles, rss, out_mb in rows:
        print("| %s | %.2f | %.2f | %.0f | %s |" % (label, seconds, triangles / seconds / 1e6, rss / 1024,
                                                   "-" if out_mb != out_mb else "%.1f" % out_mb))
    return 0


if __name__ == "__main__":
    sys.exit(main())
