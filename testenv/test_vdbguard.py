"""The front end survives VDB files that crash the OpenVDB reader (issue: bad input never crashes).

volphoton.vdbguard calls the core's guard (core/vdbGuard.h), which loads each file in the probe
executable installed beside _core. Stand-in probes, shell scripts named by HDVOLPHOTON_VDBPROBE, die
by a signal or hang, so the tests do not depend on finding a file that crashes OpenVDB.
"""

import os
import subprocess
import time

import pytest

from volphoton import _core, vdbguard

PROBE_ENV = "HDVOLPHOTON_VDBPROBE"


def stub_probe(tmp_path, name, body):
    """An executable stand-in for the probe that logs each run (its arguments) to <name>.log."""
    path = tmp_path / name
    path.write_text("#!/bin/sh\necho \"$@\" >> '%s.log'\n%s\n" % (path, body))
    path.chmod(0o755)
    return str(path)


def runs(tmp_path, name):
    log = tmp_path / (name + ".log")
    return len(log.read_text().splitlines()) if log.exists() else 0


@pytest.fixture
def guard(monkeypatch):
    """A clean verdict cache and no probe override; restored afterwards."""
    monkeypatch.delenv(PROBE_ENV, raising=False)
    vdbguard.clear_cache()
    yield monkeypatch
    vdbguard.clear_cache()


def test_crash_check_reports_a_child_that_dies_by_signal(tmp_path, guard):
    path = tmp_path / "x.vdb"
    path.write_bytes(b"not a vdb")
    guard.setenv(PROBE_ENV, stub_probe(tmp_path, "segv", "kill -SEGV $$"))
    msg = vdbguard.crash_check(str(path), "density")
    assert msg is not None and "crashed" in msg and "SIGSEGV" in msg
    # cached per file: the same answer without running a probe again
    guard.setenv(PROBE_ENV, stub_probe(tmp_path, "ok", "exit 0"))
    assert vdbguard.crash_check(str(path), "density") == msg
    assert runs(tmp_path, "segv") == 1 and runs(tmp_path, "ok") == 0


def test_crash_check_passes_files_that_load_or_fail_cleanly(tmp_path, guard):
    probe = _core.vdb_probe_path()
    assert os.path.basename(probe) == "volphoton-vdbprobe"
    assert os.path.dirname(probe) == os.path.dirname(_core.__file__), "the probe is installed beside _core"
    good = tmp_path / "good.vdb"
    _core.write_procedural_cloud_vdb(str(good), 16, 0.1, 1)
    bad = tmp_path / "truncated.vdb"
    bad.write_bytes(good.read_bytes()[:200])
    assert vdbguard.crash_check(str(good), "density") is None
    assert vdbguard.crash_check(str(bad), "density") is None  # a clean error, reported by the real load
    assert vdbguard.crash_check(str(tmp_path / "missing.vdb"), "density") is None
    # ... and the installed probe really ran the loader on them (it says so with -v).
    out = subprocess.run([probe, str(good), "density", "-v"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.startswith("loaded"), out.stdout + out.stderr
    out = subprocess.run([probe, str(bad), "density", "-v"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.startswith("refused cleanly") and str(bad) in out.stdout, out.stdout


def test_crash_check_times_out_on_a_hanging_reader(tmp_path, guard):
    path = tmp_path / "slow.vdb"
    path.write_bytes(b"x")
    guard.setenv(PROBE_ENV, stub_probe(tmp_path, "hang", "exec sleep 30"))
    guard.setattr(vdbguard, "TIMEOUT_SECONDS", 0.5)
    start = time.monotonic()
    msg = vdbguard.crash_check(str(path), "density")
    assert msg is not None and "longer than 0.5 s" in msg
    assert time.monotonic() - start < 5, "the probe is killed at the time-out, not waited for"


def test_crash_check_without_a_probe_warns_once_and_loads_unguarded(tmp_path, guard):
    path = tmp_path / "a.vdb"
    path.write_bytes(b"x")
    guard.setenv(PROBE_ENV, str(tmp_path / "no-probe-here"))
    messages = []
    _core.set_diagnostic_sink(lambda severity, message: messages.append((severity, message)))
    try:
        assert vdbguard.crash_check(str(path), "density") is None
        assert vdbguard.crash_check(str(path), "other") is None
    finally:
        _core.set_diagnostic_sink(None)
    assert len(messages) == 1 and messages[0][0] == "warning", messages
    assert "no-probe-here" in messages[0][1] and "without the guard" in messages[0][1]


def test_the_front_end_probes_every_bound_grid_with_its_voxel_cap(tmp_path, guard):
    """crash_check_medium (the check the core runs before every grid load, core/translate/volume.h)
    hands the probe all the grids the load will read."""
    path = tmp_path / "f.vdb"
    path.write_bytes(b"x")
    guard.setenv(PROBE_ENV, stub_probe(tmp_path, "args", "exit 0"))
    d = _core.GridMediumDesc()
    d.file_path = str(path)
    d.density_grid = "smoke"
    d.emission_grid = "glow"
    d.max_active_voxels = 99
    assert vdbguard.crash_check_medium(d) is None
    assert (tmp_path / "args.log").read_text() == "%s smoke --emission glow --max-voxels 99\n" % os.path.realpath(path)


def write_crashing_vdb(path):
    """A real file on which OpenVDB 10's reader corrupts its heap and aborts: the deterministic 16^3
    procedural cloud with one byte of its compressed voxel data changed (found by the byte-flip
    fuzzing of tools/stress.py). Checked by running the probe on it directly."""
    _core.write_procedural_cloud_vdb(str(path), 16, 1.0 / 16, 1)
    data = bytearray(path.read_bytes())
    assert len(data) == 15650 and data[9036] == 0, "the procedural cloud changed: find another crashing byte"
    data[9036] = 26
    path.write_bytes(bytes(data))
    return str(path)


def test_a_real_crashing_file_is_reported_and_the_host_lives_on(tmp_path, guard):
    path = write_crashing_vdb(tmp_path / "crash.vdb")
    raw = subprocess.run([_core.vdb_probe_path(), path, "density"], capture_output=True, timeout=60)
    assert raw.returncode < 0, "the file must crash the reader for this test to mean anything: %r" % raw
    msg = vdbguard.crash_check(path, "density")
    assert msg is not None and "crashed" in msg and "SIGABRT" in msg, msg
