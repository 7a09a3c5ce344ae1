// Phase functions: conventions and parameters in phase.h. Every single-lobe sampler below inverts
// the exact CDF F(mu) = 2 pi int_{-1}^{mu} p(mu') dmu' (so pdf() == eval() for all of them, and for
// mixtures of them) and is monotonic non-decreasing in u, which keeps stratified and low-discrepancy
// u well distributed. Each class cites the source of its formulas.
#include "core/phase.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace volphoton {
namespace {

/// |g| and |k| are clamped to this: at |g| = 1 the lobes become delta distributions.
constexpr double MaxAnisotropy = 0.99999;
/// Largest double below 1.
constexpr double OneMinusEpsilon = 0x1.fffffffffffffp-1;

double clampCos(double mu) { return std::clamp(mu, -1.0, 1.0); }

std::string formatNumber(double v) {
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
}

/// Throws for NaN or |value| > 1 and clamps |value| to MaxAnisotropy (phase.h's contract).
double checkedAnisotropy(double value, const char* kind, const char* name) {
    if (!(std::abs(value) <= 1.0))
        throw std::invalid_argument(std::string(kind) + " phase: parameter '" + name + "' must be in [-1, 1], got " +
                                    formatNumber(value));
    return std::clamp(value, -MaxAnisotropy, MaxAnisotropy);
}

// ---- isotropic --------------------------------------------------------------------------------
class IsotropicPhase final : public PhaseFunction {
public:
    double eval(double) const override { return Inv4Pi; }
    double sampleCosTheta(double u) const override { return clampCos(2 * u - 1); }
    double meanCosine() const override { return 0; }
    std::string describe() const override { return "isotropic"; }
};

// ---- linear anisotropic: p = (1 + x mu)/(4 pi), |x| <= 1 ----------------------------------------
// CDF F(mu) = ((1 + mu) + x (mu^2 - 1)/2)/2. With t = 2u - 1, F = u is the quadratic
// (x/2) mu^2 + mu - (t + x/2) = 0, whose root in [-1, 1] is taken in the cancellation-free form
// (Numerical Recipes 3rd ed., eq. 5.6.4) mu = (2t + x)/(1 + sqrt(1 + 2xt + x^2)); it is exactly
// mu = t at x = 0, so there is no 1/x. The discriminant is written (1 + xt)^2 + x^2 (1 - t^2) >= 0.
// <cos> = (1/2) int mu (1 + x mu) dmu = x/3.
class LinearPhase final : public PhaseFunction {
public:
    explicit LinearPhase(double x) : x_(x) {}
    double eval(double mu) const override { return std::max(0.0, 1 + x_ * clampCos(mu)) * Inv4Pi; }
    double sampleCosTheta(double u) const override {
        double t = 2 * u - 1;
        double a = 1 + x_ * t;
        double disc = a * a + x_ * x_ * (1 - t) * (1 + t);
        return clampCos((2 * t + x_) / (1 + std::sqrt(disc)));
    }
    double meanCosine() const override { return x_ / 3; }
    std::string describe() const override { return "linear(x=" + formatNumber(x_) + ")"; }

private:
    double x_;
};

// ---- Rayleigh: p = 3/(16 pi) (1 + mu^2) -----------------------------------------------------------
// F(mu) = (mu^3 + 3 mu + 4)/8, so F = u is the depressed cubic mu^3 + 3 mu = 4t (t = 2u - 1), which
// has a single real root. With mu = 2 sinh(s) the identity sinh(3s) = 3 sinh(s) + 4 sinh^3(s) turns
// it into sinh(3s) = 2t, hence mu = 2 sinh(asinh(2t)/3) -- Cardano's formula in hyperbolic form
// (equivalent to Frisvad 2011, "Importance sampling the Rayleigh phase function", JOSA A 28(12)),
// free of the cancellation that A - 1/A has near t = 0.
class RayleighPhase final : public PhaseFunction {
public:
    double eval(double mu) const override {
        mu = clampCos(mu);
        return 3.0 / (16.0 * Pi) * (1 + mu * mu);
    }
    double sampleCosTheta(double u) const override {
        return clampCos(2 * std::sinh(std::asinh(2 * (2 * u - 1)) / 3));
    }
    double meanCosine() const override { return 0; }
    std::string describe() const override { return "rayleigh"; }
};

// ---- Lambertian sphere ----------------------------------------------------------------------------
// A large sphere with a Lambertian surface, lit by a collimated beam (van de Hulst, "Light Scattering
// by Small Particles", 1957, sec. 8.42; Schoenberg's integral phase function of a Lambert sphere).
// In terms of the phase angle alpha (angle between the directions to the source and to the observer,
// alpha = pi - theta) it is (8/(3 pi)) (sin alpha + (pi - alpha) cos alpha) normalised to 4 pi; in
// terms of the scattering angle theta = acos(mu) between propagation directions:
//     p(theta) = 2 (sin theta - theta cos theta) / (3 pi^2),
// largest straight back (p(pi) = 2/(3 pi)), zero straight forward, and <cos theta> = -4/9.
// (Normalisation: int_0^pi (sin t - t cos t) sin t dt = pi/2 + pi/4 = 3 pi/4, and 2 pi * 2/(3 pi^2)
// * 3 pi/4 = 1.)
//
// Sampler: there is no closed-form inverse, but the CDF is closed-form, so the sampler solves it to
// machine precision (not an approximate table): P(Theta <= theta) = (4/(3 pi)) H(theta) with
//     H(theta) = int_0^theta (sin t - t cos t) sin t dt = theta/2 + theta cos(2 theta)/4 - 3 sin(2 theta)/8,
// an increasing function from 0 to 3 pi/4. A 257-entry table of H brackets the root, then
// safeguarded Newton (Numerical Recipes' rtsafe) converges to rounding error in ~2 steps (~0.15 us).
// The result is exact to rounding error in theta, so pdf() == eval().
class LambertianSpherePhase final : public PhaseFunction {
public:
    LambertianSpherePhase() {
        for (int j = 0; j <= TableSize; ++j) table_[j] = H(Pi * j / TableSize);
    }
    double eval(double mu) const override {
        mu = clampCos(mu);
        double theta = std::acos(mu);
        return 2.0 / (3.0 * Pi * Pi) * f(theta, std::sqrt(std::max(0.0, (1 - mu) * (1 + mu))), mu);
    }
    double sampleCosTheta(double u) const override {
        // Increasing in u: F(mu) = P(Theta >= theta) = u, i.e. H(theta) = (3 pi/4) (1 - u).
        double target = 0.75 * Pi * (1 - u);
        if (target <= 0) return 1;
        if (target >= table_[TableSize]) return -1;
        int j = int(std::upper_bound(table_.begin(), table_.end(), target) - table_.begin()) - 1;
        j = std::clamp(j, 0, TableSize - 1);
        double lo = Pi * j / TableSize, hi = Pi * (j + 1) / TableSize;
        double theta = lo + (hi - lo) * (target - table_[j]) / (table_[j + 1] - table_[j]);
        for (int it = 0; it < 100; ++it) {
            double s = std::sin(theta), c = std::cos(theta);
            double r = H(theta, s, c) - target;
            if (r == 0) break;
            if (r < 0) lo = theta; else hi = theta;
            double newton = theta - r / (f(theta, s, c) * s);
            if (newton >= lo && newton <= hi) {
                double step = std::abs(newton - theta);
                theta = newton;
                // Newton's error after a step d is ~ d^2/theta (H ~ theta^5 near 0) or ~ d^2/(pi - theta)
                // (near pi, where it moves mu by only d (pi - theta)), so a step below 1e-9 theta leaves
                // rounding error only.
                if (step <= 1e-9 * theta) break;
            } else {
                theta = 0.5 * (lo + hi);  // Newton left the bracket: bisect
                if (hi - lo <= 1e-15 * hi) break;
            }
        }
        return clampCos(std::cos(theta));
    }
    double meanCosine() const override { return -4.0 / 9.0; }
    std::string describe() const override { return "lambertianSphere"; }

private:
    static constexpr int TableSize = 256;
    static double H(double theta) { return H(theta, std::sin(theta), std::cos(theta)); }
    /// sin(theta) - theta cos(theta) given s = sin(theta), c = cos(theta); Taylor series where the two
    /// terms cancel: sum_{n>=1} (-1)^(n+1) 2n theta^(2n+1)/(2n+1)!.
    static double f(double theta, double s, double c) {
        if (theta < 0.5) {
            double t2 = theta * theta, term = theta * t2 / 6, sum = 0;  // theta^3/3!
            for (int n = 1; n < 12; ++n) {
                sum += (n % 2 ? 2.0 : -2.0) * n * term;
                term *= t2 / ((2 * n + 2) * (2 * n + 3));
            }
            return sum;
        }
        return s - theta * c;
    }
    /// H(theta) above, = (theta (3 - 2 s^2) - 3 s c)/4; series sum_{n>=2} (-1)^n 2^(2n-1) (n-1)
    /// theta^(2n+1)/(2n+1)! for small theta, where the closed form cancels (H ~ theta^5/15).
    static double H(double theta, double s, double c) {
        if (theta < 1) {
            double t2 = theta * theta;
            double term = 8 * theta * t2 * t2 / 120;  // 2^(2n-1) theta^(2n+1)/(2n+1)! at n = 2
            double sum = 0;
            for (int n = 2; n < 20; ++n) {
                sum += (n % 2 ? -1.0 : 1.0) * (n - 1) * term;
                term *= 4 * t2 / ((2 * n + 2) * (2 * n + 3));
            }
            return sum;
        }
        return 0.25 * (theta * (3 - 2 * s * s) - 3 * s * c);
    }
    std::array<double, TableSize + 1> table_{};
};

// ---- Henyey-Greenstein ----------------------------------------------------------------------------
// p = (1 - g^2)/(4 pi (1 + g^2 - 2 g mu)^(3/2)) (Henyey and Greenstein 1941, ApJ 93, 70; sampling as
// pbrt-v4's SampleHenyeyGreenstein, with our propagation-direction sign). Inverting F(mu) = u gives
//     mu = (1 + g^2 - s^2)/(2g),  s = (1 - g^2)/(1 - g + 2 g u).
// That form divides by g; for |g| < 1/2 we use the same expression multiplied out, which is a
// polynomial in t = 2u - 1 over (1 + g t)^2 with no 1/g and no cancellation (it is exactly t at g = 0):
//     mu = (t (1 + g^2) + g (t^2 + 3)/2 + g^3 (t^2 - 1)/2) / (1 + g t)^2.
// For |g| >= 1/2 the 1/g form is accurate; g < 0 is sampled as the mirror image, mu(g, u) =
// -mu(|g|, 1 - u), so that 1 - g + 2gu is a sum of non-negative terms. eval writes
// 1 + g^2 - 2 g mu = (1 - |g|)^2 + 2 |g| (1 - sign(g) mu), also a sum of non-negative terms, which
// keeps the forward peak accurate at |g| = 0.99999.
class HenyeyGreensteinPhase final : public PhaseFunction {
public:
    explicit HenyeyGreensteinPhase(double g) : g_(g) {}
    double eval(double mu) const override {
        mu = clampCos(mu);
        double a = std::abs(g_), m = g_ >= 0 ? mu : -mu;
        double denom = (1 - a) * (1 - a) + 2 * a * (1 - m);
        return Inv4Pi * (1 - a) * (1 + a) / (denom * std::sqrt(denom));
    }
    double sampleCosTheta(double u) const override {
        if (std::abs(g_) < 0.5) {
            double g = g_, t = 2 * u - 1, d = 1 + g * t;
            double num = t * (1 + g * g) + 0.5 * g * (t * t + 3) + 0.5 * g * g * g * (t - 1) * (t + 1);
            return clampCos(num / (d * d));
        }
        double a = std::abs(g_), w = g_ > 0 ? u : 1 - u;
        double s = (1 - a) * (1 + a) / ((1 - a) + 2 * a * w);
        double mu = (1 + a * a - s * s) / (2 * a);
        return clampCos(g_ > 0 ? mu : -mu);
    }
    double meanCosine() const override { return g_; }
    std::string describe() const override { return "henyeyGreenstein(g=" + formatNumber(g_) + ")"; }

private:
    double g_;
};

// ---- Schlick --------------------------------------------------------------------------------------
// p = (1 - k^2)/(4 pi (1 - k mu)^2) (Blasi, Le Saec and Schlick 1993, "A rendering algorithm for
// discrete volume density objects", Computer Graphics Forum 12(3); k > 0 scatters forward).
// F(mu) = (1 - k^2)/(2k) (1/(1 - k mu) - 1/(1 + k)), and F = u inverts to the Moebius map
//     mu = (t + k)/(1 + k t),  t = 2u - 1,
// with no 1/k. For k >= 0 it is evaluated as (2u - (1 - k))/((1 - k) + 2ku); k < 0 by mirroring.
//
// Mean cosine (derived here; it is not k): writing mu/(1 - k mu)^2 = (1/k)(1/(1 - k mu)^2 - 1/(1 - k mu)),
//     <cos> = (1 - k^2)/2 int_{-1}^{1} mu/(1 - k mu)^2 dmu
//           = (1/k)(1 - (1 - k^2)/(2k) ln((1 + k)/(1 - k))) = 1/k - (1 - k^2) atanh(k)/k^2,
// whose Taylor series sum_{n>=1} 2 k^(2n-1)/((2n-1)(2n+1)) = 2k/3 + 2k^3/15 + 2k^5/35 + ... is used
// for |k| < 1/4, where the closed form cancels.
class SchlickPhase final : public PhaseFunction {
public:
    explicit SchlickPhase(double k) : k_(k) {}
    double eval(double mu) const override {
        mu = clampCos(mu);
        double a = std::abs(k_), m = k_ >= 0 ? mu : -mu;
        double d = (1 - a) + a * (1 - m);  // 1 - k mu
        return Inv4Pi * (1 - a) * (1 + a) / (d * d);
    }
    double sampleCosTheta(double u) const override {
        double a = std::abs(k_), w = k_ >= 0 ? u : 1 - u;
        double mu = (2 * w - (1 - a)) / ((1 - a) + 2 * a * w);
        return clampCos(k_ >= 0 ? mu : -mu);
    }
    double meanCosine() const override { return schlickMeanCosine(k_); }
    std::string describe() const override { return "schlick(k=" + formatNumber(k_) + ")"; }

    static double schlickMeanCosine(double k) {
        if (std::abs(k) < 0.25) {
            double k2 = k * k, power = k, sum = 0;
            for (int n = 1; n < 40; ++n) {
                double term = 2 * power / ((2 * n - 1) * (2 * n + 1));
                sum += term;
                if (std::abs(term) <= 1e-17 * std::abs(sum)) break;
                power *= k2;
            }
            return sum;
        }
        return 1 / k - (1 - k) * (1 + k) * std::atanh(k) / (k * k);
    }

private:
    double k_;
};

// ---- tabulated ------------------------------------------------------------------------------------
// Piecewise linear p between values at mu_i = -1 + i h, h = 2/(n-1), normalised so that
// 2 pi int p dmu = 1 (the trapezoid rule is exact for it). The CDF at the nodes is tabulated; inside
// bin i, with a = p_i, b = p_{i+1} and x in [0, 1], the mass fraction is (a x + (b - a) x^2/2)/((a + b)/2),
// so the sampler solves that quadratic exactly, in the stable form x = 2R/(a + sqrt(a^2 + 2(b - a)R))
// (pbrt-v4 SampleLinear). Hence pdf() == eval().
class TabulatedPhase final : public PhaseFunction {
public:
    explicit TabulatedPhase(std::vector<double> values) : p_(std::move(values)), cdf_(p_.size()) {
        size_t n = p_.size();
        h_ = 2.0 / double(n - 1);
        cdf_[0] = 0;
        for (size_t i = 0; i + 1 < n; ++i) cdf_[i + 1] = cdf_[i] + 0.5 * (p_[i] + p_[i + 1]);
        double total = cdf_[n - 1];  // int p dmu / h
        double scale = 1.0 / (2 * Pi * h_ * total);
        double mean = 0;
        for (size_t i = 0; i + 1 < n; ++i) {
            double mu = -1 + h_ * double(i);
            mean += mu * 0.5 * (p_[i] + p_[i + 1]) + h_ * (p_[i] + 2 * p_[i + 1]) / 6;
        }
        mean_ = mean / total;
        for (double& v : p_) v *= scale;
        for (double& c : cdf_) c /= total;
        cdf_[n - 1] = 1;
    }
    double eval(double mu) const override {
        if (std::isnan(mu)) return mu;
        mu = clampCos(mu);
        double pos = (mu + 1) / h_;
        size_t i = std::min(size_t(pos), p_.size() - 2);
        double x = std::min(1.0, pos - double(i));
        return p_[i] * (1 - x) + p_[i + 1] * x;
    }
    double sampleCosTheta(double u) const override {
        size_t n = p_.size();
        // Last bin with cdf_[i] <= u; zero-mass bins are stepped over.
        size_t i = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin());
        i = std::clamp<size_t>(i, 1, n - 1) - 1;
        double width = cdf_[i + 1] - cdf_[i];
        double frac = width > 0 ? std::clamp((u - cdf_[i]) / width, 0.0, 1.0) : 0.0;
        double a = p_[i], b = p_[i + 1];
        double R = frac * 0.5 * (a + b);
        double disc = std::max(0.0, a * a + 2 * (b - a) * R);
        double denom = a + std::sqrt(disc);
        double x = denom > 0 ? std::clamp(2 * R / denom, 0.0, 1.0) : frac;
        return clampCos(-1 + h_ * (double(i) + x));
    }
    double meanCosine() const override { return mean_; }
    std::string describe() const override { return "tabulated(n=" + std::to_string(p_.size()) + ")"; }

private:
    std::vector<double> p_;    ///< normalised values at the nodes
    std::vector<double> cdf_;  ///< F(mu_i), cdf_.front() == 0, cdf_.back() == 1
    double h_ = 0;
    double mean_ = 0;
};

// ---- mixture --------------------------------------------------------------------------------------
// p = sum w_i p_i with sum w_i = 1; the lobe is chosen with u and u is rescaled to [0, 1) within
// that lobe's interval, so the sampled density is sum w_i pdf_i. Zero-weight lobes are kept in the
// description but never evaluated or sampled.
class MixturePhase final : public PhaseFunction {
public:
    MixturePhase(std::vector<double> weights, std::vector<PhasePtr> lobes, std::string description)
        : weights_(std::move(weights)), lobes_(std::move(lobes)), description_(std::move(description)) {
        cdf_.resize(weights_.size() + 1);
        cdf_[0] = 0;
        for (size_t i = 0; i < weights_.size(); ++i) cdf_[i + 1] = cdf_[i] + weights_[i];
        cdf_.back() = 1;
        for (size_t i = 0; i < lobes_.size(); ++i) mean_ += weights_[i] * lobes_[i]->meanCosine();
    }
    double eval(double mu) const override {
        double sum = 0;
        for (size_t i = 0; i < lobes_.size(); ++i) sum += weights_[i] * lobes_[i]->eval(mu);
        return sum;
    }
    double pdf(double mu) const override {
        double sum = 0;
        for (size_t i = 0; i < lobes_.size(); ++i) sum += weights_[i] * lobes_[i]->pdf(mu);
        return sum;
    }
    double sampleCosTheta(double u) const override {
        size_t m = lobes_.size();
        // Lobe i covers [cdf_[i], cdf_[i+1]); count the interior boundaries <= u.
        size_t i = size_t(std::upper_bound(cdf_.begin() + 1, cdf_.end() - 1, u) - (cdf_.begin() + 1));
        i = std::min(i, m - 1);
        double width = cdf_[i + 1] - cdf_[i];
        double v = width > 0 ? (u - cdf_[i]) / width : 0.0;
        return lobes_[i]->sampleCosTheta(std::clamp(v, 0.0, OneMinusEpsilon));
    }
    double meanCosine() const override { return mean_; }
    std::string describe() const override { return description_; }

private:
    std::vector<double> weights_;  ///< normalised, all > 0
    std::vector<PhasePtr> lobes_;
    std::vector<double> cdf_;
    std::string description_;
    double mean_ = 0;
};

}  // namespace

PhasePtr makeIsotropicPhase() { return std::make_shared<IsotropicPhase>(); }

PhasePtr makeLinearPhase(double x) {
    if (!(std::abs(x) <= 1.0))
        throw std::invalid_argument("linear phase: parameter 'x' must be in [-1, 1], got " + formatNumber(x));
    return std::make_shared<LinearPhase>(x);
}

PhasePtr makeRayleighPhase() { return std::make_shared<RayleighPhase>(); }

PhasePtr makeLambertianSpherePhase() { return std::make_shared<LambertianSpherePhase>(); }

PhasePtr makeHenyeyGreensteinPhase(double g) {
    return std::make_shared<HenyeyGreensteinPhase>(checkedAnisotropy(g, "henyeyGreenstein", "g"));
}

PhasePtr makeSchlickPhase(double k) {
    return std::make_shared<SchlickPhase>(checkedAnisotropy(k, "schlick", "k"));
}

// 1.55g - 0.55g^3 exceeds 1 for g in about (0.93, 1) (it peaks at 1.0015 near g = 0.969), so the result
// is clamped to [-1, 1] to keep makeSchlickPhase(schlickKFromG(g)) valid for every g in [-1, 1].
// NaN passes through (and makeSchlickPhase rejects it).
double schlickKFromG(double g) {
    double k = 1.55 * g - 0.55 * g * g * g;
    return std::isnan(k) ? k : std::clamp(k, -1.0, 1.0);
}

PhasePtr makeTabulatedPhase(const std::vector<double>& values) {
    if (values.size() < 2)
        throw std::invalid_argument("tabulated phase: parameter 'values' needs at least 2 entries, got " +
                                    std::to_string(values.size()));
    bool anyPositive = false;
    for (size_t i = 0; i < values.size(); ++i) {
        if (!(values[i] >= 0) || !std::isfinite(values[i]))
            throw std::invalid_argument("tabulated phase: parameter 'values' must be finite and >= 0, entry " +
                                        std::to_string(i) + " is " + formatNumber(values[i]));
        anyPositive = anyPositive || values[i] > 0;
    }
    if (!anyPositive) throw std::invalid_argument("tabulated phase: parameter 'values' is all zero");
    return std::make_shared<TabulatedPhase>(values);
}

PhasePtr makeMixturePhase(const std::vector<std::pair<double, PhasePtr>>& lobes) {
    if (lobes.empty()) throw std::invalid_argument("mixture phase: parameter 'lobes' is empty");
    double total = 0;
    for (size_t i = 0; i < lobes.size(); ++i) {
        double w = lobes[i].first;
        if (!(w >= 0) || !std::isfinite(w))
            throw std::invalid_argument("mixture phase: parameter 'weights' must be finite and >= 0, entry " +
                                        std::to_string(i) + " is " + formatNumber(w));
        if (!lobes[i].second)
            throw std::invalid_argument("mixture phase: parameter 'lobes' entry " + std::to_string(i) + " is null");
        total += w;
    }
    if (!(total > 0) || !std::isfinite(total))
        throw std::invalid_argument("mixture phase: parameter 'weights' must not all be zero");
    std::vector<double> weights;
    std::vector<PhasePtr> kept;
    std::string description = "mixture(";
    for (size_t i = 0; i < lobes.size(); ++i) {
        double w = lobes[i].first / total;
        description += (i ? ", " : "") + formatNumber(w) + " * " + lobes[i].second->describe();
        if (w > 0) {
            weights.push_back(w);
            kept.push_back(lobes[i].second);
        }
    }
    description += ")";
    return std::make_shared<MixturePhase>(std::move(weights), std::move(kept), std::move(description));
}

}  // namespace volphoton
