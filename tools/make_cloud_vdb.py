#!/usr/bin/env python3
"""Writes the procedural cloud VDB that testenv/vdb_cloud.usda and testenv/emissive_smoke.usda use.

    python tools/make_cloud_vdb.py testenv/cloud.vdb            # 96^3 voxels, cumulus
    python tools/make_cloud_vdb.py out.vdb --resolution 128 --voxel-size 0.0078125 --seed 7
    python tools/make_cloud_vdb.py blob.vdb --shape blob --resolution 64   # the tests' and benchmark's cloud

The cloud is the core's ``writeProceduralCloudVdb`` (proceduralCloud.h): a FloatGrid named "density",
values in [0, 1]; by default a cumulus (puffs on a flat base carved by Worley billows at three
octaves and eroded by fBm), or the older smooth fractal-noise blob (``--shape blob``), inside a
sphere of radius 0.45 * resolution voxels, in the
box [0, resolution * voxel_size]^3 of its object space (with the defaults the unit cube). The same
arguments give the same file on every machine. The .vdb is generated, not kept in git: the tests
write it into their temporary directories; a person rendering the example scenes runs the first
command above once.
"""

import argparse
import os
import sys


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("output", help="the .vdb file to write")
    ap.add_argument("--resolution", type=int, default=96, help="voxels per side (default 96)")
    ap.add_argument("--shape", choices=("cumulus", "blob"), default="cumulus",
                    help="cumulus (default: billows and wisps) or blob (smooth; the tests' and benchmark's cloud)")
    ap.add_argument("--voxel-size", type=float, default=None,
                    help="voxel size in scene units (default 1/resolution: the cloud fills the unit cube)")
    ap.add_argument("--seed", type=int, default=1, help="noise seed (default 1)")
    args = ap.parse_args(argv)
    try:
        from volphoton import _core
    except ImportError as e:
        print("make_cloud_vdb: error: volphoton._core is not importable (%s); run 'pip install .' first" % e,
              file=sys.stderr)
        return 1
    voxel = args.voxel_size if args.voxel_size is not None else 1.0 / max(args.resolution, 1)
    try:
        _core.write_procedural_cloud_vdb(args.output, args.resolution, voxel, args.seed, args.shape)
    except (ValueError, RuntimeError) as e:
        print("make_cloud_vdb: error: %s" % e, file=sys.stderr)
        return 1
    print("wrote %s (%s, %d^3 voxels of %g, %.0f kB)" % (args.output, args.shape, args.resolution, voxel,
                                                    os.path.getsize(args.output) / 1024.0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
