// The guard against VDB files that crash or hang the OpenVDB reader, shared by every front end.
//
// OpenVDB 10 trusts the sizes stored in a file's compressed voxel data, so a few corrupt files can
// crash its reader or make it allocate for minutes (loadGridMedium validates headers and grid
// descriptors itself, but not every voxel buffer). A crash must not take the host (volphoton render,
// usdview, usdrecord) down, so before a front end calls loadGridMedium it asks vdbCrashCheck, which
// runs the same load in a separate probe process: a signal or a time-out there becomes a message the
// front end reports with the prim and file, and the render goes on without that volume.
//
// The probe is the executable `volphoton-vdbprobe` (hdVolPhoton/vdbprobe/vdbProbe.cpp), started with
// posix_spawn, never a fork() of the host: a fork of a multi-threaded process would inherit TBB's
// and OpenVDB's state and locks held by threads that do not exist in the child.
//
// | knob                          | type   | default                      | meaning                              |
// |-------------------------------|--------|------------------------------|--------------------------------------|
// | HDVOLPHOTON_VDBPROBE (env)    | path   | next to the module           | probe executable to run instead;     |
// |                               |        |                              | read on every check (a test hook)    |
// | timeoutSeconds                | double | kVdbProbeTimeoutSeconds = 60 | wall-clock seconds before the probe  |
// |                               |        |                              | is killed and the file reported      |
//
// "Next to the module": the folder of the shared object or executable that contains the core (found
// with dladdr): volphoton/ in the Python package (beside _core), <prefix>/plugin/usd/ for the Hydra
// plug-in (beside hdVolPhoton.so), build/ for the core's tests. When no probe can be started the
// check warns once (through the diagnostics sink) and answers "no problem": the file is then loaded
// without the guard, as before the guard existed; the host is never stopped for a missing probe.
//
// Verdicts are cached per (real path, size, modification time, grids, voxel cap), so a frame range
// or a Hydra rebuild pays once per file; a rewritten file is probed again. The cache is thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "core/gridMedium.h"

namespace volphoton {

/// Default wall-clock limit for one probe (a sound file of a few GiB reads in well under this).
constexpr double kVdbProbeTimeoutSeconds = 60.0;

/// Why loading desc's grids from desc.filePath would crash or hang the reader, or nullopt when it
/// would not. Only filePath, the four grid names and maxActiveVoxels are used: the probe loads
/// exactly those, with the same voxel cap, as loadGridMedium(desc) will.
///
/// nullopt also for a missing file and for a file the loader refuses with an exception (a truncated
/// file, a missing grid, a grid over the voxel cap): the real load reports those with its own
/// message. Messages look like "the OpenVDB reader crashed on this file (SIGSEGV): its voxel data is
/// corrupt" or "reading the file took longer than 60 s: its voxel data is corrupt or enormous"; they
/// do not repeat the path (the caller names the prim and the file).
///
/// | parameter      | type          | default | units   | meaning                                    |
/// |----------------|---------------|---------|---------|--------------------------------------------|
/// | desc           | GridMediumDesc|         |         | file, grid names and voxel cap to probe    |
/// | timeoutSeconds | double        | 60      | seconds | probe wall-clock limit (> 0)               |
///
/// Blocks the calling thread for the probe's duration (one load of the file). Thread-safe.
std::optional<std::string> vdbCrashCheck(const GridMediumDesc& desc,
                                         double timeoutSeconds = kVdbProbeTimeoutSeconds);

/// vdbCrashCheck for one density grid with the default voxel cap.
std::optional<std::string> vdbCrashCheck(const std::string& path, const std::string& densityGrid,
                                         double timeoutSeconds = kVdbProbeTimeoutSeconds);

/// Forgets every cached verdict (tests; a front end never needs it: a changed file has a new key).
void clearVdbCrashCheckCache();

/// The probe executable the next check will run: HDVOLPHOTON_VDBPROBE when set and non-empty, else
/// volphoton-vdbprobe next to the module that contains the core; "" when neither can be found.
std::string vdbProbePath();

}  // namespace volphoton
