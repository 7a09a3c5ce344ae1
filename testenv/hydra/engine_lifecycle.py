#!/usr/bin/env python3
"""Render-thread lifecycle of the delegate through UsdImagingGL.Engine (no GPU): interactive
refinement past samplesPerPixel, batch convergence, pause, resume, stop, restart on a camera change,
when the coarse preview is shown, the integrator setting as usdview's dialog sets it, and photon maps
kept across camera moves, resizes and a switch of integrator but not a moved light or a changed photon
setting (photonMap, then combined). Run by
test_hydra_lifecycle.py with OpenUSD's Python (the interpreter of usdrecord) and the delegate on
PXR_PLUGINPATH_NAME:

    python3 engine_lifecycle.py SCENE.usda CAMERA_PATH LIGHT_PATH

Exits 0 when every check holds; otherwise prints the failed check and exits 1. About 5 s.
"""

import sys
import time

from pxr import CameraUtil, Gf, Glf, Sdf, Usd, UsdGeom, UsdImagingGL

SIZE = (64, 36)
QUIET = 0.5  # seconds a stopped or paused render must not advance


def check(condition, what):
    if not condition:
        print("FAILED:", what)
        sys.exit(1)


def main(scene, camera_path, light_path):
    stage = Usd.Stage.Open(scene)
    params = UsdImagingGL.Engine.Parameters()
    params.gpuEnabled = False
    engine = UsdImagingGL.Engine(params)
    check(engine.SetRendererPlugin("HdVolPhotonRendererPlugin"), "the VolPhoton plug-in loads")
    check(engine.IsPauseRendererSupported() and engine.IsStopRendererSupported(), "pause and stop are supported")
    engine.SetRendererAov("color")
    engine.SetRenderBufferSize(Gf.Vec2i(*SIZE))
    engine.SetFraming(CameraUtil.Framing(Gf.Rect2i(Gf.Vec2i(0, 0), SIZE[0], SIZE[1])))
    camera = UsdGeom.Camera(stage.GetPrimAtPath(camera_path)).GetCamera(Usd.TimeCode.Default())
    f = camera.frustum
    CameraUtil.ConformWindow(f, CameraUtil.MatchVertically, SIZE[0] / SIZE[1])
    engine.SetCameraState(f.ComputeViewMatrix(), f.ComputeProjectionMatrix())
    root, render_params = stage.GetPseudoRoot(), UsdImagingGL.RenderParams()

    def stats():
        engine.Render(root, render_params)
        return engine.GetRenderStats()

    def passes():
        return int(stats().get("passes", 0))

    def render_until(predicate, timeout=20.0):
        t0 = time.perf_counter()
        while not predicate():
            check(time.perf_counter() - t0 < timeout, "reached within %.0f s" % timeout)
            time.sleep(0.005)

    def quiet_for(seconds):
        """Passes at the start and the end of `seconds` of Render() calls."""
        first = passes()
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            passes()
            time.sleep(0.01)
        return first, passes()

    # The engine leaves enableInteractive unset, as usdview does: an interactive render.
    # The first render has no pass time to go by: a 4x4-block preview comes before the first pass.
    render_until(lambda: stats()["framesWritten"] >= 2)
    check(stats()["previewBlock"] == 4, "the first render starts with a 4x4 preview: %s" % stats()["previewBlock"])
    # Interactive: refines past convergedSamplesPerPixel until stopped and never reports converged,
    # so a viewer keeps drawing. (Set after the first Render(): the scene's RenderSettings prim,
    # synced then, sets it too.)
    engine.SetRendererSetting("convergedSamplesPerPixel", 4)
    render_until(lambda: passes() >= 3 * 4)
    s = stats()
    check(not engine.IsConverged(), "an interactive render is not converged after 3x its samplesPerPixel")
    check("percentDone" not in s and s["numCompletedSamples"] == s["passes"], "interactive stats: %s" % s)

    # Batch, as usdrecord (UsdAppUtilsFrameRecorder sets enableInteractive false): converges at
    # convergedSamplesPerPixel and stays there.
    engine.SetRendererSetting("enableInteractive", False)
    render_until(lambda: passes() > 0 and engine.IsConverged())
    s = stats()
    check(s["passes"] == 4 and s["percentDone"] == 100.0, "converged after exactly 4 passes: %s" % s["passes"])
    # Passes at 64x36 take milliseconds: a restart then shows no preview, only the 4 passes.
    check(s["previewBlock"] == 0 and s["framesWritten"] == 4, "no preview after fast passes: %s" % s)
    a, b = quiet_for(0.2)
    check(a == b == 4 and engine.IsConverged(), "a converged render stays converged")

    # Keep rendering: many passes to go.
    engine.SetRendererSetting("convergedSamplesPerPixel", 100000)
    render_until(lambda: passes() >= 3)
    check(not engine.IsConverged(), "not converged while passes remain")

    check(engine.PauseRenderer(), "PauseRenderer")
    time.sleep(0.2)  # the pass in flight completes; the next one does not start
    a, b = quiet_for(QUIET)
    check(a == b, "paused: passes did not advance (%d -> %d)" % (a, b))
    check(not engine.IsConverged(), "a paused render is not converged")

    check(engine.ResumeRenderer(), "ResumeRenderer")
    render_until(lambda: passes() >= b + 2)

    check(engine.StopRenderer(), "StopRenderer")
    a, b = quiet_for(QUIET)
    check(a == b, "stopped: passes did not advance (%d -> %d)" % (a, b))
    check(not engine.IsConverged(), "a stopped render is not converged")

    # A camera change restarts the render (the pass counter starts again), even after a stop.
    before, version = b, stats()["sceneVersion"]
    f.Transform(Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(0, 1, 0), 3.0)))
    engine.SetCameraState(f.ComputeViewMatrix(), f.ComputeProjectionMatrix())
    restarted = []
    render_until(lambda: restarted.append(passes()) or restarted[-1] < before)
    render_until(lambda: passes() >= 2)
    check(stats()["sceneVersion"] == version, "a camera change does not rebuild the scene version")

    # The integrator as usdview's settings dialog shows and sets it: a string setting (a text field;
    # UsdImagingGL has no widget for a token and warns "doesn't have a UI"). photonsTraced tells
    # which integrator runs: the path tracer traces none.
    listed = {str(x.key): x for x in engine.GetRendererSettingsList()}
    check("volphoton:integrator" in listed and listed["volphoton:integrator"].type == UsdImagingGL.RendererSettingType.STRING,
          "the integrator is listed as a string setting: %s" % sorted(listed))
    check(engine.GetRendererSetting("volphoton:integrator") == "pathTracer", "the integrator's default is pathTracer")
    for value, photons in (("photonMap", True), ("pathTracer", False)):
        engine.SetRendererSetting("volphoton:integrator", value)  # a Python str: a std::string, as the dialog sets it
        render_until(lambda: passes() >= 1)
        check((stats()["photonsTraced"] > 0) == photons, "%s: photonsTraced %s" % (value, stats()["photonsTraced"]))

    # Photon maps survive restarts for what photons do not see (camera, image size), not a light move.
    engine.SetRendererSetting("volphoton:integrator", "photonMap")
    engine.SetRendererSetting("convergedSamplesPerPixel", 3)
    engine.SetRendererSetting("volphoton:photonsPerPass", 2000)

    def converged_stats():
        render_until(lambda: passes() > 0 and engine.IsConverged())
        return stats()

    def move_camera(degrees):
        """Turns the camera, and moves the engine's camera light with it as usdview and usdrecord do
        on every frame (a lighting-state light Sprim the delegate must not take for a scene edit)."""
        f.Transform(Gf.Matrix4d().SetRotate(Gf.Rotation(Gf.Vec3d(0, 1, 0), degrees)))
        engine.SetCameraState(f.ComputeViewMatrix(), f.ComputeProjectionMatrix())
        headlight = Glf.SimpleLight()
        p = f.GetPosition()
        headlight.position = Gf.Vec4f(p[0], p[1], p[2], 1.0)
        engine.SetLightingState([headlight], Glf.SimpleMaterial(), Gf.Vec4f(0.1, 0.1, 0.1, 1.0))

    for integrator in ("photonMap", "combined"):
        engine.SetRendererAov("color")
        engine.SetRenderBufferSize(Gf.Vec2i(*SIZE))
        engine.SetFraming(CameraUtil.Framing(Gf.Rect2i(Gf.Vec2i(0, 0), SIZE[0], SIZE[1])))
        move_camera(0.0)
        if integrator == "combined":
            # Photons in the open fog too (share 1): the photon map's photons, so switching keeps its maps
            # (a settings change keeps them when the photons' key is unchanged, PhotonCache)...
            engine.SetRendererSetting("volphoton:integrator", "combined")
            engine.SetRendererSetting("volphoton:combinedPhotonShare", 1.0)
            s = converged_stats()
            check(s["integratorUsed"] == integrator and s["photonsTraced"] == 0 and s["photonPassesReused"] == 3,
                  "switching photonMap -> combined reuses every photon pass: %s" % s)
            # ... and a photon setting (the kernel's mean-free-path cap) traces them again.
            engine.SetRendererSetting("volphoton:photonRadiusMfp", 4.0)
        s = converged_stats()
        check(s["integratorUsed"] == integrator and s["photonsTraced"] == 3 * 2000 and s["photonPassesReused"] == 0,
              "%s: photons traced first: %s" % (integrator, s))
        move_camera(-2.0)
        s = converged_stats()
        check(s["photonsTraced"] == 0 and s["photonPassesReused"] == 3 and s["photonsReused"] > 0,
              "%s: a camera move reuses every photon pass: %s" % (integrator, s))
        size = (48, 27)
        engine.SetRenderBufferSize(Gf.Vec2i(*size))
        engine.SetFraming(CameraUtil.Framing(Gf.Rect2i(Gf.Vec2i(0, 0), size[0], size[1])))
        s = converged_stats()
        check(s["photonsTraced"] == 0 and s["photonPassesReused"] == 3, "%s: a resize reuses every photon pass: %s" % (integrator, s))
        light = UsdGeom.Xformable(stage.GetPrimAtPath(light_path))
        light.GetOrderedXformOps()[0].Set(Gf.Vec3d(0.3, 3.9, 0.5) if integrator == "photonMap" else Gf.Vec3d(0.2, 3.8, 0.4))
        s = converged_stats()
        check(s["photonsTraced"] == 3 * 2000 and s["photonPassesReused"] == 0, "%s: a moved light traces photons: %s" % (integrator, s))
        # Photons feed only the beauty, multiple and surface AOVs: a depth pass traces none.
        engine.SetRendererAov("depth")
        move_camera(1.0)
        s = converged_stats()
        check(s["photonsTraced"] == 0 and s["photonPassesReused"] == 0 and
              any("no bound AOV" in x for x in s["passesSkipped"]), "%s: a depth pass traces no photons: %s" % (integrator, s))
    engine.StopRenderer()
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
