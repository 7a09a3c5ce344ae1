#include "core/vdbFile.h"

#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "core/diagnostics.h"

namespace volphoton {

void initOpenVdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

namespace {

/// Thrown by this file with a complete message; the reader rethrows it unchanged and wraps any other
/// exception (OpenVDB's, std::bad_alloc, stream failures) with the file and grid it was reading.
struct GridLoadError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Bounded little-endian reader over a file: every read is checked against the file size first.
class CheckedReader {
public:
    CheckedReader(const std::string& path, uint64_t size) : in_(path, std::ios::binary), size_(size) {}
    bool ok() const { return static_cast<bool>(in_); }
    uint64_t pos() const { return pos_; }
    uint64_t remaining() const { return size_ - pos_; }
    template <typename T>
    T read(const char* what) {
        T v{};
        need(sizeof(T), what);
        in_.read(reinterpret_cast<char*>(&v), sizeof(T));
        advance(sizeof(T), what);
        return v;
    }
    void skip(uint64_t n, const char* what) {
        need(n, what);
        in_.seekg(static_cast<std::streamoff>(pos_ + n));
        advance(n, what);
    }
    std::string readString(const char* what) {
        uint32_t n = read<uint32_t>(what);
        need(n, what);
        std::string s(n, '\0');
        if (n) in_.read(&s[0], n);
        advance(n, what);
        return s;
    }
    void seek(uint64_t p, const char* what) {
        if (p > size_) fail(std::string(what) + " points past the end of the file");
        in_.seekg(static_cast<std::streamoff>(p));
        pos_ = p;
        if (!in_) fail(std::string("cannot seek to ") + what);
    }
    [[noreturn]] static void fail(const std::string& why) { throw GridLoadError(why); }

private:
    void need(uint64_t n, const char* what) {
        if (n > remaining()) fail(std::string("the file ends inside the ") + what);
    }
    void advance(uint64_t n, const char* what) {
        if (!in_) fail(std::string("cannot read the ") + what);
        pos_ += n;
    }
    std::ifstream in_;
    uint64_t size_, pos_ = 0;
};

/// Walks the VDB header, file metadata and grid descriptors (the same way io::File::open does) with
/// every length and offset checked against the file size. OpenVDB itself reads lengths from a failed
/// stream as uninitialised values, so a truncated file can make it allocate gigabytes or load garbage
/// without complaint; this catches truncation and damaged headers before OpenVDB sees the file.
/// Throws GridLoadError with a description (the caller adds the path).
void checkVdbStructure(const std::string& path, uint64_t size) {
    CheckedReader r(path, size);
    if (!r.ok()) CheckedReader::fail("cannot open the file for reading");
    if (r.read<int64_t>("header") != openvdb::OPENVDB_MAGIC) CheckedReader::fail("not a VDB file (bad magic number)");
    uint32_t version = r.read<uint32_t>("header");
    if (version > openvdb::OPENVDB_FILE_VERSION)
        CheckedReader::fail("unsupported VDB file format version " + std::to_string(version) + " (this OpenVDB reads up to " +
                            std::to_string(openvdb::OPENVDB_FILE_VERSION) + ")");
    if (version < 211) {  // separate major, minor and patch numbers
        uint32_t minor = r.read<uint32_t>("header"), patch = r.read<uint32_t>("header");
        version = 100 * version + 10 * minor + patch;
    } else {
        r.skip(8, "header");  // library major and minor version
    }
    bool hasGridOffsets = true;
    if (version >= 212) hasGridOffsets = r.read<char>("header") != 0;
    if (version >= openvdb::OPENVDB_FILE_VERSION_SELECTIVE_COMPRESSION &&
        version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
        r.skip(1, "header");
    r.skip(version >= openvdb::OPENVDB_FILE_VERSION_BOOST_UUID ? 36 : 16, "header (UUID)");
    // A metadata map: count, then (name, type name, size-prefixed value) triples.
    auto skipMetaMap = [&r](const char* what) {
        uint32_t count = r.read<uint32_t>(what);
        if (count > r.remaining()) CheckedReader::fail(std::string("the ") + what + " count is implausible");
        for (uint32_t i = 0; i < count; ++i) {
            r.readString(what);
            r.readString(what);
            r.skip(r.read<uint32_t>(what), what);
        }
    };
    skipMetaMap("file metadata");
    if (!hasGridOffsets) return;  // very old files: nothing more can be checked without reading grids
    int32_t gridCount = r.read<int32_t>("grid count");
    if (gridCount < 0 || static_cast<uint64_t>(gridCount) > r.remaining())
        CheckedReader::fail("the grid count " + std::to_string(gridCount) + " is implausible");
    for (int32_t g = 0; g < gridCount; ++g) {
        std::string name = r.readString("grid descriptor");
        r.readString("grid descriptor");  // type
        if (version >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
            r.readString("grid descriptor");  // instance parent
        int64_t gridPos = r.read<int64_t>("grid descriptor");
        int64_t blockPos = r.read<int64_t>("grid descriptor");
        int64_t endPos = r.read<int64_t>("grid descriptor");
        const uint64_t here = r.pos();
        if (gridPos < 0 || blockPos < gridPos || endPos < blockPos || static_cast<uint64_t>(gridPos) < here)
            CheckedReader::fail("the descriptor of grid " + quote(name) + " has inconsistent offsets");
        if (static_cast<uint64_t>(endPos) > size)
            CheckedReader::fail("grid " + quote(name) + " ends at byte " + std::to_string(endPos) + " but the file has only " +
                                std::to_string(size) + " bytes (truncated?)");
        // The start of the grid itself: compression flags, grid metadata and the transform's type.
        r.seek(static_cast<uint64_t>(gridPos), "grid start");
        if (version >= openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) r.skip(4, "grid compression flags");
        skipMetaMap("grid metadata");
        if (r.pos() > static_cast<uint64_t>(endPos)) CheckedReader::fail("grid " + quote(name) + "'s metadata overruns the grid");
        if (version >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING) {
            std::string map = r.readString("grid transform");
            if (!openvdb::math::MapRegistry::isRegistered(map))
                CheckedReader::fail("grid " + quote(name) + " has an unknown transform type " + quote(map));
        }
        r.seek(static_cast<uint64_t>(endPos), "grid end");
    }
}

}  // namespace

void checkVdbPath(const std::string& path) {
    std::error_code ec;
    auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status))
        throw std::runtime_error("cannot open VDB file " + quote(path) + ": file does not exist");
    if (std::filesystem::is_directory(status))
        throw std::runtime_error("cannot open VDB file " + quote(path) + ": it is a directory");
}

std::vector<std::shared_ptr<const openvdb::GridBase>> readVdbFloatGrids(const std::string& path,
                                                                        const std::vector<VdbGridRequest>& requests,
                                                                        std::uint64_t maxActiveVoxels) {
    initOpenVdb();
    std::vector<std::shared_ptr<const openvdb::GridBase>> grids;
    std::string reading = "header";
    try {
        uint64_t size = std::filesystem::file_size(path);
        try {
            checkVdbStructure(path, size);
        } catch (const GridLoadError& e) {
            throw GridLoadError("cannot read VDB file " + quote(path) + ": the file is corrupt or truncated: " + e.what());
        }
        openvdb::io::File file(path);
        // No delayed loading: the caller owns all of its data and never touches the file again.
        file.open(/*delayLoad=*/false);
        auto readFloatGrid = [&](const std::string& name, const char* role) -> std::shared_ptr<const openvdb::GridBase> {
            if (name.empty()) return nullptr;
            reading = std::string(role) + " grid " + quote(name);
            if (!file.hasGrid(name)) {
                std::ostringstream msg;
                msg << "VDB file " << quote(path) << " has no grid named " << quote(name) << " (" << role
                    << "); grids in the file:";
                bool any = false;
                for (auto it = file.beginName(); it != file.endName(); ++it) {
                    msg << (any ? ", " : " ") << quote(*it);
                    try {
                        msg << " (" << file.readGridMetadata(*it)->type() << ")";
                    } catch (...) {
                    }
                    any = true;
                }
                if (!any) msg << " none";
                throw GridLoadError(msg.str());
            }
            auto overCap = [&](std::uint64_t voxels, const char* how) {
                return GridLoadError("grid " + quote(name) + " (" + role + ") in VDB file " + quote(path) + " has " +
                                     std::to_string(voxels) + " active voxels (" + how + "), more than the grid-size cap of " +
                                     std::to_string(maxActiveVoxels) +
                                     " (volphoton:maxGridVoxels on the RenderSettings prim, or --max-grid-voxels)");
            };
            if (maxActiveVoxels > 0) {
                openvdb::MetaMap::Ptr meta = file.readGridMetadata(name);
                if (auto count = meta ? meta->getMetadata<openvdb::Int64Metadata>("file_voxel_count") : nullptr;
                    count && count->value() > 0 && std::uint64_t(count->value()) > maxActiveVoxels)
                    throw overCap(std::uint64_t(count->value()), "recorded in the file");
            }
            openvdb::GridBase::Ptr g = file.readGrid(name);
            if (!g) throw GridLoadError("VDB file " + quote(path) + ": could not read " + reading);
            if (maxActiveVoxels > 0 && g->activeVoxelCount() > maxActiveVoxels)
                throw overCap(g->activeVoxelCount(), "counted after reading");
            if (!g->isType<openvdb::FloatGrid>())
                throw GridLoadError("grid " + quote(name) + " (" + role + ") in VDB file " + quote(path) +
                                    " has value type " + g->valueType() + " (grid type " + g->type() +
                                    "), but a float grid (FloatGrid) is required");
            return g;
        };
        for (size_t i = 0; i < requests.size(); ++i) {
            // A grid named twice (the density grid also as the emission: emission proportional to
            // density) is read once and shared: half the memory, and GridMedium looks it up once.
            size_t same = 0;
            while (same < i && (requests[same].name.empty() || requests[same].name != requests[i].name)) ++same;
            grids.push_back(same < i ? grids[same] : readFloatGrid(requests[i].name, requests[i].role));
        }
        file.close();
    } catch (const GridLoadError&) {
        throw;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read VDB file " + quote(path) + " (" + reading +
                                 "): the file is unreadable or corrupt: " + e.what());
    } catch (...) {
        throw std::runtime_error("cannot read VDB file " + quote(path) + " (" + reading +
                                 "): the file is unreadable or corrupt");
    }
    return grids;
}

}  // namespace volphoton
