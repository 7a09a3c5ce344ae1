// hdVolPhoton: render buffers (AOV images).
#ifndef HDVOLPHOTON_RENDER_BUFFER_H
#define HDVOLPHOTON_RENDER_BUFFER_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/renderBuffer.h"

#include <atomic>
#include <vector>

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonRenderBuffer
///
/// CPU image of one AOV. The core accumulates samples in its own film (double sums, 32-bit sample
/// counts); after every pass the render thread writes the resolved means here with Write*(), under
/// the render thread's framebuffer lock. Map/Unmap only count readers; Resolve has nothing to do.
class HdVolPhotonRenderBuffer final : public HdRenderBuffer
{
public:
    HdVolPhotonRenderBuffer(SdfPath const &id);
    ~HdVolPhotonRenderBuffer() override;

    bool Allocate(GfVec3i const &dimensions, HdFormat format, bool multiSampled) override;
    unsigned int GetWidth() const override { return _width; }
    unsigned int GetHeight() const override { return _height; }
    unsigned int GetDepth() const override { return 1; }
    HdFormat GetFormat() const override { return _format; }
    bool IsMultiSampled() const override { return false; }
    void *Map() override;
    void Unmap() override;
    bool IsMapped() const override { return _mappers.load() != 0; }
    void Resolve() override {}
    bool IsConverged() const override { return _converged.load(); }
    void SetConverged(bool converged) { _converged.store(converged); }

    /// Writes `channels` floats per pixel (row 0 = top of the image) converting to the buffer's
    /// format; the buffer flips rows (Hydra's row 0 is the bottom).
    void WriteFloats(std::vector<float> const &pixels, int channels, float alphaFill = 1.0f,
                     std::vector<float> const *alpha = nullptr);
    void WriteInts(std::vector<int> const &pixels);
    void Clear();

protected:
    void _Deallocate() override;

private:
    unsigned int _width = 0, _height = 0;
    HdFormat _format = HdFormatInvalid;
    std::vector<uint8_t> _data;
    std::atomic<int> _mappers{0};
    std::atomic<bool> _converged{false};
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_RENDER_BUFFER_H
