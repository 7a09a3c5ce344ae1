// volphoton._core.vdb_crash_check: the core's VDB reader guard (core/vdbGuard.h) for volphoton.vdbguard.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "converters.h"
#include "core/vdbGuard.h"

namespace py = pybind11;

namespace volphoton::bindings {

void bindVdbGuard(py::module_& m) {
    m.def("vdb_crash_check", [](const GridMediumDesc& desc, double timeoutSeconds) {
        GridMediumDesc copy = desc;
        py::gil_scoped_release release;  // one probe process: up to timeout_seconds
        return vdbCrashCheck(copy, timeoutSeconds);
    }, py::arg("desc"), py::arg("timeout_seconds") = kVdbProbeTimeoutSeconds,
          "None when loading desc's grids (file_path, the four grid names, max_active_voxels) cannot crash "
          "or hang the renderer, else why it would. Runs volphoton-vdbprobe (HDVOLPHOTON_VDBPROBE overrides "
          "it) in a separate process, killed after timeout_seconds; cached per (real path, size, mtime, grids). "
          "None too for a missing file, one that fails cleanly, or when no probe can be run (warned once).");
    m.def("clear_vdb_crash_check_cache", &clearVdbCrashCheckCache, "Forgets every cached verdict (tests).");
    m.def("vdb_probe_path", &vdbProbePath,
          "The probe the next check runs: HDVOLPHOTON_VDBPROBE, else the one beside _core; '' when none is found.");
    m.attr("VDB_PROBE_TIMEOUT_SECONDS") = kVdbProbeTimeoutSeconds;
}

}  // namespace volphoton::bindings
