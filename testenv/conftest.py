"""Shared set-up of the testenv/ suite.

* The repository's schema plug-in (plugInfo/) goes on PXR_PLUGINPATH_NAME before anything imports
  pxr (USD reads plug-ins once).
* The compiled core must be importable: the suite tests the installed package (``pip install
  --no-build-isolation -e .`` or ``pip install .``).  If ``volphoton._core`` is missing the whole run
  stops with an error and a non-zero status; it is never skipped.
"""

import os
import re
import shutil
import subprocess
import sys

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TESTENV = os.path.join(REPO, "testenv")
PLUGIN_DIR = os.path.join(REPO, "plugInfo")

_paths = [p for p in os.environ.get("PXR_PLUGINPATH_NAME", "").split(os.pathsep) if p]
if PLUGIN_DIR not in _paths:
    os.environ["PXR_PLUGINPATH_NAME"] = os.pathsep.join([PLUGIN_DIR] + _paths)
assert "pxr" not in sys.modules, "pxr was imported before testenv/conftest.py set PXR_PLUGINPATH_NAME"

try:
    import volphoton  # noqa: E402
    from volphoton import _core  # noqa: E402,F401
except ImportError as _e:  # pragma: no cover - the failure path
    pytest.exit("volphoton._core is not importable (%s).\nBuild and install the package first:\n"
                "    cd %s && . .venv/bin/activate && pip install --no-build-isolation -e .\n" % (_e, REPO),
                returncode=3)


def usda(text):
    """Compact test usda -> valid usda: `def X "n" { prop }` one-liners are split into lines (the
    usda parser wants each property and the closing brace on their own lines)."""
    out = []
    for line in text.splitlines():
        m = re.match(r'^(\s*def [^{]*?)\{ (.+)$', line)
        if m:
            out.append(m.group(1) + "{")
            line = "    " + m.group(2)
        m = re.match(r'^(.*\S) \}$', line)
        if m and not re.search(r'=\s*\{', line):
            out += [m.group(1), "}"]
        else:
            out.append(line)
    return "\n".join(out) + "\n"


def volphoton_exe():
    """The installed console script; its absence is a packaging failure."""
    exe = shutil.which("volphoton")
    if exe is None:
        candidate = os.path.join(os.path.dirname(sys.executable), "volphoton")
        exe = candidate if os.path.exists(candidate) else None
    assert exe is not None, "the 'volphoton' command is not on PATH: pip install the package"
    return exe


def run_cli(*args, cwd=None, env_updates=None, drop_env=(), timeout=600):
    """Runs the installed ``volphoton`` command; returns CompletedProcess (text)."""
    env = dict(os.environ)
    for k in drop_env:
        env.pop(k, None)
    env.update(env_updates or {})
    return subprocess.run([volphoton_exe()] + [str(a) for a in args], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=timeout)


@pytest.fixture(scope="session")
def cloud_vdb(tmp_path_factory):
    """The procedural cloud written by tools/make_cloud_vdb.py (into a temporary directory)."""
    d = tmp_path_factory.mktemp("vdb")
    path = d / "cloud.vdb"
    r = subprocess.run([sys.executable, os.path.join(REPO, "tools", "make_cloud_vdb.py"), str(path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert path.stat().st_size < 1 << 20, "the generated cloud should stay below 1 MB"
    return path


@pytest.fixture
def scene_copy(tmp_path, cloud_vdb):
    """copy(name) -> path of testenv/<name> copied into tmp_path next to a cloud.vdb."""

    def copy(name):
        dst = tmp_path / name
        shutil.copy(os.path.join(TESTENV, name), dst)
        if not (tmp_path / "cloud.vdb").exists():
            shutil.copy(cloud_vdb, tmp_path / "cloud.vdb")
        return dst

    return copy
