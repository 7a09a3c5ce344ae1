// Exponential height density: coefficients scaled by d(h) = a * exp(-b h), h = dot(p - origin, up).
// Optical depth and free flights are closed form (see exponentialMedium.cpp for the derivation).
//
// | parameter | type     | default  | units          | meaning                                     |
// |-----------|----------|----------|----------------|---------------------------------------------|
// | coeffs    | MediumCoefficients |  | 1/scene unit   | coefficients at relative density 1          |
// | a         | double   | 1        |                | relative density at h = 0 (>= 0)            |
// | b         | double   | 1        | 1/scene unit   | falloff rate (>= 0)                          |
// | origin    | Vec3     | 0        | scene units    | point at h = 0                               |
// | up        | Vec3     | +Y       |                | direction of increasing h (normalised)       |
// | bounds    | Bounds3  | infinite | scene units    | support                                      |
// Emission scales with the density profile like the other coefficients.
#pragma once

#include "core/homogeneousMedium.h"

namespace volphoton {

/// Optical depth of the profile a e^{-b h} along a path that starts at height h0, climbs with
/// vertical cosine mu and has length s: a e^{-b h0} s (1 - e^{-b mu s})/(b mu), written with expm1 so
/// that it stays exact as b mu s -> 0 (near-horizontal rays).
double exponentialOpticalDepth(double a, double b, double h0, double mu, double s);

/// \class ExponentialMedium
class ExponentialMedium final : public Medium {
public:
    ExponentialMedium(const MediumCoefficients& c, double a, double b, const Vec3& origin, const Vec3& up,
                      const Bounds3& bounds = infiniteBounds());
    MediumProperties properties(const Vec3& p) const override;
    void majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const override;
    std::optional<Spectrum> opticalDepth(const Ray& ray, double t0, double t1) const override;
    bool hasClosedFormDepth() const override { return true; }
    Bounds3 bounds() const override { return bounds_; }
    bool isEmissive() const override { return !c_.emission.isBlack() && a_ > 0; }
    double maxAlbedo() const override;
    double phasePeak() const override { return volphoton::phasePeak(c_.phase.get()); }
    double lookupCost() const override { return work::ExponentialLookupCost; }
    std::string describe() const override;

    /// Relative density a e^{-b h} at p, with the exponent clamped so it stays finite.
    double relativeDensity(const Vec3& p) const;
    /// log of the largest relative density: beyond it the density is clamped (sigma_t <= 1e300).
    double densityCapExponent() const { return cap_; }

private:
    MediumCoefficients c_;
    double a_, b_;
    Vec3 origin_, up_;
    Bounds3 bounds_;
    double sigmaMaxChannel_;
    double logA_, cap_;  // log a (-inf for a = 0) and the cap, computed once: lookups are hot
};

}  // namespace volphoton
