// Pieces both integrators share: light selection by power, shadow transmittance through media and
// index-matched boundaries, what a camera path meets next, and surfaces (surfaceInteraction.cpp:
// scattering and the camera path's whole surface vertex). Internal to the core.
#pragma once

#include <functional>

#include "core/freeFlight.h"
#include "core/functionRef.h"
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

/// Camera paths meet Russian roulette only once their throughput maximum has fallen below
/// RouletteWeight: the lower bound of a weight window (Booth 1982, "A weight window/importance
/// generator for Monte Carlo streaming problems"; in rendering, Vorba and Krivanek 2016, "Adjoint-driven
/// Russian roulette and splitting", sec. 3), survivors carry weight RouletteWeight. Survival = the
/// throughput itself (pbrt-v4's and Mitsuba 3's rule, ours before 2026-12-07) ended paths at
/// throughput 0.3-0.9 whose light mattered: per-sample variance x CPU time per pass on the benchmark
/// scenes (tools/bench/README.md, "Russian roulette below a weight") 0.36x on the homogeneous cube,
/// 0.41x on the surfaces-only scene, 0.90x on the VDB cloud, 1.0x on dense media, 1.13x on the
/// translucent ball (its long walks run on). Paths end anyway by escaping; the window ends the ones
/// that would not (closed rooms, low albedo), and DeepRouletteDepth the lossless ones.
constexpr double RouletteWeight = 0.1;

/// Probability that a path at `depth` events with throughput maximum `betaMax` goes on (depth at
/// least RenderSettings::rouletteDepth): 1 down to throughput RouletteWeight, proportional to the
/// throughput below it, at most DeepRouletteSurvival once the path is deep.
inline double rouletteSurvival(double betaMax, int depth) {
    double p = std::min(1.0, betaMax / RouletteWeight);
    return depth >= DeepRouletteDepth ? std::min(p, DeepRouletteSurvival) : p;
}

/// Spectral MIS over a path (Miller, Georgiev and Jarosz 2019, "A null-scattering path integral
/// formulation of light transport", sec. 5.2; pbrt-v4's VolPathIntegrator keeps the same ratios as
/// r_u), for camera paths (pathTracer.cpp) and photons (photonMapper.cpp): a path's flights are its
/// hero channel's, picked once per path (Rng::pathChoice), from that channel's own majorant
/// (SpectralFlight: in a homogeneous or exponential medium its own sigma_t, so no null collisions)
/// and with its choices at tentative collisions; channel c is weighted by f_c / avg_j p_j over the
/// path, p_j the density of the same flights and choices had channel j made them. r holds p_j / p_h
/// normalised to average one, so the path's weight (beta, a photon's flux) stays what everything
/// else uses (next-event estimates, roulette, stored photons); an event with per-channel
/// contribution f and density d multiplies the weight by f / avg(r d) and r by d / avg(r d). The
/// weight of channel c is at most 3 f_c / p_c = 3 prod(albedo_c) however long the walk.
struct SpectralMis {
    int hero = 0;
    Spectrum r{1.0};
    /// The event with contributions f and densities d (per channel); false if no channel could have
    /// made it.
    bool apply(const Spectrum& f, const Spectrum& d, Spectrum& weight) {
        Spectrum rd = r * d;
        double avg = rd.average();
        if (!(avg > 0) || !std::isfinite(avg)) return false;
        weight *= f / avg;
        r = rd / avg;
        return true;
    }
    /// A tentative collision of the hero's flight (sf: each channel's majorant there and its optical
    /// depth since the previous event) with extinction sigma_t: a real one, taken with probability
    /// *real / sigma_maj (sigma_t where it always scatters, sigma_s where absorption ends paths; its
    /// kernel, sigma_s, is the caller's), or a null one (real == nullptr). Densities and
    /// contributions are both over e^-(majorant depth), relative to the smallest depth, which cancels.
    /// Where the flight's majorant is one for all channels and sigma_t (and *real) are grey, every
    /// channel makes the same choice with the same density: r stays, a real collision divides the
    /// weight by its density and a null one leaves it.
    bool collide(const MediumEvent& e, const SpectralFlight& sf, const Spectrum& sigma_t, const Spectrum* real, Spectrum& weight) {
        auto grey = [](const Spectrum& x) { return x[0] == x[1] && x[1] == x[2]; };
        if (!sf.chromatic && grey(sigma_t) && (!real || grey(*real))) {
            const double density = real ? std::min((*real)[0], e.sigmaMaj) : e.sigmaMaj - std::min(sigma_t[0], e.sigmaMaj);
            if (!(density > 0)) return false;
            if (real) weight *= 1 / density;
            return true;
        }
        Spectrum f, d;
        const double m = sf.chromatic ? sf.depth.minValue() : 0.0;
        for (int k = 0; k < 3; ++k) {
            double q = 1, maj = e.sigmaMaj;
            if (sf.chromatic) {
                q = sf.depth[k] == m ? 1.0 : std::exp(m - sf.depth[k]);
                maj = sf.sigmaMaj[k];
            }
            if (real) {
                f[k] = q;
                d[k] = q * std::min((*real)[k], maj);
            } else {
                f[k] = d[k] = q * (maj - std::min(sigma_t[k], maj));
            }
        }
        return apply(f, d, weight);
    }
    /// A flight that left its segment after each channel's majorant optical depth `depth` (f = d =
    /// e^-depth); false if nothing can pass.
    bool escape(const Spectrum& depth, Spectrum& weight) {
        if (depth[0] == depth[1] && depth[1] == depth[2]) return std::isfinite(depth[0]);
        double m = depth.minValue();
        if (!std::isfinite(m)) return false;
        Spectrum q;
        for (int k = 0; k < 3; ++k) q[k] = depth[k] == m ? 1.0 : std::exp(m - depth[k]);
        return apply(q, q, weight);
    }
};

/// Outcome of scattering at a surface for a path arriving along direction d.
struct SurfaceScatter {
    enum class Type { Absorbed, Diffuse, Specular, Pass };
    Type type = Type::Absorbed;
    Ray next;              ///< starts exactly at the hit point (media are tracked from there)
    double tMin = 0;       ///< where the next surface intersection may start (self-hit avoidance)
    Spectrum weight{1.0};  ///< multiplies the path throughput
    bool crossed = false;  ///< the path went through the surface (refraction or boundary)
};

/// Boundary crossings a path may make before it is ended (a ray caught between coincident boundaries).
constexpr int MaxBoundaryCrossings = 256;

/// What a camera path meets next along its ray (Integrator::nextSegment): the nearest surface, the
/// nearest light, and inside a broken mesh medium the way out through a hole; the medium segment
/// ends at the nearest of them (or the ray's tMax).
struct PathSegment {
    SurfaceHit hit;
    bool hasHit = false;
    double tEnd = 0;  ///< end of the medium segment along the ray
    bool hasLight = false;
    double tLight = 0;  ///< the light's distance (infinity for distant and dome lights)
    Spectrum lightLe;
    double lightPdf = 0;  ///< the light's own solid-angle density of the direction (for MIS)
    int light = -1;
    double leakExit = Infinity;  ///< where the path leaves a broken mesh medium (Integrator::leakDistance)

    /// The path reaches the light before any surface.
    bool reachesLight() const { return hasLight && (!hasHit || tLight <= hit.t); }
    /// The path leaves a broken mesh medium through a hole before meeting anything else.
    bool leavesHole() const { return leakExit == tEnd && !std::isinf(leakExit); }
};

/// How a camera path goes on from a surface hit (Integrator::cameraSurfaceHit).
enum class SurfaceStep {
    Stop,     ///< absorbed, past settings.maxDepth or past MaxBoundaryCrossings: the path ends
    Crossed,  ///< went straight through an index-matched boundary (no vertex; the medium changed)
    Bounced,  ///< scattered by the surface (a vertex): the path goes on along the sampled direction
};

/// The ray a camera path follows: surfaces are searched in [tMin, tMax] (tMax is the camera's far
/// clip, or infinity after a bounce) and media are tracked from mediumFrom (the near clip on the
/// camera ray, the vertex itself after it). Lights are met beyond lightsFrom (past the lights the
/// path went through on this ray: lights are not scene geometry, Integrator::hitLight).
struct PathRay {
    Ray ray;
    double tMin, tMax, mediumFrom;
    double lightsFrom = 0;

    /// Straight on through an index-matched boundary met at distance t (the far clip still counts).
    void passBoundary(const SurfaceScatter& s, double t) {
        ray = s.next;
        tMin = s.tMin;
        mediumFrom = 0;
        lightsFrom = 0;
        if (!std::isinf(tMax)) tMax -= t;
    }
    /// On along the same ray through a light with extent met at distance t (its emission counted):
    /// media are tracked from t and lights met beyond it. Surfaces are still searched from tMin (one
    /// at t itself, behind a light mounted flush on it, is met next).
    void passLight(double t) {
        mediumFrom = t;
        lightsFrom = t;
    }
    /// Out of a broken (open) medium mesh through a hole at distance t: the path is outside it now.
    /// t = 0: a closed mesh crossed unnoticed (Integrator::leakDistance); the same ray goes on, with
    /// the same surface offset, so the crossing it skipped is not met again from the wrong side.
    void leaveHole(MediumStack& stack, double t) {
        stack.toggle(stack.innermost());
        if (t > 0) tMin = 0;
        ray = {ray.at(t), ray.d};
        mediumFrom = 0;
        lightsFrom = std::max(0.0, lightsFrom - t);
        if (!std::isinf(tMax)) tMax -= t;
    }
    /// A new direction from a vertex (a medium event or a surface).
    void bounce(const Ray& next, double nextTMin) {
        ray = next;
        tMin = nextTMin;
        mediumFrom = 0;
        lightsFrom = 0;
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
    /// Before pass 0: a pilot of camera samples (Renderer::cameraPilotWork) that counts the work
    /// (workCount.h) one camera pass takes with the integrator as it stands when called, on the calling
    /// thread. The photon map sizes its automatic photon count from it: once without photons, once with
    /// its pilot photons' maps (what a stored photon adds to a camera pass: its gathers).
    virtual void setCameraPilot(std::function<work::Count()> pilot) { (void)pilot; }
    /// The automatic photon count's measurement (PhotonMapper, "how many photons"): true while this
    /// pass's camera samples report their photon gathers' half-difference (PathRadiance::photonSplit).
    virtual bool measuresPhotonNoise() const { return false; }
    /// After the measurement passes: `photonVariance`, the mean over pixels of the photon map's share
    /// of a sample's variance (from photonSplit), and `sampleVariance`, a sample's whole variance
    /// (from the spread of the passes), both of the beauty's channel average.
    virtual void photonNoiseMeasured(double photonVariance, double sampleVariance, int64_t pixels, RenderStats& stats) {
        (void)photonVariance; (void)sampleVariance; (void)pixels; (void)stats;
    }
    /// The denoiser guides of a camera ray (integrator.h, "AOVs"): *albedo and *normal at its first
    /// non-specular vertex (through boundaries and smooth dielectrics); a medium collision is sampled
    /// with the free-flight routine (a real collision accepted with probability average sigma_t /
    /// sigma_maj). Black and zero where the ray escapes into nothing.
    void firstVertexGuides(const Ray& ray, double tMin, double tMax, Rng& rng, Spectrum* albedo, Spectrum* normal) const;

protected:
    /// One light picked by power (pick probability, then the light's own pair of draws). With `phase`
    /// (a medium vertex: its coefficients, reached along direction d) the pick is mediumLightPickProb's
    /// and a constant dome's direction is drawn from the phase function instead (one more draw, the
    /// lobe; ls.pdf is the phase density).
    struct PhaseAt {
        const MediumProperties& mp;
        Vec3 d;
    };
    DirectSample sampleDirect(const Vec3& p, Rng& rng, const PhaseAt* phase = nullptr) const;
    /// A medium vertex's next-event estimate samples a constant dome's direction from the phase
    /// function (the integrand's only directional factor but the transmittance) instead of the dome's
    /// sphere, so the power heuristic weighs it against the path's own continuation, drawn from the
    /// same density: a dome hit by the continuation has the light density pick x that phase density.
    /// Benchmark scene 1 (a dome-lit HG 0.5 cube): 0.60x the per-sample variance; the next-event
    /// estimate alone (the continuation's hits weighted 0) measured 1.57x (tools/bench/README.md,
    /// "Constant domes at surfaces and in media").
    bool mediumSamplesDomeByPhase(int light) const { return scene_.lights()[light]->isConstantDome(); }
    /// Probability that sampleDirect() picks light i times the light's own solid-angle density.
    double lightPickProb(int light) const { return lightDist_.size() ? lightDist_.discretePdf(light) : 0.0; }
    /// A medium vertex picks the light of its next-event estimate by power too, but constant domes
    /// count at MediumDomePickScale of theirs: such a sample draws its direction from the phase
    /// function (above), the density the path's own continuation draws from, so it is a second
    /// sample of what the continuation finds anyway, while a sun's or a small light's sample is the
    /// only one that sees it (a sun at all). By power, a sun of irradiance 3 beside a sky of radiance
    /// 0.1 lost a third of its samples to the sky (benchmark scene 2). Per-sample variance against
    /// picks by power (16 spp x 16 seeds; CPU time per pass unchanged): VDB cloud 0.74x, dense cloud
    /// 0.93x; scene 1's cube with a sun of irradiance 0.05 / 0.5 / 3 beside its dome of radiance 1
    /// 0.94x / 0.61x / 0.36x (scales 0.2 and 0.05 within 10% of 0.1; leaving domes out, scale 0,
    /// 1.47x with the faint sun: there the dome's rare samples still count). Lambertian vertices
    /// leave such domes to their bounce altogether (surfaceLeavesToBounce).
    static constexpr double MediumDomePickScale = 0.1;
    /// Probability that a medium vertex's sampleDirect() picks light i.
    double mediumLightPickProb(int light) const { return mediumLightDist_.size() ? mediumLightDist_.discretePdf(light) : 0.0; }
    /// Lambertian vertices sample every light (one sample and shadow ray each) instead of picking one
    /// by power when the scene has at most this many: picking one of a sun and a sky had 5x the
    /// per-sample variance of the two lights' separate renders on benchmark scene 7 (issue 16).
    static constexpr size_t AllLightsMax = 4;
    static_assert(2 * AllLightsMax <= Rng::eventWidth(Rng::Event::Light), "each light of an all-lights vertex has its own sampler pair");
    bool surfaceSamplesAllLights() const { return scene_.lights().size() <= AllLightsMax; }
    /// A lambertian vertex with MIS leaves a constant dome to its cosine-sampled bounce alone, as
    /// pbrt-v4's UniformInfiniteLight::SampleLi does when allowIncompletePDF: cosine sampling is
    /// proportional to that light's unoccluded integrand, while sampling the light's sphere puts half
    /// its samples below the horizon and adds the rest's variance. Benchmark scene 7: 0.84x the
    /// per-sample variance at 0.85x the time; a cosine-sampled next-event estimate weighed against the
    /// bounce measured 1.22x this (tools/bench/README.md, "Constant domes at surfaces and in media").
    bool surfaceLeavesToBounce(int light) const { return scene_.lights()[light]->isConstantDome(); }
    /// Probability with which a lambertian vertex's next-event estimation with MIS chooses light i.
    double surfaceLightPickProb(int light) const {
        return surfaceLeavesToBounce(light) ? 0.0 : surfaceSamplesAllLights() ? 1.0 : lightPickProb(light);
    }
    /// The nearest light with extent the ray meets in (tFrom, tMax); lights at infinity (dome, distant
    /// lights with extent) only when tMax is infinite, and then the first of them (lightsAtInfinity()
    /// gives them all). cameraRay: the ray is still the camera's own (first segment), so a dome hidden
    /// by RenderSettings::domeVisibleToCamera is not met.
    /// Lights are not scene geometry: shadow rays and photons pass through them, and so do camera
    /// paths (PathRay::passLight), adding the emission of every light they pass, as Cycles' paths do
    /// (integrate_light in intern/cycles/kernel/integrator/shade_light.h moves the ray's tmin past the
    /// light and the path goes on).
    bool hitLight(const Ray& ray, double tFrom, double tMax, double* t, Spectrum* Le, double* pdf, int* light,
                  bool cameraRay) const;
    /// A dome the camera's own ray does not meet (RenderSettings::domeVisibleToCamera).
    bool hiddenFromCamera(const Light& light, bool cameraRay) const {
        return cameraRay && !settings_.domeVisibleToCamera && light.isDome();
    }
    /// Every light at infinity an escaping ray meets, with its emission and its own solid-angle density.
    void lightsAtInfinity(const Ray& ray, bool cameraRay, FunctionRef<void(int light, const Spectrum& Le, double pdf)> f) const;
    /// Transmittance from p along unit w over dist, through media and index-matched boundaries;
    /// 0 if any other surface blocks. `stack` is the medium stack at p; surfaces are searched from
    /// t = tMin (a spawn offset off the surface p lies on), media from t = 0.
    Spectrum shadowTransmittance(const Vec3& p, const Vec3& w, double dist, MediumStack stack, Rng& rng,
                                 double tMin = 0) const;
    /// Next-event estimate at a lambertian hit for a path arriving along ray.d: albedo/pi cos T Li / pdf
    /// for every light (surfaceSamplesAllLights) or one light picked by power. With `mis`, lights with extent are weighted by the power
    /// heuristic against cosine sampling (the path tracer), and a constant dome is left to the bounce
    /// (surfaceLeavesToBounce); without, light sampling stands alone.
    Spectrum directAtLambertian(const Ray& ray, const SurfaceHit& hit, const MediumStack& stack, Rng& rng, bool mis) const;
    /// Radiance an emissive lambertian surface sends back along ray.d (from its front face, the side
    /// hit.ng points to), else black. The camera paths add it at their hits (weighted: emissive
    /// meshes are lights too, Scene::instanceLight).
    Spectrum surfaceEmission(const Ray& ray, const SurfaceHit& hit) const;
    /// Density (pick probability times solid angle) with which next-event estimation from `from` (a
    /// lambertian vertex when fromSurface, else a medium vertex) produces the emitter point of `hit`:
    /// 0 when the hit's instance is not a mesh light. For MIS at hits.
    double emitterDensity(const Vec3& from, const SurfaceHit& hit, bool fromSurface) const;
    /// Scatter at a surface hit. radianceMode: camera paths (divide by eta^2 on refraction); false for photons.
    SurfaceScatter scatterSurface(const Ray& ray, const SurfaceHit& hit, MediumStack& stack, Rng& rng, bool radianceMode) const;
    /// The surface, light and hole a camera path meets next along path.ray (surfaces in [tMin, tMax];
    /// lights up to the surface, or to infinity without one). cameraRay as in hitLight(). With a
    /// finite `within`, everything is searched up to it only (the segment ends there when nothing is
    /// met: tEnd == within): the path tracer's flight sampled before the search (pathTracer.cpp,
    /// EarlyFlight), where the origin is known to lie inside the media of `stack`.
    PathSegment nextSegment(const PathRay& path, const MediumStack& stack, bool cameraRay,
                            double within = Infinity) const;
    /// A camera path at a surface hit, shared by both integrators' Li(). An index-matched boundary is
    /// crossed (the stack toggled; Stop past MaxBoundaryCrossings). Any other surface is a vertex:
    /// past settings.maxDepth the path stops; else a lambertian surface adds its next-event estimate
    /// (directAtLambertian with `mis`) and the surface is sampled (scatterSurface, radiance mode):
    /// Stop when absorbed, else beta *= the sample's weight and the path bounces -> Bounced, the
    /// sample in *scatter. `add` receives beta * the direct estimate (the caller routes it to its
    /// AOVs; the hit's own emission is the caller's, surfaceEmission). Random numbers:
    /// directAtLambertian's, then scatterSurface's.
    SurfaceStep cameraSurfaceHit(PathRay& path, const SurfaceHit& hit, MediumStack& stack, Spectrum& beta, int& depth,
                                 int& crossings, Rng& rng, bool mis, FunctionRef<void(const Spectrum&)> add,
                                 SurfaceScatter* scatter) const;
    /// Distance at which a path inside a mesh medium with no surface ahead leaves the mesh's bounds
    /// (infinity when it is inside no mesh). Warns once per render: the mesh is not closed.
    double leakDistance(const MediumStack& stack, const Ray& ray) const;
    const Scene& scene_;
    RenderSettings settings_;
    TransmittanceSettings transmittance_;
    Distribution1D lightDist_;        ///< lights by power
    Distribution1D mediumLightDist_;  ///< lights by power, constant domes scaled (mediumLightPickProb)
    MediumStack cameraStack_;
};

/// Fresnel reflectance of a smooth dielectric (unpolarised); eta = n_transmitted / n_incident.
double fresnelDielectric(double cosI, double eta);

/// \class PhotonEstimate
/// The photon side of integrator = combined (photonMapper.cpp), asked by the path tracer's camera
/// paths on every segment in a medium: the photon map's estimate of the light that reaches the segment
/// after one or more scattering events (or a bounce or a refraction) and scatters towards the camera
/// along it, the photon-map integrator's multiple-scattering gather. The path tracer weights it by
/// share(stack) and continues its own paths from medium collisions with probability 1 - share: the
/// two estimates of multiply scattered light are mixed per vertex (pathTracer.cpp). Where the photon
/// side takes the whole segment (wholeSegment) the segment is the photon-map integrator's camera
/// segment: its march's single scattering too (in open media), no collision sampled.
class PhotonEstimate {
public:
    virtual ~PhotonEstimate() = default;
    /// The photon map's share of multiply scattered light at medium vertices inside the meshes of
    /// `stack`: 1 inside a translucent object (Scene::sealedFromLights: next-event estimation finds
    /// nothing there, and a delta light's light arrives only as photons), settings.combinedPhotonShare
    /// elsewhere; 0 when this pass has no photons.
    virtual double share(const MediumStack& stack) const = 0;
    /// Whether a segment in the media of `stack` is the photon-map integrator's camera segment (share
    /// 1 there): inside translucent objects, and in open media when the combined integrator's automatic
    /// share found the photon map leading there (makePhotonMapper's openMediaSegments).
    virtual bool wholeSegment(const MediumStack& stack) const = 0;
    struct Along {
        Spectrum single;    ///< whole segments in open media: the march's single scattering
        Spectrum multiple;  ///< the gather, per unit camera throughput
        Spectrum T{1.0};    ///< the segment's transmittance (closed form, else marched)
        bool interacted = false;  ///< the segment crossed a medium of nonzero density
        /// In the photon-noise measurement passes (Integrator::measuresPhotonNoise): the gather's
        /// photons of one half of the pass's paths minus the other's (Photon::half), else zero.
        Spectrum multipleSplit;
    };
    /// The gather along local.o + t local.d, t in [0, length], in the media `media` (transmittance
    /// from local.o included), single scattering too where wholeSegment(stack), and the
    /// transmittance over the whole segment. Emission stays the path tracer's.
    virtual Along along(const MediumAggregate& media, const Ray& local, double length, const MediumStack& stack,
                        Rng& rng) const = 0;
};

/// `photons`: integrator = combined's photon estimate (null: the path tracer alone).
std::unique_ptr<Integrator> makePathTracer(const Scene& scene, const RenderSettings& settings,
                                           const PhotonEstimate* photons = nullptr);
/// openMediaSegments (integrator = combined): camera segments in open media are the photon map's too
/// (wholeSegment): the automatic share where auto's pilot finds the photon map leading there.
std::unique_ptr<Integrator> makePhotonMapper(const Scene& scene, const RenderSettings& settings,
                                             std::shared_ptr<PhotonCache> cache = nullptr, bool openMediaSegments = false);

}  // namespace volphoton
