"""Helpers of the Hydra tests: usdrecord with this build's plug-ins (see conftest.py)."""

import os
import shutil
import subprocess
import warnings

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


# An intermittent abort, "terminate called without an active exception", after usdrecord has
# written its image (an exit-time abort): seen on 2026-12-02 in about 1 of 30 usdrecord runs inside
# pytest (twice in one CI run, twice in three runs of test_hydra_scale.py), never in 64 plain runs of
# the same stages nor in 40 under gdb. hd/renderer.cpp then stopped reporting convergence before the
# last pass was written (a real race, and a suspect): 0 aborts in the next 72 runs, but 1 in the
# ~300 usdrecord runs of the next full fresh-clone run, so the cause is still open (session notes,
# README "Known gaps"). Such an abort is retried, at most twice, with a warning in the test report.
_INTERMITTENT_ABORT = "terminate called without an active exception"
_ABORT_RETRIES = 2


def run_usdrecord(hydra_env, args, scene_index=False, timeout=600):
    env = dict(hydra_env["env"])
    if scene_index:
        env["USDIMAGINGGL_ENGINE_ENABLE_SCENE_INDEX"] = "1"
    cmd = [hydra_env["usdrecord"], "--renderer", "VolPhoton", "--disableGpu"] + [str(a) for a in args]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    for _ in range(_ABORT_RETRIES):
        if not (r.returncode == -6 and _INTERMITTENT_ABORT in r.stderr):
            break
        written = os.path.exists(str(args[-1]))
        warnings.warn("usdrecord aborted (%s; its output %s written), retried: %s"
                      % (_INTERMITTENT_ABORT, "was" if written else "was not", " ".join(cmd)))
        r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    return r


def volphoton_exe():
    exe = shutil.which("volphoton") or os.path.join(REPO, ".venv", "bin", "volphoton")
    assert os.path.exists(exe), "the volphoton command is not installed"
    return exe
