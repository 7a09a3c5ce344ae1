// Rendering helpers shared by the integrator and scene tests: small deterministic settings and
// per-seed image statistics.
#pragma once

#include <functional>

#include "core/integrator.h"
#include "tests/testUtil.h"

namespace volphoton::test {

constexpr int RenderSeeds = 16;

/// 8x8 pixels, deep paths, a modest photon map: the settings every statistical image test starts from.
inline RenderSettings smallSettings(RenderSettings::Integrator integrator, int spp, uint64_t seed) {
    RenderSettings s;
    s.integrator = integrator;
    s.width = s.height = 8;
    s.samplesPerPixel = spp;
    s.seed = seed;
    s.maxDepth = 1000;
    s.photonsPerPass = 4000;
    s.initialRadius = 0.05;
    return s;
}

/// statistic(film) over RenderSeeds renders (seeds 0..15) of one scene: its mean and standard error.
inline MeanAndError imageMean(const SceneDesc& desc, RenderSettings s, const std::function<double(const Film&)>& statistic) {
    auto scene = std::make_shared<Scene>(desc);
    std::vector<double> xs;
    for (int seed = 0; seed < RenderSeeds; ++seed) {
        s.seed = seed;
        Renderer r(scene, s);
        r.render();
        xs.push_back(statistic(r.film()));
    }
    return meanAndError(xs);
}

/// Mean of an AOV over pixels and channels, or of one channel when channel >= 0.
inline double aovMean(const Film& f, Film::Aov aov, int channel = -1) {
    auto v = f.resolveRgb(aov);
    double s = 0;
    size_t n = 0;
    for (size_t i = 0; i < v.size(); ++i)
        if (channel < 0 || static_cast<int>(i % 3) == channel) {
            s += v[i];
            ++n;
        }
    return s / n;
}

}  // namespace volphoton::test
