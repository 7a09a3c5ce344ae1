// Overlapping media seen as one: coefficients add, each medium keeps its own scattering lobe (so
// the phase function at a point is the sigma_s-weighted mixture), and majorants add piecewise.
#pragma once

#include "core/medium.h"

namespace volphoton {

/// \class MediumAggregate
/// A non-owning view of up to MaxMedia media. It is cheap to build (an array of pointers), so the
/// integrators compose one per ray segment from the scene's unbounded media plus the medium of the
/// closed mesh the ray is inside; the scene owns the media.
class MediumAggregate final : public Medium {
public:
    static constexpr int MaxMedia = 8;
    MediumAggregate() = default;
    /// Adds a medium; returns false (and ignores it) when MaxMedia are already present.
    bool add(const Medium* medium);
    int size() const { return count_; }
    const Medium* operator[](int i) const { return media_[i]; }

    MediumProperties properties(const Vec3& p) const override;
    Spectrum extinction(const Vec3& p) const override;
    void majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const override;
    std::optional<Spectrum> opticalDepth(const Ray& ray, double t0, double t1) const override;
    /// Every medium has one.
    bool hasClosedFormDepth() const override { return count_ > 0 && closedForm_; }
    Bounds3 bounds() const override;
    bool isEmissive() const override;
    double maxAlbedo() const override;
    double phasePeak() const override;
    /// Its media's lookup costs summed.
    double lookupCost() const override { return lookupCost_; }
    std::string describe() const override;

private:
    const Medium* media_[MaxMedia] = {};
    int count_ = 0;
    double lookupCost_ = 0;
    bool closedForm_ = true;
};

}  // namespace volphoton
