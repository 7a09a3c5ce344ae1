// Homogeneous and exponential media, aggregates, the free-flight routine and the transmittance
// estimators against closed forms. Statistical tolerances: 4 standard errors of the mean over 16
// seeds (a false failure rate of ~6e-5 per assertion under a normal approximation).
#include <gtest/gtest.h>

#include "core/exponentialMedium.h"
#include "core/freeFlight.h"
#include "core/homogeneousMedium.h"
#include "core/mediumAggregate.h"
#include "core/transmittance.h"
#include "tests/testUtil.h"

using namespace volphoton;
using volphoton::test::overSeeds;

namespace {
constexpr int Seeds = 16;
constexpr double K = 4.0;

MediumCoefficients grey(double sigma_t, double albedo = 0.5) {
    return MediumCoefficients::fromAlbedo(sigma_t, Spectrum(1.0), Spectrum(albedo), Spectrum(0.0), makeIsotropicPhase());
}
MediumCoefficients chromatic(const Spectrum& sigma_t) {
    return MediumCoefficients::fromAlbedo(1.0, sigma_t, Spectrum(0.5), Spectrum(0.0), makeIsotropicPhase());
}
}  // namespace

TEST(MediaExponential, OpticalDepthClosedFormValues) {
    // Values from the issue, independently: tau = a e^{-b h0} (1 - e^{-b mu s}) / (b mu).
    EXPECT_NEAR(exponentialOpticalDepth(1, 0.5, 1, 0.5, 10), 2.226974365379, 1e-11);
    EXPECT_NEAR(exponentialOpticalDepth(1, 0.5, 3, -0.6, 5), 2.589566132839, 1e-11);
}

TEST(MediaExponential, NearHorizontalRaysStayExact) {
    // mu = 1e-12: x = b mu s = 5e-12; tau = a e^{-b h0} s (1 - x/2 + x^2/6 - ...).
    double x = 0.5 * 1e-12 * 10;
    double expected = std::exp(-0.5) * 10 * (1 - x / 2 + x * x / 6);
    EXPECT_NEAR(exponentialOpticalDepth(1, 0.5, 1, 1e-12, 10) / expected, 1.0, 1e-15);
    // And exactly horizontal.
    EXPECT_DOUBLE_EQ(exponentialOpticalDepth(1, 0.5, 1, 0.0, 10), std::exp(-0.5) * 10);
    // The naive (1 - e^{-x})/x loses it: show the test can tell the difference.
    double naive = std::exp(-0.5) * 10 * (1 - std::exp(-x)) / x;
    EXPECT_GT(std::abs(naive / expected - 1), 1e-8);
}

TEST(MediaExponential, OpticalDepthAlongRayMatchesQuadrature) {
    ExponentialMedium m(grey(2.0), 1.5, 0.7, Vec3(0, 1, 0), Vec3(0, 1, 0));
    Ray r{Vec3(0.3, 2.0, -1.0), normalize(Vec3(0.2, -0.5, 1.0))};
    double tau = (*m.opticalDepth(r, 0.5, 6.0))[0];
    double q = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) q += m.properties(r.at(0.5 + (i + 0.5) * 5.5 / n)).sigma_t()[0] * 5.5 / n;
    EXPECT_NEAR(tau / q, 1.0, 1e-8);
}

TEST(MediaExponential, MajorantBoundsTheClampedDensity) {
    // a = b = 1e6: below h = (ln a - cap) / b the density is clamped (flat). The majorant must bound
    // sigma_t everywhere along rays that start in, end in or cross the clamped part; a decaying
    // majorant started inside it fell below the flat density (the photon-map energy gain of stress
    // cases 259-262).
    ExponentialMedium m(grey(1.0), 1e6, 1e6, Vec3(), Vec3(0, 1, 0), Bounds3{Vec3(-1, -1, -1), Vec3(1, 1, 1)});
    const double hCap = (std::log(1e6) - m.densityCapExponent()) / 1e6;
    ASSERT_LT(hCap, 0.0);
    for (Vec3 dir : {Vec3(0, 1, 0), Vec3(0, -1, 0), normalize(Vec3(1, 1e-4, 0)), normalize(Vec3(0.3, 0.8, 0.1)),
                     normalize(Vec3(0.3, -0.8, 0.1))}) {
        for (double h0 : {-0.5, hCap - 1e-9, hCap + 1e-7, 1e-5}) {
            Ray r{Vec3(-dir.x * 0.5, h0, -dir.z * 0.5), dir};
            int segments = 0;
            m.majorants(r, 0.0, 2.0, [&](const MajorantSegment& seg) {
                ++segments;
                for (int i = 0; i <= 100; ++i) {
                    double t = seg.tMin + (seg.tMax - seg.tMin) * i / 100.0;
                    double maj = std::min(seg.sigmaMaj * std::exp(-seg.decay * (t - seg.tMin)), 1e300);
                    double st = m.properties(r.at(t)).sigma_t().maxValue();
                    EXPECT_LE(st, maj * (1 + 1e-9)) << "h0 " << h0 << " dir " << dir.y << " t " << t;
                }
                return true;
            });
            EXPECT_GE(segments, 1);
        }
    }
}

TEST(MediaHomogeneous, BeerLambertClosedForm) {
    HomogeneousMedium m(chromatic(Spectrum(1, 2, 0.5)));
    Rng rng(1);
    Ray r{Vec3(0, 0, 0), Vec3(0, 0, 1)};
    Spectrum T = transmittance(m, r, 1.7, rng);
    EXPECT_DOUBLE_EQ(T[0], std::exp(-1.7));
    EXPECT_DOUBLE_EQ(T[1], std::exp(-3.4));
    EXPECT_DOUBLE_EQ(T[2], std::exp(-0.85));
}

TEST(MediaHomogeneous, BoxBoundsClipTheSupport) {
    HomogeneousMedium m(grey(3.0), Bounds3{Vec3(-1, -1, 2), Vec3(1, 1, 3)});
    Rng rng(1);
    Ray r{Vec3(0, 0, 0), Vec3(0, 0, 1)};
    EXPECT_DOUBLE_EQ(transmittance(m, r, 10, rng)[0], std::exp(-3.0));
    EXPECT_DOUBLE_EQ(transmittance(m, r, 2.5, rng)[0], std::exp(-1.5));
    EXPECT_EQ(m.properties(Vec3(0, 0, 1)).sigma_t()[0], 0.0);
}

namespace {
/// Mean of `n` estimates of one estimator for one seed, channel c.
double meanEstimate(const Medium& m, const Ray& r, double tMax, int seed, int c, const TransmittanceSettings& s, int n = 4000) {
    Rng rng(static_cast<uint64_t>(seed) + 1000, 7);
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += transmittance(m, r, tMax, rng, s)[c];
    return sum / n;
}

void expectUnbiased(const Medium& m, const Ray& r, double tMax, const TransmittanceSettings& s) {
    Spectrum exact = exp(-*m.opticalDepth(r, 0, tMax));
    for (int c = 0; c < 3; ++c) {
        auto est = overSeeds(Seeds, [&](int seed) { return meanEstimate(m, r, tMax, seed, c, s); });
        EXPECT_NEAR(est.mean, exact[c], K * est.stderr_ + 1e-12) << m.describe() << " channel " << c;
        EXPECT_GT(est.stderr_, 0.0) << "the estimator is stochastic, so a zero error means it was not exercised";
    }
}
}  // namespace

TEST(MediaTransmittance, RatioTrackingIsUnbiasedOnHomogeneous) {
    HomogeneousMedium m(chromatic(Spectrum(1, 2, 0.5)), Bounds3{Vec3(-5, -5, 0.5), Vec3(5, 5, 2.5)});
    TransmittanceSettings s;
    s.mode = TransmittanceMode::RatioTracking;
    expectUnbiased(m, {Vec3(0, 0, 0), Vec3(0, 0, 1)}, 3.0, s);
}

TEST(MediaTransmittance, RatioTrackingIsUnbiasedOnChromaticExponential) {
    ExponentialMedium m(chromatic(Spectrum(1.0, 0.4, 2.0)), 1.0, 0.5, Vec3(0, 0, 0), Vec3(0, 1, 0));
    TransmittanceSettings s;
    s.mode = TransmittanceMode::RatioTracking;
    expectUnbiased(m, {Vec3(0, 1, 0), normalize(Vec3(1, 0.5, 0))}, 4.0, s);
    expectUnbiased(m, {Vec3(0, 3, 0), normalize(Vec3(1, -0.6, 0))}, 5.0, s);
}

TEST(MediaTransmittance, RatioTrackingIsUnbiasedOnAggregate) {
    HomogeneousMedium fog(grey(0.3), Bounds3{Vec3(-1, -1, -1), Vec3(1, 1, 1)});
    ExponentialMedium air(chromatic(Spectrum(0.5, 0.8, 1.2)), 1.0, 0.8, Vec3(0, -1, 0), Vec3(0, 1, 0));
    MediumAggregate both;
    both.add(&fog);
    both.add(&air);
    TransmittanceSettings s;
    s.mode = TransmittanceMode::RatioTracking;
    expectUnbiased(both, {Vec3(-3, -0.5, 0.2), normalize(Vec3(1, 0.3, 0))}, 6.0, s);
    // The closed form of the aggregate is the sum of its members'.
    Ray r{Vec3(-3, -0.5, 0.2), normalize(Vec3(1, 0.3, 0))};
    Spectrum sum = *fog.opticalDepth(r, 0, 6) + *air.opticalDepth(r, 0, 6);
    EXPECT_NEAR((*both.opticalDepth(r, 0, 6))[2], sum[2], 1e-12);
}

TEST(MediaTransmittance, RouletteStaysUnbiasedAndCutoffBiasIsBounded) {
    HomogeneousMedium thick(grey(1.0), Bounds3{Vec3(-5, -5, 0), Vec3(5, 5, 4)});
    // Make ratio tracking pay: an aggregate with a second member has no exact majorant.
    HomogeneousMedium thin(grey(0.5), Bounds3{Vec3(-5, -5, 1), Vec3(5, 5, 3)});
    MediumAggregate both;
    both.add(&thick);
    both.add(&thin);
    Ray r{Vec3(0, 0, 0), Vec3(0, 0, 1)};
    TransmittanceSettings s;
    s.mode = TransmittanceMode::RatioTracking;
    s.rouletteThreshold = 0.5;  // roulette nearly always
    expectUnbiased(both, r, 4.0, s);
    // Deterministic cut-off: the expectation drops by at most the cut-off.
    s.rouletteThreshold = 0;
    s.cutoff = 0.01;
    double exact = std::exp(-5.0);
    auto est = overSeeds(Seeds, [&](int seed) { return meanEstimate(both, r, 4.0, seed, 0, s); });
    EXPECT_LE(est.mean, exact + K * est.stderr_);
    EXPECT_GE(est.mean, exact - s.cutoff - K * est.stderr_);
}

TEST(MediaTransmittance, RayMarchingConvergesWithStep) {
    ExponentialMedium m(grey(1.0), 1.0, 0.5, Vec3(0, 0, 0), Vec3(0, 1, 0), Bounds3{Vec3(-10, -10, -10), Vec3(10, 10, 10)});
    Ray r{Vec3(0, 1, 0), normalize(Vec3(1, 0.5, 0))};
    double exact = std::exp(-(*m.opticalDepth(r, 0, 10))[0]);
    Rng rng(3);
    double coarse = 0, fine = 0;
    for (int i = 0; i < 2000; ++i) coarse += marchedTransmittance(m, r, 10, rng, 1.0)[0] / 2000;
    for (int i = 0; i < 2000; ++i) fine += marchedTransmittance(m, r, 10, rng, 0.01)[0] / 2000;
    EXPECT_NEAR(fine, exact, 1e-4);
    EXPECT_GT(std::abs(coarse - exact), std::abs(fine - exact));  // biased, and the bias shrinks with the step
}

TEST(MediaFreeFlight, HomogeneousFirstCollisionIsExponential) {
    // Fraction of first tentative collisions beyond x = e^{-sigma x}, in 8 bins, with a chi-square
    // style bound per bin (4 sigma of the binomial).
    HomogeneousMedium m(grey(2.0));
    Ray r{Vec3(0, 0, 0), Vec3(1, 0, 0)};
    Rng rng(11);
    const int n = 200000;
    std::vector<int> bins(8, 0);
    for (int i = 0; i < n; ++i) {
        double tHit = Infinity;
        sampleFreeFlight(m, r, 4.0, rng, [&](const MediumEvent& e) { tHit = e.t; return false; });
        bins[tHit >= 3.5 ? 7 : static_cast<int>(tHit / 0.5)]++;
    }
    for (int b = 0; b < 8; ++b) {
        double p = b < 7 ? std::exp(-2.0 * 0.5 * b) - std::exp(-2.0 * 0.5 * (b + 1)) : std::exp(-2.0 * 3.5);
        EXPECT_NEAR(bins[b], n * p, K * std::sqrt(n * p * (1 - p)) + 1) << "bin " << b;
    }
}

TEST(MediaFreeFlight, ExponentialClosedFormAndEscape) {
    // Grey exponential medium: the majorant is exact, so every tentative collision is real and the
    // first one is distributed as 1 - exp(-tau(t)). A ray climbing out may never reach the sampled
    // tau: P(escape to infinity) = exp(-tau(inf)) = exp(-sigma a e^{-b h0} / (b mu)).
    ExponentialMedium m(grey(1.0), 1.0, 0.5, Vec3(0, 0, 0), Vec3(0, 1, 0));
    Ray r{Vec3(0, 1, 0), normalize(Vec3(1, 1, 0))};
    double mu = r.d.y;
    double tauInf = std::exp(-0.5) / (0.5 * mu);
    Rng rng(5);
    const int n = 200000;
    int escaped = 0, beforeOne = 0, nonReal = 0;
    for (int i = 0; i < n; ++i) {
        bool reached = FlightEnd::Escaped == sampleFreeFlight(m, r, Infinity, rng, [&](const MediumEvent& e) {
            if (e.mp.sigma_t()[0] < e.sigmaMaj * (1 - 1e-9)) nonReal++;
            if (e.t < 1.0) beforeOne++;
            return false;
        });
        escaped += reached;
    }
    double pEsc = std::exp(-tauInf);
    EXPECT_NEAR(escaped, n * pEsc, K * std::sqrt(n * pEsc * (1 - pEsc)));
    double p1 = 1 - std::exp(-exponentialOpticalDepth(1.0, 0.5, 1.0, mu, 1.0));
    EXPECT_NEAR(beforeOne, n * p1, K * std::sqrt(n * p1 * (1 - p1)));
    EXPECT_EQ(nonReal, 0);
}

TEST(MediaAggregate, CoefficientsAddAndPhaseIsWeightedMixture) {
    auto hg = makeHenyeyGreensteinPhase(0.7);
    HomogeneousMedium a(MediumCoefficients::fromAlbedo(2.0, Spectrum(1.0), Spectrum(0.5), Spectrum(0.1), makeIsotropicPhase()));
    HomogeneousMedium b(MediumCoefficients::fromAlbedo(1.0, Spectrum(1.0), Spectrum(0.9), Spectrum(0.0), hg));
    MediumAggregate both;
    both.add(&a);
    both.add(&b);
    MediumProperties mp = both.properties(Vec3(0, 0, 0));
    EXPECT_DOUBLE_EQ(mp.sigma_t()[0], 3.0);
    EXPECT_DOUBLE_EQ(mp.sigma_s[0], 1.9);
    EXPECT_DOUBLE_EQ(mp.emission[0], 0.1);
    for (double c : {-0.9, 0.0, 0.5, 0.99}) {
        double expected = 1.0 * Inv4Pi + 0.9 * hg->eval(c);
        EXPECT_NEAR(mp.scatterKernel(c)[1], expected, 1e-12);
        EXPECT_NEAR(mp.scatterPdf(c), expected / 1.9, 1e-12);
    }
}

TEST(MediaAggregate, MajorantBoundsTheSumEverywhere) {
    HomogeneousMedium fog(grey(0.3), Bounds3{Vec3(-1, -1, -1), Vec3(1, 1, 1)});
    ExponentialMedium air(chromatic(Spectrum(0.5, 0.8, 1.2)), 1.0, 3.0, Vec3(0, -1, 0), Vec3(0, 1, 0));
    MediumAggregate both;
    both.add(&fog);
    both.add(&air);
    Ray r{Vec3(-3, -2, 0.2), normalize(Vec3(1, 0.9, 0))};
    int checked = 0;
    double covered = 0;
    both.majorants(r, 0, 8, [&](const MajorantSegment& s) {
        covered += s.tMax - s.tMin;
        for (int i = 0; i < 20; ++i) {  // segments are half-open [tMin, tMax)
            double t = s.tMin + (s.tMax - s.tMin) * (i + 0.5) / 20.0;
            double bound = s.sigmaMaj * std::exp(-s.decay * (t - s.tMin));
            EXPECT_LE(both.properties(r.at(t)).sigma_t().maxValue(), bound * (1 + 1e-9)) << "t=" << t;
            ++checked;
        }
        return true;
    });
    EXPECT_GT(checked, 20);
    EXPECT_NEAR(covered, 8.0, 1e-9);  // the unbounded atmosphere covers the whole ray
}

TEST(MediaStress, ExtremeParametersNeverGiveNaN) {
    Rng rng(9);
    for (double sigma : {0.0, 1e-12, 1e-3, 1.0, 1e3, 1e7}) {
        for (double scale : {1e-4, 1.0, 1e5}) {
            HomogeneousMedium h(grey(sigma / scale, 1.0), Bounds3{Vec3(-scale, -scale, -scale), Vec3(scale, scale, scale)});
            ExponentialMedium e(grey(sigma / scale, 0.0), 1.0, 1.0 / scale, Vec3(0, 0, 0), Vec3(0, 0, 1));
            MediumAggregate both;
            both.add(&h);
            both.add(&e);
            for (const Medium* m : {static_cast<const Medium*>(&h), static_cast<const Medium*>(&e), static_cast<const Medium*>(&both)}) {
                for (auto mode : {TransmittanceMode::ClosedForm, TransmittanceMode::RatioTracking, TransmittanceMode::RayMarching}) {
                    TransmittanceSettings s;
                    s.mode = mode;
                    s.marchStep = scale * 0.05;
                    for (Vec3 d : {Vec3(1, 0, 0), normalize(Vec3(1, 0, 1e-12)), normalize(Vec3(0.1, 0, -1)), Vec3(0, 0, 1)}) {
                        Ray r{Vec3(-2 * scale, 0, 0.1 * scale), d};
                        Spectrum T = transmittance(*m, r, 4 * scale, rng, s);
                        ASSERT_TRUE(T.isFinite()) << m->describe() << " sigma " << sigma << " scale " << scale;
                        ASSERT_GE(T.minValue(), 0.0);
                    }
                }
            }
        }
    }
}

TEST(MediaValidation, BadParametersThrow) {
    EXPECT_THROW(HomogeneousMedium(grey(-1.0)), std::invalid_argument);
    EXPECT_THROW(HomogeneousMedium(grey(std::nan(""))), std::invalid_argument);
    EXPECT_THROW(ExponentialMedium(grey(1.0), 1.0, -1.0, Vec3(), Vec3(0, 1, 0)), std::invalid_argument);
    EXPECT_THROW(ExponentialMedium(grey(1.0), 1.0, 1.0, Vec3(), Vec3(0, 0, 0)), std::invalid_argument);
}

#include "core/gridMedium.h"
#include "core/proceduralCloud.h"

namespace {
/// A procedural cloud (32^3 voxels of 1/32, seed 3) written to the test's temporary `file` and
/// described at density scale 3 with a chromatic extinction colour.
GridMediumDesc chromaticCloudDesc(const std::string& file) {
    GridMediumDesc gd;
    gd.filePath = ::testing::TempDir() + "/" + file;
    writeProceduralCloudVdb(gd.filePath, 32, 1.0 / 32, 3);
    gd.densityScale = 3.0;
    gd.extinctionColor = Spectrum(1.0, 0.6, 1.4);
    return gd;
}
}  // namespace

TEST(MediaTransmittance, RatioTrackingIsUnbiasedOnVdb) {
    // A procedural cloud written and read back as a .vdb file, under a rotation + scale; the
    // reference optical depth is a fine midpoint quadrature of properties() along the ray, which
    // shares nothing with the majorant grid the estimators walk.
    GridMediumDesc gd = chromaticCloudDesc("media_test_cloud.vdb");
    double c = std::cos(0.4), s = std::sin(0.4);
    gd.objectToWorld.m[0][0] = 1.5 * c; gd.objectToWorld.m[0][2] = 1.5 * s;
    gd.objectToWorld.m[2][0] = -1.5 * s; gd.objectToWorld.m[2][2] = 1.5 * c;
    gd.objectToWorld.m[1][1] = 1.5;
    auto grid = loadGridMedium(gd);
    Bounds3 b = grid->bounds();
    Vec3 center = (b.lo + b.hi) * 0.5;
    for (Vec3 dir : {normalize(Vec3(1, 0.2, 0.1)), normalize(Vec3(-0.3, 1, 0.5))}) {
        Ray r{center - dir * 2.0, dir};
        const int n = 400000;
        Spectrum tau;
        for (int i = 0; i < n; ++i) tau += grid->properties(r.at((i + 0.5) * 4.0 / n)).sigma_t() * (4.0 / n);
        ASSERT_GT(tau[0], 0.3) << "the ray must cross the cloud";
        Spectrum exact = exp(-tau);
        TransmittanceSettings ratio;
        ratio.mode = TransmittanceMode::RatioTracking;
        for (int ch = 0; ch < 3; ++ch) {
            auto est = overSeeds(Seeds, [&](int seed) { return meanEstimate(*grid, r, 4.0, seed, ch, ratio); });
            EXPECT_NEAR(est.mean, exact[ch], K * est.stderr_ + 1e-4) << "channel " << ch;  // 1e-4: quadrature error
        }
    }
}

namespace {
/// A medium whose majorant is 1e12 but whose density is 0: every tentative collision is null.
class LooseMajorant final : public Medium {
public:
    MediumProperties properties(const Vec3&) const override { return {}; }
    void majorants(const Ray&, double tMin, double tMax, MajorantCallback segment) const override {
        segment(MajorantSegment{tMin, std::min(tMax, 1.0), 1e12, 0.0});
    }
    Bounds3 bounds() const override { return {Vec3(-1, -1, -1), Vec3(1, 1, 1)}; }
    bool isEmissive() const override { return false; }
    double maxAlbedo() const override { return 0; }
    double phasePeak() const override { return 1; }
    double lookupCost() const override { return 1; }
    std::string describe() const override { return "loose"; }
};
}  // namespace

TEST(MediaExtinction, EqualsTheSigmaTOfTheFullProperties) {
    // extinction() (ratio tracking's lookup, FlightLookup::Extinction) against properties().sigma_t()
    // at points inside, at the edge of and outside a chromatic VDB cloud with an albedo below 1, an
    // exponential atmosphere, and their aggregate with a homogeneous box: equal to rounding.
    GridMediumDesc gd = chromaticCloudDesc("media_test_extinction.vdb");
    gd.albedo = Spectrum(0.3, 0.8, 0.5);
    auto grid = loadGridMedium(gd);
    ExponentialMedium air(MediumCoefficients::fromAlbedo(1.0, Spectrum(0.2, 0.5, 1.0), Spectrum(0.9), Spectrum(0.0), makeRayleighPhase()),
                          0.5, 0.7, Vec3(0, 0, 0), Vec3(0, 1, 0));
    HomogeneousMedium box(MediumCoefficients::fromAlbedo(2.0, Spectrum(1.0), Spectrum(0.5), Spectrum(0.1), makeIsotropicPhase()),
                          Bounds3{Vec3(-0.2, -0.2, -0.2), Vec3(0.4, 0.4, 0.4)});
    MediumAggregate all;
    all.add(grid.get());
    all.add(&air);
    all.add(&box);
    Bounds3 b = grid->bounds();
    Rng rng(7);
    int inside = 0;
    for (int i = 0; i < 2000; ++i) {
        Vec3 p;
        for (int a = 0; a < 3; ++a) p[a] = b.lo[a] + (b.hi[a] - b.lo[a]) * (1.4 * rng.uniform() - 0.2);  // a margin around the cloud
        for (const Medium* m : {static_cast<const Medium*>(grid.get()), static_cast<const Medium*>(&air),
                                static_cast<const Medium*>(&all)}) {
            Spectrum full = m->properties(p).sigma_t(), fast = m->extinction(p);
            for (int c = 0; c < 3; ++c) ASSERT_NEAR(fast[c], full[c], 1e-12 * (1 + full[c])) << m->describe() << " at point " << i;
        }
        inside += grid->extinction(p)[0] > 0;
    }
    EXPECT_GT(inside, 200) << "too few points inside the cloud";
    EXPECT_LT(inside, 1900) << "too few points outside the cloud";
}

TEST(MediaFreeFlight, HopelesslyLooseMajorantsEndInsteadOfHanging) {
    LooseMajorant m;
    Rng rng(1);
    int events = 0;
    FlightEnd end = sampleFreeFlight(m, {Vec3(), Vec3(1, 0, 0)}, 1.0, rng, [&](const MediumEvent&) { ++events; return true; });
    EXPECT_EQ(end, FlightEnd::Truncated);
    EXPECT_EQ(events, MaxTentativeCollisions);
    TransmittanceSettings s;
    s.mode = TransmittanceMode::RatioTracking;
    EXPECT_EQ(transmittance(m, {Vec3(), Vec3(1, 0, 0)}, 1.0, rng, s)[0], 0.0);
}

TEST(MediaStress, HugeExponentialDensitiesStayFinite) {
    // a = b = 1e6 with a tilted up axis: a e^{-b h} overflows double unless computed in log space.
    ExponentialMedium m(grey(1e7, 1.0), 1e6, 1e6, Vec3(0, 0, 0), normalize(Vec3(0.3, 1, 0.1)));
    for (double y : {-1.0, -1e-3, 0.0, 1e-3, 1.0}) {
        MediumProperties mp = m.properties(Vec3(0.1, y, 0.2));
        EXPECT_TRUE(mp.sigma_t().isFinite() && mp.sigma_s.isFinite() && mp.scatterKernel(0.3).isFinite()) << y;
    }
    Rng rng(2);
    for (Vec3 d : {Vec3(0, -1, 0), Vec3(0, 1, 0), normalize(Vec3(1, 0.01, 0))}) {
        Ray r{Vec3(0, 0.5, 0), d};
        EXPECT_TRUE(transmittance(m, r, 2.0, rng).isFinite());
        EXPECT_TRUE(std::isfinite(exponentialOpticalDepth(1e6, 1e6, -0.5, -0.5, 1.0)) ||
                    std::isinf(exponentialOpticalDepth(1e6, 1e6, -0.5, -0.5, 1.0)));  // +inf is opaque, never NaN
        EXPECT_FALSE(std::isnan(exponentialOpticalDepth(1e6, 1e6, -0.5, -0.5, 1.0)));
    }
}
