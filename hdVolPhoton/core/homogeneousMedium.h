// Homogeneous medium, optionally confined to a box.
//
// | parameter | type     | default  | units          | meaning                                   |
// |-----------|----------|----------|----------------|-------------------------------------------|
// | sigma_a   | Spectrum | 0        | 1/scene unit   | absorption coefficient per channel        |
// | sigma_s   | Spectrum | 0        | 1/scene unit   | scattering coefficient per channel        |
// | emission  | Spectrum | 0        | radiance/unit  | volume emission source term               |
// | phase     | phase    | isotropic|                | phase function                            |
// | bounds    | Bounds3  | infinite | scene units    | support; the medium is empty outside      |
#pragma once

#include "core/medium.h"
#include "core/workCount.h"

namespace volphoton {

/// Coefficients shared by the procedural media before any spatial density profile is applied.
struct MediumCoefficients {
    Spectrum sigma_a;
    Spectrum sigma_s;
    Spectrum emission;
    PhasePtr phase;

    /// sigma_t = density * extinctionColor, sigma_s = albedo * sigma_t: the schema's parametrisation.
    static MediumCoefficients fromAlbedo(double density, const Spectrum& extinctionColor, const Spectrum& albedo,
                                         const Spectrum& emission, PhasePtr phase);
    Spectrum sigma_t() const { return sigma_a + sigma_s; }
    /// Largest sigma_s / sigma_t over the channels with non-zero extinction.
    double maxAlbedo() const;
};

/// \class HomogeneousMedium
class HomogeneousMedium final : public Medium {
public:
    explicit HomogeneousMedium(const MediumCoefficients& c, const Bounds3& bounds = infiniteBounds());
    MediumProperties properties(const Vec3& p) const override;
    void majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const override;
    std::optional<Spectrum> opticalDepth(const Ray& ray, double t0, double t1) const override;
    bool hasClosedFormDepth() const override { return true; }
    Bounds3 bounds() const override { return bounds_; }
    bool isEmissive() const override { return !c_.emission.isBlack(); }
    double maxAlbedo() const override;
    double phasePeak() const override { return volphoton::phasePeak(c_.phase.get()); }
    double lookupCost() const override { return work::HomogeneousLookupCost; }
    std::string describe() const override;

private:
    MediumCoefficients c_;
    Bounds3 bounds_;
    double sigmaMaj_;
};

}  // namespace volphoton
