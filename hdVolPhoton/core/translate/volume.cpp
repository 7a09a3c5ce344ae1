#include "core/translate/volume.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <system_error>

#include "core/vdbGuard.h"

namespace volphoton::translate {

namespace {
// Two spellings of one file (a relative and an absolute path, a symlink) are the same file.
bool sameFile(const std::string& a, const std::string& b) {
    if (a == b) return true;
    std::error_code ec;
    bool same = std::filesystem::equivalent(a, b, ec);
    return !ec && same;
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}
}  // namespace

std::optional<GridMediumDesc> gridMediumFromFields(const std::string& volumePath, const MediumParams& params,
                                                   const Affine& objectToWorld,
                                                   const std::vector<GridFieldInput>& fields,
                                                   std::uint64_t maxActiveVoxels, Diagnostics& diag) {
    auto density = std::find_if(fields.begin(), fields.end(), [](const GridFieldInput& f) { return f.slot == "density"; });
    if (density == fields.end() || density->filePath.empty()) return std::nullopt;
    GridMediumDesc g = gridMediumDesc(params, objectToWorld, diag);
    g.filePath = density->filePath;
    g.densityGrid = density->fieldName.empty() ? "density" : density->fieldName;
    g.maxActiveVoxels = maxActiveVoxels;
    for (const GridFieldInput& f : fields) {
        // Index 0 is the first grid of the name, which is the one taken (UsdImaging reports 0 for an
        // unauthored fieldIndex, so 0 must not warn).
        if (f.fieldIndex > 0)
            diag.warn(f.primPath, "fieldIndex",
                      "fieldIndex " + std::to_string(f.fieldIndex) + " is ignored; the first grid named '" +
                          (f.fieldName.empty() ? f.slot : f.fieldName) + "' is used");
        std::string* target = f.slot == "temperature" ? &g.temperatureGrid
                              : f.slot == "emission"  ? &g.emissionGrid
                              : f.slot == "albedo"    ? &g.albedoGrid
                                                      : nullptr;
        if (!target || f.filePath.empty()) continue;
        if (!sameFile(f.filePath, density->filePath)) {
            diag.error(f.primPath, "filePath",
                       "field:" + f.slot + " of " + volumePath + " is in " + f.filePath + " but the density field is in " +
                           density->filePath + "; every field must come from the density's file; field ignored");
            continue;
        }
        *target = f.fieldName.empty() ? f.slot : f.fieldName;
    }
    return g;
}

MediumPtr loadGridMediumReported(const std::string& volumePath, const std::string& densityPrim,
                                 const GridMediumDesc& g, Diagnostics& diag) {
    const std::string prim = densityPrim.empty() ? volumePath : densityPrim;
    if (std::optional<std::string> problem = vdbCrashCheck(g)) {
        diag.error(prim, "filePath",
                   "field:density of " + volumePath + " (file " + g.filePath + "): " + *problem + "; volume skipped");
        return nullptr;
    }
    try {
        return loadGridMedium(g);
    } catch (const std::exception& e) {
        // A readable file whose grid is missing or unusable is the asset's fieldName's fault; a file
        // that cannot be opened or read is its filePath's.
        const std::string msg = lower(e.what());
        std::error_code ec;
        const bool readable = std::filesystem::is_regular_file(g.filePath, ec);
        const bool gridProblem = readable && msg.find("grid") != std::string::npos &&
                                 msg.find("cannot read") == std::string::npos &&
                                 msg.find("cannot open") == std::string::npos;
        diag.error(prim, gridProblem ? "fieldName" : "filePath",
                   "field:density of " + volumePath + " (file " + g.filePath + ", grid '" + g.densityGrid +
                       "'): " + e.what() + "; volume skipped");
        return nullptr;
    }
}

}  // namespace volphoton::translate
