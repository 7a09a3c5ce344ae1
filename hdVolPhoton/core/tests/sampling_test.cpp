// The camera samples' randomised quasi-Monte Carlo prefix (Rng::stratify): the Sobol' pair is a
// (0, 2)-sequence, scrambling keeps the net property, each sample is uniform over the keys, pairs are
// decorrelated, and it integrates a smooth 2D function with far less error than independent samples.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "core/rng.h"
#include "core/sampling.h"

using namespace volphoton;

namespace {

/// True if the 2^m points stratify every elementary interval of area 2^-m (a (0, m, 2)-net in base 2).
bool isNet(const std::vector<std::pair<uint32_t, uint32_t>>& pts, int m) {
    for (int a = 0; a <= m; ++a) {  // 2^a columns x 2^(m-a) rows
        std::set<uint64_t> cells;
        for (auto [x, y] : pts) {
            uint64_t cx = a == 0 ? 0 : x >> (32 - a);
            uint64_t cy = m - a == 0 ? 0 : y >> (32 - (m - a));
            cells.insert((cx << 32) | cy);
        }
        if (cells.size() != pts.size()) return false;
    }
    return true;
}

std::vector<std::pair<uint32_t, uint32_t>> stratifiedPair(uint64_t key, int pair, int count) {
    std::vector<std::pair<uint32_t, uint32_t>> pts;
    for (int i = 0; i < count; ++i) {
        Rng rng(99, i);
        rng.stratify(static_cast<uint32_t>(i), key, 2 * (pair + 1));
        for (int k = 0; k < pair; ++k) rng.uniform(), rng.uniform();
        double x = rng.uniform(), y = rng.uniform();
        pts.emplace_back(static_cast<uint32_t>(std::ldexp(x, 32)), static_cast<uint32_t>(std::ldexp(y, 32)));
    }
    return pts;
}

}  // namespace

TEST(Sampling, SobolPairIsAZeroTwoSequence) {
    for (int m : {4, 7, 10}) {
        std::vector<std::pair<uint32_t, uint32_t>> pts;
        for (uint32_t i = 0; i < (1u << m); ++i) pts.emplace_back(sobol0(i), sobol1(i));
        EXPECT_TRUE(isNet(pts, m)) << "m " << m;
        // A later block of 2^m consecutive indices is a net too (a (0, 2)-sequence, not just a net).
        pts.clear();
        for (uint32_t i = 5u << m; i < (6u << m); ++i) pts.emplace_back(sobol0(i), sobol1(i));
        EXPECT_TRUE(isNet(pts, m)) << "block, m " << m;
    }
    // The reversed table agrees with the plain one.
    for (uint32_t i : {0u, 1u, 77u, 123456u, 0x80000001u, 0xffffffffu})
        EXPECT_EQ(sobol1Reversed(reverseBits32(i)), reverseBits32(sobol1(i)));
}

TEST(Sampling, ScrambledShuffledPairsStayNets) {
    // Every pair of draws of the first 2^m passes of a pixel is a net, for several pixels and pairs.
    for (uint64_t key : {1ull, 0xabcdefull, 1234567890123ull})
        for (int pair : {0, 1, 5, 15})
            for (int m : {3, 6, 8}) EXPECT_TRUE(isNet(stratifiedPair(key, pair, 1 << m), m)) << key << " " << pair << " " << m;
    // Scrambling is not the identity: two pixels see different points.
    EXPECT_NE(stratifiedPair(1, 0, 4), stratifiedPair(2, 0, 4));
}

TEST(Sampling, EachSampleIsUniformAndPairsAreDecorrelated) {
    // Over many pixels (keys), sample i's draws are uniform: mean 1/2, variance 1/12; draws of
    // different pairs are uncorrelated. n = 40000 keys: standard error of a mean 0.0014, of a
    // correlation 0.005; tolerances are 5 of them.
    const int n = 40000;
    for (uint32_t index : {0u, 3u, 1000u}) {
        double s[4] = {}, s2[4] = {}, c02 = 0, c13 = 0;
        for (int k = 0; k < n; ++k) {
            Rng rng(k, index);
            rng.stratify(index, mix64(k + 1), 8);
            double u[4];
            for (double& v : u) v = rng.uniform();
            for (int d = 0; d < 4; ++d) {
                s[d] += u[d];
                s2[d] += u[d] * u[d];
            }
            c02 += (u[0] - 0.5) * (u[2] - 0.5);
            c13 += (u[1] - 0.5) * (u[3] - 0.5);
        }
        for (int d = 0; d < 4; ++d) {
            EXPECT_NEAR(s[d] / n, 0.5, 0.007) << "index " << index << " dim " << d;
            EXPECT_NEAR(s2[d] / n - std::pow(s[d] / n, 2), 1.0 / 12, 0.004) << "index " << index << " dim " << d;
        }
        EXPECT_NEAR(c02 / n * 12, 0.0, 0.025) << "index " << index;
        EXPECT_NEAR(c13 / n * 12, 0.0, 0.025) << "index " << index;
    }
}

TEST(Sampling, StratifiedEstimatesConvergeFaster) {
    // f(x, y) = exp(x) sin(pi y) over [0,1]^2, integral (e - 1) 2 / pi, with 256 samples per key:
    // root-mean-square error over 200 keys, RQMC against independent draws. Owen-scrambled nets of
    // a smooth integrand reach ~N^-1.5; independent draws N^-0.5: the ratio at N = 256 is ~100. The
    // test asks for 10.
    const double exact = (std::exp(1.0) - 1) * 2 / M_PI;
    double mseQmc = 0, mseRandom = 0;
    const int keys = 200, n = 256;
    for (int k = 0; k < keys; ++k) {
        double q = 0, r = 0;
        for (int i = 0; i < n; ++i) {
            Rng a(k, i);
            a.stratify(static_cast<uint32_t>(i), mix64(k + 7), 2);
            double x = a.uniform(), y = a.uniform();
            q += std::exp(x) * std::sin(M_PI * y);
            double xr = a.uniform(), yr = a.uniform();  // past the prefix: independent PCG32 draws
            r += std::exp(xr) * std::sin(M_PI * yr);
        }
        mseQmc += std::pow(q / n - exact, 2) / keys;
        mseRandom += std::pow(r / n - exact, 2) / keys;
    }
    EXPECT_LT(std::sqrt(mseQmc) * 10, std::sqrt(mseRandom));
}

namespace {

/// Sample `i` of pixel `key` as the path tracer draws it: camera pair, then per segment an
/// equiangular pair, a flight event with `flights(i, s)` tentative collisions (a varying number of
/// draws, as delta tracking makes), then the light pick and pair. Returns segment `segment`'s light pair.
std::pair<uint32_t, uint32_t> lightPairAfterFlights(uint64_t key, uint32_t i, int segment, int dims) {
    Rng rng(key, i);
    rng.stratify(i, key, dims);
    rng.uniform2();
    rng.uniform2();
    Rng count(key ^ 0x5a5a, i);  // how many draws each flight takes: 0..15, unrelated to the samples
    std::pair<double, double> u;
    for (int s = 0; s <= segment; ++s) {
        rng.startSegment(s);
        rng.event(Rng::Event::Flight);
        for (int k = static_cast<int>(count.nextU32() % 16); k > 0; --k) rng.uniform();
        rng.event(Rng::Event::Light);
        rng.uniform();  // light pick
        u = rng.uniform2();
        rng.event(Rng::Event::Scatter);
        rng.uniform2();
        rng.uniform();
    }
    return {static_cast<uint32_t>(std::ldexp(u.first, 32)), static_cast<uint32_t>(std::ldexp(u.second, 32))};
}

}  // namespace

TEST(Sampling, SegmentEventsKeepTheirDimensionsWhateverCameBefore) {
    // The light pair of segment s stays a (0, m, 2)-net over a pixel's samples however many draws
    // the flights before it took (0..15 each, so without per-segment dimensions it would land on
    // different dimensions in different samples and stratify nothing).
    for (uint64_t key : {3ull, 0xfeedull})
        for (int segment : {0, 1, 4})
            for (int m : {4, 7}) {
                std::vector<std::pair<uint32_t, uint32_t>> pts;
                for (uint32_t i = 0; i < (1u << m); ++i) pts.push_back(lightPairAfterFlights(key, i, segment, 1024));
                EXPECT_TRUE(isNet(pts, m)) << key << " segment " << segment << " m " << m;
            }
    // Past the stratified dimensions the draws are independent (PCG32): no net at segment 4 with 64 dims.
    std::vector<std::pair<uint32_t, uint32_t>> pts;
    for (uint32_t i = 0; i < 128; ++i) pts.push_back(lightPairAfterFlights(3, i, 4, 64));
    EXPECT_FALSE(isNet(pts, 7));
}

TEST(Sampling, PathChoicesAreStratifiedOverAPixelsSamplesAndTakeNoDimension) {
    // The path tracer's hero channel (Rng::pathChoice(3)): over any 2^m consecutive samples of a
    // pixel each of the 3 choices comes within 2 of 2^m / 3 times (a scrambled van der Corput point
    // per sample, one in each interval of width 2^-m: a choice's third of [0, 1) holds all of the
    // intervals it covers and at most the two it cuts), where independent draws miss that by about
    // 11 at m = 9; and the draw takes none of the stratified dimensions (nor, unstratified, any draw).
    for (uint64_t key : {3ull, 0xfeedull, 12345ull})
        for (int m : {3, 6, 9}) {
            int count[3] = {0, 0, 0}, pcg[3] = {0, 0, 0};
            const uint32_t n = 1u << m;
            for (uint32_t i = 0; i < n; ++i) {
                Rng rng(key, i);
                rng.stratify(i, key, 64);
                ++count[rng.pathChoice(3)];
                Rng plain(key, i);
                ++pcg[plain.pathChoice(3)];
            }
            for (int c = 0; c < 3; ++c)
                EXPECT_LE(std::abs(3 * count[c] - static_cast<int>(n)), 6) << key << " m " << m << " choice " << c << ": " << count[c];
            if (m == 9) {  // the independent draws' counts spread by about sqrt(512 * 2/9) = 11
                int spread = 0;
                for (int c = 0; c < 3; ++c) spread = std::max(spread, std::abs(3 * pcg[c] - static_cast<int>(n)));
                EXPECT_GT(spread, 6) << key;
            }
        }
    for (uint32_t i = 0; i < 16; ++i) {
        Rng a(7, i), b(7, i);
        a.stratify(i, 77, 64);
        b.stratify(i, 77, 64);
        a.pathChoice(3);
        EXPECT_EQ(a.uniform(), b.uniform()) << i;
        // Unstratified (photons): a hash of the state, which stays as it was.
        Rng c(7, i), d(7, i);
        c.pathChoice(3);
        EXPECT_EQ(c.uniform(), d.uniform()) << i;
    }
}

TEST(Sampling, NoDimensionIsUsedTwiceInOneSample) {
    // Going back to an event whose dimensions the sample has passed draws from PCG32, not the
    // stratified value already used (which would correlate two decisions of one path).
    for (uint32_t i = 0; i < 64; ++i) {
        Rng a(7, i), b(7, i);
        a.stratify(i, 77, 256);
        b.stratify(i, 77, 256);
        a.startSegment(0);
        b.startSegment(0);
        a.event(Rng::Event::Flight);
        double flight = a.uniform();
        b.event(Rng::Event::Scatter);
        b.uniform();
        b.event(Rng::Event::Flight);  // behind: PCG32
        EXPECT_NE(b.uniform(), flight) << i;
        // A pair that does not fit in what is left of an event comes from PCG32 as a whole.
        Rng c(7, i);
        c.stratify(i, 77, 256);
        c.startSegment(0);
        c.event(Rng::Event::Roulette);  // width 1
        auto [x, y] = c.uniform2();
        Rng d(7, i);
        d.stratify(i, 77, 256);
        for (int k = 0; k < Rng::CameraDims + static_cast<int>(Rng::Event::Roulette) - 1; ++k) d.uniform();
        auto [sx, sy] = d.uniform2();  // the stratified pair holding the roulette's dimension
        EXPECT_NE(y, sy) << i;
        EXPECT_NE(x, sx) << i;
    }
}

TEST(Sampling, NeighbouringPixelsAreUncorrelated) {
    // Pixels are keyed as the renderer keys them (hashKeys of a tag, x, y, seed). For sample index i
    // of pixel (x, y) and of its right and lower neighbours, the same dimension's values must be
    // uncorrelated (each pixel's points are scrambled and shuffled independently): over 160 x 120
    // pixels x 2 indices (38400 pairs) the correlation's standard error is 1/sqrt(38400) = 0.005;
    // the tolerance is 5 of them. The test fails if the scramble seeds ignore the pixel (correlation 1).
    for (int dim : {0, 1, Rng::CameraDims + static_cast<int>(Rng::Event::Light) + 1})
        for (int dx : {0, 1}) {
            int dy = 1 - dx;
            double sum = 0;
            int n = 0;
            for (uint32_t index : {0u, 13u})
                for (int y = 0; y < 120; ++y)
                    for (int x = 0; x < 160; ++x) {
                        auto draw = [&](int px, int py) {
                            Rng rng(hashKeys(px, py, 0), index);
                            rng.stratify(index, hashKeys(0x51534d43ULL, px, py, 0), 64);
                            double u = 0;
                            for (int k = 0; k <= dim; ++k) u = rng.uniform();
                            return u;
                        };
                        sum += (draw(x, y) - 0.5) * (draw(x + dx, y + dy) - 0.5) * 12;
                        ++n;
                    }
            EXPECT_NEAR(sum / n, 0.0, 5 / std::sqrt(double(n))) << "dim " << dim << " dx " << dx;
        }
}

namespace {
/// Exact integral of 1 / |p - c| over the unit pixel [0, 1)^2 for c inside it: the pixel split at c
/// into four rectangles a x b with c at a corner, each a asinh(b / a) + b asinh(a / b).
double inverseDistanceIntegral(double cx, double cy) {
    auto rect = [](double a, double b) { return a > 0 && b > 0 ? a * std::asinh(b / a) + b * std::asinh(a / b) : 0.0; };
    return rect(cx, cy) + rect(1 - cx, cy) + rect(cx, 1 - cy) + rect(1 - cx, 1 - cy);
}
}  // namespace

TEST(Sampling, PixelPositionsAroundALightAreUnbiasedWithBoundedWeights) {
    // samplePixelAroundPoint: E[weight g(position)] is the pixel integral of g for g = 1, a smooth g and
    // g = 1/h (the singular shape of a medium's light near a point light), and weight / h is bounded by
    // 4 pi R (R the farthest corner), which uniform positions are not. Light images at the centre,
    // near a corner, on an edge and at a corner. Tolerance: 5 standard errors of 2^18 samples.
    struct Case {
        double cx, cy;
    };
    for (Case c : {Case{0.5, 0.5}, Case{0.93, 0.08}, Case{0.0, 0.37}, Case{1e-9, 1e-9}}) {
        const int n = 1 << 18;
        double sum[3] = {0, 0, 0}, sumSq[3] = {0, 0, 0}, maxSingular = 0;
        Rng rng(hashKeys(17, int(c.cx * 1000), int(c.cy * 1000)));
        const double R = std::hypot(std::max(c.cx, 1 - c.cx), std::max(c.cy, 1 - c.cy));
        for (int i = 0; i < n; ++i) {
            double u0 = rng.uniform(), u1 = rng.uniform();
            PixelPosition p = samplePixelAroundPoint(3, 5, ImagePoint{3 + c.cx, 5 + c.cy}, u0, u1);
            ASSERT_TRUE(p.x >= 3 && p.x < 4 && p.y >= 5 && p.y < 6);
            ASSERT_TRUE(p.weight >= 0 && p.weight <= 2);
            double x = p.x - 3, y = p.y - 5, h = std::hypot(x - c.cx, y - c.cy);
            double g[3] = {1.0, x * x + y, h > 0 ? 1 / h : 0.0};
            if (h == 0) ASSERT_EQ(p.weight, 0.0);
            for (int k = 0; k < 3; ++k) {
                sum[k] += p.weight * g[k];
                sumSq[k] += p.weight * g[k] * p.weight * g[k];
            }
            maxSingular = std::max(maxSingular, p.weight * g[2]);
        }
        const double exact[3] = {1.0, 1.0 / 3 + 0.5, inverseDistanceIntegral(c.cx, c.cy)};
        for (int k = 0; k < 3; ++k) {
            double mean = sum[k] / n, se = std::sqrt((sumSq[k] / n - mean * mean) / n);
            EXPECT_NEAR(mean, exact[k], 5 * se + 1e-12) << "g" << k << " at " << c.cx << ", " << c.cy;
        }
        EXPECT_LE(maxSingular, 4 * Pi * R * (1 + 1e-9));
    }
}
