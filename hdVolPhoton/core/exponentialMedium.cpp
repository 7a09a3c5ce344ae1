#include "core/exponentialMedium.h"

#include <sstream>
#include <stdexcept>

namespace volphoton {
namespace {
// exp() of anything above this overflows double; densities beyond e^MaxExponent are clamped.
constexpr double MaxExponent = 700.0;

/// (1 - e^{-x}) / x, exact as x -> 0 (the naive form cancels catastrophically below x ~ 1e-8).
double oneMinusExpOverX(double x) {
    if (x == 0) return 1.0;
    return -std::expm1(-x) / x;
}
}  // namespace

double exponentialOpticalDepth(double a, double b, double h0, double mu, double s) {
    // tau = int_0^s a e^{-b (h0 + mu t)} dt = a e^{-b h0} s (1 - e^{-b mu s}) / (b mu s)
    // a e^{-b h0} in log space, so a huge a with a large exponent cannot overflow to inf (and inf * 0
    // to NaN further on); a = 0 gives log 0 = -inf, hence 0.
    double start = std::exp(std::min(std::log(a) - b * h0, MaxExponent));
    double x = b * mu * s;
    if (x < -MaxExponent) return Infinity;  // the path dives far below h0: opaque
    return start * s * oneMinusExpOverX(x);
}

ExponentialMedium::ExponentialMedium(const MediumCoefficients& c, double a, double b, const Vec3& origin,
                                     const Vec3& up, const Bounds3& bounds)
    : c_(c), a_(a), b_(b), origin_(origin), bounds_(bounds) {
    if (!(a >= 0) || !std::isfinite(a)) throw std::invalid_argument("exponential medium: a must be finite and >= 0");
    if (!(b >= 0) || !std::isfinite(b)) throw std::invalid_argument("exponential medium: b must be finite and >= 0");
    if (!isFinite(up) || length(up) == 0) throw std::invalid_argument("exponential medium: up must be a non-zero vector");
    if (!isFinite(origin)) throw std::invalid_argument("exponential medium: origin must be finite");
    if (!c.phase) throw std::invalid_argument("exponential medium: missing phase function");
    up_ = normalize(up);
    sigmaMaxChannel_ = c_.sigma_t().maxValue();
    logA_ = std::log(a_);
    // Capped so that sigma_t itself stays finite (<= 1e300): beyond that the medium is opaque anyway.
    cap_ = std::min(MaxExponent, std::log(1e300 / std::max(1.0, sigmaMaxChannel_)));
}

double ExponentialMedium::relativeDensity(const Vec3& p) const {
    double h = dot(p - origin_, up_);
    return std::exp(std::min(logA_ - b_ * h, cap_));
}

MediumProperties ExponentialMedium::properties(const Vec3& p) const {
    MediumProperties mp;
    if (!bounds_.contains(p)) return mp;
    double d = relativeDensity(p);
    mp.sigma_a = c_.sigma_a * d;
    mp.emission = c_.emission * d;
    mp.addLobe(c_.phase.get(), c_.sigma_s * d);
    return mp;
}

// The majorant handed to the free-flight routine is the exact channel-max extinction
// sigma_max a e^{-b h(t)} = sigmaMaj e^{-b mu (t - t0)}: a decaying segment. For grey media it equals
// sigma_t, so every tentative collision is real and free flights are sampled in closed form by
// inverting tau (see freeFlight.h); chromatic media see null collisions only in the thinner channels.
// Where relativeDensity() clamps (log density above densityCapExponent()), the density is flat, so
// that part of the ray gets a constant segment: a decaying majorant there would fall below the
// clamped density and every event would gain energy (sigma_t / sigma_maj > 1 per event).
void ExponentialMedium::majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const {
    double t0, t1;
    if (sigmaMaxChannel_ == 0 || a_ == 0 || !bounds_.intersect(ray, tMin, tMax, &t0, &t1)) return;
    const double cap = densityCapExponent();
    const double decay = b_ * dot(ray.d, up_);                                // d(log density)/dt = -decay
    const double log0 = logA_ - b_ * dot(ray.at(t0) - origin_, up_);  // unclamped, at t0
    auto emit = [&](double ta, double tb, bool clamped, double logStart) {
        const Spectrum scale = c_.sigma_t() / sigmaMaxChannel_;  // each channel's own majorant
        if (clamped) segment(MajorantSegment{ta, tb, sigmaMaxChannel_ * std::exp(cap), 0.0, scale});
        else segment(MajorantSegment{ta, tb, sigmaMaxChannel_ * std::exp(std::min(logStart, cap)), decay, scale});
    };
    const double tCross = decay != 0 ? t0 + (log0 - cap) / decay : Infinity;  // log density = cap there
    if (tCross > t0 && tCross < t1) {
        if (decay > 0) {  // thinning along the ray: clamped, then decaying from the cap
            emit(t0, tCross, true, cap);
            emit(tCross, t1, false, cap);
        } else {  // thickening: growing up to the cap, then clamped
            emit(t0, tCross, false, log0);
            emit(tCross, t1, true, cap);
        }
        return;
    }
    emit(t0, t1, log0 > cap, log0);
}

std::optional<Spectrum> ExponentialMedium::opticalDepth(const Ray& ray, double t0, double t1) const {
    double a, b;
    if (!bounds_.intersect(ray, t0, t1, &a, &b)) return Spectrum(0.0);
    double h0 = dot(ray.at(a) - origin_, up_);
    double tau = exponentialOpticalDepth(a_, b_, h0, dot(ray.d, up_), b - a);
    Spectrum st = c_.sigma_t();
    Spectrum r;
    for (int i = 0; i < 3; ++i) r[i] = st[i] == 0 ? 0.0 : st[i] * tau;
    return r;
}

double ExponentialMedium::maxAlbedo() const { return c_.maxAlbedo(); }

std::string ExponentialMedium::describe() const {
    std::ostringstream s;
    s << "exponential(a=" << a_ << " b=" << b_ << " phase=" << c_.phase->describe() << ")";
    return s.str();
}

}  // namespace volphoton
