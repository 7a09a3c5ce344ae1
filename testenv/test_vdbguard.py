"""The front end survives VDB files that crash the OpenVDB reader (issue: bad input never crashes)."""

import os
import subprocess
import sys

from volphoton import vdbguard


def test_crash_check_reports_a_child_that_dies_by_signal(tmp_path, monkeypatch):
    # A stand-in child that segfaults, so the test does not depend on finding a crashing file.
    path = tmp_path / "x.vdb"
    path.write_bytes(b"not a vdb")
    monkeypatch.setattr(vdbguard, "_CHILD", "import os, signal; os.kill(os.getpid(), signal.SIGSEGV)")
    vdbguard._cache.clear()
    msg = vdbguard.crash_check(str(path), "density")
    assert msg is not None and "crashed" in msg and "SIGSEGV" in msg
    # cached per file: the same answer without running the child again
    monkeypatch.setattr(vdbguard, "_CHILD", "raise SystemExit(0)")
    assert vdbguard.crash_check(str(path), "density") == msg


def test_crash_check_passes_files_that_load_or_fail_cleanly(tmp_path):
    from volphoton import _core

    good = tmp_path / "good.vdb"
    _core.write_procedural_cloud_vdb(str(good), 16, 0.1, 1)
    bad = tmp_path / "truncated.vdb"
    bad.write_bytes(good.read_bytes()[:200])
    vdbguard._cache.clear()
    assert vdbguard.crash_check(str(good), "density") is None
    assert vdbguard.crash_check(str(bad), "density") is None  # a clean error, reported by the real load
    assert vdbguard.crash_check(str(tmp_path / "missing.vdb"), "density") is None


def test_crash_check_times_out_on_a_hanging_reader(tmp_path, monkeypatch):
    path = tmp_path / "slow.vdb"
    path.write_bytes(b"x")
    monkeypatch.setattr(vdbguard, "_CHILD", "import time; time.sleep(30)")
    monkeypatch.setattr(vdbguard, "TIMEOUT_SECONDS", 0.5)
    vdbguard._cache.clear()
    msg = vdbguard.crash_check(str(path), "density")
    assert msg is not None and "longer than" in msg
