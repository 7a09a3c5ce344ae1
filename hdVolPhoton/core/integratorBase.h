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

/// Russian roulette past DeepRouletteDepth events: a path survives each further event with
/// probability at most DeepRouletteSurvival (its weight divided by it: unbiased). Ordinary roulette
/// on the throughput ends paths in absorbing media long before; this ends the paths that lose no
/// energy (an albedo-1 enclosure), on average 1000 events later, so the default maxDepth
/// (RenderSettings::DefaultMaxDepth) stays a safety cap that no furnace or slab test can detect.
constexpr int DeepRouletteDepth = 1024;
constexpr double DeepRouletteSurvival = 0.999;

/// Probability that a path at `depth` events with throughput maximum `betaMax` goes on (depth at
/// least RenderSettings::rouletteDepth): the throughput itself, at most DeepRouletteSurvival once
/// the path is deep.
inline double rouletteSurvival(double betaMax, int depth) {
    double p = std::min(1.0, betaMax);
    return depth >= DeepRouletteDepth ? std::min(p, DeepRouletteSurvival) : p;
}

/// Outcome of scattering at a surface for a path arriving along direction d.
struct SurfaceScatter {
    enum class Type { Absorbed, Diffuse, Specular, Pass };
    Type type = Type::Absorbed;
    Ray next;              ///< starts exactly at the hit point (media are tracked from there)
    double tMin = 0;       ///< where the next surface intersection may start (self-hit avoidance)
    Spectrum weight{1.0};  ///< multiplies the path throughput
    bool crossed = false;  ///< the path went through the surface (refraction or boundary)
};

/// The ray a camera path follows: surfaces are searched in [tMin, tMax] (tMax is the camera's far
/// clip, or infinity after a bounce) and media are tracked from mediumFrom (the near clip on the
/// camera ray, the vertex itself after it).
struct PathRay {
    Ray ray;
    double tMin, tMax, mediumFrom;

    /// Straight on through an index-matched boundary met at distance t (the far clip still counts).
    void passBoundary(const SurfaceScatter& s, double t) {
        ray = s.next;
        tMin = s.tMin;
        mediumFrom = 0;
        if (!std::isinf(tMax)) tMax -= t;
    }
    /// Out of a broken (open) medium mesh through a hole at distance t: the path is outside it now.
    /// t = 0: a closed mesh crossed unnoticed (Integrator::leakDistance); the same ray goes on, with
    /// the same surface offset, so the crossing it skipped is not met again from the wrong side.
    void leaveHole(MediumStack& stack, double t) {
        stack.toggle(stack.innermost());
        if (t > 0) tMin = 0;
        ray = {ray.at(t), ray.d};
        mediumFrom = 0;
        if (!std::isinf(tMax)) tMax -= t;
    }
    /// A new direction from a vertex (a medium event or a surface).
    void bounce(const Ray& next, double nextTMin) {
        ray = next;
        tMin = nextTMin;
        mediumFrom = 0;
        tMax = Infinity;
    }
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
    /// The nearest light the ray meets before tMax. cameraRay: the ray is still the camera's own (first
    /// segment), so a dome hidden by RenderSettings::domeVisibleToCamera is not met.
    bool hitLight(const Ray& ray, double tMax, double* t, Spectrum* Le, double* pdf, int* light, bool cameraRay) const;
    /// Transmittance from p along unit w over dist, through media and index-matched boundaries;
    /// 0 if any other surface blocks. `stack` is the medium stack at p; surfaces are searched from
    /// t = tMin (a spawn offset off the surface p lies on), media from t = 0.
    Spectrum shadowTransmittance(const Vec3& p, const Vec3& w, double dist, MediumStack stack, Rng& rng,
                                 double tMin = 0) const;
    /// Next-event estimate at a lambertian hit for a path arriving along ray.d: albedo/pi cos T Li / pdf
    /// for one light picked by power. With `mis`, lights with extent are weighted by the power
    /// heuristic against cosine sampling (the path tracer); without, light sampling stands alone.
    Spectrum directAtLambertian(const Ray& ray, const SurfaceHit& hit, const MediumStack& stack, Rng& rng, bool mis) const;
    /// Scatter at a surface hit. radianceMode: camera paths (divide by eta^2 on refraction); false for photons.
    SurfaceScatter scatterSurface(const Ray& ray, const SurfaceHit& hit, MediumStack& stack, Rng& rng, bool radianceMode) const;
    /// Distance at which a path inside a mesh medium with no surface ahead leaves the mesh's bounds
    /// (infinity when it is inside no mesh). Warns once per render: the mesh is not closed.
    double leakDistance(const MediumStack& stack, const Ray& ray) const;
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
