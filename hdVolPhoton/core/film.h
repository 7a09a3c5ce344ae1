// Float accumulation buffers for the beauty image and its AOVs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"

namespace volphoton {

/// Radiance of one camera sample split by light path (see integrator.h for the definitions).
/// beauty() is their sum by construction.
struct PathRadiance {
    Spectrum single, multiple, emission, surface;
    double alpha = 0;          ///< 1 when the first segment met a surface or a medium interaction
    double depth = Infinity;   ///< camera distance to the first surface (infinity if none)
    Spectrum beauty() const { return single + multiple + emission + surface; }
};

/// \class Film
/// Sums of samples per pixel and 32-bit sample counts; resolve() divides. Rows are top to bottom.
/// Each pixel is written by one thread at a time (tiles do not overlap).
class Film {
public:
    enum Aov { Beauty, Single, Multiple, Emission, Surface, RgbAovCount };
    Film(int width, int height);
    void add(int x, int y, const PathRadiance& r);
    /// Mean per pixel: RGB AOVs, alpha, depth (minimum over samples, +inf where nothing was hit).
    std::vector<float> resolveRgb(Aov aov) const;
    std::vector<float> resolveAlpha() const;
    std::vector<float> resolveDepth() const;
    uint32_t samples(int x, int y) const { return count_[index(x, y)]; }
    int width() const { return width_; }
    int height() const { return height_; }
    void clear();
    /// Adds every pixel of other (same size) into this film.
    void merge(const Film& other);

private:
    size_t index(int x, int y) const { return static_cast<size_t>(y) * width_ + x; }
    int width_, height_;
    std::vector<double> rgb_[RgbAovCount];
    std::vector<double> alpha_;
    std::vector<float> depth_;
    std::vector<uint32_t> count_;
};

}  // namespace volphoton
