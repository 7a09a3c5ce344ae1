// Pieces both integrators share: light selection by power, shadow transmittance through media and
// index-matched boundaries, and surface scattering. Internal to the core.
#pragma once

#include "core/integrator.h"
#include "core/rng.h"
#include "core/sampling.h"

namespace volphoton {

/// A light picked in proportion to power and sampled from a point.
struct DirectSample {
    LightSample ls;
    double pickProb = 0;
    int light = -1;
};

/// Outcome of scattering at a surface for a path arriving along direction d.
struct SurfaceScatter {
    enum class Type { Absorbed, Diffuse, Specular, Pass };
    Type type = Type::Absorbed;
    Ray next;
    Spectrum weight{1.0};  ///< multiplies the path throughput
    bool crossed = false;  ///< the path went through the surface (refraction or boundary)
};

/// \class Integrator
/// Camera-path estimator. beginPass() runs once per pass before the camera samples (the photon pass);
/// Li() is called concurrently from render threads and must be const.
class Integrator {
public:
    Integrator(const Scene& scene, const RenderSettings& settings);
    virtual ~Integrator() = default;
    virtual bool beginPass(int pass, RenderStats& stats, const CancelCallback& cancel) {
        (void)pass; (void)stats; (void)cancel;
        return true;
    }
    virtual PathRadiance Li(const Ray& ray, double tMin, double tMax, Rng& rng) const = 0;

protected:
    DirectSample sampleDirect(const Vec3& p, Rng& rng) const;
    /// Probability that sampleDirect() picks light i times the light's own solid-angle density.
    double lightPickProb(int light) const { return lightDist_.size() ? lightDist_.discretePdf(light) : 0.0; }
    /// Nearest light with extent hit by ray before tMax (including escape to dome/distant lights).
    bool hitLight(const Ray& ray, double tMax, double* t, Spectrum* Le, double* pdf, int* light) const;
    /// Transmittance from p along unit w over dist, through media and index-matched boundaries;
    /// 0 if any other surface blocks. `stack` is the medium stack at p.
    Spectrum shadowTransmittance(const Vec3& p, const Vec3& w, double dist, MediumStack stack, Rng& rng) const;
    /// Next-event estimate at a lambertian hit for a path arriving along ray.d: albedo/pi cos T Li / pdf
    /// for one light picked by power. With `mis`, lights with extent are weighted by the power
    /// heuristic against cosine sampling (the path tracer); without, light sampling stands alone.
    Spectrum directAtLambertian(const Ray& ray, const SurfaceHit& hit, const MediumStack& stack, Rng& rng, bool mis) const;
    /// Scatter at a surface hit. radianceMode: camera paths (divide by eta^2 on refraction); false for photons.
    SurfaceScatter scatterSurface(const Ray& ray, const SurfaceHit& hit, MediumStack& stack, Rng& rng, bool radianceMode) const;
    /// Origin offset off a surface towards the side of direction w.
    Vec3 offset(const SurfaceHit& hit, const Vec3& w) const {
        return hit.p + hit.ng * (dot(w, hit.ng) > 0 ? scene_.epsilon() : -scene_.epsilon());
    }

    const Scene& scene_;
    RenderSettings settings_;
    TransmittanceSettings transmittance_;
    Distribution1D lightDist_;
    MediumStack cameraStack_;
};

/// Fresnel reflectance of a smooth dielectric (unpolarised); eta = n_transmitted / n_incident.
double fresnelDielectric(double cosI, double eta);

std::unique_ptr<Integrator> makePathTracer(const Scene& scene, const RenderSettings& settings);
std::unique_ptr<Integrator> makePhotonMapper(const Scene& scene, const RenderSettings& settings);

}  // namespace volphoton
