// The camera samples' randomised quasi-Monte Carlo prefix (Rng::stratify): the Sobol' pair is a
// (0, 2)-sequence, scrambling keeps the net property, each sample is uniform over the keys, pairs are
// decorrelated, and it integrates a smooth 2D function with far less error than independent samples.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "core/rng.h"

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
