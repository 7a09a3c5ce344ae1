#!/usr/bin/env python3
"""Hydra benchmarks of the hdVolPhoton delegate, driven through UsdImagingGLEngine (gpuEnabled off).

Run with OpenUSD's Python (the interpreter of `usdrecord`, which has OpenUSD's pxr), with the
delegate on PXR_PLUGINPATH_NAME (testenv/hydra/hydra_util.py shows the set-up):

    python3 tools/bench_hydra.py interactive [SCENE.usda ...]   # default: every testenv/*.usda
    python3 tools/bench_hydra.py sync --vdb CLOUD256.vdb        # 1,000 instanced meshes + a 256^3 VDB

interactive: time from a camera change to the first updated frame. The scene renders at 320x180
until a few passes are done; then the camera orbits by 5 degrees (SetCameraState) and we call
Render() until the delegate's stats show the restarted render's first frame written to the buffers
(framesWritten: the coarse preview where the delegate makes one, else the first full pass). Median
and maximum over 10 moves per scene (target: under 100 ms); also the preview block sizes used (0:
none) and the median time to the first full-resolution pass. HDVOLPHOTON_PREVIEW=0 measures the
delegate without its coarse preview. Measured on the 2-core development machine (README.md, "Hydra"):
the first frame after a move is 10-30 ms on every testenv scene with the preview (subsurface_bunny:
13.5 ms, 154 ms without).

sync: a stage with a PointInstancer of 1,000 copies of a 5,120-triangle sphere, with and without a
256^3 OpenVDB cloud (write it with volphoton._core.write_procedural_cloud_vdb(path, 256, 1/256, 1)).
Time of the first Render() call (Hydra's sync of every prim) and until the first complete frame at
1 sample per pixel (adds the delegate's scene build and one sample), for VolPhoton and for hdEmbree
(HdEmbreeRendererPlugin, built with OpenUSD when Embree is found) on the same mesh scene (hdEmbree has
no volumes). Best of 3 fresh engines each. Needs numpy in that Python (Debian: python3-numpy).

Prints Markdown tables. Not a test: the figures depend on the machine (say which when reporting).
"""

from __future__ import annotations

import argparse
import glob
import math
import os
import statistics
import sys
import tempfile
import time

from pxr import CameraUtil, Gf, Sdf, Usd, UsdGeom, UsdImagingGL, UsdLux, UsdVol

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
SIZE = (320, 180)


def make_engine(plugin: str) -> UsdImagingGL.Engine:
    params = UsdImagingGL.Engine.Parameters()
    params.gpuEnabled = False
    engine = UsdImagingGL.Engine(params)
    if not engine.SetRendererPlugin(plugin):
        raise SystemExit("renderer plug-in %s is not available (PXR_PLUGINPATH_NAME?)" % plugin)
    engine.SetRendererAov("color")
    engine.SetRenderBufferSize(Gf.Vec2i(*SIZE))
    engine.SetFraming(CameraUtil.Framing(Gf.Rect2i(Gf.Vec2i(0, 0), SIZE[0], SIZE[1])))
    return engine


def camera_of(stage: Usd.Stage) -> UsdGeom.Camera:
    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.Camera):
            return UsdGeom.Camera(prim)
    raise SystemExit("%s has no camera" % stage.GetRootLayer().identifier)


def frustum(camera: UsdGeom.Camera, orbit_deg: float) -> Gf.Frustum:
    """The camera's frustum turned by orbit_deg about the world Y axis through the origin."""
    f = camera.GetCamera(Usd.TimeCode.Default()).frustum
    f.Transform(Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(0, 1, 0), orbit_deg)))
    CameraUtil.ConformWindow(f, CameraUtil.MatchVertically, SIZE[0] / SIZE[1])
    return f


def passes(engine) -> int:
    return int(engine.GetRenderStats().get("passes", 0))


def render_until(engine, root, params, predicate, timeout=60.0) -> float:
    t0 = time.perf_counter()
    while not predicate():
        engine.Render(root, params)
        if time.perf_counter() - t0 > timeout:
            raise SystemExit("no frame within %.0f s" % timeout)
        time.sleep(0.0005)
    return time.perf_counter() - t0


def frames(engine) -> int:
    return int(engine.GetRenderStats().get("framesWritten", 0))


def interactive(scenes) -> int:
    print("| scene | camera move -> first updated frame, median ms | max ms | preview block | -> first full pass, median ms |")
    print("|---|---:|---:|---:|---:|")
    for path in scenes:
        stage = Usd.Stage.Open(path)
        engine = make_engine("HdVolPhotonRendererPlugin")
        engine.SetRendererSetting("convergedSamplesPerPixel", 100000)  # keep rendering between moves
        params = UsdImagingGL.RenderParams()
        root = stage.GetPseudoRoot()
        camera = camera_of(stage)
        f = frustum(camera, 0.0)
        engine.SetCameraState(f.ComputeViewMatrix(), f.ComputeProjectionMatrix())
        render_until(engine, root, params, lambda: passes(engine) >= 3)
        times, full, blocks = [], [], []
        for move in range(1, 11):
            before = frames(engine)
            f = frustum(camera, 5.0 * move)
            t0 = time.perf_counter()
            engine.SetCameraState(f.ComputeViewMatrix(), f.ComputeProjectionMatrix())
            restarted = [False]

            def first_frame_done():
                n = frames(engine)
                restarted[0] = restarted[0] or n < before
                return restarted[0] and n >= 1
            render_until(engine, root, params, first_frame_done)
            times.append(1000 * (time.perf_counter() - t0))
            blocks.append(int(engine.GetRenderStats().get("previewBlock", 0)))
            render_until(engine, root, params, lambda: passes(engine) >= 1)
            full.append(1000 * (time.perf_counter() - t0))
            render_until(engine, root, params, lambda: passes(engine) >= 3)
        print("| %s | %.1f | %.1f | %s | %.1f |" % (os.path.basename(path), statistics.median(times), max(times),
                                                   "/".join(str(b) for b in sorted(set(blocks))), statistics.median(full)))
        engine.StopRenderer()
        del engine
    return 0


def sync_stage(path: str, vdb: str | None) -> None:
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    cam = UsdGeom.Camera.Define(stage, "/World/camera")
    cam.AddTranslateOp().Set(Gf.Vec3d(0, 0, 60))
    UsdLux.DomeLight.Define(stage, "/World/sky")  # hdEmbree ignores lights (ambient occlusion)
    sys.path.insert(0, os.path.join(HERE, "bench"))
    import scenes  # icosphere
    pts, tris = scenes.icosphere(4)
    inst = UsdGeom.PointInstancer.Define(stage, "/World/instancer")
    proto = UsdGeom.Mesh.Define(stage, "/World/instancer/prototypes/sphere")
    proto.CreatePointsAttr([Gf.Vec3f(*map(float, p)) for p in pts])
    proto.CreateFaceVertexCountsAttr([3] * len(tris))
    proto.CreateFaceVertexIndicesAttr([int(i) for i in tris.reshape(-1)])
    proto.CreateSubdivisionSchemeAttr("none")
    inst.CreatePrototypesRel().SetTargets([proto.GetPath()])
    positions = [Gf.Vec3f(2.5 * (i % 10) - 11.25, 2.5 * ((i // 10) % 10) - 11.25, 2.5 * (i // 100) - 11.25)
                 for i in range(1000)]
    inst.CreatePositionsAttr(positions)
    inst.CreateProtoIndicesAttr([0] * 1000)
    inst.CreateScalesAttr([Gf.Vec3f(0.8)] * 1000)
    if vdb:
        vol = UsdVol.Volume.Define(stage, "/World/cloud")
        asset = UsdVol.OpenVDBAsset.Define(stage, "/World/cloud/density")
        asset.CreateFilePathAttr(Sdf.AssetPath(os.path.abspath(vdb)))
        asset.CreateFieldNameAttr("density")
        vol.CreateFieldRelationship("density", asset.GetPath())
        vol.AddTransformOp().Set(Gf.Matrix4d().SetScale(30.0) * Gf.Matrix4d().SetTranslate(Gf.Vec3d(-15, -15, -15)))
    stage.GetRootLayer().Save()


def first_frame_seconds(path: str, plugin: str):
    """(seconds of the first Render() call, seconds until a 1-sample frame is complete): the first
    holds Hydra's sync of every prim; the second adds the delegate's scene build (BVH, VDB majorant
    grid) and one sample per pixel at 320x180."""
    stage = Usd.Stage.Open(path)
    engine = make_engine(plugin)
    engine.SetRendererSetting("convergedSamplesPerPixel", 1)
    engine.SetRendererSetting("enableInteractive", False)  # a batch render converges (see renderDelegate.h)
    f = frustum(camera_of(stage), 0.0)
    engine.SetCameraState(f.ComputeViewMatrix(), f.ComputeProjectionMatrix())
    params = UsdImagingGL.RenderParams()
    t0 = time.perf_counter()
    engine.Render(stage.GetPseudoRoot(), params)
    first = time.perf_counter() - t0
    render_until(engine, stage.GetPseudoRoot(), params, engine.IsConverged, timeout=600)
    done = time.perf_counter() - t0
    engine.StopRenderer()
    return first, done


def sync(vdb: str) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        meshes = os.path.join(tmp, "meshes.usda")
        both = os.path.join(tmp, "meshes_vdb.usda")
        sync_stage(meshes, None)
        sync_stage(both, vdb)
        rows = [("1,000 instanced meshes", "HdEmbreeRendererPlugin", meshes),
                ("1,000 instanced meshes", "HdVolPhotonRendererPlugin", meshes),
                ("1,000 instanced meshes + 256^3 VDB", "HdVolPhotonRendererPlugin", both)]
        print("| scene | delegate | first Render() call (sync), s | to a complete 1-spp frame, s |")
        print("|---|---|---:|---:|")
        for label, plugin, path in rows:
            runs = [first_frame_seconds(path, plugin) for _ in range(3)]
            print("| %s | %s | %.3f | %.3f |" % (label, plugin.replace("RendererPlugin", ""), min(r[0] for r in runs),
                                               min(r[1] for r in runs)))
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="mode", required=True)
    i = sub.add_parser("interactive")
    i.add_argument("scenes", nargs="*")
    s = sub.add_parser("sync")
    s.add_argument("--vdb", required=True)
    args = ap.parse_args(argv)
    if args.mode == "interactive":
        return interactive(args.scenes or sorted(glob.glob(os.path.join(REPO, "testenv", "*.usda"))))
    return sync(args.vdb)


if __name__ == "__main__":
    sys.exit(main())
