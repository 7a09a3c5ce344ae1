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
    /// Denoiser guides (RenderSettings::guideAovs; Integrator::firstVertexGuides): the albedo and the
    /// camera-facing normal at the camera path's first vertex. Not part of beauty().
    Spectrum albedo, normal;
    double alpha = 0;          ///< 1 when the first segment met a surface or a medium interaction
    double depth = Infinity;   ///< camera distance to the first surface (infinity if none)
    /// The photon gathers' half-difference (PhotonEstimate::Along::multipleSplit) with the path's
    /// weights: its square estimates the photon map's variance of this sample (the Renderer's
    /// photon-noise measurement). Not on the film.
    Spectrum photonSplit;
    Spectrum beauty() const { return single + multiple + emission + surface; }
};

/// What a pixel's camera ray met first: the front end's opaque ids of the instance
/// (InstanceDesc::objectId, instanceId) and the element (MeshDesc::triangleElements). -1: nothing.
struct PixelIds {
    int object = -1, instance = -1, element = -1;
};

/// \class Film
/// Sums of samples per pixel, the sum of the squared beauty luminance (for the noise estimate) and
/// 32-bit sample counts; resolve() divides. Rows are top to bottom.
/// Each pixel is written by one thread at a time (tiles do not overlap). The id images hold one
/// PixelIds per pixel, written once per render from the pixel-centre ray (Renderer), not averaged.
class Film {
public:
    enum Aov { Beauty, Single, Multiple, Emission, Surface, Albedo, Normal, RgbAovCount };
    enum IdAov { ObjectId, InstanceId, ElementId };
    Film(int width, int height);
    void add(int x, int y, const PathRadiance& r);
    void setIds(int x, int y, const PixelIds& ids) { ids_[index(x, y)] = ids; }
    PixelIds ids(int x, int y) const { return ids_[index(x, y)]; }
    /// One id image, rows top to bottom; -1 where nothing was met.
    std::vector<int> resolveIds(IdAov which) const;
    /// Mean per pixel: RGB AOVs, alpha, depth (minimum over samples, +inf where nothing was hit).
    std::vector<float> resolveRgb(Aov aov) const;
    std::vector<float> resolveAlpha() const;
    std::vector<float> resolveDepth() const;
    uint32_t samples(int x, int y) const { return count_[index(x, y)]; }
    /// Estimated relative error of each pixel's beauty: the standard error of the mean luminance
    /// over the pixel's samples, sqrt((E[Y^2] - E[Y]^2) / (n - 1)), divided by max(mean, floor), the
    /// floor being ErrorFloor x the image's mean luminance (so that near-black pixels of a bright
    /// image do not demand relative precision no viewer can see). Rows top to bottom; pixels with
    /// fewer than 2 samples report +inf, pixels whose samples are all 0 report 0.
    std::vector<float> resolveRelativeError() const;
    static constexpr double ErrorFloor = 0.02;
    int width() const { return width_; }
    int height() const { return height_; }
    void clear();
    /// Adds every pixel of other (same size) into this film; ids come from other where this has none.
    void merge(const Film& other);

private:
    size_t index(int x, int y) const { return static_cast<size_t>(y) * width_ + x; }
    int width_, height_;
    std::vector<double> rgb_[RgbAovCount];
    std::vector<double> alpha_;
    std::vector<double> lumSq_;  ///< sum over samples of luminance(beauty)^2
    std::vector<float> depth_;
    std::vector<uint32_t> count_;
    std::vector<PixelIds> ids_;
};

}  // namespace volphoton
