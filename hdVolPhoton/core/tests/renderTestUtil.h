// Rendering helpers shared by the integrator and scene tests: small deterministic settings and
// per-seed image statistics.
#pragma once

#include <functional>
#include <string>

#include "core/integrator.h"
#include "tests/testUtil.h"

namespace volphoton::test {

constexpr int RenderSeeds = 16;

/// A pinhole camera at eye looking at target (y up; x up when looking straight along y).
inline CameraDesc lookAt(const Vec3& eye, const Vec3& target, double tanHalfFov = 0.6) {
    Vec3 f = normalize(target - eye);  // camera looks down -Z
    Vec3 up = std::abs(f.y) > 0.99 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    Vec3 x = normalize(cross(f, up)), y = cross(x, f);
    CameraDesc c;
    for (int r = 0; r < 3; ++r) {
        c.cameraToWorld.m[r][0] = x[r];
        c.cameraToWorld.m[r][1] = y[r];
        c.cameraToWorld.m[r][2] = -f[r];
        c.cameraToWorld.m[r][3] = eye[r];
    }
    c.tanHalfFovX = tanHalfFov;
    return c;
}

/// The closed box [lo, hi] as 12 outward-wound triangles; vertex i is corner (x, y, z) = bits (1, 2, 4)
/// of i (lo where the bit is clear). The last two triangles are the +x face.
inline MeshDesc boxMesh(const std::string& name, const Vec3& lo, const Vec3& hi) {
    MeshDesc m;
    m.name = name;
    for (int i = 0; i < 8; ++i) m.points.push_back(Vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z));
    m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    return m;
}

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
