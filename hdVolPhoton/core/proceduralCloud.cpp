#include "core/proceduralCloud.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/diagnostics.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/vdbFile.h"

namespace volphoton {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::FloatTree;

namespace {

/// Lattice value in [-1, 1] from one 64-bit mix of the seed and the integer coordinates.
inline double latticeValue(uint64_t seed, int64_t i, int64_t j, int64_t k) {
    uint64_t h = mix64(seed ^ (static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ULL) ^
                       (static_cast<uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL) ^ (static_cast<uint64_t>(k) * 0x165667B19E3779F9ULL));
    return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

inline double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }  // quintic, C2

/// Value noise with quintic interpolation (smooth, deterministic, only +, *, floor).
double valueNoise(uint64_t seed, double x, double y, double z) {
    double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    int64_t i = static_cast<int64_t>(fx), j = static_cast<int64_t>(fy), k = static_cast<int64_t>(fz);
    double u = fade(x - fx), v = fade(y - fy), w = fade(z - fz);
    double c[8];
    for (int n = 0; n < 8; ++n) c[n] = latticeValue(seed, i + (n >> 2), j + ((n >> 1) & 1), k + (n & 1));
    return trilinear(c, u, v, w);
}

/// Five octaves of value noise, normalised to about [-1, 1].
double fractalNoise(uint64_t seed, double x, double y, double z) {
    double sum = 0, amp = 1, norm = 0, f = 1;
    for (int o = 0; o < 5; ++o) {
        sum += amp * valueNoise(mix64(seed + static_cast<uint64_t>(o)), x * f, y * f, z * f);
        norm += amp;
        amp *= 0.5;
        f *= 2.03;
    }
    return sum / norm;
}

/// Distance from p to the nearest of one jittered feature point per unit cell (Worley's cellular
/// basis F1), over the 27 cells around p; about [0, 1].
double worley(uint64_t seed, double x, double y, double z) {
    double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    double best = 1e9;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                int64_t i = static_cast<int64_t>(fx) + dx, j = static_cast<int64_t>(fy) + dy, k = static_cast<int64_t>(fz) + dz;
                double px = i + 0.5 + 0.5 * latticeValue(seed, i, j, k), py = j + 0.5 + 0.5 * latticeValue(seed + 1, i, j, k),
                       pz = k + 0.5 + 0.5 * latticeValue(seed + 2, i, j, k);
                best = std::min(best, (px - x) * (px - x) + (py - y) * (py - y) + (pz - z) * (pz - z));
            }
    return std::sqrt(best);
}

/// Billows: inverted Worley noise at three octaves (weights 0.625, 0.25, 0.125), in [0, 1], high
/// inside puffs.
double billows(uint64_t seed, double x, double y, double z) {
    double sum = 0, f = 1;
    const double weight[3] = {0.625, 0.25, 0.125};
    for (int o = 0; o < 3; ++o, f *= 2.0)
        sum += weight[o] * std::clamp(1.0 - worley(mix64(seed + 101 * o), x * f, y * f, z * f), 0.0, 1.0);
    return sum;
}

inline double smoothstep(double a, double b, double x) {
    double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
    return t * t * (3 - 2 * t);
}

/// Cumulus density at u (the unit ball's coordinates, y up): a heap of puffs on a flat base whose
/// coverage is carved by billows and eroded at the edges by fBm (Schneider and Vos 2015's remap).
double cumulusDensity(uint64_t seed, double ux, double uy, double uz) {
    // The heap: a wide low puff, a tall central tower and two shoulders (union of ellipsoids).
    struct Puff { double x, y, z, rx, ry, rz; };
    static const Puff puffs[] = {{0.0, -0.30, 0.0, 0.85, 0.38, 0.62}, {0.05, 0.05, 0.0, 0.48, 0.55, 0.45},
                                 {-0.40, -0.12, 0.10, 0.38, 0.36, 0.36}, {0.42, -0.15, -0.08, 0.36, 0.32, 0.34}};
    double shape = 0;
    for (const Puff& p : puffs) {
        double dx = (ux - p.x) / p.rx, dy = (uy - p.y) / p.ry, dz = (uz - p.z) / p.rz;
        shape = std::max(shape, 1.0 - (dx * dx + dy * dy + dz * dz));
    }
    if (shape <= 0) return 0;
    shape *= smoothstep(-0.62, -0.50, uy);  // the flat base
    double b = billows(seed, 3.2 * ux + 5.0, 3.2 * uy + 9.0, 3.2 * uz + 13.0);
    // Remap (Schneider and Vos): coverage that the billows' gaps do not reach is cut away.
    double carved = (shape - (1.0 - b) * 0.55) / std::max(1e-6, 1.0 - (1.0 - b) * 0.55);
    if (carved <= 0) return 0;
    double wisps = 0.5 + 0.5 * fractalNoise(seed ^ 0x77697370ULL, 9.0 * ux, 9.0 * uy, 9.0 * uz);
    double eroded = carved - 0.25 * (1.0 - carved) * wisps;
    return std::clamp(eroded * 3.0, 0.0, 1.0);
}

}  // namespace

void writeProceduralCloudVdb(const std::string& path, int resolution, double voxelSize, uint64_t seed, CloudShape shape) {
    if (resolution < 1) throw std::invalid_argument("writeProceduralCloudVdb: resolution must be >= 1");
    if (!(voxelSize > 0) || !std::isfinite(voxelSize))
        throw std::invalid_argument("writeProceduralCloudVdb: voxelSize must be finite and > 0");
    initOpenVdb();
    const double centre = 0.5 * (resolution - 1);
    const double radius = 0.45 * resolution;
    const uint64_t noiseSeed = mix64(seed ^ 0x636c6f7564ULL);  // "cloud"
    const int D = static_cast<int>(FloatTree::LeafNodeType::DIM);
    const int blocks = (resolution + D - 1) / D;

    // Slabs of one leaf depth in z go to different trees (disjoint leaves), merged afterwards: the
    // result does not depend on the thread schedule.
    tbb::enumerable_thread_specific<FloatTree> trees(0.0f);
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks), [&](const tbb::blocked_range<int>& r) {
        FloatTree& tree = trees.local();
        openvdb::tree::ValueAccessor<FloatTree> acc(tree);
        for (int b = r.begin(); b != r.end(); ++b)
            for (int k = b * D; k < std::min(resolution, (b + 1) * D); ++k)
                for (int j = 0; j < resolution; ++j)
                    for (int i = 0; i < resolution; ++i) {
                        double ux = (i - centre) / radius, uy = (j - centre) / radius, uz = (k - centre) / radius;
                        double r2 = ux * ux + uy * uy + uz * uz;
                        if (r2 >= 1) continue;
                        double d;
                        if (shape == CloudShape::Cumulus) {
                            d = cumulusDensity(noiseSeed, ux, uy, uz);
                        } else {
                            double n = fractalNoise(noiseSeed, 2.5 * ux + 17.0, 2.5 * uy + 31.0, 2.5 * uz + 47.0);
                            d = (1.0 - r2) * (0.45 + 1.2 * n) * 1.4 - 0.08;
                        }
                        if (d <= 0) continue;
                        acc.setValue(Coord(i, j, k), static_cast<float>(std::min(d, 1.0)));
                    }
    });
    FloatGrid::Ptr grid = FloatGrid::create(0.0f);
    for (FloatTree& t : trees) grid->tree().merge(t, openvdb::MERGE_ACTIVE_STATES);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
    try {
        openvdb::io::File file(path);
        file.write({grid});
        file.close();
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write VDB file " + quote(path) + ": " + e.what());
    }
}

}  // namespace volphoton
