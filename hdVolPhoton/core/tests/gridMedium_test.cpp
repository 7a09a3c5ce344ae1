// OpenVDB grid media and the majorant grid: trilinear lookups against an analytic linear field,
// the majorant bounding the density along random rays, empty-space skipping, load errors,
// sanitising of invalid voxels and the procedural cloud writer.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <thread>
#include <stdexcept>
#include <vector>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "core/blackbody.h"
#include "core/diagnostics.h"
#include "core/freeFlight.h"
#include "core/gridMedium.h"
#include "core/majorantGrid.h"
#include "core/proceduralCloud.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "core/vdbFile.h"

using namespace volphoton;
using openvdb::Coord;
using openvdb::FloatGrid;

namespace {

std::string tempPath(const std::string& name) {
    std::string dir = ::testing::TempDir();
    if (!dir.empty() && dir.back() != '/') dir += '/';
    return dir + "volphoton_grid_" + name;
}

/// Captures diagnostics while alive; restores the default (stderr) sink afterwards.
struct CaptureDiagnostics {
    std::mutex mutex;
    std::vector<std::string> messages;
    CaptureDiagnostics() {
        setDiagnosticSink([this](Severity, const std::string& m) {
            std::lock_guard<std::mutex> lock(mutex);
            messages.push_back(m);
        });
    }
    ~CaptureDiagnostics() { setDiagnosticSink(DiagnosticSink{}); }
};

/// Rotation by `angle` about the unit axis `a`, times a scale, plus a translation.
Affine rotationScaleTranslate(const Vec3& axis, double angle, double scale, const Vec3& t) {
    Vec3 a = normalize(axis);
    double c = std::cos(angle), s = std::sin(angle), C = 1 - c;
    double R[3][3] = {{c + a.x * a.x * C, a.x * a.y * C - a.z * s, a.x * a.z * C + a.y * s},
                      {a.y * a.x * C + a.z * s, c + a.y * a.y * C, a.y * a.z * C - a.x * s},
                      {a.z * a.x * C - a.y * s, a.z * a.y * C + a.x * s, c + a.z * a.z * C}};
    Affine m;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m.m[i][j] = R[i][j] * scale;
        m.m[i][3] = t[i];
    }
    return m;
}

void writeGrids(const std::string& path, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    openvdb::io::File file(path);
    file.write(grids);
    file.close();
}

/// Expects `f` to throw std::runtime_error whose message contains every string in `needles`.
template <typename F>
void expectRuntimeError(F&& f, const std::vector<std::string>& needles) {
    try {
        f();
        ADD_FAILURE() << "no exception thrown";
    } catch (const std::runtime_error& e) {
        std::string what = e.what();
        for (const auto& n : needles) EXPECT_NE(what.find(n), std::string::npos) << "'" << n << "' not in: " << what;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "wrong exception type: " << e.what();
    }
}

struct Segment {
    double t0, t1, sigmaMaj;
};
std::vector<Segment> collectSegments(const Medium& m, const Ray& r, double tMin, double tMax) {
    std::vector<Segment> segs;
    m.majorants(r, tMin, tMax, [&](const MajorantSegment& s) {
        segs.push_back({s.tMin, s.tMax, s.sigmaMaj});
        EXPECT_EQ(s.decay, 0.0);
        return true;
    });
    return segs;
}

/// A sparse, spiky grid: random isolated voxels, a dense block, an active tile (an 8^3 region held
/// as one value) and a few high single voxels, so that the majorant's dilation is exercised.
FloatGrid::Ptr spikyGrid(uint64_t seed) {
    FloatGrid::Ptr g = FloatGrid::create(0.0f);
    auto acc = g->getAccessor();
    Rng rng(seed);
    for (int n = 0; n < 400; ++n) {
        Coord c(int(rng.uniform() * 60), int(rng.uniform() * 50), int(rng.uniform() * 40));
        acc.setValue(c, float(rng.uniform() * 5.0));
    }
    for (int i = 20; i < 30; ++i)
        for (int j = 10; j < 17; ++j)
            for (int k = 5; k < 12; ++k) acc.setValue(Coord(i, j, k), float(1.0 + 0.1 * ((i + j + k) % 7)));
    g->tree().fill(openvdb::CoordBBox(Coord(40, 32, 16), Coord(47, 39, 23)), 7.5f, /*active=*/true);
    acc.setValue(Coord(8, 40, 30), 20.0f);
    acc.setValue(Coord(55, 3, 2), 12.0f);
    return g;
}

}  // namespace

// ---- MajorantGrid ------------------------------------------------------------------------------

TEST(GridMajorantWalk, MatchesBruteForceCellLookupAndMergesRuns) {
    MajorantGrid g(Bounds3{{-2, 1, 0.5}, {10, 7, 4.5}}, 6, 3, 4);
    Rng rng(3);
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 6; ++x) {
                double u = rng.uniform();
                g.raise(x, y, z, u < 0.4 ? 0.0f : float(int(u * 4)));  // few distinct values: many merges
            }
    for (int n = 0; n < 300; ++n) {
        Vec3 o(-6 + 20 * rng.uniform(), -3 + 14 * rng.uniform(), -3 + 11 * rng.uniform());
        Vec3 d(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
        if (n % 7 == 0) d.y = 0;  // axis-parallel components
        d = d * (0.1 + 5 * rng.uniform());  // not unit length
        double tMin = -1 + rng.uniform(), tMax = 2 + 10 * rng.uniform();
        std::vector<Segment> segs;
        g.walk(o, d, tMin, tMax, [&](double t0, double t1, double v) {
            segs.push_back({t0, t1, v});
            return true;
        });
        for (size_t i = 0; i < segs.size(); ++i) {
            EXPECT_LT(segs[i].t0, segs[i].t1);
            EXPECT_GE(segs[i].t0, tMin);
            EXPECT_LE(segs[i].t1, tMax);
            EXPECT_GT(segs[i].sigmaMaj, 0.0);
            if (i > 0) {
                EXPECT_GE(segs[i].t0, segs[i - 1].t1);
                // Touching runs must differ in value (equal neighbours are merged).
                if (segs[i].t0 == segs[i - 1].t1) {
                    EXPECT_NE(segs[i].sigmaMaj, segs[i - 1].sigmaMaj);
                }
            }
        }
        // Brute force: the cell under each point must carry the reported value (0 = in no run).
        for (int k = 0; k < 400; ++k) {
            double t = tMin + (tMax - tMin) * (k + 0.5) / 400;
            Vec3 p = o + d * t;
            double expected = 0;
            if (g.box().contains(p)) {
                int c[3];
                for (int a = 0; a < 3; ++a)
                    c[a] = std::clamp(int(std::floor((p[a] - g.box().lo[a]) / (g.box().hi[a] - g.box().lo[a]) *
                                                     g.resolution(a))),
                                      0, g.resolution(a) - 1);
                // Skip points within rounding of a cell face, where either cell is right.
                bool nearFace = false;
                for (int a = 0; a < 3; ++a) {
                    double f = (p[a] - g.box().lo[a]) / (g.box().hi[a] - g.box().lo[a]) * g.resolution(a);
                    nearFace |= std::abs(f - std::round(f)) < 1e-9;
                }
                if (nearFace) continue;
                expected = g.at(c[0], c[1], c[2]);
            }
            double got = 0;
            for (const auto& s : segs)
                if (t >= s.t0 && t < s.t1) got = s.sigmaMaj;
            EXPECT_EQ(got, expected) << "ray " << n << " t=" << t;
        }
    }
}

TEST(GridMajorantWalk, StopsWhenCallbackReturnsFalse) {
    MajorantGrid g(Bounds3{{0, 0, 0}, {4, 1, 1}}, 4, 1, 1);
    for (int x = 0; x < 4; ++x) g.raise(x, 0, 0, float(x + 1));
    int calls = 0;
    g.walk(Vec3(-1, 0.5, 0.5), Vec3(1, 0, 0), 0, 100, [&](double, double, double) { return ++calls < 2; });
    EXPECT_EQ(calls, 2);
    std::vector<Segment> segs;
    g.walk(Vec3(-1, 0.5, 0.5), Vec3(2, 0, 0), 0, 100, [&](double t0, double t1, double v) {
        segs.push_back({t0, t1, v});
        return true;
    });
    ASSERT_EQ(segs.size(), 4u);
    for (int x = 0; x < 4; ++x) {  // t = (X + 1) / 2 because |d| = 2
        EXPECT_NEAR(segs[x].t0, (x + 1) / 2.0, 1e-12);
        EXPECT_NEAR(segs[x].t1, (x + 2) / 2.0, 1e-12);
        EXPECT_EQ(segs[x].sigmaMaj, x + 1.0);
    }
}

// ---- trilinear lookup ----------------------------------------------------------------------------

TEST(GridLookup, TrilinearReproducesLinearFieldUnderTransforms) {
    // f(i, j, k) is linear in the index coordinates, so trilinear interpolation reproduces it
    // exactly (up to float storage) everywhere inside the filled block.
    auto f = [](double i, double j, double k) { return 10.0 + 0.5 * i - 0.25 * j + 0.75 * k; };
    FloatGrid::Ptr grid = FloatGrid::create(0.0f);
    auto acc = grid->getAccessor();
    const int N = 20;
    for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j)
            for (int k = 0; k < N; ++k) acc.setValue(Coord(i, j, k), float(f(i, j, k)));
    // The grid's own transform: non-uniform voxel size, a rotation and a translation.
    openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
    m.preScale(openvdb::Vec3d(0.37, 0.5, 0.29));
    m.postRotate(openvdb::math::Z_AXIS, 0.3);
    m.postRotate(openvdb::math::X_AXIS, -0.7);
    m.postTranslate(openvdb::Vec3d(0.4, -1.2, 2.0));
    grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
    grid->setName("density");

    GridMediumDesc desc;
    desc.densityScale = 0.8;
    desc.extinctionColor = Spectrum(1.0, 0.5, 2.0);
    desc.albedo = Spectrum(0.9, 0.5, 0.1);
    desc.objectToWorld = rotationScaleTranslate(Vec3(1, 2, 3), 1.1, 2.5, Vec3(3, -4, 5));
    GridMedium medium(desc, GridMediumGrids{grid});

    Rng rng(7);
    for (int n = 0; n < 2000; ++n) {
        openvdb::Vec3d idx(rng.uniform() * (N - 1), rng.uniform() * (N - 1), rng.uniform() * (N - 1));
        openvdb::Vec3d obj = grid->transform().indexToWorld(idx);  // OpenVDB's own map, independently
        Vec3 p = desc.objectToWorld.point(Vec3(obj.x(), obj.y(), obj.z()));
        double expected = f(idx.x(), idx.y(), idx.z());
        EXPECT_NEAR(medium.density(p), expected, 1e-9 * expected);
        MediumProperties mp = medium.properties(p);
        for (int c = 0; c < 3; ++c) {
            double st = 0.8 * expected * desc.extinctionColor[c];
            EXPECT_NEAR(mp.sigma_t()[c], st, 1e-9 * st);
            EXPECT_NEAR(mp.sigma_s[c], st * desc.albedo[c], 1e-9 * st);
        }
        ASSERT_EQ(mp.lobeCount, 1);
    }
    // Outside the support (active bbox dilated by one voxel) everything is zero.
    openvdb::Vec3d outside = grid->transform().indexToWorld(openvdb::Vec3d(-1.5, 5, 5));
    Vec3 po = desc.objectToWorld.point(Vec3(outside.x(), outside.y(), outside.z()));
    EXPECT_EQ(medium.properties(po).sigma_t().maxValue(), 0.0);
    EXPECT_FALSE(medium.indexBounds().contains(medium.worldToIndex().point(po)));
    EXPECT_NEAR(medium.worldToIndex().point(po).x, -1.5, 1e-9);
    // Half a voxel outside the filled block, trilinear mixes with the zero background.
    openvdb::Vec3d half = grid->transform().indexToWorld(openvdb::Vec3d(-0.5, 5, 5));
    Vec3 ph = desc.objectToWorld.point(Vec3(half.x(), half.y(), half.z()));
    EXPECT_NEAR(medium.density(ph), 0.5 * f(0, 5, 5), 1e-5);
    EXPECT_TRUE(medium.bounds().contains(ph));
    EXPECT_EQ(medium.activeVoxelCount(), size_t(N * N * N));
    Bounds3 ib = medium.indexBounds();
    EXPECT_EQ(ib.lo.x, -1.0);
    EXPECT_EQ(ib.hi.z, double(N));
}

// ---- majorants -----------------------------------------------------------------------------------

namespace {

void checkMajorantsBoundDensity(const GridMedium& medium, uint64_t seed, int rays) {
    Bounds3 b = medium.bounds();
    ASSERT_FALSE(b.empty());
    Vec3 centre = (b.lo + b.hi) * 0.5;
    double radius = length(b.hi - b.lo);
    Rng rng(seed);
    size_t segmentsSeen = 0, pointsWithDensity = 0;
    for (int n = 0; n < rays; ++n) {
        // Half the rays start far outside and aim at a random point in the box, half start inside.
        Vec3 target(b.lo.x + (b.hi.x - b.lo.x) * rng.uniform(), b.lo.y + (b.hi.y - b.lo.y) * rng.uniform(),
                    b.lo.z + (b.hi.z - b.lo.z) * rng.uniform());
        Vec3 o = n % 2 ? centre + sphericalDirection(Vec3(0, 0, 1), 2 * rng.uniform() - 1, 2 * Pi * rng.uniform()) * radius
                       : target;
        Vec3 d = n % 2 ? normalize(target - o) : sphericalDirection(Vec3(0, 0, 1), 2 * rng.uniform() - 1, 2 * Pi * rng.uniform());
        Ray r{o, d};
        double tMin = n % 3 == 0 ? 0.1 * radius * rng.uniform() : 0.0, tMax = n % 5 == 0 ? radius * rng.uniform() : Infinity;
        std::vector<Segment> segs = collectSegments(medium, r, tMin, tMax);
        segmentsSeen += segs.size();
        for (size_t i = 0; i < segs.size(); ++i) {
            ASSERT_LT(segs[i].t0, segs[i].t1);
            ASSERT_GE(segs[i].t0, tMin);
            ASSERT_LE(segs[i].t1, tMax);
            if (i) {
                ASSERT_GE(segs[i].t0, segs[i - 1].t1);
            }
            for (int k = 0; k < 64; ++k) {
                double t = segs[i].t0 + (segs[i].t1 - segs[i].t0) * rng.uniform();
                double st = medium.properties(r.at(t)).sigma_t().maxValue();
                ASSERT_LE(st, segs[i].sigmaMaj * (1 + 1e-12) + 1e-12) << "ray " << n << " t=" << t;
            }
        }
        // Coverage: every point with density lies inside a segment.
        double t0, t1;
        if (!b.intersect(r, tMin, std::min(tMax, 1e30), &t0, &t1)) continue;
        for (int k = 0; k < 2000; ++k) {
            double t = t0 + (t1 - t0) * (k + 0.5) / 2000;
            if (medium.properties(r.at(t)).sigma_t().maxValue() <= 0) continue;
            ++pointsWithDensity;
            bool covered = false;
            for (const auto& s : segs) covered |= t >= s.t0 && t <= s.t1;
            ASSERT_TRUE(covered) << "ray " << n << " t=" << t << " has density but no majorant segment";
        }
    }
    EXPECT_GT(segmentsSeen, size_t(rays / 4));
    EXPECT_GT(pointsWithDensity, size_t(rays));
}

}  // namespace

TEST(GridMajorant, BoundsDensityOnProceduralCloud) {
    std::string path = tempPath("cloud48.vdb");
    writeProceduralCloudVdb(path, 48, 0.05, 11);
    GridMediumDesc desc;
    desc.filePath = path;
    desc.densityScale = 30.0;
    desc.extinctionColor = Spectrum(0.5, 1.0, 1.5);
    desc.objectToWorld = rotationScaleTranslate(Vec3(-1, 0.5, 2), 0.8, 1.7, Vec3(-2, 1, 0.5));
    auto medium = loadGridMedium(desc);
    checkMajorantsBoundDensity(*medium, 21, 300);
    std::remove(path.c_str());
}

TEST(GridMajorant, BoundsDensityOnSpikySparseGridWithTiles) {
    FloatGrid::Ptr grid = spikyGrid(5);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.13));
    GridMediumDesc desc;
    desc.densityScale = 2.0;
    desc.objectToWorld = rotationScaleTranslate(Vec3(0.3, 1, -0.2), 2.0, 0.7, Vec3(1, 2, 3));
    GridMedium medium(desc, GridMediumGrids{grid});
    // The 20.0 voxel and the 7.5 tile are in the data: the maximum must see both.
    EXPECT_EQ(medium.maxDensity(), 20.0);
    checkMajorantsBoundDensity(medium, 22, 400);
}

TEST(GridMajorant, EmptySpaceIsSkipped) {
    // Two 6^3 blobs of density 1 at opposite ends of a 256-voxel-long grid.
    FloatGrid::Ptr grid = FloatGrid::create(0.0f);
    auto acc = grid->getAccessor();
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            for (int k = 0; k < 6; ++k) {
                acc.setValue(Coord(i, j, k), 1.0f);
                acc.setValue(Coord(250 + i, j, k), 1.0f);
            }
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.1));
    GridMediumDesc desc;
    desc.densityScale = 4.0;
    GridMedium medium(desc, GridMediumGrids{grid});
    // Along x through both blobs: one merged run per blob.
    Ray r{Vec3(-1.0, 0.25, 0.25), Vec3(1, 0, 0)};
    std::vector<Segment> segs = collectSegments(medium, r, 0, Infinity);
    ASSERT_EQ(segs.size(), 2u);
    for (const auto& s : segs) EXPECT_NEAR(s.sigmaMaj, 4.0, 1e-6);
    // World x of voxel i is 0.1 i; t = x + 1. The empty middle, x in [3, 22], is in no segment.
    EXPECT_LT(segs[0].t1, 1.0 + 3.0);
    EXPECT_GT(segs[1].t0, 1.0 + 22.0);
    // The first covers the first blob, the second the second.
    EXPECT_LE(segs[0].t0, 1.0 + 0.0);
    EXPECT_GE(segs[1].t1, 1.0 + 25.5);
    // A ray across the empty middle reports nothing at all.
    Ray middle{Vec3(12.0, -5.0, 0.25), Vec3(0, 1, 0)};
    EXPECT_TRUE(collectSegments(medium, middle, 0, Infinity).empty());
    // So does a ray along x restricted to the middle.
    EXPECT_TRUE(collectSegments(medium, r, 1.0 + 4.0, 1.0 + 20.0).empty());
    // Most of the majorant grid is empty.
    const MajorantGrid& mg = medium.majorantGrid();
    size_t nonZero = 0;
    for (int z = 0; z < mg.resolution(2); ++z)
        for (int y = 0; y < mg.resolution(1); ++y)
            for (int x = 0; x < mg.resolution(0); ++x) nonZero += mg.at(x, y, z) > 0;
    EXPECT_LT(nonZero, mg.cellCount() / 4);
}

TEST(GridMajorant, NonZeroBackgroundIsBoundedInsideSupport) {
    FloatGrid::Ptr grid = FloatGrid::create(0.25f);
    auto acc = grid->getAccessor();
    acc.setValue(Coord(0, 0, 0), 1.0f);
    acc.setValue(Coord(40, 30, 20), 0.5f);
    CaptureDiagnostics capture;
    GridMedium medium(GridMediumDesc{}, GridMediumGrids{grid});
    ASSERT_EQ(capture.messages.size(), 1u);
    EXPECT_NE(capture.messages[0].find("background"), std::string::npos);
    // Inside the support, between the voxels, the density is the background.
    EXPECT_NEAR(medium.density(Vec3(20, 15, 10)), 0.25, 1e-7);
    std::vector<Segment> segs = collectSegments(medium, Ray{Vec3(20, 15, -5), Vec3(0, 0, 1)}, 0, Infinity);
    ASSERT_FALSE(segs.empty());
    for (const auto& s : segs) EXPECT_GE(s.sigmaMaj, 0.25);
    checkMajorantsBoundDensity(medium, 23, 100);
}

TEST(GridMajorant, EnormousDensitiesAreClampedAndCheapToCross) {
    // A 16^3 block of density 1e30 (voxel 1/32): one voxel's optical depth would be 3e28. The density
    // is clamped to an optical depth of 1e4 per voxel (opaque either way) with a warning, and a free
    // flight into the block costs about sqrt(2 x 1e4) ~ 140 tentative collisions in the trilinear ramp
    // at its face. (Before: no clamp, and majorant cells one layer beyond the block at full value, so
    // flights ran into the 2^20 truncation; stress cases 250/251 and the 3e38 VDB took hours.)
    FloatGrid::Ptr grid = FloatGrid::create(0.0f);
    auto acc = grid->getAccessor();
    for (int i = 0; i < 16; ++i)
        for (int j = 0; j < 16; ++j)
            for (int k = 0; k < 16; ++k) acc.setValue(Coord(i, j, k), 1e30f);
    // Thin haze voxels at two far corners: the block sits inside the support with empty space around.
    acc.setValue(Coord(-24, -24, -24), 1e-3f);
    acc.setValue(Coord(40, 40, 40), 1e-3f);
    const double voxel = 1.0 / 32;
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    CaptureDiagnostics capture;
    GridMedium medium(GridMediumDesc{}, GridMediumGrids{grid});
    ASSERT_EQ(capture.messages.size(), 1u);
    EXPECT_NE(capture.messages[0].find("clamped to 10000 per voxel"), std::string::npos) << capture.messages[0];
    const double cap = 1e4 / voxel;
    EXPECT_NEAR(medium.properties(Vec3(0.25, 0.25, 0.25)).sigma_t().maxValue(), cap, 1e-6 * cap);
    Rng rng(7);
    int64_t total = 0;
    const int rays = 2000;
    for (int n = 0; n < rays; ++n) {
        // From outside, towards a random point of the block, from a random direction.
        Vec3 target = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (15 * voxel);
        Vec3 d = uniformSphere(rng.uniform(), rng.uniform());
        Ray r{target - d * 2.0, d};
        int64_t events = 0;
        FlightEnd end = sampleFreeFlight(medium, r, 4.0, rng, [&](const MediumEvent& e) {
            ++events;
            EXPECT_LE(e.mp.sigma_t().maxValue(), e.sigmaMaj * (1 + 1e-9));
            return rng.uniform() >= e.mp.sigma_t().maxValue() / e.sigmaMaj;  // null: go on
        });
        EXPECT_NE(end, FlightEnd::Truncated);
        total += events;
    }
    EXPECT_LT(double(total) / rays, 1000.0) << "mean tentative collisions per flight";
}

// ---- loading errors ----------------------------------------------------------------------------

TEST(GridLoad, MissingFileThrows) {
    GridMediumDesc desc;
    desc.filePath = tempPath("does_not_exist.vdb");
    expectRuntimeError([&] { loadGridMedium(desc); }, {desc.filePath, "does not exist"});
    desc.filePath = "";
    expectRuntimeError([&] { loadGridMedium(desc); }, {"no VDB file"});
}

TEST(GridLoad, CorruptAndTruncatedFilesThrow) {
    std::string garbage = tempPath("garbage.vdb");
    {
        std::ofstream out(garbage, std::ios::binary);
        Rng rng(1);
        for (int i = 0; i < 5000; ++i) out.put(char(rng.nextU32() & 0xff));
    }
    GridMediumDesc desc;
    desc.filePath = garbage;
    expectRuntimeError([&] { loadGridMedium(desc); }, {garbage});
    std::ofstream(tempPath("empty.vdb"), std::ios::binary).close();
    desc.filePath = tempPath("empty.vdb");
    expectRuntimeError([&] { loadGridMedium(desc); }, {desc.filePath});

    // Truncate a real file at many lengths (header, metadata, descriptors, compressed data).
    std::string good = tempPath("good.vdb");
    writeProceduralCloudVdb(good, 24, 0.1, 3);
    std::ifstream in(good, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 1000u);
    std::string cut = tempPath("truncated.vdb");
    std::vector<size_t> lengths = {1, 8, 16, 40, 100, 200, 300, 400, 600, 1000, bytes.size() / 2, bytes.size() - 100,
                                   bytes.size() - 1};
    for (size_t len : lengths) {
        {
            std::ofstream out(cut, std::ios::binary | std::ios::trunc);
            out.write(bytes.data(), std::streamsize(len));
        }
        desc.filePath = cut;
        SCOPED_TRACE("truncated to " + std::to_string(len) + " of " + std::to_string(bytes.size()) + " bytes");
        expectRuntimeError([&] { loadGridMedium(desc); }, {cut});
    }
    // Garbage written over the compressed voxel data.
    std::vector<char> smashed = bytes;
    for (size_t i = smashed.size() / 2; i < smashed.size() / 2 + 64; ++i) smashed[i] = char(0xA5);
    {
        std::ofstream out(cut, std::ios::binary | std::ios::trunc);
        out.write(smashed.data(), std::streamsize(smashed.size()));
    }
    try {  // may or may not be detected (it depends on what the bytes hit), but must not crash
        loadGridMedium(desc);
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(cut), std::string::npos);
    }
    for (const auto& p : {garbage, tempPath("empty.vdb"), good, cut}) std::remove(p.c_str());
}

TEST(GridLoad, WrongGridNameListsAvailableGrids) {
    std::string path = tempPath("names.vdb");
    FloatGrid::Ptr a = FloatGrid::create(0.0f);
    a->setName("smoke");
    a->tree().setValue(Coord(1, 2, 3), 1.0f);
    FloatGrid::Ptr b = FloatGrid::create(0.0f);
    b->setName("heat");
    b->tree().setValue(Coord(1, 2, 3), 900.0f);
    writeGrids(path, {a, b});
    GridMediumDesc desc;
    desc.filePath = path;
    expectRuntimeError([&] { loadGridMedium(desc); }, {path, "'density'", "'smoke'", "'heat'"});
    desc.densityGrid = "smoke";
    desc.temperatureGrid = "temperature";
    expectRuntimeError([&] { loadGridMedium(desc); }, {path, "'temperature'", "'smoke'", "'heat'"});
    desc.temperatureGrid = "heat";
    auto m = loadGridMedium(desc);
    EXPECT_EQ(m->activeVoxelCount(), 1u);
    EXPECT_NE(m->describe().find("smoke"), std::string::npos);
    std::remove(path.c_str());
}

TEST(GridLoad, WrongGridTypeThrows) {
    std::string path = tempPath("vec3.vdb");
    openvdb::initialize();
    openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create();
    v->setName("density");
    v->tree().setValue(Coord(0, 0, 0), openvdb::Vec3s(1, 2, 3));
    writeGrids(path, {v});
    GridMediumDesc desc;
    desc.filePath = path;
    expectRuntimeError([&] { loadGridMedium(desc); }, {path, "'density'", "vec3s", "FloatGrid"});
    // In memory as well.
    expectRuntimeError([&] { GridMedium m(GridMediumDesc{}, GridMediumGrids{v}); }, {"'density'", "vec3s"});
    std::remove(path.c_str());
}

TEST(GridLoad, BadTransformsThrow) {
    FloatGrid::Ptr g = FloatGrid::create(0.0f);
    g->setName("density");
    g->tree().setValue(Coord(0, 0, 0), 1.0f);
    GridMediumDesc desc;
    desc.filePath = "mem.vdb";
    desc.objectToWorld = Affine::scale(Vec3(1, 0, 1));
    expectRuntimeError([&] { GridMedium m(desc, GridMediumGrids{g}); }, {"mem.vdb", "not invertible"});
    desc.objectToWorld = Affine::translate(Vec3(std::nan(""), 0, 0));
    expectRuntimeError([&] { GridMedium m(desc, GridMediumGrids{g}); }, {"mem.vdb", "non-finite"});
    // Frustum transforms are rejected.
    desc.objectToWorld = Affine();
    FloatGrid::Ptr f = g->deepCopy();
    f->setTransform(openvdb::math::Transform::createFrustumTransform(
        openvdb::BBoxd(openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(10, 10, 10)), 0.5, 2.0, 0.1));
    expectRuntimeError([&] { GridMedium m(desc, GridMediumGrids{f}); }, {"'density'", "mem.vdb", "non-linear"});
    // And through the loader, with a file.
    std::string path = tempPath("frustum.vdb");
    writeGrids(path, {f});
    desc.filePath = path;
    expectRuntimeError([&] { loadGridMedium(desc); }, {path, "'density'", "non-linear"});
    desc.objectToWorld = Affine::scale(Vec3(0, 0, 0));
    expectRuntimeError([&] { loadGridMedium(desc); }, {path, "not invertible"});
    std::remove(path.c_str());
}

// ---- sanitising ----------------------------------------------------------------------------------

TEST(GridSanitize, InvalidValuesAreClampedWithOneWarningPerGrid) {
    FloatGrid::Ptr g = FloatGrid::create(0.0f);
    g->setName("dens");
    auto acc = g->getAccessor();
    for (int i = 0; i < 16; ++i)
        for (int j = 0; j < 16; ++j)
            for (int k = 0; k < 16; ++k) acc.setValue(Coord(i, j, k), 1.0f);
    acc.setValue(Coord(3, 3, 3), std::numeric_limits<float>::quiet_NaN());
    acc.setValue(Coord(4, 12, 3), std::numeric_limits<float>::quiet_NaN());
    acc.setValue(Coord(10, 10, 10), std::numeric_limits<float>::infinity());
    acc.setValue(Coord(5, 6, 7), -2.0f);
    acc.setValue(Coord(6, 6, 7), -3.0f);
    acc.setValue(Coord(7, 6, 7), -4.0f);
    g->tree().fill(openvdb::CoordBBox(Coord(32, 0, 0), Coord(39, 7, 7)), -1.0f, true);  // a negative tile

    GridMediumDesc desc;
    desc.filePath = "clouds.vdb";
    {
        CaptureDiagnostics capture;
        GridMedium m(desc, GridMediumGrids{g});
        ASSERT_EQ(capture.messages.size(), 1u);
        const std::string& w = capture.messages[0];
        for (const char* s : {"'dens'", "clouds.vdb", "2 NaN", "1 infinite", "4 negative"})
            EXPECT_NE(w.find(s), std::string::npos) << "'" << s << "' not in: " << w;
        // At the centre of a clamped voxel the density is exactly the clamped 0.
        EXPECT_EQ(m.density(Vec3(3, 3, 3)), 0.0);
        EXPECT_EQ(m.density(Vec3(10, 10, 10)), 0.0);
        EXPECT_EQ(m.density(Vec3(6, 6, 7)), 0.0);
        EXPECT_EQ(m.density(Vec3(35, 3, 3)), 0.0);
        EXPECT_NEAR(m.density(Vec3(3.5, 3, 3)), 0.5, 1e-7);
        EXPECT_EQ(m.maxDensity(), 1.0);
        // Everything finite and the majorant still bounds it.
        for (double x = -1; x < 40; x += 0.37) {
            MediumProperties mp = m.properties(Vec3(x, 3.1, 3.05));
            ASSERT_TRUE(mp.sigma_t().isFinite());
            ASSERT_GE(mp.sigma_t().minValue(), 0.0);
        }
        checkMajorantsBoundDensity(m, 5, 50);
    }
    // The caller's grid is left untouched.
    EXPECT_TRUE(std::isnan(g->tree().getValue(Coord(3, 3, 3))));
    // Through a file: the warning names the file and the grid.
    std::string path = tempPath("bad_values.vdb");
    writeGrids(path, {g});
    desc.filePath = path;
    desc.densityGrid = "dens";
    {
        CaptureDiagnostics capture;
        auto m = loadGridMedium(desc);
        ASSERT_EQ(capture.messages.size(), 1u);
        EXPECT_NE(capture.messages[0].find(path), std::string::npos);
        EXPECT_NE(capture.messages[0].find("'dens'"), std::string::npos);
        EXPECT_EQ(m->density(Vec3(3, 3, 3)), 0.0);
    }
    // A clean grid gives no warning.
    {
        CaptureDiagnostics capture;
        GridMedium clean(GridMediumDesc{}, GridMediumGrids{spikyGrid(1)});
        EXPECT_TRUE(capture.messages.empty());
    }
    std::remove(path.c_str());
}

// ---- emission ----------------------------------------------------------------------------------

TEST(GridEmission, BlackbodyColourAndTemperatureEmission) {
    for (double T : {800.0, 1500.0, 3000.0, 6500.0, 12000.0}) EXPECT_NEAR(luminance(blackbodyColor(T)), 1.0, 1e-6);
    Spectrum warm = blackbodyColor(1500), white = blackbodyColor(6500), blue = blackbodyColor(15000);
    EXPECT_GT(warm[0], 2 * warm[2]);
    EXPECT_GT(blue[2], blue[0]);
    EXPECT_NEAR(white[0] / white[2], 1.0, 0.15);  // 6500 K is near the D65 white point
    EXPECT_NEAR(luminance(blackbodyRadiance(2000)), 16.0, 1e-5);
    EXPECT_TRUE(blackbodyRadiance(0).isBlack());
    EXPECT_TRUE(blackbodyRadiance(-5).isBlack());

    FloatGrid::Ptr dens = FloatGrid::create(0.0f), temp = FloatGrid::create(0.0f);
    dens->tree().fill(openvdb::CoordBBox(Coord(0, 0, 0), Coord(15, 15, 15)), 2.0f, true);
    temp->tree().fill(openvdb::CoordBBox(Coord(-8, -8, -8), Coord(23, 23, 23)), 3.0f, true);
    GridMediumDesc desc;
    desc.densityScale = 0.5;
    desc.albedo = Spectrum(0.25);
    desc.temperatureScale = 500.0;  // 1500 K
    desc.emissionScale = 2.0;
    desc.temperatureGrid = "temp";
    GridMedium m(desc, GridMediumGrids{dens, temp});
    EXPECT_TRUE(m.isEmissive());
    MediumProperties mp = m.properties(Vec3(8, 8, 8));
    Spectrum expected = Spectrum(0.5 * 2.0 * 0.75) * blackbodyRadiance(1500.0) * 2.0;  // sigma_a B(T) scale
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mp.emission[c], expected[c], 1e-9 * expected.maxValue());
    // No emission where there is no density, even where the temperature is set.
    EXPECT_TRUE(m.properties(Vec3(-4, 8, 8)).emission.isBlack());
    EXPECT_NEAR(m.maxAlbedo(), 0.25, 1e-12);
    desc.temperatureGrid.clear();
    EXPECT_FALSE(GridMedium(desc, GridMediumGrids{dens}).isEmissive());
}

TEST(GridEmission, ADensityGridNamedAsTheEmissionIsReadOnceAndLookedUpOnce) {
    // Emission proportional to density (field:emission naming the density grid, as benchmark scene
    // 6 does): the file's grid is read once and shared (readVdbFloatGrids), and the medium's
    // coefficients are those with a separate grid of twice the values as the emission, but for the
    // factor 2 (exact in floating point), point for point.
    std::string path = tempPath("emission_is_density.vdb");
    FloatGrid::Ptr smoke = FloatGrid::create(0.0f);
    smoke->setName("smoke");
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) smoke->tree().setValue(Coord(i, j, k), 0.1f + 0.3f * i + 0.05f * j * k);
    FloatGrid::Ptr glow = smoke->deepCopy();
    glow->setName("glow");
    for (auto v = glow->tree().beginValueOn(); v; ++v) v.setValue(2 * *v);
    writeGrids(path, {smoke, glow});
    auto grids = readVdbFloatGrids(path, {{"smoke", "density"}, {"", "temperature"}, {"smoke", "emission"}, {"glow", "albedo"}}, 0);
    EXPECT_EQ(grids[0], grids[2]);
    EXPECT_NE(grids[0], grids[3]);
    GridMediumDesc desc;
    desc.filePath = path;
    desc.densityGrid = "smoke";
    desc.emission = Spectrum(3.0, 0.9, 0.2);
    desc.emissionGrid = "smoke";
    auto shared = loadGridMedium(desc);
    desc.emissionGrid = "glow";
    auto separate = loadGridMedium(desc);
    Rng rng(7);
    for (int n = 0; n < 200; ++n) {
        Vec3 p(-1 + 10 * rng.uniform(), -1 + 10 * rng.uniform(), -1 + 10 * rng.uniform());
        MediumProperties a = shared->properties(p), b = separate->properties(p);
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(2 * a.emission[c], b.emission[c]) << "at " << p.x << " " << p.y << " " << p.z;
            EXPECT_EQ(a.sigma_t()[c], b.sigma_t()[c]);
        }
    }
    EXPECT_GT(shared->properties(Vec3(4, 4, 4)).emission[0], 0.0);
    std::remove(path.c_str());
}

// ---- concurrency -------------------------------------------------------------------------------

TEST(GridConcurrency, ThreadsAndInterleavedMediaAgreeWithSerialLookups) {
    // Per-thread accessors are cached per medium: lookups from several threads, alternating
    // between two media (and one destroyed and replaced), must equal the serial answers exactly.
    std::string path = tempPath("conc.vdb");
    writeProceduralCloudVdb(path, 32, 1.0 / 32, 5);
    GridMediumDesc desc;
    desc.filePath = path;
    auto a = loadGridMedium(desc);
    auto b = std::make_unique<GridMedium>(GridMediumDesc{}, GridMediumGrids{spikyGrid(9)});
    std::vector<Vec3> pa, pb;
    Rng rng(17);
    for (int i = 0; i < 20000; ++i) {
        pa.push_back(Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
        pb.push_back(Vec3(60 * rng.uniform(), 50 * rng.uniform(), 40 * rng.uniform()));
    }
    std::vector<double> ra, rb;
    for (int i = 0; i < 20000; ++i) ra.push_back(a->density(pa[i]));
    for (int i = 0; i < 20000; ++i) rb.push_back(b->density(pb[i]));
    std::atomic<int> mismatches{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            for (int i = t; i < 20000; i += 2) {
                if (a->density(pa[i]) != ra[i]) ++mismatches;
                if (b->density(pb[i]) != rb[i]) ++mismatches;
            }
        });
    for (auto& th : threads) th.join();
    EXPECT_EQ(mismatches.load(), 0);
    // Replace b by a different medium: no thread may see the old one's cached nodes.
    b = std::make_unique<GridMedium>(GridMediumDesc{}, GridMediumGrids{spikyGrid(10)});
    std::vector<double> rb2;
    for (int i = 0; i < 20000; ++i) rb2.push_back(b->density(pb[i]));
    EXPECT_NE(rb2, rb);
    for (int i = 0; i < 20000; ++i) {
        ASSERT_EQ(b->density(pb[i]), rb2[i]);
        ASSERT_EQ(a->density(pa[i]), ra[i]);
    }
    std::remove(path.c_str());
}

// ---- procedural cloud ----------------------------------------------------------------------------

TEST(GridProcedural, CloudIsLoadableAndDeterministic) {
    std::string a = tempPath("procA.vdb"), b = tempPath("procB.vdb"), c = tempPath("procC.vdb");
    writeProceduralCloudVdb(a, 40, 0.02, 99);
    writeProceduralCloudVdb(b, 40, 0.02, 99);
    writeProceduralCloudVdb(c, 40, 0.02, 100);
    GridMediumDesc desc;
    desc.filePath = a;
    auto ma = loadGridMedium(desc);
    EXPECT_GT(ma->activeVoxelCount(), 1000u);
    EXPECT_LT(ma->activeVoxelCount(), size_t(40 * 40 * 40 / 2));  // inside a sphere of radius 0.45 res
    EXPECT_GT(ma->maxDensity(), 0.3);
    EXPECT_LE(ma->maxDensity(), 1.0);
    Bounds3 ib = ma->indexBounds();
    EXPECT_GE(ib.lo.x, -1.0);
    EXPECT_LE(ib.hi.x, 40.0);
    Bounds3 wb = ma->bounds();
    EXPECT_GE(wb.lo.x, -0.02 - 1e-12);
    EXPECT_LE(wb.hi.x, 0.8 + 1e-12);

    openvdb::initialize();
    auto readDensity = [](const std::string& p) {
        openvdb::io::File f(p);
        f.open();
        auto g = openvdb::gridPtrCast<FloatGrid>(f.readGrid("density"));
        f.close();
        return g;
    };
    FloatGrid::Ptr ga = readDensity(a), gb = readDensity(b), gc = readDensity(c);
    ASSERT_TRUE(ga && gb && gc);
    EXPECT_EQ(ga->activeVoxelCount(), gb->activeVoxelCount());
    size_t differ = 0, differC = 0;
    for (auto it = ga->cbeginValueOn(); it; ++it) {
        differ += gb->tree().getValue(it.getCoord()) != *it;
        differC += gc->tree().getValue(it.getCoord()) != *it;
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(differC, ga->activeVoxelCount() / 2);  // another seed, another cloud
    EXPECT_THROW(writeProceduralCloudVdb(a, 0, 0.1, 1), std::invalid_argument);
    EXPECT_THROW(writeProceduralCloudVdb(tempPath("no/such/dir/x.vdb"), 8, 0.1, 1), std::runtime_error);
    for (const auto& p : {a, b, c}) std::remove(p.c_str());
}
