"""Reads a VDB file once in a separate process before the renderer loads it.

OpenVDB 10 trusts the sizes stored in a file's compressed voxel data, so a few corrupted files can
crash its reader or make it allocate for minutes (the core validates headers and grid descriptors
itself, but not every voxel buffer). A crash must not take the render down, so the front end first
asks the core's guard (core/vdbGuard.h, shared with the Hydra delegate): it loads the grids in the
probe executable `volphoton-vdbprobe` installed beside `_core`; a signal or a time-out there becomes
a clear error naming the file, and the render goes on without that volume. Verdicts are cached per
(real path, size, mtime, grids), so a frame range pays once per file.

HDVOLPHOTON_VDBPROBE names another probe executable (a test hook: the tests point it at scripts that
crash or hang). Without a probe the guard warns once and the files are read unguarded.
"""

from __future__ import annotations

from typing import Optional

from . import _core

#: Seconds the probe may take to read one file before the file is reported as unreadable.
TIMEOUT_SECONDS = 60.0


def crash_check_medium(desc: "_core.GridMediumDesc", timeout: Optional[float] = None) -> Optional[str]:
    """None when loading desc's grids (file_path, the four grid names, max_active_voxels) cannot crash
    the renderer, else why it would. None too for a missing file or one that fails cleanly: the real
    load reports those."""
    return _core.vdb_crash_check(desc, TIMEOUT_SECONDS if timeout is None else timeout)


def crash_check(path: str, grid: str, timeout: Optional[float] = None) -> Optional[str]:
    """None when reading `grid` from `path` cannot crash the renderer, else why it would."""
    desc = _core.GridMediumDesc()
    desc.file_path = path
    desc.density_grid = grid
    return crash_check_medium(desc, timeout)


def clear_cache() -> None:
    """Forgets every cached verdict (tests)."""
    _core.clear_vdb_crash_check_cache()
