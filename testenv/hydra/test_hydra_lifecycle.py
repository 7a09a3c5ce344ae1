"""Pause, resume, stop, convergence and restart of the delegate's render thread, driven through
UsdImagingGL.Engine by engine_lifecycle.py in OpenUSD's Python (see that script for the checks)."""

import os
import subprocess

from hydra_util import TESTENV

HERE = os.path.dirname(os.path.abspath(__file__))


def test_interactive_refinement_batch_convergence_pause_resume_stop_restart(hydra_env):
    python = open(hydra_env["usdrecord"]).readline()[2:].strip()  # usdrecord's interpreter has OpenUSD's pxr
    p = subprocess.run([python, os.path.join(HERE, "engine_lifecycle.py"), os.path.join(TESTENV, "fog_spotlight.usda"),
                        "/World/camera", "/World/spot"], capture_output=True, text=True, env=hydra_env["env"], timeout=60)
    assert p.returncode == 0 and "OK" in p.stdout, p.stdout + p.stderr
    # UsdImagingGL lists every setting for usdview's dialog and warns about those without a widget.
    assert "doesn't have a UI" not in p.stderr, p.stderr
