#include "core/homogeneousMedium.h"

#include <sstream>
#include <stdexcept>

namespace volphoton {

MediumCoefficients MediumCoefficients::fromAlbedo(double density, const Spectrum& extinctionColor,
                                                  const Spectrum& albedo, const Spectrum& emission,
                                                  PhasePtr phase) {
    MediumCoefficients c;
    Spectrum sigma_t = extinctionColor * density;
    c.sigma_s = sigma_t * albedo;
    c.sigma_a = sigma_t - c.sigma_s;
    c.emission = emission;
    c.phase = phase ? std::move(phase) : makeIsotropicPhase();
    return c;
}

double MediumCoefficients::maxAlbedo() const {
    Spectrum st = sigma_t();
    double m = 0;
    for (int i = 0; i < 3; ++i)
        if (st[i] > 0) m = std::max(m, sigma_s[i] / st[i]);
    return m;
}

namespace {
void validate(const MediumCoefficients& c, const char* what) {
    for (int i = 0; i < 3; ++i) {
        if (!(c.sigma_a[i] >= 0) || !(c.sigma_s[i] >= 0) || !std::isfinite(c.sigma_a[i]) || !std::isfinite(c.sigma_s[i]))
            throw std::invalid_argument(std::string(what) + ": sigma_a and sigma_s must be finite and >= 0");
        if (!std::isfinite(c.emission[i]) || c.emission[i] < 0)
            throw std::invalid_argument(std::string(what) + ": emission must be finite and >= 0");
    }
    if (!c.phase) throw std::invalid_argument(std::string(what) + ": missing phase function");
}
}  // namespace

HomogeneousMedium::HomogeneousMedium(const MediumCoefficients& c, const Bounds3& bounds)
    : c_(c), bounds_(bounds), sigmaMaj_(c.sigma_t().maxValue()) {
    validate(c_, "homogeneous medium");
}

MediumProperties HomogeneousMedium::properties(const Vec3& p) const {
    MediumProperties mp;
    if (!bounds_.contains(p)) return mp;
    mp.sigma_a = c_.sigma_a;
    mp.emission = c_.emission;
    mp.addLobe(c_.phase.get(), c_.sigma_s);
    return mp;
}

void HomogeneousMedium::majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const {
    double t0, t1;
    if (sigmaMaj_ == 0 || !bounds_.intersect(ray, tMin, tMax, &t0, &t1)) return;
    segment(MajorantSegment{t0, t1, sigmaMaj_, 0.0, c_.sigma_t() / sigmaMaj_});
}

std::optional<Spectrum> HomogeneousMedium::opticalDepth(const Ray& ray, double t0, double t1) const {
    double a, b;
    if (!bounds_.intersect(ray, t0, t1, &a, &b)) return Spectrum(0.0);
    return c_.sigma_t() * (b - a);
}

double HomogeneousMedium::maxAlbedo() const { return c_.maxAlbedo(); }

std::string HomogeneousMedium::describe() const {
    std::ostringstream s;
    s << "homogeneous(sigma_t=" << c_.sigma_t()[0] << "," << c_.sigma_t()[1] << "," << c_.sigma_t()[2]
      << " phase=" << c_.phase->describe() << ")";
    return s.str();
}

}  // namespace volphoton
