// Reading float grids from OpenVDB (.vdb) files, with the file's structure checked first. OpenVDB
// reads lengths from a failed stream as uninitialised values, so a truncated or damaged file can make
// it allocate gigabytes or load garbage without complaint; the header, file metadata and grid
// descriptors are therefore walked here (the way openvdb::io::File::open walks them) with every
// length and offset checked against the file size before OpenVDB sees the file. Errors are
// std::runtime_error with a message naming the file and the grid.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <openvdb/version.h>  // light: only the version namespace macros (no OpenVDB types here)

namespace openvdb {
OPENVDB_USE_VERSION_NAMESPACE
namespace OPENVDB_VERSION_NAME {
class GridBase;
}
}  // namespace openvdb

namespace volphoton {

/// openvdb::initialize(), once per process (thread-safe). Everything here calls it first.
void initOpenVdb();

/// Throws std::runtime_error when `path` does not exist or is a directory.
void checkVdbPath(const std::string& path);

/// One grid to read from a file.
struct VdbGridRequest {
    std::string name;  ///< grid name in the file; "" = not wanted (its result is null)
    const char* role;  ///< what the grid is for ("density", ...), for messages
};

/// Opens `path`, checks its structure and reads the requested grids, each of which must be a
/// FloatGrid; the result has one entry per request, in order (null where the name is ""; requests
/// of the same name share one grid). Nothing is
/// loaded lazily: the grids never touch the file again. Throws std::runtime_error naming the file and
/// grid on a corrupt or truncated file, a name not in the file (the message lists the grids that are
/// there with their types), a grid that is not a FloatGrid (naming its type), or one with more than
/// `maxActiveVoxels` active voxels (0 = no cap; refused before its tree is read when the file records
/// its voxel count in OpenVDB's "file_voxel_count" metadata).
std::vector<std::shared_ptr<const openvdb::GridBase>> readVdbFloatGrids(const std::string& path,
                                                                        const std::vector<VdbGridRequest>& grids,
                                                                        std::uint64_t maxActiveVoxels);

}  // namespace volphoton
