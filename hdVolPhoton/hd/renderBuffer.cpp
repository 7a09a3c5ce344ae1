#include "hd/renderBuffer.h"

#include "pxr/base/gf/half.h"
#include "pxr/base/gf/vec3i.h"
#include "pxr/base/tf/diagnostic.h"

#include <cstring>

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonRenderBuffer::HdVolPhotonRenderBuffer(SdfPath const &id) : HdRenderBuffer(id) {}

HdVolPhotonRenderBuffer::~HdVolPhotonRenderBuffer() = default;

bool HdVolPhotonRenderBuffer::Allocate(GfVec3i const &dimensions, HdFormat format, bool) {
    _Deallocate();
    if (dimensions[2] != 1) {
        TF_WARN("%s: only 2D render buffers are supported", GetId().GetText());
        return false;
    }
    _width = dimensions[0];
    _height = dimensions[1];
    _format = format;
    _data.assign(static_cast<size_t>(_width) * _height * HdDataSizeOfFormat(format), 0);
    return true;
}

void HdVolPhotonRenderBuffer::_Deallocate() {
    _width = _height = 0;
    _format = HdFormatInvalid;
    _data.clear();
    _mappers.store(0);
    _converged.store(false);
}

void *HdVolPhotonRenderBuffer::Map() {
    ++_mappers;
    return _data.data();
}

void HdVolPhotonRenderBuffer::Unmap() { --_mappers; }

void HdVolPhotonRenderBuffer::Clear() { std::fill(_data.begin(), _data.end(), 0); }

void HdVolPhotonRenderBuffer::WriteFloats(std::vector<float> const &pixels, int channels, float alphaFill,
                                          std::vector<float> const *alpha) {
    size_t n = static_cast<size_t>(_width) * _height;
    if (pixels.size() != n * channels) return;
    HdFormat component = HdGetComponentFormat(_format);
    size_t count = HdGetComponentCount(_format);
    size_t pixelBytes = HdDataSizeOfFormat(_format);
    for (unsigned y = 0; y < _height; ++y)
        for (unsigned x = 0; x < _width; ++x) {
            size_t src = static_cast<size_t>(y) * _width + x;
            size_t dst = static_cast<size_t>(_height - 1 - y) * _width + x;
            uint8_t *out = _data.data() + dst * pixelBytes;
            for (size_t c = 0; c < count; ++c) {
                float v = c < static_cast<size_t>(channels) ? pixels[src * channels + c]
                                                            : (alpha ? (*alpha)[src] : alphaFill);
                if (component == HdFormatFloat32) std::memcpy(out + 4 * c, &v, 4);
                else if (component == HdFormatFloat16) {
                    GfHalf h(v);
                    std::memcpy(out + 2 * c, &h, 2);
                } else if (component == HdFormatUNorm8) {
                    out[c] = static_cast<uint8_t>(std::min(255.0f, std::max(0.0f, v * 255.0f + 0.5f)));
                } else if (component == HdFormatInt32) {
                    int32_t i = static_cast<int32_t>(v);
                    std::memcpy(out + 4 * c, &i, 4);
                }
            }
        }
}

void HdVolPhotonRenderBuffer::WriteInts(std::vector<int> const &pixels) {
    size_t n = static_cast<size_t>(_width) * _height;
    if (pixels.size() != n || HdGetComponentFormat(_format) != HdFormatInt32) return;
    for (unsigned y = 0; y < _height; ++y)
        std::memcpy(_data.data() + static_cast<size_t>(_height - 1 - y) * _width * 4, pixels.data() + static_cast<size_t>(y) * _width,
                    _width * 4);
}

PXR_NAMESPACE_CLOSE_SCOPE
