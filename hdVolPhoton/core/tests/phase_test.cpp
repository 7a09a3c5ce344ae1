// Phase functions (core/phase.h) against quadrature, closed forms and chi-square goodness-of-fit
// tests of their samplers.
//
// Quadrature: composite 16-point Gauss-Legendre over a graded mesh -- 64 uniform panels plus
// panels at 1 -/+ 10^(-j/4), j = 1..64, towards both poles, plus the caller's kinks (table nodes) --
// so every panel holds a smooth function that varies by at most ~2.4x across it, including the
// HG forward peak of width (1 - g)^2/(2g) = 5e-9 at g = 0.9999. Accurate to ~1e-12 here.
//
// Chi-square (as pbrt-v3's ChiSquareTest and Mitsuba's chi2 tests): 1e6 directions per phase
// function with a fixed seed, histogrammed over (cosTheta, phi) in 16 phi bins times ~70 cosTheta
// bins (40 uniform bins, the outer two subdivided geometrically down to 5e-10 from the poles);
// expected counts from quadrature of pdf(); cells with expected count < 5 pooled. The p-value is
// Q(dof/2, chi2/2) with the regularised incomplete gamma function (Numerical Recipes). Significance:
// family-wise alpha = 0.01 over all chi-square tests in this file, Bonferroni corrected, i.e. each
// test requires p > 0.01 / ChiSquareTestCount. Negative controls check the tests have power.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/phase.h"
#include "core/rng.h"

using namespace volphoton;

namespace {

// ---- quadrature ---------------------------------------------------------------------------------

struct GaussLegendre {
    static constexpr int N = 16;
    double x[N], w[N];
    // Nodes and weights on [-1, 1] by Newton on P_N (Numerical Recipes 3rd ed., sec. 4.6, gauleg).
    GaussLegendre() {
        for (int i = 0; i < (N + 1) / 2; ++i) {
            double z = std::cos(Pi * (i + 0.75) / (N + 0.5)), pp = 0;
            for (int it = 0; it < 100; ++it) {
                double p1 = 1, p2 = 0;
                for (int j = 0; j < N; ++j) {
                    double p3 = p2;
                    p2 = p1;
                    p1 = ((2 * j + 1) * z * p2 - j * p3) / (j + 1);
                }
                pp = N * (z * p1 - p2) / (z * z - 1);
                double z1 = z;
                z = z1 - p1 / pp;
                if (std::abs(z - z1) < 1e-15) break;
            }
            x[i] = -z, x[N - 1 - i] = z;
            w[i] = w[N - 1 - i] = 2 / ((1 - z * z) * pp * pp);
        }
    }
};

const std::vector<double>& gradedBreakpoints() {
    static const std::vector<double> points = [] {
        std::vector<double> p;
        for (int i = 0; i <= 64; ++i) p.push_back(-1 + 2.0 * i / 64);
        for (int j = 1; j <= 64; ++j) {
            double d = std::pow(10.0, -j / 4.0);
            p.push_back(1 - d);
            p.push_back(-1 + d);
        }
        std::sort(p.begin(), p.end());
        p.erase(std::unique(p.begin(), p.end()), p.end());
        return p;
    }();
    return points;
}

/// int_a^b f(mu) dmu for -1 <= a <= b <= 1; `kinks` are points where f is not smooth.
double integrate(const std::function<double(double)>& f, double a, double b, const std::vector<double>& kinks = {}) {
    static const GaussLegendre gl;
    std::vector<double> pts{a, b};
    for (double p : gradedBreakpoints())
        if (p > a && p < b) pts.push_back(p);
    for (double p : kinks)
        if (p > a && p < b) pts.push_back(p);
    std::sort(pts.begin(), pts.end());
    double sum = 0;
    for (size_t s = 0; s + 1 < pts.size(); ++s) {
        double lo = pts[s], hi = pts[s + 1];
        if (!(hi > lo)) continue;
        double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo), part = 0;
        for (int i = 0; i < GaussLegendre::N; ++i) part += gl.w[i] * f(mid + half * gl.x[i]);
        sum += half * part;
    }
    return sum;
}

// ---- statistics ---------------------------------------------------------------------------------

/// Regularised upper incomplete gamma function Q(a, x) = Gamma(a, x)/Gamma(a): series for x < a + 1,
/// modified-Lentz continued fraction otherwise (Press et al., Numerical Recipes 3rd ed., sec. 6.2,
/// gser and gcf).
double gammaQ(double a, double x) {
    if (x <= 0) return 1;
    double logPrefactor = -x + a * std::log(x) - std::lgamma(a);
    if (x < a + 1) {
        double ap = a, del = 1 / a, sum = del;
        for (int n = 0; n < 100000; ++n) {
            ap += 1;
            del *= x / ap;
            sum += del;
            if (std::abs(del) < std::abs(sum) * 1e-16) break;
        }
        return std::max(0.0, 1 - sum * std::exp(logPrefactor));
    }
    constexpr double FpMin = 1e-300;
    double b = x + 1 - a, c = 1 / FpMin, d = 1 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        if (std::abs(d) < FpMin) d = FpMin;
        c = b + an / c;
        if (std::abs(c) < FpMin) c = FpMin;
        d = 1 / d;
        double del = d * c;
        h *= del;
        if (std::abs(del - 1) < 1e-16) break;
    }
    return std::exp(logPrefactor) * h;
}

/// Every chi-square test in this file, for the Bonferroni correction: one per PhaseCase plus the
/// Lambertian-sphere physical-model test (negative controls are not counted: they must fail).
int chiSquareTestCount();
constexpr double FamilyAlpha = 0.01;

constexpr int SampleCount = 1000000;
constexpr int PhiBins = 16;
const Vec3 DirIn = normalize(Vec3(0.3, -0.5, 0.8));

std::vector<double> cosThetaBinEdges() {
    std::vector<double> e;
    for (int i = 0; i <= 40; ++i) e.push_back(-1 + 2.0 * i / 40);
    for (int j = 1; j <= 16; ++j) {
        double d = 0.05 * std::pow(10.0, -j / 2.0);
        e.push_back(1 - d);
        e.push_back(-1 + d);
    }
    std::sort(e.begin(), e.end());
    e.erase(std::unique(e.begin(), e.end()), e.end());
    return e;
}

struct ChiSquareResult {
    double chi2 = 0;
    int dof = 0;
    double pValue = 0;
    double totalExpectedProbability = 0;
};

/// Histograms `count` directions from `sampler` over (cosTheta, phi) around DirIn and tests them
/// against the density pdf(cosTheta)/(2 pi) per unit cosTheta per unit phi.
ChiSquareResult chiSquare(const std::function<Vec3(Rng&)>& sampler, const std::function<double(double)>& pdf,
                          const std::vector<double>& kinks, uint64_t seed, int count = SampleCount) {
    const std::vector<double> edges = cosThetaBinEdges();
    const int muBins = int(edges.size()) - 1;
    Vec3 b1 = normalize(cross(DirIn, Vec3(1, 0, 0))), b2 = cross(DirIn, b1);

    std::vector<double> observed(size_t(muBins) * PhiBins, 0.0);
    Rng rng(seed);
    for (int i = 0; i < count; ++i) {
        Vec3 w = sampler(rng);
        double mu = std::clamp(dot(DirIn, w), -1.0, 1.0);
        double phi = std::atan2(dot(w, b2), dot(w, b1));
        if (phi < 0) phi += 2 * Pi;
        int mb = int(std::upper_bound(edges.begin(), edges.end(), mu) - edges.begin()) - 1;
        mb = std::clamp(mb, 0, muBins - 1);
        int pb = std::clamp(int(phi / (2 * Pi) * PhiBins), 0, PhiBins - 1);
        observed[size_t(mb) * PhiBins + pb] += 1;
    }
    ChiSquareResult r;
    std::vector<double> expected(observed.size());
    for (int mb = 0; mb < muBins; ++mb) {
        double prob = 2 * Pi * integrate(pdf, edges[mb], edges[mb + 1], kinks);
        r.totalExpectedProbability += prob;
        for (int pb = 0; pb < PhiBins; ++pb) expected[size_t(mb) * PhiBins + pb] = prob / PhiBins * count;
    }
    // Pool cells with expected count < 5 (pbrt-v3 ChiSquareTest).
    std::vector<size_t> order(observed.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    double pooledObs = 0, pooledExp = 0;
    for (size_t idx : order) {
        if (expected[idx] == 0) {
            if (observed[idx] > 0) r.chi2 = Infinity;  // samples where the pdf says none can be
            continue;
        }
        if (expected[idx] < 5 || (pooledExp > 0 && pooledExp < 5)) {
            pooledObs += observed[idx];
            pooledExp += expected[idx];
        } else {
            double d = observed[idx] - expected[idx];
            r.chi2 += d * d / expected[idx];
            ++r.dof;
        }
    }
    if (pooledExp > 0 || pooledObs > 0) {
        double d = pooledObs - pooledExp;
        r.chi2 += pooledExp > 0 ? d * d / pooledExp : Infinity;
        ++r.dof;
    }
    r.dof -= 1;
    r.pValue = std::isfinite(r.chi2) ? gammaQ(0.5 * r.dof, 0.5 * r.chi2) : 0.0;
    return r;
}

std::function<Vec3(Rng&)> phaseSampler(const PhaseFunction& phase) {
    return [&phase](Rng& rng) {
        double u1 = rng.uniform(), u2 = rng.uniform();
        return phase.sample(DirIn, u1, u2).dirOut;
    };
}

// ---- the phase functions under test ----------------------------------------------------------

double hgValue(double g, double mu) { return (1 - g * g) / (4 * Pi * std::pow(1 + g * g - 2 * g * mu, 1.5)); }

/// A measured-looking table: forward peak, weak back lobe and a ripple, in arbitrary units, with a
/// run of exact zeros (zero-mass bins must never be sampled).
std::vector<double> measuredTable() {
    std::vector<double> v;
    const int n = 181;
    for (int i = 0; i < n; ++i) {
        double mu = -1 + 2.0 * i / (n - 1);
        double value = 37 * (0.8 * hgValue(0.85, mu) + 0.2 * hgValue(-0.4, mu) + 0.01 * (1 + std::cos(25 * mu)));
        if (mu > -0.3 && mu < -0.2) value = 0;
        v.push_back(value);
    }
    return v;
}
const std::vector<double> GapTable = {0, 0, 1, 3, 0, 0, 2, 5, 0};

std::vector<double> tableNodes(size_t n) {
    std::vector<double> nodes;
    for (size_t i = 0; i < n; ++i) nodes.push_back(-1 + 2.0 * double(i) / double(n - 1));
    return nodes;
}

/// Mean cosine of the piecewise-linear table, computed from the raw values independently of
/// phase.cpp: int mu p dmu / int p dmu, each exact for a linear p on each bin.
double tableMeanCosine(const std::vector<double>& v) {
    size_t n = v.size();
    double h = 2.0 / double(n - 1), num = 0, den = 0;
    for (size_t i = 0; i + 1 < n; ++i) {
        double a = -1 + h * double(i), b = a + h;
        // p = v_i (b - mu)/h + v_{i+1} (mu - a)/h; int mu p over [a, b] by Simpson (exact for quadratics).
        auto p = [&](double mu) { return (v[i] * (b - mu) + v[i + 1] * (mu - a)) / h; };
        double m = 0.5 * (a + b);
        num += h / 6 * (a * p(a) + 4 * m * p(m) + b * p(b));
        den += h / 2 * (v[i] + v[i + 1]);
    }
    return num / den;
}

/// <cos> of Schlick's phase function, 1/k - (1 - k^2) atanh(k)/k^2, in long double (80-bit on x86-64)
/// so that the cancellation at small k stays far below the test tolerance.
double schlickMeanClosedForm(double k) {
    if (k == 0) return 0;
    long double kk = k;
    return double(1 / kk - (1 - kk * kk) * std::atanh(kk) / (kk * kk));
}

struct PhaseCase {
    std::string name;
    PhasePtr phase;
    double analyticMean;
    std::vector<double> kinks;  ///< where eval is not smooth (for the quadrature)
};

std::string paramName(const std::string& prefix, double v) {
    std::ostringstream s;
    s << v;
    std::string out = prefix + "_";
    for (char c : s.str()) out += c == '-' ? 'm' : c == '.' ? 'p' : c == '+' ? 'P' : c;
    return out;
}

const std::vector<PhaseCase>& phaseCases() {
    static const std::vector<PhaseCase> cases = [] {
        std::vector<PhaseCase> c;
        c.push_back({"isotropic", makeIsotropicPhase(), 0.0, {}});
        c.push_back({"rayleigh", makeRayleighPhase(), 0.0, {}});
        c.push_back({"lambertianSphere", makeLambertianSpherePhase(), -4.0 / 9.0, {}});
        for (double x : {-1.0, -0.4, 0.0, 1.0}) c.push_back({paramName("linear", x), makeLinearPhase(x), x / 3, {}});
        for (double g : {-0.9999, -0.7, -1e-5, 0.0, 1e-5, 0.3, 0.9, 0.9999})
            c.push_back({paramName("hg", g), makeHenyeyGreensteinPhase(g), g, {}});
        for (double k : {-0.9999, -0.7, -1e-5, 0.0, 1e-5, 0.3, 0.9, 0.9999})
            c.push_back({paramName("schlick", k), makeSchlickPhase(k), schlickMeanClosedForm(k), {}});
        std::vector<double> measured = measuredTable();
        c.push_back({"tabulatedMeasured", makeTabulatedPhase(measured), tableMeanCosine(measured), tableNodes(181)});
        c.push_back({"tabulatedGaps", makeTabulatedPhase(GapTable), tableMeanCosine(GapTable), tableNodes(GapTable.size())});
        c.push_back({"tabulatedTwoPoints", makeTabulatedPhase({0.2, 0.7}), tableMeanCosine({0.2, 0.7}), {}});
        // Three weighted lobes (unnormalised weights 2.5 : 1.5 : 1), one a nested mixture, plus a
        // zero-weight lobe that must never be used.
        PhasePtr nested = makeMixturePhase({{0.6, makeHenyeyGreensteinPhase(-0.3)}, {0.4, makeRayleighPhase()}});
        PhasePtr mixture = makeMixturePhase({{2.5, makeHenyeyGreensteinPhase(0.8)},
                                             {1.5, nested},
                                             {1.0, makeTabulatedPhase(measured)},
                                             {0.0, makeHenyeyGreensteinPhase(-0.99)}});
        double mixtureMean = (2.5 * 0.8 + 1.5 * (0.6 * -0.3 + 0.4 * 0.0) + 1.0 * tableMeanCosine(measured)) / 5.0;
        c.push_back({"mixtureNested", mixture, mixtureMean, tableNodes(181)});
        return c;
    }();
    return cases;
}

int chiSquareTestCount() { return int(phaseCases().size()) + 1; }

double chiSquareThreshold() { return FamilyAlpha / chiSquareTestCount(); }

class PhaseFunctionTest : public ::testing::TestWithParam<size_t> {
protected:
    const PhaseCase& c() const { return phaseCases()[GetParam()]; }
    const PhaseFunction& phase() const { return *c().phase; }
    double integrateP(const std::function<double(double)>& weight) const {
        const PhaseFunction& p = phase();
        return 2 * Pi * integrate([&](double mu) { return weight(mu) * p.eval(mu); }, -1, 1, c().kinks);
    }
};

// 1. 2 pi int p dmu = 1.
TEST_P(PhaseFunctionTest, NormalisedByQuadrature) {
    EXPECT_NEAR(integrateP([](double) { return 1.0; }), 1.0, 1e-4) << phase().describe();
    // The pdf too (it differs from eval only for mixtures, where it is assembled separately).
    const PhaseFunction& p = phase();
    EXPECT_NEAR(2 * Pi * integrate([&](double mu) { return p.pdf(mu); }, -1, 1, c().kinks), 1.0, 1e-4);
}

// 2. The sampler follows pdf(): chi-square goodness of fit over (cosTheta, phi).
TEST_P(PhaseFunctionTest, SamplerPassesChiSquare) {
    const PhaseFunction& p = phase();
    ChiSquareResult r = chiSquare(phaseSampler(p), [&](double mu) { return p.pdf(mu); }, c().kinks, 1000 + GetParam());
    EXPECT_NEAR(r.totalExpectedProbability, 1.0, 1e-6);
    EXPECT_GT(r.dof, 10);
    EXPECT_GT(r.pValue, chiSquareThreshold()) << p.describe() << ": chi2 = " << r.chi2 << ", dof = " << r.dof;
}

// 2b. Deterministic complement to the chi-square test, which cannot see density errors much below
// 1e-3: every sampler except the mixture (a composition of lobe samplers, covered by PhaseMixture)
// is the exact inverse of F(mu) = 2 pi int_{-1}^{mu} pdf, with F by quadrature.
TEST_P(PhaseFunctionTest, SamplerInvertsCdf) {
    if (c().name.rfind("mixture", 0) == 0) return;
    const PhaseFunction& p = phase();
    std::vector<double> us{1e-9, 1e-6, 1e-3, 1 - 1e-3, 1 - 1e-6, 1 - 1e-9};
    for (int i = 0; i < 64; ++i) us.push_back((i + 0.5) / 64);
    for (double u : us) {
        double mu = p.sampleCosTheta(u);
        double F = 2 * Pi * integrate([&](double m) { return p.pdf(m); }, -1, mu, c().kinks);
        EXPECT_NEAR(F, u, 1e-8) << p.describe() << " mu = " << mu;
    }
}

// 3. The density reported with a sample is the pdf at the sampled direction and equals eval.
TEST_P(PhaseFunctionTest, SampledPdfEqualsEval) {
    const PhaseFunction& p = phase();
    Rng rng(77, GetParam());
    for (int i = 0; i < 20000; ++i) {
        double u1 = rng.uniform(), u2 = rng.uniform();
        double mu = p.sampleCosTheta(u1);
        PhaseSample s = p.sample(DirIn, u1, u2);
        ASSERT_GT(s.pdf, 0) << p.describe() << " u = " << u1;
        // Every sampler in phase.cpp is exact, so pdf == eval (to rounding).
        ASSERT_NEAR(s.pdf / s.p, 1.0, 1e-9) << p.describe() << " mu = " << mu;
        ASSERT_NEAR(s.pdf / p.pdf(mu), 1.0, 1e-12);
        ASSERT_NEAR(std::abs(length(s.dirOut)), 1.0, 1e-12);
        ASSERT_NEAR(dot(DirIn, s.dirOut), mu, 1e-13);
        // Recomputing cosTheta from the two directions moves it by ~1e-16; at the HG g = 0.9999 peak
        // the relative slope of p is 3/(1 - g)^2 = 3e8, hence 1e-6 rather than 1e-9 here.
        ASSERT_NEAR(p.pdf(DirIn, s.dirOut) / s.pdf, 1.0, 1e-6) << p.describe() << " mu = " << mu;
        ASSERT_NEAR(p.eval(DirIn, s.dirOut) / s.p, 1.0, 1e-6);
    }
}

// 4a. <cos> by quadrature == meanCosine() == the analytic value.
TEST_P(PhaseFunctionTest, MeanCosineMatchesQuadratureAndClosedForm) {
    double quadrature = integrateP([](double mu) { return mu; });
    EXPECT_NEAR(phase().meanCosine(), quadrature, 1e-8) << phase().describe();
    EXPECT_NEAR(phase().meanCosine(), c().analyticMean, 1e-10) << phase().describe();
}

// 4b. The sample mean of cosTheta over 1e6 samples lies within 5 standard errors of meanCosine().
TEST_P(PhaseFunctionTest, SampleMeanCosineWithinFiveStandardErrors) {
    const PhaseFunction& p = phase();
    double mean = p.meanCosine();
    double variance = integrateP([&](double mu) { return (mu - mean) * (mu - mean); });
    Rng rng(4242, GetParam());
    double sum = 0;
    for (int i = 0; i < SampleCount; ++i) sum += p.sampleCosTheta(rng.uniform()) - mean;
    double standardError = std::sqrt(variance / SampleCount);
    EXPECT_LT(std::abs(sum / SampleCount), 5 * standardError)
        << p.describe() << ": sample mean " << mean + sum / SampleCount << " vs " << mean;
}

// 5. Reciprocity: p(w -> w') = p(w' -> w), and reversing the path (-w', -w) changes nothing.
TEST_P(PhaseFunctionTest, Reciprocal) {
    const PhaseFunction& p = phase();
    Rng rng(5, GetParam());
    for (int i = 0; i < 10000; ++i) {
        Vec3 a = sphericalDirection(Vec3(0, 0, 1), 2 * rng.uniform() - 1, 2 * Pi * rng.uniform());
        Vec3 b = sphericalDirection(Vec3(0, 0, 1), 2 * rng.uniform() - 1, 2 * Pi * rng.uniform());
        ASSERT_EQ(p.eval(a, b), p.eval(b, a)) << p.describe();
        ASSERT_EQ(p.eval(a, b), p.eval(-b, -a));
        ASSERT_EQ(p.pdf(a, b), p.pdf(b, a));
        ASSERT_NEAR(p.eval(a, b), p.eval(dot(a, b)), 1e-12 * p.eval(a, b));
    }
}

// 6 (all cases). Finite values and |cos| <= 1 at the extreme u and mu; the samplers are monotonic
// in u and reach both poles.
TEST_P(PhaseFunctionTest, FiniteAtExtremesAndMonotonic) {
    const PhaseFunction& p = phase();
    for (double u : {0.0, 1e-300, 1e-17, 0.5, 1 - 0x1p-53}) {
        double mu = p.sampleCosTheta(u);
        ASSERT_TRUE(std::isfinite(mu)) << p.describe() << " u = " << u;
        ASSERT_LE(std::abs(mu), 1.0);
        PhaseSample s = p.sample(DirIn, u, u);
        ASSERT_TRUE(isFinite(s.dirOut) && std::isfinite(s.p) && std::isfinite(s.pdf));
    }
    for (double mu : {-1.0, -1 + 0x1p-53, -0.5, 0.0, 0.5, 1 - 0x1p-53, 1.0}) {
        ASSERT_TRUE(std::isfinite(p.eval(mu)) && p.eval(mu) >= 0) << p.describe() << " mu = " << mu;
        ASSERT_TRUE(std::isfinite(p.pdf(mu)) && p.pdf(mu) >= 0);
    }
    if (c().name.rfind("mixture", 0) != 0) {  // a mixture is monotonic only within each lobe
        double previous = -2;
        for (int i = 0; i <= 100000; ++i) {
            double mu = p.sampleCosTheta(std::min(i / 100000.0, 1 - 0x1p-53));
            ASSERT_GE(mu, previous) << p.describe() << " u = " << i / 100000.0;
            previous = mu;
        }
        // The extreme u reach the ends of the support (the first/last 1e-3 step where p > 0).
        double lo = -1, hi = 1;
        while (lo < 1 && p.eval(lo + 1e-3) == 0) lo += 1e-3;
        while (hi > -1 && p.eval(hi - 1e-3) == 0) hi -= 1e-3;
        EXPECT_LT(p.sampleCosTheta(1e-12), lo + 0.01) << p.describe();
        EXPECT_GT(p.sampleCosTheta(1 - 1e-12), hi - 0.01) << p.describe();
    }
    EXPECT_FALSE(p.describe().empty());
}

INSTANTIATE_TEST_SUITE_P(PhaseAll, PhaseFunctionTest, ::testing::Range<size_t>(0, phaseCases().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) { return phaseCases()[info.param].name; });

// ---- per-function checks ------------------------------------------------------------------------

TEST(PhaseLambertianSphere, MatchesPhysicalDiffuseSphere) {
    // The phase function of a large Lambertian sphere, sampled physically: a ray hits a uniformly
    // random point of the projected disc (surface normal cosine-distributed about -dirIn) and leaves
    // with a cosine-weighted direction about that normal. Checks the formula itself, not just the
    // sampler's consistency with it.
    PhasePtr p = makeLambertianSpherePhase();
    auto cosineAbout = [](const Vec3& n, double u1, double u2) {
        return sphericalDirection(n, std::sqrt(1 - u1), 2 * Pi * u2);
    };
    auto physical = [&](Rng& rng) {
        double a = rng.uniform(), b = rng.uniform(), c = rng.uniform(), d = rng.uniform();
        return cosineAbout(cosineAbout(-DirIn, a, b), c, d);
    };
    ChiSquareResult r = chiSquare(physical, [&](double mu) { return p->eval(mu); }, {}, 31337);
    EXPECT_GT(r.pValue, chiSquareThreshold()) << "chi2 = " << r.chi2 << ", dof = " << r.dof;
    // Values: zero straight forward, 2/(3 pi) straight back.
    EXPECT_NEAR(p->eval(1.0), 0.0, 1e-15);
    EXPECT_NEAR(p->eval(-1.0), 2 / (3 * Pi), 1e-15);
    EXPECT_NEAR(p->eval(0.0), 2 / (3 * Pi * Pi), 1e-15);
}

TEST(PhaseLambertianSphere, SamplerInvertsClosedFormCdf) {
    PhasePtr p = makeLambertianSpherePhase();
    // The root-finding sampler inverts the closed-form CDF
    // F(mu) = 1 - (theta (1 + 2 mu^2) - 3 mu sin(theta))/(3 pi) to rounding error (long double here),
    // on many u so that rare early exits of the iteration show up.
    auto F = [](double mu) {
        long double m = mu, theta = std::acos(m);
        return double(1 - (theta * (1 + 2 * m * m) - 3 * m * std::sqrt(1 - m * m)) / (3 * 3.14159265358979323846264338L));
    };
    double worst = 0;
    Rng rng(99);
    for (int i = 0; i < 200000; ++i) {
        double u = i < 20 ? std::ldexp(1.0, -3 * i - 1) : rng.uniform();
        for (double v : {u, std::min(1 - u, 1 - 0x1p-53)}) worst = std::max(worst, std::abs(F(p->sampleCosTheta(v)) - v));
    }
    EXPECT_LT(worst, 1e-14);
}

TEST(PhaseHenyeyGreenstein, ValuesAndSmallGContinuity) {
    for (double g : {-0.9, -0.3, 0.2, 0.6, 0.95}) {
        PhasePtr p = makeHenyeyGreensteinPhase(g);
        for (double mu : {-1.0, -0.3, 0.0, 0.4, 1.0}) EXPECT_NEAR(p->eval(mu) / hgValue(g, mu), 1.0, 1e-13);
    }
    // The small-|g| polynomial sampler and the 1/g form agree across the switch at |g| = 1/2.
    for (double u : {0.001, 0.2, 0.5, 0.9, 0.999}) {
        EXPECT_NEAR(makeHenyeyGreensteinPhase(0.5 - 1e-12)->sampleCosTheta(u),
                    makeHenyeyGreensteinPhase(0.5)->sampleCosTheta(u), 1e-11);
        EXPECT_NEAR(makeHenyeyGreensteinPhase(-0.5 + 1e-12)->sampleCosTheta(u),
                    makeHenyeyGreensteinPhase(-0.5)->sampleCosTheta(u), 1e-11);
        // g -> 0 tends to the isotropic sampler 2u - 1 without cancellation.
        EXPECT_NEAR(makeHenyeyGreensteinPhase(1e-12)->sampleCosTheta(u), 2 * u - 1, 1e-11);
        EXPECT_NEAR(makeHenyeyGreensteinPhase(-1e-12)->sampleCosTheta(u), 2 * u - 1, 1e-11);
    }
    // The exact inverse CDF: F(mu) = (1 - g^2)/(2g) ((1 + g^2 - 2 g mu)^(-1/2) - 1/(1 + g)).
    for (double g : {-0.7, 0.3, 0.9}) {
        PhasePtr p = makeHenyeyGreensteinPhase(g);
        for (double u : {0.01, 0.37, 0.8}) {
            double mu = p->sampleCosTheta(u);
            double F = (1 - g * g) / (2 * g) * (1 / std::sqrt(1 + g * g - 2 * g * mu) - 1 / (1 + g));
            EXPECT_NEAR(F, u, 1e-12);
        }
    }
}

TEST(PhaseSchlick, ExactInverseCdfAndMeanCosineClosedForm) {
    for (double k : {-0.8, -0.2, 0.45, 0.95}) {
        PhasePtr p = makeSchlickPhase(k);
        for (double u : {0.01, 0.37, 0.8}) {
            double mu = p->sampleCosTheta(u);
            double F = (1 - k * k) / (2 * k) * (1 / (1 - k * mu) - 1 / (1 + k));
            EXPECT_NEAR(F, u, 1e-12);
        }
        EXPECT_NEAR(p->eval(0.3), (1 - k * k) / (4 * Pi * (1 - 0.3 * k) * (1 - 0.3 * k)), 1e-14);
    }
    // meanCosine() switches from the series to the closed form at |k| = 1/4: both sides agree, and
    // it is not k.
    for (double k : {0.25 - 1e-12, 0.25, -0.25, 0.5, 1e-3}) {
        EXPECT_NEAR(makeSchlickPhase(k)->meanCosine(), schlickMeanClosedForm(k), 1e-14) << k;
    }
    EXPECT_NEAR(makeSchlickPhase(0.5)->meanCosine(), 2 - 1.5 * std::log(3.0), 1e-15);  // 1/k - (1-k^2) atanh(k)/k^2
    EXPECT_GT(std::abs(makeSchlickPhase(0.5)->meanCosine() - 0.5), 0.1);
}

TEST(PhaseSchlick, KFromG) {
    EXPECT_DOUBLE_EQ(schlickKFromG(0.0), 0.0);
    EXPECT_DOUBLE_EQ(schlickKFromG(0.5), 1.55 * 0.5 - 0.55 * 0.125);
    EXPECT_DOUBLE_EQ(schlickKFromG(-0.5), -(1.55 * 0.5 - 0.55 * 0.125));
    EXPECT_DOUBLE_EQ(schlickKFromG(1.0), 1.0);
    // 1.55g - 0.55g^3 overshoots 1 near g = 0.97; the result is clamped so the factory accepts it.
    EXPECT_LE(schlickKFromG(0.97), 1.0);
    for (int i = -100; i <= 100; ++i) EXPECT_NO_THROW(makeSchlickPhase(schlickKFromG(i / 100.0)));
    // The k from g gives a lobe whose mean cosine is roughly g (the fit matches shape, not <cos>).
    for (double g : {-0.6, 0.3, 0.7}) EXPECT_NEAR(makeSchlickPhase(schlickKFromG(g))->meanCosine(), g, 0.1);
}

TEST(PhaseLinear, ExactInverseCdf) {
    for (double x : {-1.0, -0.3, 1e-9, 0.6, 1.0}) {
        PhasePtr p = makeLinearPhase(x);
        for (double u : {0.0, 0.01, 0.37, 0.8, 1 - 0x1p-53}) {
            double mu = p->sampleCosTheta(u);
            EXPECT_NEAR(0.5 * ((1 + mu) + x * (mu * mu - 1) / 2), u, 1e-13) << x;
        }
    }
}

TEST(PhaseRayleigh, ExactInverseCdf) {
    PhasePtr p = makeRayleighPhase();
    for (double u : {0.0, 1e-9, 0.01, 0.37, 0.5, 0.8, 1 - 0x1p-53}) {
        double mu = p->sampleCosTheta(u);
        EXPECT_NEAR((mu * mu * mu + 3 * mu + 4) / 8, u, 1e-14);
    }
    EXPECT_NEAR(p->eval(1.0), 3 / (8 * Pi), 1e-16);
}

TEST(PhaseIsotropic, Values) {
    PhasePtr p = makeIsotropicPhase();
    for (double u : {0.0, 0.25, 0.5, 0.9}) EXPECT_EQ(p->sampleCosTheta(u), 2 * u - 1);
    EXPECT_EQ(p->eval(0.3), 1 / (4 * Pi));
}

TEST(PhaseTabulated, InterpolatesNormalisedValues) {
    // {0, 1} is p proportional to 1 + mu, i.e. linear x = 1.
    PhasePtr t = makeTabulatedPhase({0, 1}), l = makeLinearPhase(1);
    for (double mu : {-1.0, -0.3, 0.2, 1.0}) EXPECT_NEAR(t->eval(mu), l->eval(mu), 1e-15);
    for (double u : {0.0, 0.3, 0.9}) EXPECT_NEAR(t->sampleCosTheta(u), l->sampleCosTheta(u), 1e-14);
    // Scale invariance and interpolation between nodes.
    PhasePtr a = makeTabulatedPhase({1, 2, 4}), b = makeTabulatedPhase({10, 20, 40});
    EXPECT_DOUBLE_EQ(a->eval(0.5), b->eval(0.5));
    EXPECT_NEAR(a->eval(0.5) / a->eval(0.0), 3.0 / 2.0, 1e-14);
    // Zero-mass bins are never sampled, not even at u = 0 or at u exactly on a bin's CDF boundary.
    EXPECT_NEAR(makeTabulatedPhase({0, 0, 1, 1})->sampleCosTheta(0.0), -1.0 / 3.0, 1e-15);
    EXPECT_NEAR(makeTabulatedPhase({1, 0, 0, 1})->sampleCosTheta(0.5), 1.0 / 3.0, 1e-15);
    PhasePtr gaps = makeTabulatedPhase(GapTable);
    EXPECT_EQ(gaps->sampleCosTheta(0.0), -0.75);
    Rng rng(3);
    for (int i = 0; i < 100000; ++i) ASSERT_GT(gaps->eval(gaps->sampleCosTheta(rng.uniform())), 0);
}

TEST(PhaseMixture, WeightsAndLobeSelection) {
    PhasePtr hg = makeHenyeyGreensteinPhase(0.7), ray = makeRayleighPhase();
    PhasePtr m = makeMixturePhase({{3, hg}, {1, ray}});
    for (double mu : {-1.0, 0.0, 0.6, 1.0}) {
        EXPECT_NEAR(m->eval(mu), 0.75 * hg->eval(mu) + 0.25 * ray->eval(mu), 1e-15);
        EXPECT_NEAR(m->pdf(mu), m->eval(mu), 1e-15);
    }
    EXPECT_NEAR(m->meanCosine(), 0.75 * 0.7, 1e-15);
    // u in [0, 0.75) picks the HG lobe with u/0.75; [0.75, 1) the Rayleigh lobe with (u - 0.75)/0.25.
    EXPECT_NEAR(m->sampleCosTheta(0.3), hg->sampleCosTheta(0.4), 1e-14);
    EXPECT_NEAR(m->sampleCosTheta(0.8), ray->sampleCosTheta(0.2), 1e-14);
    EXPECT_TRUE(std::isfinite(m->sampleCosTheta(1 - 0x1p-53)));
    // A single lobe is that lobe.
    PhasePtr single = makeMixturePhase({{0.2, hg}});
    EXPECT_DOUBLE_EQ(single->sampleCosTheta(0.123), hg->sampleCosTheta(0.123));
    EXPECT_NE(m->describe().find("henyeyGreenstein"), std::string::npos);
}

// 6. Stability at the anisotropy clamps and at g, k -> 0.
TEST(PhaseStability, ExtremeParameters) {
    std::vector<PhasePtr> phases;
    for (double v : {0.99999, -0.99999, 1.0, -1.0, 1e-12, -1e-12, 1 - 1e-16, 0.999995}) {
        phases.push_back(makeHenyeyGreensteinPhase(v));
        phases.push_back(makeSchlickPhase(v));
    }
    for (const PhasePtr& p : phases) {
        for (double u : {0.0, 1e-300, 0.5, 1 - 0x1p-53}) {
            double mu = p->sampleCosTheta(u);
            ASSERT_TRUE(std::isfinite(mu)) << p->describe() << " u = " << u;
            ASSERT_LE(std::abs(mu), 1.0);
            ASSERT_TRUE(std::isfinite(p->eval(mu)) && p->eval(mu) >= 0) << p->describe() << " u = " << u;
            ASSERT_TRUE(std::isfinite(p->pdf(mu)) && p->pdf(mu) > 0) << p->describe() << " u = " << u;
            PhaseSample s = p->sample(DirIn, u, u);
            ASSERT_TRUE(isFinite(s.dirOut) && std::isfinite(s.p) && std::isfinite(s.pdf));
        }
        for (double mu : {-1.0, -1 + 0x1p-53, 0.0, 1 - 0x1p-53, 1.0})
            ASSERT_TRUE(std::isfinite(p->eval(mu)) && p->eval(mu) > 0) << p->describe() << " mu = " << mu;
        ASSERT_LE(std::abs(p->meanCosine()), 0.99999 + 1e-12) << p->describe();
    }
    // |g| = 1 is clamped to 0.99999 and the clamped lobe is still normalised.
    PhasePtr hg = makeHenyeyGreensteinPhase(1.0);
    EXPECT_DOUBLE_EQ(hg->meanCosine(), 0.99999);
    EXPECT_NEAR(2 * Pi * integrate([&](double mu) { return hg->eval(mu); }, -1, 1), 1.0, 1e-6);
    PhasePtr sk = makeSchlickPhase(-1.0);
    EXPECT_NEAR(2 * Pi * integrate([&](double mu) { return sk->eval(mu); }, -1, 1), 1.0, 1e-6);
    EXPECT_NEAR(sk->meanCosine(), schlickMeanClosedForm(-0.99999), 1e-12);
}

// 7. Invalid parameters throw std::invalid_argument naming the parameter.
template <typename F>
void expectInvalid(F&& make, const std::string& parameter) {
    try {
        make();
        ADD_FAILURE() << "no exception; expected one naming '" << parameter << "'";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(parameter), std::string::npos) << e.what();
    }
}

TEST(PhaseInvalid, FactoriesThrow) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (double v : {nan, 1.0000001, -1.5, Infinity, -Infinity}) {
        expectInvalid([&] { makeHenyeyGreensteinPhase(v); }, "'g'");
        expectInvalid([&] { makeSchlickPhase(v); }, "'k'");
        expectInvalid([&] { makeLinearPhase(v); }, "'x'");
    }
    expectInvalid([] { makeSchlickPhase(schlickKFromG(std::numeric_limits<double>::quiet_NaN())); }, "'k'");
    expectInvalid([] { makeTabulatedPhase({}); }, "'values'");
    expectInvalid([] { makeTabulatedPhase({1.0}); }, "'values'");
    expectInvalid([] { makeTabulatedPhase({1.0, -0.1}); }, "'values'");
    expectInvalid([&] { makeTabulatedPhase({1.0, nan}); }, "'values'");
    expectInvalid([] { makeTabulatedPhase({1.0, Infinity}); }, "'values'");
    expectInvalid([] { makeTabulatedPhase({0.0, 0.0, 0.0}); }, "'values'");
    PhasePtr iso = makeIsotropicPhase();
    expectInvalid([] { makeMixturePhase({}); }, "'lobes'");
    expectInvalid([&] { makeMixturePhase({{1.0, iso}, {-0.5, iso}}); }, "'weights'");
    expectInvalid([&] { makeMixturePhase({{nan, iso}}); }, "'weights'");
    expectInvalid([&] { makeMixturePhase({{Infinity, iso}}); }, "'weights'");
    expectInvalid([&] { makeMixturePhase({{0.0, iso}, {0.0, iso}}); }, "'weights'");
    expectInvalid([&] { makeMixturePhase({{1.0, nullptr}}); }, "'lobes'");
    // Boundary values are valid.
    EXPECT_NO_THROW(makeLinearPhase(1.0));
    EXPECT_NO_THROW(makeLinearPhase(-1.0));
    EXPECT_NO_THROW(makeHenyeyGreensteinPhase(-1.0));
    EXPECT_NO_THROW(makeSchlickPhase(1.0));
    EXPECT_NO_THROW(makeMixturePhase({{0.0, iso}, {1e-300, iso}}));
}

// ---- the test machinery itself ------------------------------------------------------------------

TEST(PhaseTestHarness, IncompleteGammaAgainstClosedForms) {
    for (double x : {0.01, 0.5, 2.0, 10.0, 40.0}) {
        EXPECT_NEAR(gammaQ(1.0, x), std::exp(-x), 1e-14 + 1e-12 * std::exp(-x));          // Q(1, x) = e^-x
        EXPECT_NEAR(gammaQ(0.5, x), std::erfc(std::sqrt(x)), 1e-14);                       // Q(1/2, x)
        EXPECT_NEAR(gammaQ(2.0, x), (1 + x) * std::exp(-x), 1e-14 + 1e-12 * std::exp(-x));  // Q(2, x)
    }
    // Chi-square with 100 dof: the median is ~99.33.
    EXPECT_NEAR(gammaQ(50.0, 99.3341 / 2), 0.5, 1e-4);
}

TEST(PhaseTestHarness, QuadratureIsAccurateOnPeakedLobes) {
    // int (1 + g^2 - 2 g mu)^(-3/2) dmu = 2/(1 - g^2) exactly; the base is written as
    // (1 - |g|)^2 + 2|g|(1 -/+ mu) so that the integrand itself is accurate at the peak.
    for (double g : {0.9999, -0.99999}) {
        double a = std::abs(g);
        double v = integrate(
            [&](double mu) { return std::pow((1 - a) * (1 - a) + 2 * a * (1 - (g > 0 ? mu : -mu)), -1.5); }, -1, 1);
        // At |g| = 0.99999 the peak (width 5e-11) spans only ~5e5 doubles, so the rounding of the
        // Gauss nodes to representable mu limits the accuracy to ~1e-7.
        EXPECT_NEAR(v * (1 - g * g) / 2, 1.0, a < 0.99995 ? 1e-9 : 1e-6) << g;
    }
}

// Negative controls: the chi-square and sample-mean tests reject samplers that are slightly wrong,
// so a passing test above means something. (Not part of the Bonferroni family: these must fail.)
TEST(PhaseTestHarness, ChiSquareRejectsWrongSamplers) {
    PhasePtr hg = makeHenyeyGreensteinPhase(0.3), hgOff = makeHenyeyGreensteinPhase(0.31);
    EXPECT_LT(chiSquare(phaseSampler(*hgOff), [&](double mu) { return hg->pdf(mu); }, {}, 9).pValue, 1e-6);
    // Schlick with k(g) is a close but different lobe from HG(g).
    PhasePtr hg9 = makeHenyeyGreensteinPhase(0.9), sk9 = makeSchlickPhase(schlickKFromG(0.9));
    EXPECT_LT(chiSquare(phaseSampler(*sk9), [&](double mu) { return hg9->pdf(mu); }, {}, 10).pValue, 1e-6);
    // A Lambertian-sphere sampler with u slightly warped.
    PhasePtr ls = makeLambertianSpherePhase();
    auto warped = [&](Rng& rng) {
        double u1 = rng.uniform(), u2 = rng.uniform();
        return sphericalDirection(DirIn, ls->sampleCosTheta(std::pow(u1, 1.05)), 2 * Pi * u2);
    };
    EXPECT_LT(chiSquare(warped, [&](double mu) { return ls->pdf(mu); }, {}, 11).pValue, 1e-6);
    // Non-uniform azimuth is caught by the phi bins.
    auto badPhi = [&](Rng& rng) {
        double u1 = rng.uniform(), u2 = rng.uniform();
        return sphericalDirection(DirIn, hg->sampleCosTheta(u1), 2 * Pi * (0.1 * u2 * u2 + 0.9 * u2));
    };
    EXPECT_LT(chiSquare(badPhi, [&](double mu) { return hg->pdf(mu); }, {}, 12).pValue, 1e-6);
    // The sample mean of HG(0.3)'s sampler is far (~9 standard errors) from 0.305.
    Rng rng(13);
    double sum = 0;
    for (int i = 0; i < SampleCount; ++i) sum += hg->sampleCosTheta(rng.uniform());
    double se = std::sqrt((1 - 0.09) / 3 / SampleCount);  // HG variance (1 - g^2)/3
    EXPECT_GT(std::abs(sum / SampleCount - 0.305), 5 * se);
}

}  // namespace
