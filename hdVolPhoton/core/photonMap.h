// Volume photon map with beam queries: every photon is a disc of radius r facing the query ray, kept
// in an Embree BVH (RTC_GEOMETRY_TYPE_DISC_POINT), so one traversal finds every photon within r of a
// ray segment (Jarosz, Zwicker and Jensen 2008, "The Beam Radiance Estimate for Volumetric Photon
// Mapping"). The intersection filter records each disc and rejects it so traversal goes on.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/embreeRay.h"
#include "core/functionRef.h"
#include "core/math.h"

namespace volphoton {

/// A photon stored at a volume scattering event: the flux arriving there, without the medium's
/// scattering coefficient. sum(power * kernel) estimates the radiance arriving at a point (per
/// direction dir), and a gather applies sigma_s p of the media at its own point (PhotonMapper::gather):
/// the kernel then blurs the radiance, which is smooth across a jump of density, and not the
/// scattered source sigma_s L, which jumps with it (a camera ray in a thin medium beside a dense one
/// gathered the dense one's source with its own transmittance: up to 2x the furnace's radiance).
struct Photon {
    float p[3];
    float dir[3];  ///< propagation direction before the event
    float power[3];
    int region : 31;  ///< innermost medium mesh at the photon (-1: outside every mesh)
    /// Which half of the pass's photon paths it came from (alternate paths): the two halves' gathers
    /// differ by the photon map's own noise (PhotonMapper, "how many photons").
    unsigned half : 1;
    /// Kernel radius of this photon. The tracer stores a cap tied to the local mean free path; the map
    /// lowers it to the pass radius. Each disc's kernel integrates to one over its own area, so
    /// per-photon radii keep the estimate's energy (a sample-point kernel estimate; Jarosz et al. 2008
    /// use per-photon radii too).
    float radius;
};

/// A stored kernel radius (a mean-free-path cap, or NaN for none) as a map uses it: at most the pass
/// radius, at least 1e-6 of it (a radius of 0, a cap below float's range, would divide by zero in
/// the kernel). PhotonMap and PhotonBeamMap.
inline float kernelRadius(float stored, double passRadius) {
    const float rMax = static_cast<float>(passRadius), rMin = static_cast<float>(1e-6 * passRadius);
    return std::isnan(stored) ? rMax : std::clamp(stored, rMin, rMax);
}

/// The fraction of a disc of radius r on the near side of a line at distance `ell` from its centre
/// (1 for ell >= r, 1/2 at ell = 0): one minus the circular segment beyond the chord,
/// (r^2 acos(ell/r) - ell sqrt(r^2 - ell^2)) / (pi r^2). Negative distances count as 0 (the centre on
/// the line), so the fraction is never below 1/2.
inline double discFractionInside(double ell, double r) {
    if (!(ell < r)) return 1.0;
    double u = std::max(0.0, ell / r);
    return 1.0 - (std::acos(u) - u * std::sqrt(std::max(0.0, 1.0 - u * u))) / Pi;
}

/// \class PhotonMap
/// Built once per pass from that pass's photons, then queried concurrently.
class PhotonMap {
public:
    PhotonMap(std::vector<Photon> photons, double radius);

    /// Calls visit(photon, t along the ray, squared distance to the ray) for every photon whose own
    /// radius (Photon::radius, at most radius()) reaches the segment ray.o + t ray.d, t in [tMin, tMax].
    void query(const Ray& ray, double tMin, double tMax, FunctionRef<void(const Photon&, double, double)> visit) const;
    /// The pass radius: the largest photon radius.
    double radius() const { return radius_; }
    size_t size() const { return photons_.size(); }
    size_t bytes() const { return photons_.size() * BytesPerPhoton; }
    /// Approximate memory per stored photon: the record, its disc in Embree's vertex buffer (16 bytes)
    /// and a share of the BVH over it (an estimate of 32 bytes for Embree 3 point geometry).
    static constexpr size_t BytesPerPhoton = sizeof(Photon) + 16 + 32;

private:
    std::vector<Photon> photons_;
    double radius_;
    EmbreeScene embree_{"the photon map"};
};

}  // namespace volphoton
