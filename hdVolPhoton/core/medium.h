// The medium interface shared by every estimator: local coefficients at a point, and majorant
// segments along a ray for the single free-flight routine (freeFlight.h).
#pragma once

#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "core/functionRef.h"
#include "core/math.h"
#include "core/phase.h"

namespace volphoton {

/// One scattering lobe at a point: a phase function and the scattering coefficient it carries.
struct ScatterLobe {
    const PhaseFunction* phase = nullptr;
    Spectrum sigma_s;
};

/// Coefficients of the radiative transfer equation at a point (pbrt's MediumProperties). Where media
/// overlap, coefficients add and each medium contributes its own lobe, so the phase function at the
/// point is the sigma_s-weighted mixture, per colour channel.
struct MediumProperties {
    static constexpr int MaxLobes = 8;
    Spectrum sigma_a;
    Spectrum sigma_s;
    /// Volume emission source term: radiance added per unit length (W sr^-1 m^-2 per unit length).
    Spectrum emission;
    ScatterLobe lobes[MaxLobes];
    int lobeCount = 0;

    Spectrum sigma_t() const { return sigma_a + sigma_s; }
    void addLobe(const PhaseFunction* phase, const Spectrum& s) {
        sigma_s += s;
        if (s.isBlack()) return;
        if (lobeCount < MaxLobes) {
            lobes[lobeCount++] = {phase, s};
        } else {  // Beyond MaxLobes overlapping scatterers the last lobe absorbs the rest's weight.
            lobes[MaxLobes - 1].sigma_s += s;
        }
    }
    /// Scattering kernel sigma_s(c) p(cosTheta) summed over lobes (1/(length sr)), per channel.
    Spectrum scatterKernel(double cosTheta) const {
        Spectrum k;
        for (int i = 0; i < lobeCount; ++i) k += lobes[i].sigma_s * lobes[i].phase->eval(cosTheta);
        return k;
    }
    /// Density of sampleScatter(): the lobe mixture weighted by channel-average sigma_s.
    double scatterPdf(double cosTheta) const {
        double total = 0, pdf = 0;
        for (int i = 0; i < lobeCount; ++i) {
            double w = lobes[i].sigma_s.average();
            total += w;
            pdf += w * lobes[i].phase->pdf(cosTheta);
        }
        return total > 0 ? pdf / total : 0.0;
    }
    /// Picks a lobe in proportion to its average sigma_s with u0 and samples it with (u1, u2).
    /// Returns the new direction; the caller weights by scatterKernel / scatterPdf.
    Vec3 sampleScatter(const Vec3& dirIn, double u0, double u1, double u2) const {
        double total = 0;
        for (int i = 0; i < lobeCount; ++i) total += lobes[i].sigma_s.average();
        double target = u0 * total;
        int chosen = lobeCount - 1;
        for (int i = 0; i < lobeCount; ++i) {
            target -= lobes[i].sigma_s.average();
            if (target < 0) { chosen = i; break; }
        }
        return lobes[chosen].phase->sample(dirIn, u1, u2).dirOut;
    }
};

/// A piece [tMin, tMax) of a ray over which the scalar majorant
///   sigma_maj(t) = sigmaMaj * exp(-decay * (t - tMin))
/// bounds max_c sigma_t,c from above. decay = 0 is pbrt's constant RayMajorantSegment; a non-zero
/// decay lets the exponential-height medium hand over its exact extinction, so its free flights are
/// sampled in closed form by the same routine (no null collisions for grey media).
struct MajorantSegment {
    double tMin = 0, tMax = 0;
    double sigmaMaj = 0;
    double decay = 0;
    /// Each channel's own majorant over the piece is channelScale[c] x the scalar one (components in
    /// [0, 1]): a homogeneous or exponential medium's sigma_t over its largest channel, 1 where the
    /// majorant bounds all channels alike (grids, overlaps). The path tracer's hero-channel flights
    /// draw their tentative collisions from their channel's own majorant (sampleFreeFlight,
    /// SpectralFlight), so in a chromatic homogeneous medium they meet no null collisions.
    Spectrum channelScale{1.0};
    /// The majorant's optical depth over the first `len` of the piece: sigmaMaj len (1 - e^{-x}) / x,
    /// x = decay len (expm1: exact as x -> 0).
    double opticalDepth(double len) const {
        double x = decay * len;
        return sigmaMaj * len * (x == 0 ? 1.0 : -std::expm1(-x) / x);
    }
};

using MajorantCallback = FunctionRef<bool(const MajorantSegment&)>;

/// \class Medium
/// Immutable after construction and shared between render threads. Positions are world space.
class Medium {
public:
    virtual ~Medium() = default;
    /// Local coefficients at p. Outside the medium's support every coefficient is zero.
    virtual MediumProperties properties(const Vec3& p) const = 0;
    /// sigma_t at p alone, what ratio tracking needs: a grid skips its albedo, emission and lobes.
    virtual Spectrum extinction(const Vec3& p) const { return properties(p).sigma_t(); }
    /// Calls `segment` for consecutive majorant segments covering the parts of [tMin, tMax] where the
    /// medium may be non-zero, in increasing t. Gaps have zero extinction. Stops when it returns false.
    virtual void majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const = 0;
    /// Closed-form optical depth per channel along [t0, t1], where one exists (homogeneous, exponential).
    virtual std::optional<Spectrum> opticalDepth(const Ray& ray, double t0, double t1) const {
        (void)ray; (void)t0; (void)t1;
        return std::nullopt;
    }
    /// opticalDepth() has a value for every ray: transmittance is exp(-tau), no tracking.
    virtual bool hasClosedFormDepth() const { return false; }
    /// World-space box outside which the medium is empty (may be infinite).
    virtual Bounds3 bounds() const = 0;
    virtual bool isEmissive() const = 0;
    /// Largest single-scattering albedo anywhere (channel max); used to skip multiple scattering.
    virtual double maxAlbedo() const = 0;
    /// The largest phasePeak() of its phase functions (1: isotropic).
    virtual double phasePeak() const = 0;
    /// What one properties() call costs, in work units (core/workCount.h): the automatic photon
    /// count weighs the lookups of a camera pass and of a photon with it.
    virtual double lookupCost() const = 0;
    virtual std::string describe() const = 0;
};

using MediumPtr = std::shared_ptr<const Medium>;

/// Bounds with every coordinate infinite: an unbounded medium (fog everywhere, an atmosphere).
inline Bounds3 infiniteBounds() { return {{-Infinity, -Infinity, -Infinity}, {Infinity, Infinity, Infinity}}; }

}  // namespace volphoton
