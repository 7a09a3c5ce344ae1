// Multi-layer OpenEXR output (and read-back, for tests and tools) for the renderer's film.
//
// Channel names follow the OpenEXR layer convention "<layer>.<channel>"; the usd-core front end
// writes the beauty as R, G, B, A and the AOVs as single.R/G/B, multiple.R/G/B, emission.R/G/B,
// surface.R/G/B and depth.Z (32-bit float, +inf where the camera ray met no surface).
//
// | parameter   | type                      | meaning                                                   |
// |-------------|---------------------------|-----------------------------------------------------------|
// | path        | string                    | output file (written in place; callers rename atomically) |
// | width/height| int                       | image size; the data window is [0, w) x [0, h)            |
// | channels    | ExrChannel[]              | name + float32 plane (row-major, rows top to bottom)      |
// | attributes  | (name, string value)[]    | extra string header attributes (software, settings JSON)  |
// | compression | enum                      | ZIP (lossless, 16 scanlines per block) by default          |
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace volphoton {

struct ExrChannel {
    std::string name;
    const float* data = nullptr;  ///< width*height*stride floats
    int stride = 1;               ///< floats between horizontally adjacent samples (3 for packed RGB)
};

enum class ExrCompression { None, Zip, Piz };

/// Writes a scanline float32 OpenEXR file. Throws std::runtime_error naming the file on failure,
/// std::invalid_argument on an empty channel list, a null plane, a duplicate name or a bad size.
void writeExr(const std::string& path, int width, int height, const std::vector<ExrChannel>& channels,
              const std::vector<std::pair<std::string, std::string>>& attributes = {},
              ExrCompression compression = ExrCompression::Zip);

/// An EXR read back as float32 planes (any pixel type is converted), plus its string attributes.
struct ExrImage {
    int width = 0, height = 0;
    std::map<std::string, std::vector<float>> channels;  ///< name -> width*height floats
    std::map<std::string, std::string> attributes;       ///< string-valued header attributes
};

/// Reads every channel of a scanline or tiled OpenEXR file (the data window's contents).
/// Throws std::runtime_error naming the file.
ExrImage readExr(const std::string& path);

}  // namespace volphoton
