#!/usr/bin/env python3
"""Benchmark scene 3 (the dense cloud) before a wall that fills the view: the check that `auto` needs no
rule against views of opaque surfaces (README, "Which integrator"). Writes dense_cloud_wall.usda (the
benchmark's camera: the cloud on 40% of the view) and dense_cloud_wall_far.usda (the camera 5 units
further back: 7%) into --out, their VDB path made absolute.

    python tools/bench/make_wall_variant.py [--out /tmp/volphoton-wall]
    cd tools && python bench_light_pixel.py --scene /tmp/volphoton-wall/dense_cloud_wall.usda --resolution 160 120 \\
        --reference 240 --seeds 3 --variants pathTracer,beams,combined
"""

import argparse
import os

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BENCH = os.path.join(REPO, "testenv", "bench")

# A default-material (lambertian, albedo 0.5) quad at z = -2, behind the cloud, facing the camera.
WALL = '''    def Mesh "wall"
    {
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(-6, -4, -2), (6, -4, -2), (6, 6, -2), (-6, 6, -2)]
    }

'''
CAMERA_AT = "(0, 0.5, 4.6, 1)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="/tmp/volphoton-wall")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(BENCH, "dense_cloud.usda")) as f:
        text = f.read()
    sun = '    def DistantLight "sun0"'
    if sun not in text or CAMERA_AT not in text or "@./cloud.vdb@" not in text:
        raise SystemExit("testenv/bench/dense_cloud.usda changed: update make_wall_variant.py")
    text = text.replace(sun, WALL + sun, 1).replace("@./cloud.vdb@", "@%s@" % os.path.join(BENCH, "cloud.vdb"))
    for name, camera in (("dense_cloud_wall", CAMERA_AT), ("dense_cloud_wall_far", "(0, 0.5, 9.6, 1)")):
        path = os.path.join(a.out, name + ".usda")
        with open(path, "w") as f:
            f.write(text.replace(CAMERA_AT, camera, 1))
        print(path)


if __name__ == "__main__":
    main()
