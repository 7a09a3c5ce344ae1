#!/usr/bin/env python3
"""Renders every example scene (testenv/*.usda) to a noise target and writes a contact sheet.

    python tools/gallery.py                 # 480x270, noise target 3%, at most 60 s a scene
    python tools/gallery.py --quick         # 192x108, noise target 10%, at most 6 s a scene (< 2 min)
    python tools/gallery.py --out DIR --noise-target 0.02 --time-limit 120 --resolution 640 360

Each scene goes through ``volphoton render`` (the front end users run) with ``--noise-target`` and
``--time-limit`` (core/integrator.h: adaptive sampling stops each pixel once its estimated relative
error and its neighbours' are at or below the target; the time limit ends the render first when it
is too short). The sheet (DIR/gallery.png) shows every image with its name, render time, the median
estimated per-pixel error over the image and over the subject (pixels with alpha > 0: the sky and
empty space are noiseless and would flatter the image-wide figure) and why it stopped, and a row with the light-path split of the VDB cloud
(single scattering, multiple scattering, surfaces: the AOVs that sum to its beauty). DIR/gallery.json
holds the figures. Generated assets the scenes need (testenv/cloud.vdb, the glTF statue) are made
first when missing, as tools/setup.sh makes them.
"""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TESTENV = os.path.join(REPO, "testenv")
SPLIT_SCENE = "vdb_cloud"
SPLIT_LAYERS = ("single", "multiple", "surface")


def volphoton_command():
    exe = os.path.join(os.path.dirname(sys.executable), "volphoton")
    return [exe] if os.path.exists(exe) else [sys.executable, "-c", "import sys; from volphoton.cli import main; sys.exit(main())"]


def ensure_assets():
    if not os.path.exists(os.path.join(TESTENV, "cloud.vdb")):
        subprocess.run([sys.executable, os.path.join(REPO, "tools", "make_cloud_vdb.py"),
                        os.path.join(TESTENV, "cloud.vdb")], check=True, stdout=subprocess.DEVNULL)
    if not os.path.exists(os.path.join(TESTENV, "gltf", "statue.usdc")):
        subprocess.run([sys.executable, os.path.join(REPO, "tools", "make_gltf_assets.py"),
                        os.path.join(TESTENV, "gltf")], check=True, stdout=subprocess.DEVNULL)


def render(scene, out_dir, args):
    name = os.path.splitext(os.path.basename(scene))[0]
    exr, stats = os.path.join(out_dir, name + ".exr"), os.path.join(out_dir, name + ".json")
    cmd = volphoton_command() + ["render", scene, "-o", exr, "--quiet", "--stats", stats,
                                 "--resolution", str(args.resolution[0]), str(args.resolution[1]),
                                 "--noise-target", repr(args.noise_target), "--time-limit", repr(args.time_limit)]
    start = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if r.returncode != 0 or not os.path.exists(exr):
        return {"scene": name, "ok": False, "message": (r.stderr.strip().splitlines() or ["failed"])[-1], "wall_seconds": wall}
    frame = json.load(open(stats))["frames"][0]
    from volphoton import output

    # The image-wide median counts noiseless background (sky, empty space) too; the median over the
    # pixels whose first segment met something (alpha > 0) is the figure that describes the subject.
    ch, _ = output.read_exr(exr)
    covered = (ch["A"] > 0) & (ch["error.Y"] >= 0)
    subject = float(np.median(ch["error.Y"][covered])) if covered.any() else -1.0
    return {"subject_median_relative_error": subject,"scene": name, "ok": True, "exr": exr, "png": frame["output"]["png"], "wall_seconds": wall,
            "render_seconds": frame["timings"]["render_seconds"], "passes": frame["render"]["passes"],
            "median_relative_error": frame["render"]["median_relative_error"],
            "stop_reason": frame["render"]["stop_reason"], "integrator": frame["settings"]["integrator"],
            "mean_samples_per_pixel": frame["render"]["camera_samples"] / float(args.resolution[0] * args.resolution[1])}


def contact_sheet(results, path, args):
    from PIL import Image, ImageDraw, ImageFont

    from volphoton import output

    w, h = args.resolution
    label_h, pad, cols = 30, 6, 3
    font = ImageFont.load_default()
    tiles = []
    for res in results:
        img = Image.open(res["png"]).convert("RGB") if res["ok"] else Image.new("RGB", (w, h), (60, 0, 0))
        if res["ok"]:
            err = res["median_relative_error"]
            sub = res["subject_median_relative_error"]
            text = "%s  %.1f s  %.0f spp avg\nmedian error %s (subject %s), %s" % (
                res["scene"], res["render_seconds"], res["mean_samples_per_pixel"],
                "%.1f%%" % (100 * err) if err >= 0 else "n/a", "%.1f%%" % (100 * sub) if sub >= 0 else "n/a", {"noiseTarget": "target met", "timeLimit": "time limit",
                                                              "maxSamplesPerPixel": "sample cap"}.get(res["stop_reason"], res["stop_reason"]))
        else:
            text = "%s  FAILED\n%s" % (res["scene"], res["message"][:60])
        tiles.append((img, text))
    split = next((r for r in results if r["scene"] == SPLIT_SCENE and r["ok"]), None)
    if split:
        ch, _ = output.read_exr(split["exr"])
        display = output.display_transform()
        for layer in SPLIT_LAYERS:
            rgb = np.stack([ch["%s.%s" % (layer, c)] for c in "RGB"], axis=-1)
            tiles.append((Image.fromarray(display.to_uint8(np.ascontiguousarray(rgb, np.float32))),
                          "%s: %s\n(AOV; single + multiple + surface = beauty)" % (SPLIT_SCENE, layer)))
    rows = (len(tiles) + cols - 1) // cols
    sheet = Image.new("RGB", (cols * (w + pad) + pad, rows * (h + label_h + pad) + pad + 20), (24, 24, 24))
    draw = ImageDraw.Draw(sheet)
    draw.text((pad, 4), "hdVolPhoton example scenes: %dx%d, noise target %g%%, time limit %g s (tools/gallery.py%s)"
              % (w, h, 100 * args.noise_target, args.time_limit, " --quick" if args.quick else ""), fill=(230, 230, 230), font=font)
    for i, (img, text) in enumerate(tiles):
        x, y = pad + (i % cols) * (w + pad), 20 + pad + (i // cols) * (h + label_h + pad)
        sheet.paste(img.resize((w, h)), (x, y))
        draw.text((x + 2, y + h + 2), text, fill=(230, 230, 230), font=font)
    output.ensure_directory(path)
    sheet.save(path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(REPO, "out", "gallery"), help="output folder (default out/gallery)")
    ap.add_argument("--quick", action="store_true", help="192x108, noise target 10%%, 6 s a scene")
    ap.add_argument("--resolution", nargs=2, type=int, metavar=("W", "H"))
    ap.add_argument("--noise-target", type=float)
    ap.add_argument("--time-limit", type=float, help="seconds of rendering per scene")
    ap.add_argument("--scenes", nargs="*", help="scene names (default: every testenv/*.usda)")
    args = ap.parse_args(argv)
    quick = args.quick
    args.resolution = args.resolution or ([192, 108] if quick else [480, 270])
    args.noise_target = args.noise_target if args.noise_target is not None else (0.10 if quick else 0.03)
    args.time_limit = args.time_limit if args.time_limit is not None else (6.0 if quick else 60.0)
    ensure_assets()
    scenes = sorted(f for f in os.listdir(TESTENV) if f.endswith(".usda"))
    if args.scenes:
        scenes = [s for s in scenes if os.path.splitext(s)[0] in args.scenes]
    os.makedirs(args.out, exist_ok=True)
    results = []
    for s in scenes:
        res = render(os.path.join(TESTENV, s), args.out, args)
        results.append(res)
        if res["ok"]:
            print("gallery: %-22s %6.1f s  %6.0f spp avg  median error %5.1f%% (subject %5.1f%%)  (%s)" % (
                res["scene"], res["render_seconds"], res["mean_samples_per_pixel"], 100 * max(res["median_relative_error"], 0),
                100 * max(res["subject_median_relative_error"], 0), res["stop_reason"]), flush=True)
        else:
            print("gallery: %-22s FAILED: %s" % (res["scene"], res["message"]), flush=True)
    sheet = os.path.join(args.out, "gallery.png")
    contact_sheet(results, sheet, args)
    with open(os.path.join(args.out, "gallery.json"), "w") as f:
        json.dump({"resolution": args.resolution, "noise_target": args.noise_target, "time_limit": args.time_limit,
                   "scenes": results}, f, indent=2)
    print("gallery: contact sheet %s" % sheet)
    return 0 if all(r["ok"] for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
