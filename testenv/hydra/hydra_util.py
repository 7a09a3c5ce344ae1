"""Helpers of the Hydra tests: usdrecord with this build's plug-ins (see conftest.py)."""

import os
import shutil
import subprocess

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TESTENV = os.path.join(REPO, "testenv")
BUILD = os.path.join(REPO, "build")
STAGE = os.path.join(BUILD, "hydra-stage")


def make_hydra_env():
    usdrecord = shutil.which("usdrecord")
    assert usdrecord, "usdrecord is not on PATH (OpenUSD's bin folder)"
    p = subprocess.run(["cmake", "--install", BUILD, "--prefix", STAGE], capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr
    plugin_dirs = [os.path.join(STAGE, "plugin", "usd", "hdVolPhoton", "resources"),
                   os.path.join(STAGE, "plugin", "usd", "usdVolPhotonGltf", "resources"),
                   os.path.join(STAGE, "plugin", "usd", "volPhotonSchemas", "resources")]
    for d in plugin_dirs:
        assert os.path.exists(os.path.join(d, "plugInfo.json")), d
    env = dict(os.environ)
    env["PXR_PLUGINPATH_NAME"] = os.pathsep.join(plugin_dirs)
    env.pop("PYTHONPATH", None)  # usdrecord's own Python finds OpenUSD's pxr, not the venv's usd-core
    env.pop("VIRTUAL_ENV", None)
    env["PATH"] = os.pathsep.join(p for p in env["PATH"].split(os.pathsep) if ".venv" not in p)
    return {"usdrecord": usdrecord, "env": env}


def run_usdrecord(hydra_env, args, scene_index=False, timeout=600):
    env = dict(hydra_env["env"])
    if scene_index:
        env["USDIMAGINGGL_ENGINE_ENABLE_SCENE_INDEX"] = "1"
    return subprocess.run([hydra_env["usdrecord"], "--renderer", "VolPhoton", "--disableGpu"] + [str(a) for a in args],
                          capture_output=True, text=True, env=env, timeout=timeout)


def volphoton_exe():
    exe = shutil.which("volphoton") or os.path.join(REPO, ".venv", "bin", "volphoton")
    assert os.path.exists(exe), "the volphoton command is not installed"
    return exe
