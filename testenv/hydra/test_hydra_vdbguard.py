"""A VDB file that crashes the OpenVDB reader does not take usdrecord down (issue 18).

The delegate asks the core's reader guard (core/vdbGuard.h) before it loads a grid, as the standalone
front end does. bad.vdb is a real crashing file: the deterministic procedural cloud with one byte of
its compressed voxel data changed, on which OpenVDB 10's reader corrupts its heap (the installed probe
aborts; loaded in-process, the load throws a clean-looking error and the host crashes later). Without
the guard (HDVOLPHOTON_VDBPROBE=/nonexistent) usdrecord died on this scene in 2 of 3 runs (SIGSEGV,
SIGABRT), and the third reported a clean-looking read error, not the crash.
A second variant simulates a SIGSEGV with a stand-in probe (HDVOLPHOTON_VDBPROBE, a script that kills
itself for bad.vdb and runs the installed probe on every other file), so the mechanism is tested
even if a future OpenVDB reads the crafted file safely.
"""

import os
import subprocess

import numpy as np
import pytest

from hydra_util import STAGE, run_usdrecord, volphoton_exe

from volphoton import _core, output  # noqa: E402

WIDTH = 32

CLOUD = """
    def Volume "{name}" (
        prepend apiSchemas = ["VolPhotonMediumAPI"]
    )
    {{
        float volphoton:density = 9
        color3f volphoton:albedo = (0.95, 0.95, 0.95)
        rel field:density = </World/{name}/density>
        double3 xformOp:translate = ({x}, -0.5, -1)
        uniform token[] xformOpOrder = ["xformOp:translate"]

        def OpenVDBAsset "density"
        {{
            asset filePath = @./{file}@
            token fieldName = "density"
        }}
    }}
"""


def write_scene(folder, with_bad):
    volumes = CLOUD.format(name="good", x=-1.1, file="good.vdb")
    if with_bad:
        volumes += CLOUD.format(name="bad", x=0.1, file="bad.vdb")
    path = folder / ("scene_bad.usda" if with_bad else "scene_good_only.usda")
    path.write_text("""#usda 1.0
(
    defaultPrim = "World"
    metersPerUnit = 1
    upAxis = "Y"
    renderSettingsPrimPath = "/Render/settings"
)

def Scope "Render"
{
    def RenderSettings "settings"
    {
        int2 resolution = (32, 18)
        rel camera = </World/camera>
        int volphoton:samplesPerPixel = 4
        int volphoton:seed = 3
    }
}

def Xform "World"
{
    def Camera "camera"
    {
        float focalLength = 35
        float horizontalAperture = 36
        float verticalAperture = 20.25
        double3 xformOp:translate = (0, 0, 3.5)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
%s
    def DistantLight "sun"
    {
        float inputs:intensity = 3
        float3 xformOp:rotateXYZ = (-30, 20, 0)
        uniform token[] xformOpOrder = ["xformOp:rotateXYZ"]
    }

    def DomeLight "sky"
    {
        float inputs:intensity = 0.3
    }
}
""" % volumes)
    return str(path)


def write_crashing_vdb(path):
    """The 16^3 procedural cloud with byte 9036 (compressed voxel data) set to 26: OpenVDB 10 aborts
    on it ("malloc(): corrupted top size"); found by the byte-flip fuzzing of tools/stress.py."""
    _core.write_procedural_cloud_vdb(str(path), 16, 1.0 / 16, 1)
    data = bytearray(path.read_bytes())
    assert len(data) == 15650 and data[9036] == 0, "the procedural cloud changed: find another crashing byte"
    data[9036] = 26
    path.write_bytes(bytes(data))


@pytest.fixture(params=["real", "simulated"])
def crash_scene(request, tmp_path, hydra_env):
    """(hydra env, scene with the bad volume, scene without it, the signal expected)."""
    _core.write_procedural_cloud_vdb(str(tmp_path / "good.vdb"), 16, 1.0 / 16, 1)
    real_probe = os.path.join(STAGE, "plugin", "usd", "volphoton-vdbprobe")
    assert os.access(real_probe, os.X_OK), "cmake --install puts the probe beside hdVolPhoton.so"
    env = dict(hydra_env["env"])
    env.pop("HDVOLPHOTON_VDBPROBE", None)
    if request.param == "real":
        write_crashing_vdb(tmp_path / "bad.vdb")
        raw = subprocess.run([real_probe, str(tmp_path / "bad.vdb"), "density"], capture_output=True, timeout=60)
        assert raw.returncode < 0, "bad.vdb must crash the reader for this test to mean anything: %r" % raw
        signal = ""  # SIGABRT with glibc's malloc checks; the test does not depend on which
    else:
        (tmp_path / "bad.vdb").write_bytes((tmp_path / "good.vdb").read_bytes())  # crashes through the stand-in
        probe = tmp_path / "probe.sh"
        probe.write_text('#!/bin/sh\ncase "$1" in\n  */bad.vdb) kill -SEGV $$ ;;\nesac\nexec "%s" "$@"\n' % real_probe)
        probe.chmod(0o755)
        env["HDVOLPHOTON_VDBPROBE"] = str(probe)
        signal = "SEGV"
    scenes = write_scene(tmp_path, True), write_scene(tmp_path, False)
    return {"usdrecord": hydra_env["usdrecord"], "env": env}, scenes[0], scenes[1], "(SIG" + signal


def record(hydra_env, scene, out):
    r = run_usdrecord(hydra_env, ["--renderSettingsPrimPath", "/Render/settings", "--camera", "/World/camera",
                                  "--imageWidth", WIDTH, scene, out])
    assert r.returncode == 0 and os.path.exists(out), r.stdout + r.stderr
    channels, _ = output.read_exr(out)
    return r, np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)


def test_usdrecord_survives_a_crashing_vdb_and_renders_the_rest(tmp_path, crash_scene):
    env, bad_scene, good_scene, signal = crash_scene
    r, img = record(env, bad_scene, str(tmp_path / "bad.exr"))
    bad_file = os.path.realpath(tmp_path / "bad.vdb")
    warnings = [line for line in r.stderr.splitlines() if "bad.vdb" in line]
    assert len(warnings) >= 1, r.stderr
    w = warnings[0]
    assert "/World/bad/density.filePath" in w and "/World/bad" in w and bad_file in w, w
    assert "crashed on this file " + signal in w and "volume skipped" in w, w
    assert "good.vdb" not in r.stderr, "the sound file passes the real probe: " + r.stderr
    # The rest renders as if the bad volume were not there: the same seed gives the same image.
    _, reference = record(env, good_scene, str(tmp_path / "good.exr"))
    lit = (reference.sum(axis=-1) > 0).mean()
    assert lit > 0.05, "the good cloud is visible (lit pixels: %g of the image)" % lit
    assert np.array_equal(img, reference), "max difference %g" % np.abs(img - reference).max()


def test_volphoton_render_reports_the_same_error(tmp_path, crash_scene):
    env, bad_scene, _, signal = crash_scene
    cli_env = dict(os.environ)
    cli_env.pop("HDVOLPHOTON_VDBPROBE", None)
    if "HDVOLPHOTON_VDBPROBE" in env["env"]:
        cli_env["HDVOLPHOTON_VDBPROBE"] = env["env"]["HDVOLPHOTON_VDBPROBE"]
    r = subprocess.run([volphoton_exe(), "render", bad_scene, "-o", str(tmp_path / "cli.exr"), "--no-png", "-q"],
                       capture_output=True, text=True, timeout=600, env=cli_env)
    assert r.returncode == 1 and os.path.exists(tmp_path / "cli.exr"), "error reported, image written: " + r.stderr
    lines = [line for line in r.stderr.splitlines() if "bad.vdb" in line]
    assert lines and "/World/bad/density" in lines[0] and "crashed on this file " + signal in lines[0], r.stderr
    assert "volume skipped" in lines[0], lines[0]
