"""Reads a VDB file once in a separate process before the renderer loads it.

OpenVDB 10 trusts the sizes stored in a file's compressed voxel data, so a few corrupted files can
crash its reader or make it allocate for minutes (the core validates headers and grid descriptors
itself, but not every voxel buffer). A crash must not take the render down, so the front end first
loads each file in a child interpreter: a signal or a time-out there becomes a clear error naming the
file, and the render goes on without that volume. Results are cached per (path, size, mtime), so a
frame range pays once per file.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from typing import Dict, Optional, Tuple

#: Seconds a child may take to read one file before the file is reported as unreadable.
TIMEOUT_SECONDS = 60.0

_cache: Dict[Tuple[str, int, int], Optional[str]] = {}

_CHILD = (
    "import sys\n"
    "from volphoton import _core\n"
    "_core.set_diagnostic_sink(lambda severity, message: None)\n"
    "d = _core.GridMediumDesc()\n"
    "d.file_path = sys.argv[1]\n"
    "d.density_grid = sys.argv[2]\n"
    "try:\n"
    "    _core.load_grid_medium(d)\n"
    "except Exception:\n"
    "    pass  # ordinary load errors are reported by the real load, with their message\n"
)


def crash_check(path: str, grid: str) -> Optional[str]:
    """None when reading `grid` from `path` cannot crash the renderer, else why it would."""
    try:
        st = os.stat(path)
    except OSError:
        return None  # the real load reports a missing file
    key = (os.path.realpath(path), st.st_size, int(st.st_mtime_ns))
    if key in _cache:
        return _cache[key]
    try:
        r = subprocess.run([sys.executable, "-c", _CHILD, path, grid], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL, timeout=TIMEOUT_SECONDS)
        if r.returncode < 0:
            name = signal.Signals(-r.returncode).name if -r.returncode in signal.valid_signals() else str(-r.returncode)
            problem = "the OpenVDB reader crashed on this file (%s): its voxel data is corrupt" % name
        else:
            problem = None
    except subprocess.TimeoutExpired:
        problem = "reading the file took longer than %g s: its voxel data is corrupt or enormous" % TIMEOUT_SECONDS
    _cache[key] = problem
    return problem
