// Integrator 2: photon mapping with separate single- and multiple-scattering passes.
//
//  - Single scattering: each camera segment inside media is ray marched with stratified jittered
//    steps; at each step one light (picked by power among lights with extent and distant/dome lights)
//    is sampled with a shadow ray. Point and spot lights are handled by equiangular sampling of the
//    segment instead (Kulla and Fajardo 2012), one sample per point light per segment.
//  - Multiple scattering: photons leave the lights in proportion to power, fly through the core's
//    free-flight routine, each by one hero channel with spectral MIS (SpectralMis, integratorBase.h;
//    for grey media that is d = -ln(xi)/sigma_t with absorption by Russian roulette on the albedo;
//    photon-map per-sample variance on the benchmark's atmosphere 0.48x, marble figurine 0.67x against
//    spectral tracking under the largest majorant), and are stored at volume scattering events once
//    they have scattered, bounced or met a dielectric before (the first event of light arriving in a
//    straight line is the single pass's; its shadow rays stop at dielectrics, so light refracted into
//    a translucent object is all in the photon map).
//    Camera segments gather them with the beam radiance estimate (photonMap.h); the radius shrinks
//    as r_{i+1}^2 = r_i^2 (i + alpha)/(i + 1) (Knaus and Zwicker 2011, 2D kernel) per 1e5 photons
//    traced (passRadius), so the average over passes converges.
//  - Surfaces: direct light by light sampling; indirect light by continuing the camera path with a
//    diffuse bounce, whose media segments again get single + multiple estimates. So surfaces lit by
//    media and media lit through surfaces are both counted, each exactly once.
//  - Camera transmittance: closed form where the media have one, else the marched optical depth.
//    Early termination: below a transmittance of 1e-3 the march continues with probability 1/2 and
//    doubled weight (Russian roulette, unbiased given the march); `transmittanceCutoff` stops it
//    outright instead (BIASED).
//
//  - Volume emission: along camera segments by the march (the `emission` AOV); emissive media also
//    emit photons (uniform points in the medium's box, weighted by the local emission) so light they
//    send into scattering media is in the photon map.
//
// Integrator 3, combined, is this class too: its photon passes, and the path tracer's camera paths
// (cameraPaths_, pathTracer.cpp) asking it for the multiple-scattering gather along their segments
// (PhotonEstimate, integratorBase.h: share(), wholeSegment() and along()). With combinedPhotonShare 0
// it stores photons inside translucent objects only (storedIn) and traces none where there is no such
// object; with openMediaSegments its march takes single scattering in open media too.
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstring>
#include <mutex>

#include "core/diagnostics.h"
#include "core/freeFlight.h"
#include "core/integratorBase.h"
#include "core/photonCache.h"
#include "core/photonBeams.h"
#include "core/photonMap.h"
#include "core/workCount.h"

namespace volphoton {
namespace {

constexpr int PhotonBatch = 1024;

class PhotonMapper final : public Integrator, public PhotonEstimate {
public:
    PhotonMapper(const Scene& scene, const RenderSettings& settings, std::shared_ptr<PhotonCache> cache, bool openMediaSegments)
        : Integrator(scene, settings),
          openSegments_(openMediaSegments && settings.integrator == RenderSettings::Integrator::Combined),
          cache_(std::move(cache)) {
        // integrator = combined: the path tracer's camera paths, asking this map along their segments.
        if (settings.integrator == RenderSettings::Integrator::Combined) {
            cameraPaths_ = makePathTracer(scene, settings, this);
            // With no photon share in open media, only photons inside translucent objects are asked for.
            sealedOnly_ = settings.combinedPhotonShare == 0;
        }
        // Defaults follow the media, not the scene: a fog layer over kilometres of terrain keeps its
        // own kernel and step (the scene's size when a medium is unbounded). Photons from distant
        // and dome lights aim half at the media (PhotonAim).
        double diameter = 2 * (scene.mediaRadius() > 0 ? scene.mediaRadius() : scene.radius());
        radius_ = settings.initialRadius > 0 ? settings.initialRadius : diameter / 100;
        step_ = settings.marchStep > 0 ? settings.marchStep : diameter / 256;
        aim_ = {scene.center(), scene.radius(), scene.mediaCenter(), scene.mediaRadius(), Bounds3()};
        sceneBox_ = {scene.center() - Vec3(1, 1, 1) * scene.radius(), scene.center() + Vec3(1, 1, 1) * scene.radius()};
        // Nothing lies outside the scene's box unless a medium is unbounded.
        if (scene.mediaRadius() > 0) aim_.box = scene.bounds();
        std::vector<double> extended, point;
        for (const LightPtr& l : scene.lights()) {
            bool isPoint = l->pointPosition().has_value();
            double p = l->power(scene.radius()).average();
            extended.push_back(isPoint ? 0.0 : p);
            if (isPoint) pointLights_.push_back(static_cast<int>(&l - &scene.lights()[0]));
        }
        hasExtended_ = false;
        for (double p : extended) hasExtended_ |= p > 0;
        if (hasExtended_) extendedDist_ = Distribution1D(extended);
        hasMeshMedia_ = false;
        for (const MeshDesc& m : scene.desc().meshes) hasMeshMedia_ |= m.material.kind != SurfaceMaterial::Kind::Lambertian;
        findEmitters();
        std::vector<double> power;
        for (const LightPtr& l : scene.lights()) power.push_back(l->power(scene.radius()).average());
        for (const Emitter& e : emitters_) power.push_back(e.power);
        if (!power.empty()) sourceDist_ = Distribution1D(power);
        if (settings_.photonBeams) {
            // Beams where a region's media are optically thin and their phases moderate, points
            // elsewhere (beamsIn).
            MediumAggregate open;
            for (int i : scene.desc().unboundedMedia) open.add(scene.desc().media[i].get());
            beamRegions_.push_back(open.size() && open.phasePeak() <= ModeratePhasePeak &&
                                   opticalThickness(open, withinScene(open.bounds())) <= ThickOpticalDepth);
            for (size_t mi = 0; mi < scene.desc().meshes.size(); ++mi) {
                int interior = scene.desc().meshes[mi].interiorMedium;
                MediumAggregate media = open;
                if (interior >= 0) media.add(scene.desc().media[interior].get());
                beamRegions_.push_back(interior >= 0 && !scene.meshTranslucent(static_cast<int>(mi)) &&
                                       media.phasePeak() <= ModeratePhasePeak &&
                                       opticalThickness(media, scene.meshBounds(static_cast<int>(mi))) <= ThickOpticalDepth);
            }
        }
    }

    /// photonBeams stores beams in a region (the open media, or a mesh's interior: stack.innermost())
    /// whose optical thickness is at most this, points elsewhere and inside translucent objects. In
    /// optically thick media beams are short and their kernels narrow (the mean-free-path cap), and a
    /// beam pass is heavy-tailed: the stress suite's long form with beams everywhere put single passes
    /// of its emissive furnaces with optical depth 2000 across their box (cases 294, 300, 306) at
    /// 0.1-5x the furnace, and of its overlapping sigma_t = 1000 boxes (case 194) at 4-14x before
    /// photons carried flux only. The benchmark's open media, where beams lead points (README), are
    /// below it: dense cloud 65.6, VDB cloud 13.1, emissive smoke 9.8, cube 6.9, atmosphere 0.87, fog
    /// 0.42. In translucent objects (Scene::meshTranslucent) beams measured 1.30x the points' RMSE on
    /// the marble figurine (thickness 89.5) and 1.02-1.04x on the ball (34.6; two runs), so they keep points.
    static constexpr double ThickOpticalDepth = 100;
    /// Phases at most this peaked (phasePeak: Henyey-Greenstein |g| <= 0.6; the bound rounds above g
    /// = 0.6's 10) are moderate: beams are stored only where every medium's phase is, and the single-
    /// scattering pass samples lights alone there (phaseSampleProbability). A beam's gather weighs it
    /// by p / sin(theta): with a forward-peaked phase, beams nearly parallel to the camera ray make the
    /// estimate heavy-tailed (a photon-map furnace with HG g = 0.9, camera inside the fog, 4000 photons
    /// a pass, 4 passes, read 0.73-0.79 per pixel over 16 seeds with beams, 1 with points).
    static constexpr double ModeratePhasePeak = 10 * (1 + 1e-6);

    /// Whether photons in region `region` are stored and gathered as beams (beamRegions_, empty
    /// without photonBeams).
    bool beamsIn(int region) const {
        return region + 1 < static_cast<int>(beamRegions_.size()) && beamRegions_[region + 1];
    }

    /// A box clipped to the scene's (an unbounded medium's bounds are infinite).
    Bounds3 withinScene(const Bounds3& b) const { return {vmax(b.lo, sceneBox_.lo), vmin(b.hi, sceneBox_.hi)}; }

    /// A region's optical thickness: the largest majorant optical depth along the three axes and the
    /// four diagonals through the centre of `box` (an upper bound of the extinction's integral there).
    static double opticalThickness(const Medium& media, const Bounds3& box) {
        if (box.empty()) return 0.0;
        Vec3 c = 0.5 * (box.lo + box.hi);
        if (!std::isfinite(c.x + c.y + c.z)) return Infinity;
        const double k = 1 / std::sqrt(3.0);
        double thickest = 0;
        for (Vec3 d : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(k, k, k), Vec3(-k, k, k), Vec3(k, -k, k), Vec3(k, k, -k)}) {
            double t0, t1;
            if (!box.intersect(Ray{c, d}, -Infinity, Infinity, &t0, &t1)) continue;
            Ray ray{c + t0 * d, d};
            double tau = 0;
            media.majorants(ray, 0.0, t1 - t0, [&](const MajorantSegment& m) {
                tau += m.opticalDepth(m.tMax - m.tMin);
                return true;
            });
            thickest = std::max(thickest, tau);
        }
        return thickest;
    }

    bool beginPass(int pass, RenderStats& stats, const CancelCallback& cancel) override {
        if (pass == 0) decidePasses(stats);
        measuringNoise_ = photonsEnabled_ && measureNoise_ && pass < PhotonNoisePasses;
        if (!photonsEnabled_) return true;
        double r = passRadius(pass), rBeams = passBeamRadius(pass);
        stats.photonRadius = beamsIn(-1) ? rBeams : r;
        if (cache_) {
            if (std::shared_ptr<const PhotonCache::Pass> kept = cache_->find(pass)) {
                map_ = kept->map;
                beams_ = kept->beams;
                stats.photonPassesReused += 1;
                stats.photonsReused += kept->size();
                stats.photonsStored += kept->size();
                stats.photonsRadiusCapped += kept->radiusCapped;
                stats.photonMapBytes = std::max(stats.photonMapBytes, kept->bytes());
                return true;
            }
        }
        PhotonRecords records;
        PhotonCache::Pass traced;
        if (!tracePhotons(pass, photonsFor(pass), &records, &traced.traced, nullptr, cancel, &traced.thinned)) return false;
        buildMaps(std::move(records), r, rBeams, &traced);
        stats.photonsTraced += traced.traced;
        stats.photonsThinned += traced.thinned;
        stats.photonsRadiusCapped += traced.radiusCapped;
        stats.photonsStored += traced.size();
        stats.photonMapBytes = std::max(stats.photonMapBytes, traced.bytes());
        if (cache_) cache_->store(pass, std::move(traced), settings_.photonMapBudgetBytes);
        return true;
    }

    void setCameraPilot(std::function<work::Count()> pilot) override { cameraPilot_ = std::move(pilot); }

    // ---- how many photons ---------------------------------------------------------------------
    // The automatic count starts where a photon pass costs as much as a camera pass (autoPhotonsPerPass:
    // the pilots' work ratio, the "balance"). The best count is sqrt(a C / (b c)) = balance x sqrt(r):
    // the time to a given noise is (a/P + b)(C + cP) with a/P the photon map's share of a sample's
    // variance and b the camera side's, r = a / (b balance) (integrator.h). The first PhotonNoisePasses
    // passes measure a/P and a + b on the render's own samples: each pass's photon paths alternate
    // between two halves (Photon::half), and a camera sample's gathers of one half minus the other's
    // (PathRadiance::photonSplit) have the variance of its photon estimate, its camera path held fixed
    // (the halves are independent and each has half the paths: Var(E0 - E1) = Var(E0) + Var(E1) =
    // Var(E)); the spread of a pixel's two samples gives the whole (Renderer). Only a larger count is
    // taken (at most MaxPhotonGrowth x): two passes' spread overstates b (a pixel's samples are
    // stratified over the passes, and stratification lowers later passes' variance, not the first two's),
    // and an overstated b can only understate the count. (A pilot before the render that measured r
    // with its own camera samples read it 50x apart over seeds, and its independent samples put the
    // VDB cloud's b 10x above the render's: it halved the count there and doubled the time to a given
    // noise; the bench README, "Scenes 8-10 at the automatic photon count", and the 2026-12-07 note.)
    bool measuresPhotonNoise() const override { return measuringNoise_; }

    void photonNoiseMeasured(double photonVariance, double sampleVariance, int64_t pixels, RenderStats& stats) override {
        measureNoise_ = measuringNoise_ = false;
        const double s = photonVariance, v = sampleVariance;
        stats.photonVarianceShare = v > 0 ? s / v : 0.0;
        const double balance = stats.photonWorkRatio > 0 ? stats.photonWorkRatio : double(photonsPerPass_);
        double best = photonsPerPass_;
        if (s > 0 && v > 0) {
            const double b = std::max(v - s, v / CameraShareFloor);
            best = std::sqrt(s * photonsPerPass_ * balance / b);
        }
        // Never below the start: a count followed from a cache may exceed MaxAutoPhotons (an explicit
        // count cached before), and then stays as it is.
        const double most = std::max(double(photonsPerPass_), std::min(double(MaxPhotonGrowth) * photonsPerPass_, double(MaxAutoPhotons)));
        resizedPhotons_ = static_cast<int>(std::clamp(best, double(photonsPerPass_), most));
        stats.photonsPerPassResized = resizedPhotons_;
        if (cache_) cache_->setResizedPhotonsPerPass(resizedPhotons_);
        char text[200];
        std::snprintf(text, sizeof text, "photons: %d a pass for %d passes, then %d (the photon map's share of a sample's variance %.2g, "
                      "measured over %lld pixels)", photonsPerPass_, PhotonNoisePasses, resizedPhotons_, stats.photonVarianceShare,
                      static_cast<long long>(pixels));
        stats.passesRun.push_back(text);
    }

    /// Photons traced in pass `pass`, and before it.
    int photonsFor(int pass) const { return pass >= PhotonNoisePasses && resizedPhotons_ > 0 ? resizedPhotons_ : photonsPerPass_; }
    double photonsBefore(int pass) const {
        if (pass <= PhotonNoisePasses || resizedPhotons_ <= 0) return double(pass) * photonsPerPass_;
        return double(PhotonNoisePasses) * photonsPerPass_ + double(pass - PhotonNoisePasses) * resizedPhotons_;
    }

    /// The beam radius of pass `pass` (photonBeams): the 1D kernel's schedule r_{i+1} = r_i (i + alpha)/(i + 1)
    /// (Jarosz et al. 2011, "Progressive photon beams", eq. 21), counted in 1e5 photons as passRadius.
    double passBeamRadius(int pass) const {
        double r = passRadius(pass) / radius_;
        return radius_ * r * r;
    }

    /// The kernel radius of pass `pass`. Knaus and Zwicker's schedule r_{i+1}^2 = r_i^2 (i + alpha)/(i + 1)
    /// is r_i^2 = r_0^2 Gamma(i + alpha) / (Gamma(alpha) Gamma(i + 1)); it is applied here to the photons
    /// traced before the pass counted in units of RadiusReferencePhotons (the former fixed count, for
    /// which the default initial radius was chosen): x = pass x photonsPerPass / 1e5. So the radius
    /// shrinks with the photons gathered, not the passes: a render with 4096 photons a pass (a small
    /// image's automatic count) narrows its kernels 24x more slowly per pass than one with 1e5, and the
    /// two reach the same radius after the same number of photons (with 1e5 a pass, the formula is the
    /// recurrence above exactly).
    double passRadius(int pass) const {
        constexpr double RadiusReferencePhotons = 1e5;
        double a = settings_.radiusAlpha, x = photonsBefore(pass) / RadiusReferencePhotons;
        if (!(x > 0) || a >= 1) return radius_;
        return radius_ * std::exp(0.5 * (std::lgamma(x + a) - std::lgamma(a) - std::lgamma(x + 1)));
    }

    /// Before the photon passes are decided (Renderer's camera-pass pilot, which sizes the automatic
    /// photon count) the share is the setting too, so the pilot counts the work of the combined
    /// integrator's short camera paths, not the path tracer's full ones.
    double share(const MediumStack& stack) const override {
        if (!(map_ || beams_ || !passesDecided_)) return 0.0;
        return wholeSegment(stack) ? 1.0 : settings_.combinedPhotonShare;
    }
    bool wholeSegment(const MediumStack& stack) const override { return openSegments_ || scene_.sealedFromLights(stack); }
    Along along(const MediumAggregate& media, const Ray& local, double length, const MediumStack& stack, Rng& rng) const override {
        SegmentResult r = integrateSegment(media, local, length, stack, rng, openSegments_ ? Parts::Scattered : Parts::Gather);
        return {r.single, r.multiple, r.T, r.interacted, r.multipleSplit};
    }

    PathRadiance Li(const Ray& cameraRay, double nearClip, double farClip, Rng& rng) const override {
        if (cameraPaths_) return cameraPaths_->Li(cameraRay, nearClip, farClip, rng);
        PathRadiance out;
        PathRay path{cameraRay, nearClip, farClip, nearClip};
        auto& [ray, tMin, tMax, mediumFrom, lightsFrom] = path;
        Spectrum beta(1.0);
        MediumStack stack = cameraStack_;
        bool firstSegment = true, onlySpecular = true;
        int depth = 0, crossings = 0;
        // Which AOV a contribution goes to: the first non-boundary vertex decides (integrator.h).
        auto route = [&](Spectrum& medium) -> Spectrum& { return firstSegment ? medium : out.surface; };

        while (true) {
            PathSegment ahead = nextSegment(path, stack, firstSegment);
            const double tEnd = ahead.tEnd;
            if (firstSegment && ahead.hasHit) out.depth = ahead.hit.t;

            Spectrum Tseg(1.0);
            if (scene_.hasMedia()) {
                MediumAggregate media = scene_.mediaFor(stack);
                if (media.size()) {
                    Ray local{ray.at(mediumFrom), ray.d};
                    double length = std::isinf(tEnd) ? 1e30 : tEnd - mediumFrom;
                    SegmentResult seg = integrateSegment(media, local, length, stack, rng);
                    route(out.single) += beta * seg.single;
                    route(out.multiple) += beta * seg.multiple;
                    out.photonSplit += beta * seg.multipleSplit;
                    route(out.emission) += beta * seg.emission;
                    if (firstSegment && seg.interacted) out.alpha = 1;
                    Tseg = seg.T;
                }
            }
            beta *= Tseg;
            if (beta.isBlack()) break;
            if (ahead.leavesHole()) {
                path.leaveHole(stack, ahead.leakExit);
                continue;
            }
            if (ahead.reachesLight()) {
                // Lights are found by light sampling at diffuse vertices, so a hit counts only after
                // the camera or specular bounces.
                if (std::isinf(ahead.tLight)) {  // escaped: every light at infinity
                    if (onlySpecular)
                        lightsAtInfinity(ray, firstSegment, [&](int, const Spectrum& Le, double) { out.surface += beta * Le; });
                    break;
                }
                // Through the light, as shadow rays and photons go (Integrator::hitLight).
                if (onlySpecular) out.surface += beta * ahead.lightLe;
                if (firstSegment) out.alpha = 1;
                path.passLight(ahead.tLight);
                continue;
            }
            if (!ahead.hasHit) break;
            if (firstSegment) out.alpha = 1;
            // Emissive meshes are lights too (light-sampled at diffuse vertices, Scene::instanceLight),
            // so, as for lights above, their hits count only after the camera or specular bounces.
            if (onlySpecular || scene_.instanceLight(ahead.hit.instance) < 0)
                out.surface += beta * surfaceEmission(ray, ahead.hit);
            SurfaceScatter s;
            SurfaceStep step = cameraSurfaceHit(path, ahead.hit, stack, beta, depth, crossings, rng, /*mis=*/false,
                                                [&](const Spectrum& L) { out.surface += L; }, &s);
            if (step == SurfaceStep::Crossed) continue;
            if (step == SurfaceStep::Stop) break;
            firstSegment = false;
            onlySpecular = onlySpecular && s.type == SurfaceScatter::Type::Specular;
            if (depth >= settings_.rouletteDepth) {
                double p = rouletteSurvival(beta.maxValue(), depth);
                if (p < 1) {
                    if (!(rng.uniform() < p)) break;
                    beta /= p;
                }
            }
        }
        return out;
    }

private:
    struct SegmentResult {
        Spectrum single, multiple, emission;
        Spectrum multipleSplit;  ///< the gather's two halves' difference (measurement passes)
        Spectrum T{1.0};
        bool interacted = false;
    };

    /// Per-segment transmittance from the segment start: closed form if the media have one, else the
    /// march's cumulative optical depth, linearly interpolated.
    struct SegmentTransmittance {
        const Medium* media = nullptr;
        const Ray* ray = nullptr;
        bool closedForm = false;
        std::vector<double> t, tau[3];
        Spectrum at(double x) const {
            if (closedForm) return exp(-*media->opticalDepth(*ray, 0.0, x));
            if (t.empty() || x <= t.front()) return Spectrum(1.0);
            size_t i = std::upper_bound(t.begin(), t.end(), x) - t.begin();
            Spectrum depth;
            for (int c = 0; c < 3; ++c) {
                if (i >= t.size()) depth[c] = tau[c].back();
                else {
                    double f = (x - t[i - 1]) / (t[i] - t[i - 1]);
                    depth[c] = tau[c][i - 1] + f * (tau[c][i] - tau[c][i - 1]);
                }
            }
            return exp(-depth);
        }
    };

    /// What integrateSegment estimates: everything (the photon-map integrator's camera paths); single
    /// and multiple scattering (combined, whole segments in open media: the path tracer estimates
    /// emission); the multiple-scattering gather alone (combined elsewhere: the path tracer estimates
    /// single scattering and emission; the march then runs only for a transmittance without closed form).
    enum class Parts { All, Scattered, Gather };
    SegmentResult integrateSegment(const MediumAggregate& media, const Ray& ray, double length, const MediumStack& stack, Rng& rng,
                                   Parts parts = Parts::All) const {
        SegmentResult r;
        SegmentTransmittance tr;
        tr.media = &media;
        tr.ray = &ray;
        tr.closedForm = static_cast<bool>(media.opticalDepth(ray, 0.0, 0.0));
        bool emissive = parts == Parts::All && media.isEmissive();
        // No light sampling inside a dielectric that no shadow ray can leave (Scene::sealedFromLights).
        bool single = parts != Parts::Gather && settings_.singleScattering && !scene_.sealedFromLights(stack);
        double weight = 1.0;  // Russian-roulette weight of the march's early termination
        Spectrum tauRun;      // marched optical depth so far
        double supportStart = Infinity, supportEnd = 0;
        bool stop = false;
        double offsetU = rng.uniform();
        // One step's share of the segment: emission and single scattering at p, with transmittance T
        // from the segment start, times `measure` (dt x weight for a marched step).
        auto addStep = [&](const Vec3& p, const MediumProperties& mp, const Spectrum& T, const Spectrum& measure) {
            if (!mp.sigma_t().isBlack()) r.interacted = true;
            if (emissive) r.emission += mp.emission * T * measure;
            if (single && hasExtended_ && !mp.sigma_s.isBlack()) {
                // Light sampling costs a shadow ray. Steps whose weight sigma_s T measure is tiny (the
                // march resolves the majorant, so at a dense grid's edge thousands of steps cross a ramp
                // of little density) sample it with probability weight / NeeWeight and divide by that
                // probability: unbiased, and ordinary steps (weight >= 1e-5) are unaffected.
                constexpr double NeeWeight = 1e-5;
                double q = std::min(1.0, (mp.sigma_s * T * measure).maxValue() / NeeWeight);
                if (q >= 1 || rng.uniform() < q) r.single += directExtended(p, ray.d, mp, stack, rng) * T * measure / q;
            }
        };
        // The march serves volume emission, light sampling of lights with extent and transmittance
        // without a closed form. With none of them (homogeneous or exponential media lit by point and
        // spot lights: equiangular sampling below), only the media's support along the ray is needed.
        const bool march = emissive || (single && hasExtended_) || !tr.closedForm;
        media.majorants(ray, 0.0, length, [&](const MajorantSegment& seg) {
            supportStart = std::min(supportStart, seg.tMin);
            supportEnd = std::max(supportEnd, seg.tMax);
            if (!march) {
                r.interacted |= seg.sigmaMaj > 0;
                return true;
            }
            // Steps of at most step_ that also resolve the local mean free path (a quarter of it,
            // from the majorant at the step's far end, so a ray descending into a steep exponential
            // atmosphere shortens its steps as the density grows); each step is sampled at the same
            // jittered fraction offsetU. An unbounded segment is marched for at most MaxSteps steps,
            // by which the early termination below has usually ended it.
            // XXX: a thin unbounded medium beyond MaxSteps steps is not marched.
            constexpr int MaxSteps = 100000;
            double t0 = seg.tMin;
            for (int i = 0; i < MaxSteps && t0 < seg.tMax && !stop; ++i) {
                double sigmaHere = seg.decay == 0 ? seg.sigmaMaj : seg.sigmaMaj * std::exp(std::min(-seg.decay * (t0 - seg.tMin), 700.0));
                double dt = std::min({step_, 0.25 / sigmaHere, seg.tMax - t0});
                if (seg.decay < 0) dt = std::min(dt, 0.25 / (sigmaHere * std::exp(std::min(-seg.decay * dt, 700.0))));
                if (!(t0 + dt > t0)) {
                    // The step is below the floating-point resolution of t (a density near the 1e300
                    // clamp): the march cannot advance, and the medium is opaque here at this precision.
                    // Close the segment with the step integral of a homogeneous layer,
                    // int_0^inf x e^{-sigma_t s} ds = x / sigma_t per channel, and stop (T = 0).
                    // Summing x T dt over steps that do not move would add up without bound.
                    Vec3 p = ray.at(t0);
                    MediumProperties mp = media.properties(p);
                    Spectrum sigma_t = mp.sigma_t();
                    Spectrum invSigma;
                    for (int c = 0; c < 3; ++c) invSigma[c] = sigma_t[c] > 0 ? 1 / sigma_t[c] : 0.0;
                    addStep(p, mp, tr.closedForm ? tr.at(t0) : exp(-tauRun), invSigma * weight);
                    stop = true;
                    break;
                }
                double t = t0 + offsetU * dt;
                t0 += dt;
                Vec3 p = ray.at(t);
                MediumProperties mp = media.properties(p);
                Spectrum sigma_t = mp.sigma_t();
                Spectrum T = tr.closedForm ? tr.at(t) : exp(-(tauRun + sigma_t * (offsetU * dt)));
                if (!tr.closedForm) {
                    tauRun += sigma_t * dt;
                    tr.t.push_back(t0);
                    for (int c = 0; c < 3; ++c) tr.tau[c].push_back(tauRun[c]);
                }
                addStep(p, mp, T, Spectrum(dt * weight));
                // Early termination of the march.
                double Tmax = T.maxValue() * weight;
                if (Tmax < settings_.transmittanceCutoff) { stop = true; break; }
                if (Tmax < 1e-3) {
                    if (rng.uniform() < 0.5) { stop = true; break; }
                    weight *= 2;
                }
            }
            return !stop;
        });
        if (supportEnd <= supportStart) return r;
        r.T = stop ? Spectrum(0.0) : tr.at(length);
        if (tr.closedForm && !stop) r.T = exp(-*media.opticalDepth(ray, 0.0, length));
        if (!tr.closedForm && !stop) r.T = exp(-tauRun);
        if (single)
            for (int light : pointLights_) r.single += equiangular(light, media, ray, supportStart, std::min(supportEnd, length), tr, stack, rng);
        // Only the media's support gathers (sigma_s is zero elsewhere); a kernel that reaches past an
        // interface is renormalised to its part inside (SurfaceCuts: surfaces and media boxes).
        double b = std::min(length, supportEnd);
        Spectrum* split = measuringNoise_ ? &r.multipleSplit : nullptr;
        if (beams_ && beamsIn(stack.innermost()))
            r.multiple = gatherBeams(media, ray, supportStart, b, tr, stack, SurfaceCuts(scene_, media, ray, supportStart, b, beams_->radius()), split);
        else if (map_)
            r.multiple = gather(media, ray, supportStart, b, tr, stack, SurfaceCuts(scene_, media, ray, supportStart, b, map_->radius()), split);
        return r;
    }

    /// Light from lights with extent and distant/dome lights scattered at p towards the camera
    /// (direction -d): the integral of sigma_s p L T over directions, by two strategies combined with
    /// the power heuristic (Veach 1997, as the path tracer's vertices do): light sampling (one light
    /// picked by power), and, with probability phaseSampleProbability(mp), a direction from the phase
    /// function, which counts every light a ray that way meets (Light::intersect). Delta lights and
    /// mesh lights (met by surface hits only) keep light sampling alone (weight 1). Without the phase
    /// strategy a strongly forward or backward phase (HG |g| -> 1) sees a dome or sphere light only
    /// when a light sample happens to fall in its narrow lobe: unbiased, but the rare large values
    /// were missing from any practical number of passes (stress cases 189/191 read 0.62x and 0.50x
    /// the path tracer's single scattering at 64 passes).
    Spectrum directExtended(const Vec3& p, const Vec3& d, const MediumProperties& mp, const MediumStack& stack, Rng& rng) const {
        const double alpha = phaseSampleProbability(mp);
        Spectrum L;
        double pick;
        size_t li = extendedDist_.sampleDiscrete(rng.uniform(), &pick);
        auto [u1, u2] = rng.uniform2();
        const Light& light = *scene_.lights()[li];
        LightSample ls = light.sample(p, u1, u2);
        if (ls.pdf > 0 && !ls.Li.isBlack()) {
            double cosTheta = dot(d, ls.wi);
            Spectrum f = mp.scatterKernel(cosTheta);
            if (!f.isBlack()) {
                double w = ls.isDelta || light.isGeometry() ? 1.0 : powerHeuristic(pick * ls.pdf, alpha * mp.scatterPdf(cosTheta));
                L += f * shadowTransmittance(p, ls.wi, ls.dist, stack, rng) * ls.Li * (w / (pick * ls.pdf));
            }
        }
        if (alpha > 0 && rng.uniform() < alpha) {
            auto [s1, s2] = rng.uniform2();
            double uLobe = rng.uniform();
            Vec3 wi = mp.sampleScatter(d, uLobe, s1, s2);
            double cosTheta = dot(d, wi);
            double phasePdf = alpha * mp.scatterPdf(cosTheta);
            if (!(phasePdf > 0)) return L;
            Spectrum f = mp.scatterKernel(cosTheta);
            for (size_t j = 0; j < scene_.lights().size(); ++j) {
                const Light& lj = *scene_.lights()[j];
                double pickJ = extendedDist_.discretePdf(j), t, lightPdf;
                Spectrum Le;
                if (!(pickJ > 0) || lj.isDelta() || lj.isGeometry() || !lj.intersect({p, wi}, Infinity, &t, &Le, &lightPdf)) continue;
                double w = powerHeuristic(phasePdf, pickJ * lightPdf);
                L += f * shadowTransmittance(p, wi, t, stack, rng) * Le * (w / phasePdf);
            }
        }
        return L;
    }

    /// How often directExtended also samples the phase function: 0 (light sampling alone, no extra
    /// ray) up to a peak of PhasePeakMin, then rising to 1/2 as the phase approaches a delta (HG g =
    /// 0.7: 0.24, 0.85: 0.44, 0.9: 0.47). The peak is 4 pi times the larger of p(+1), p(-1) (the
    /// maximum of HG, Schlick and Rayleigh; 1 for isotropic). Any value in [0, 1) keeps the estimate
    /// unbiased; only variance and cost depend on it. Measured (tools/bench_photon_bias.py, 4 seeds x
    /// 4 s) with 0.5 (1 - 1/peak) on the benchmark's moderate phases (HG g = 0.5, 0.6, 0.3): 26-30%
    /// fewer passes for a 1.02-1.03x worse RMSE, so moderate peaks keep light sampling alone.
    static double phaseSampleProbability(const MediumProperties& mp) {
        double peak = 4 * Pi * std::max(mp.scatterPdf(1.0), mp.scatterPdf(-1.0));
        return peak > ModeratePhasePeak ? 0.5 * (1 - ModeratePhasePeak / peak) : 0.0;
    }

    /// Equiangular sampling of [a, b], within what the light lights, for a point light (Kulla and
    /// Fajardo 2012, eq. 6-7).
    Spectrum equiangular(int light, const Medium& media, const Ray& ray, double a, double b, const SegmentTransmittance& tr,
                         const MediumStack& stack, Rng& rng) const {
        const Light& L = *scene_.lights()[light];
        // Only the part the light reaches (a spot's cone, Light::litInterval), as the path tracer does.
        double lit0, lit1;
        L.litInterval(ray, &lit0, &lit1);
        a = std::max(a, lit0);
        b = std::min(b, lit1);
        if (!(b > a)) return {};
        Vec3 lp = *L.pointPosition();
        double delta = dot(lp - ray.o, ray.d);
        double D = length(lp - ray.at(delta));
        double t, pdf;
        double u = rng.uniform();
        if (D < 1e-9 * (1 + std::abs(delta))) {  // the ray passes through the light: uniform fallback
            t = a + u * (b - a);
            pdf = 1 / (b - a);
        } else {
            double thA = std::atan2(a - delta, D), thB = std::atan2(b - delta, D);
            t = delta + D * std::tan(thA + u * (thB - thA));
            pdf = D / ((thB - thA) * (D * D + (t - delta) * (t - delta)));
        }
        Vec3 p = ray.at(t);
        MediumProperties mp = media.properties(p);
        if (mp.sigma_s.isBlack()) return {};
        auto [l1, l2] = rng.uniform2();
        LightSample ls = L.sample(p, l1, l2);
        if (!(ls.pdf > 0) || ls.Li.isBlack()) return {};
        Spectrum f = mp.scatterKernel(dot(ray.d, ls.wi));
        Spectrum T = shadowTransmittance(p, ls.wi, ls.dist, stack, rng);
        return tr.at(t) * f * T * ls.Li / (ls.pdf * pdf);
    }

    /// A photon's kernel radius cap: settings.photonRadiusMfp mean free paths at the photon. The
    /// radiance in an optically thick layer changes over a few mean free paths from its skin, and a
    /// disc far wider blurs it; before photons carried flux only (Photon), such discs also let camera
    /// segments outside the layer gather its skin's source with their own transmittance (~1) instead of
    /// the photons' (~0): an energy gain without bound as the layer got denser (tools/stress.py,
    /// exponential media with a = 1e6). The cap keeps the kernel inside the region the photon's light
    /// actually reaches.
    /// Only photons outside every closed medium mesh get it: inside one, gathering is already limited
    /// to the mesh's interior (Photon::region), so no camera segment passes outside such a medium
    /// within its kernel, and an explicit wide radius (a laterally uniform slab) keeps its low noise.
    /// The default of 8 mean free paths is a compromise measured on tools/stress.py's long form:
    /// narrower kernels make the estimate heavy-tailed at practical photon counts (a cap of 1 put single
    /// passes of cases 192/193, overlapping sigma_t = 1000 boxes, at 8x the furnace), wider ones keep
    /// more of the skin's blur (a cap of 16: case 193 at 1.30 L; 8: 1.11 L, within the check's noise;
    /// a = 1e6 layers: 1.48 L uncapped, 0.57 L capped). (PhotonMap clamps the cap to [1e-6, 1] x the
    /// pass radius.)
    float radiusCap(double sigmaTMax) const {
        if (!(settings_.photonRadiusMfp > 0) || !(sigmaTMax > 0)) return std::numeric_limits<float>::infinity();
        return static_cast<float>(settings_.photonRadiusMfp / sigmaTMax);
    }

    /// Surfaces and media boxes that cut the gather discs along a camera segment (the kernel's boundary
    /// bias). Photons lie on the segment's side of a surface only, so the disc of radius r around a ray
    /// point within r of one collects photons over the part of its area on that side: the count
    /// estimates f x the density, f the disc's fraction inside (1/2 at the surface). Each photon's
    /// contribution is divided by f at its ray point (the renormalisation correction of kernel density
    /// estimation at a boundary; M. C. Jones 1993, "Simple boundary correction for kernel density
    /// estimation"); a beam's 1D kernel across the ray likewise by the part of its width inside
    /// (insideAcross). Without it a camera ray grazing the ground of benchmark scene 5 lost 29% of its
    /// blue multiple scattering. The surface is taken as its tangent plane at the point nearest to the
    /// middle of a cell of the segment (cells 2r long); a cell's closest-point query runs when a photon
    /// first falls in it. A medium's box (Medium::bounds) cuts the same way: no photon lies outside it,
    /// and the ray's point is in it (the gather has sigma_s there); where boxes overlap, the box that
    /// leaves the disc the most counts (the media's union holds at least that much of it).
    class SurfaceCuts {
    public:
        SurfaceCuts(const Scene& scene, const MediumAggregate& media, const Ray& ray, double a, double b, double r)
            : scene_(scene), ray_(ray), a_(a), b_(b) {
            for (int i = 0; i < media.size() && boxes_ < MediumAggregate::MaxMedia; ++i) box_[boxes_++] = media[i]->bounds();
            if (!scene.hasSurfaces() || !(b > a) || !(r > 0)) return;
            // At most MaxCells cells along a segment: a longer one samples planes further apart.
            constexpr int MaxCells = 256;
            h_ = std::max(2 * r, (b - a) / MaxCells);
            reach_ = r + 0.5 * h_;
            count_ = std::min(MaxCells, static_cast<int>(std::ceil((b - a) / h_)));
        }
        /// The fraction of the disc of radius r around the ray point at t that lies on the ray's side of
        /// the nearest surface (1 where none is within r).
        double inside(double t, double r) {
            // The plane meets the disc (normal d) in a line at distance delta / sin(angle(n, d)) from
            // its centre; a disc parallel to the plane is not cut. A ray point behind the plane
            // (a curved or another surface there) is left uncorrected rather than guessed.
            auto cut = [&](double delta, double cosN) {
                double sinN = std::sqrt(std::max(0.0, 1 - cosN * cosN));
                return sinN * r > delta && delta >= 0 ? discFractionInside(delta / sinN, r) : 1.0;
            };
            const Cell* c = cell(t);
            double f = c ? cut(dot(c->towards, ray_.at(t) - c->p), dot(c->towards, ray_.d)) : 1.0;
            return std::min(f, boxes(t, [&](double delta, int axis) { return cut(delta, ray_.d[axis]); }));
        }
        /// The same for a beam's 1D kernel: the fraction of the segment [-r, r] along the unit vector u
        /// (across both the ray and the beam) around the ray point at t on the ray's side.
        double insideAcross(double t, double r, const Vec3& u) {
            auto cut = [&](double delta, double nu) {
                nu = std::abs(nu);
                return nu * r > delta && delta >= 0 ? 0.5 * (1 + delta / (nu * r)) : 1.0;
            };
            const Cell* c = cell(t);
            double f = c ? cut(dot(c->towards, ray_.at(t) - c->p), dot(c->towards, u)) : 1.0;
            return std::min(f, boxes(t, [&](double delta, int axis) { return cut(delta, u[axis]); }));
        }

    private:
        /// The largest fraction over the media boxes holding the ray's point at t, each the smallest
        /// fraction over its six faces (fraction(distance inside the face, axis)); 1 in no box.
        template <class Fraction>
        double boxes(double t, Fraction fraction) const {
            Vec3 q = ray_.at(t);
            double best = -1;
            for (int i = 0; i < boxes_; ++i) {
                const Bounds3& b = box_[i];
                if (!b.contains(q)) continue;
                double f = 1.0;
                for (int k = 0; k < 3; ++k) f = std::min({f, fraction(q[k] - b.lo[k], k), fraction(b.hi[k] - q[k], k)});
                best = std::max(best, f);
            }
            return best < 0 ? 1.0 : best;
        }
        struct Cell {
            bool known = false, cut = false;
            Vec3 p, towards;
        };
        /// The cell holding t with its surface plane, or null where no surface is within reach.
        const Cell* cell(double t) {
            if (count_ == 0) return nullptr;
            if (cells_.empty()) cells_.resize(count_);
            int k = std::clamp(static_cast<int>((t - a_) / h_), 0, count_ - 1);
            Cell& c = cells_[k];
            if (!c.known) {
                c.known = true;
                // The middle of the cell's part of the segment: a point on the segment's side of the
                // surfaces (a cell reaching past the segment's end would look from beyond a surface).
                double mid = 0.5 * (a_ + k * h_ + std::min(b_, a_ + (k + 1) * h_));
                if (std::optional<Scene::NearestSurface> s = scene_.nearestSurface(ray_.at(mid), reach_)) {
                    c.cut = true;
                    c.p = s->p;
                    c.towards = s->towards;
                }
            }
            return c.cut ? &c : nullptr;
        }
        const Scene& scene_;
        Ray ray_;
        double a_, b_, h_ = 0, reach_ = 0;
        int count_ = 0;
        std::vector<Cell> cells_;
        Bounds3 box_[MediumAggregate::MaxMedia];
        int boxes_ = 0;
    };

    /// The beam radiance estimate along a camera segment: sum over photons of their flux x sigma_s p
    /// of the media at the photon's point on the ray x T x the disc kernel (Photon: the kernel blurs
    /// the arriving radiance, and the scattering coefficient is the ray's own).
    /// `split` (measurement passes, measuringNoise_): adds the photons of half 0 minus those of half 1.
    Spectrum gather(const Medium& media, const Ray& ray, double a, double b, const SegmentTransmittance& tr,
                    const MediumStack& stack, SurfaceCuts cuts, Spectrum* split) const {
        Spectrum sum;
        int region = stack.innermost();
        map_->query(ray, a, b, [&](const Photon& ph, double t, double) {
            if (ph.region != region) return;
            double cosTheta = -(ph.dir[0] * ray.d.x + ph.dir[1] * ray.d.y + ph.dir[2] * ray.d.z);
            Vec3 x = ray.at(t);
            Spectrum f = media.properties(x).scatterKernel(std::clamp(cosTheta, -1.0, 1.0));
            if (f.isBlack()) return;
            double invArea = 1 / (Pi * double(ph.radius) * ph.radius * cuts.inside(t, ph.radius));
            Spectrum c = Spectrum(ph.power[0], ph.power[1], ph.power[2]) * f * tr.at(t) * invArea;
            sum += c;
            if (split) *split += ph.half ? -c : c;
        });
        return sum;
    }

    /// Beam x beam 1D with short beams (photonBeams.h): flux sigma_s p / (2 r sin theta) T_camera, over
    /// the part of the kernel's width on the ray's side of a surface (SurfaceCuts).
    Spectrum gatherBeams(const Medium& media, const Ray& ray, double a, double b, const SegmentTransmittance& tr,
                         const MediumStack& stack, SurfaceCuts cuts, Spectrum* split) const {
        Spectrum sum;
        int region = stack.innermost();
        beams_->query(ray, a, b, [&](const BeamHit& h) {
            const PhotonBeam& beam = *h.beam;
            if (beam.region != region) return;
            Vec3 beamDir(beam.dir[0], beam.dir[1], beam.dir[2]);
            double kernel = 1 / (2 * double(beam.radius) * cuts.insideAcross(h.tCamera, beam.radius, cross(ray.d, beamDir) / h.sinTheta));
            // sigma_s p at the ray's point, as for photons (gather).
            Spectrum f = media.properties(ray.at(h.tCamera)).scatterKernel(std::clamp(h.cosTheta, -1.0, 1.0));
            if (f.isBlack()) return;
            Spectrum c = Spectrum(beam.power[0], beam.power[1], beam.power[2]) * f * tr.at(h.tCamera) * (kernel / h.sinTheta);
            sum += c;
            if (split) *split += beam.half ? -c : c;
        });
        return sum;
    }

    /// What a photon pass stores: points (Photon) and, with photonBeams, beams (beamsIn).
    struct PhotonRecords {
        std::vector<Photon> photons;
        std::vector<PhotonBeam> beams;
        size_t size() const { return photons.size() + beams.size(); }
        size_t bytes() const { return photons.size() * PhotonMap::BytesPerPhoton + beams.size() * PhotonBeamMap::BytesPerBeam; }
        void append(PhotonRecords&& o) {
            photons.insert(photons.end(), o.photons.begin(), o.photons.end());
            beams.insert(beams.end(), o.beams.begin(), o.beams.end());
        }
    };

    /// The gathers' maps (map_, beams_) from a pass's records: beams in the regions that take them
    /// (beamsIn), points elsewhere, so each region's gathers read one. Counts capped radii into *traced
    /// and keeps the maps there.
    void buildMaps(PhotonRecords&& records, double r, double rBeams, PhotonCache::Pass* traced) {
        map_ = nullptr;
        beams_ = nullptr;
        if (!records.beams.empty()) {
            for (const PhotonBeam& b : records.beams) traced->radiusCapped += b.radius < rBeams;
            traced->beams = beams_ = std::make_shared<const PhotonBeamMap>(std::move(records.beams), rBeams);
        }
        if (!records.photons.empty() || !beams_) {
            traced->radiusCapped += noteNarrowKernels(records.photons, r);
            traced->map = map_ = std::make_shared<const PhotonMap>(std::move(records.photons), r);
        }
    }

    /// Photon tracing; fills photons (stored events) and, for the pilot, the energy at first events
    /// (index 0) and at stored events (index 1), and into workDone the work counted (workCount.h). Batches run in groups, appended in batch order; with
    /// `thinned`, whenever the photons kept pass twice the memory budget they are thinned to it
    /// (thinToBudget: uniform, power rescaled, so repeated thinning stays unbiased). The pass's peak
    /// memory is then about twice the budget plus one group's photons, not everything traced.
    bool tracePhotons(int pass, int count, PhotonRecords* photons, uint64_t* traced, double energy[2], const CancelCallback& cancel,
                      uint64_t* thinned = nullptr, work::Count* workDone = nullptr) const {
        if (!sourceDist_.size() || count <= 0) return true;
        constexpr int GroupBatches = 16;
        const size_t budget = settings_.photonMapBudgetBytes;
        int batches = (count + PhotonBatch - 1) / PhotonBatch, round = 0;
        for (int g0 = 0; g0 < batches; g0 += GroupBatches) {
            int g1 = std::min(batches, g0 + GroupBatches);
            std::vector<PhotonRecords> perBatch(g1 - g0);
            std::vector<std::array<double, 2>> perEnergy(g1 - g0, {0.0, 0.0});
            std::vector<work::Count> perWork(g1 - g0);
            std::atomic<bool> cancelled{false};
            tbb::parallel_for(g0, g1, [&](int b) {
                if (cancelled || (cancel && cancel())) { cancelled = true; return; }
                Rng rng(hashKeys(0x50484f54ULL, settings_.seed, pass, b, energy ? 1 : 0));
                int n = std::min(PhotonBatch, count - b * PhotonBatch);
                work::Snapshot before = work::snapshot();
                PhotonRecords& out = perBatch[b - g0];
                for (int i = 0; i < n; ++i) {
                    const size_t photons0 = out.photons.size(), beams0 = out.beams.size();
                    tracePhoton(rng, count, &out, perEnergy[b - g0].data());
                    // Alternate paths make the two halves (Photon::half; batches hold an even count).
                    for (size_t k = photons0; k < out.photons.size(); ++k) out.photons[k].half = i & 1;
                    for (size_t k = beams0; k < out.beams.size(); ++k) out.beams[k].half = i & 1;
                }
                perWork[b - g0] = work::since(before);
            });
            if (cancelled) return false;
            for (int b = 0; b < g1 - g0; ++b) {
                photons->append(std::move(perBatch[b]));
                if (energy) { energy[0] += perEnergy[b][0]; energy[1] += perEnergy[b][1]; }
                if (workDone) *workDone += perWork[b];
            }
            if (thinned && photons->bytes() > 2 * budget) *thinned += thinToBudget(pass, round++, photons);
        }
        if (thinned) *thinned += thinToBudget(pass, round, photons);
        *traced += count;
        return true;
    }

    /// An emissive medium as a photon source: uniform points in `box` where the medium is present,
    /// uniform directions. Volume emission is photon-traced so that its scattered light (which the
    /// single-scattering pass does not compute) is in the photon map.
    struct Emitter {
        const Medium* medium;
        int mesh;  ///< the closed mesh bounding it, or -1 for an unbounded medium
        Bounds3 box;
        double volume;
        double power;  ///< channel-average emitted power, estimated by a deterministic pilot
    };

    /// Emission source term of an emitter at p (zero outside its mesh).
    Spectrum emitterSource(const Emitter& e, const Vec3& p) const {
        if (e.mesh >= 0 && scene_.stackAt(p).innermost() != e.mesh) return {};
        return e.medium->properties(p).emission;
    }

    void findEmitters() {
        auto add = [&](const Medium* m, int mesh) {
            if (!m->isEmissive()) return;
            Bounds3 box = withinScene(m->bounds());
            if (box.empty()) return;
            Vec3 size = box.hi - box.lo;
            Emitter e{m, mesh, box, size.x * size.y * size.z, 0.0};
            Rng rng(hashKeys(0x454d4954ULL, emitters_.size()));
            const int n = 4096;
            for (int i = 0; i < n; ++i) {
                Vec3 p = box.lo + Vec3(size.x * rng.uniform(), size.y * rng.uniform(), size.z * rng.uniform());
                e.power += emitterSource(e, p).average() * 4 * Pi * e.volume / n;
            }
            if (e.power > 0) emitters_.push_back(e);
        };
        for (int i : scene_.desc().unboundedMedia) add(scene_.desc().media[i].get(), -1);
        for (size_t mi = 0; mi < scene_.desc().meshes.size(); ++mi) {
            const MeshDesc& m = scene_.desc().meshes[mi];
            if (m.interiorMedium >= 0) add(scene_.desc().media[m.interiorMedium].get(), static_cast<int>(mi));
        }
    }

    /// The stretch [t0, t1] of a photon's flight along ray, clipped to the media's box within the
    /// scene's (a flight from a floor to a fog box, or out to an unbounded distance, has no beam
    /// outside them), as a beam carrying `flux`.
    void addBeamPiece(const Ray& ray, double t0, double t1, const Spectrum& flux, const Medium& media, int region,
                      float radius, std::vector<PhotonBeam>* out) const {
        Bounds3 box = withinScene(media.bounds());
        if (!box.intersect(ray, t0, t1, &t0, &t1) || !(t1 > t0) || flux.isBlack()) return;
        PhotonBeam beam;
        Vec3 o = ray.at(t0);
        for (int c = 0; c < 3; ++c) {
            beam.origin[c] = static_cast<float>(o[c]);
            beam.dir[c] = static_cast<float>(ray.d[c]);
            beam.power[c] = static_cast<float>(flux[c]);
        }
        beam.length = static_cast<float>(t1 - t0);
        beam.region = region;
        beam.radius = radius;
        out->push_back(beam);
    }

    /// Whether photons (or beams) in the media of `stack` are stored: everywhere, except for combined
    /// with no share in open media (sealedOnly_), where only translucent objects ask for them.
    bool storedIn(const MediumStack& stack) const { return !sealedOnly_ || scene_.sealedFromLights(stack); }

    void tracePhoton(Rng& rng, int count, PhotonRecords* out, double energy[2]) const {
        double pick;
        size_t source = sourceDist_.sampleDiscrete(rng.uniform(), &pick);
        double u[4] = {rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()};
        // Surfaces are searched from path.tMin; media are tracked from the ray origin (mediumFrom 0).
        PathRay path{Ray{}, 0.0, Infinity, 0.0};
        Ray& ray = path.ray;
        Spectrum flux;
        int events = 0;  // scatterings, diffuse bounces and dielectric interactions so far
        if (source < scene_.lights().size()) {
            PhotonEmission e = scene_.lights()[source]->emitPhoton(aim_, u);
            ray = e.ray;
            flux = e.flux / (pick * count);
        } else {
            const Emitter& em = emitters_[source - scene_.lights().size()];
            Vec3 size = em.box.hi - em.box.lo;
            Vec3 p = em.box.lo + Vec3(size.x * u[0], size.y * u[1], size.z * rng.uniform());
            ray = {p, uniformSphere(u[2], u[3])};
            flux = emitterSource(em, p) * (4 * Pi * em.volume / (pick * count));
            events = 1;  // every scattering of emitted light belongs to the photon map
        }
        if (flux.isBlack() || !flux.isFinite()) return;
        MediumStack stack = hasMeshMedia_ ? scene_.stackAt(ray.o) : MediumStack();
        MediumEvent ev;  // where the photon scatters (read only when `scattered`); built once per photon
        SpectralMis mis;
        mis.hero = rng.pathChoice(3);
        SpectralFlight flight;  // the hero's flights
        flight.channel = mis.hero;
        for (int depth = 0, crossings = 0; depth <= settings_.maxDepth && crossings < MaxBoundaryCrossings;) {
            SurfaceHit hit;
            bool hasHit = scene_.intersect(ray, path.tMin, Infinity, &hit);
            double tEnd = hasHit ? hit.t : std::min(1e30, leakDistance(stack, ray));
            bool scattered = false, absorbed = false;
            MediumAggregate media = scene_.mediaFor(stack);
            if (media.size()) {
                // Beams (photonBeams) of multiply scattered light: the flight in pieces of constant
                // spectral weight, each ending where the flight or the weight changed (photonBeams.h).
                const bool beams = events >= 1 && storedIn(stack) && beamsIn(stack.innermost());
                double pieceStart = 0, sigmaMaj = 0;  // the majorant where the last piece ended
                auto addBeam = [&](double t1, const Spectrum& carried) {
                    int region = stack.innermost();
                    // The mean-free-path cap, as for points (radiusCap), from the majorant at the
                    // piece's end: beams in an opaque layer's skin are short, and so are their kernels.
                    float cap = region < 0 ? radiusCap(sigmaMaj) : std::numeric_limits<float>::infinity();
                    if (beams) addBeamPiece(ray, pieceStart, t1, carried, media, region, cap, &out->beams);
                    pieceStart = t1;
                };
                // The hero channel's flight (SpectralMis): absorption, scattering and null collisions
                // with its probabilities sigma_a, sigma_s and sigma_n over its majorant: its own
                // majorant, except where the flight leaves beams. A beam carries one flux along its
                // length, which the channels' weights keep only between events; under the hero's own
                // majorant (no null collisions in homogeneous media) they would change continuously
                // along it, as e^-(sigma_c - sigma_h) s. Under the scalar majorant the weights change
                // at null collisions only, where a new beam starts.
                if (beams) {
                    flight.chromatic = false;
                    flight.depth = Spectrum(0.0);
                }
                FlightEnd end = sampleFreeFlight(media, ray, tEnd, rng, [&](const MediumEvent& m) {
                    sigmaMaj = m.sigmaMaj;
                    const int h = mis.hero;
                    const double maj = flight.chromatic ? flight.sigmaMaj[h] : m.sigmaMaj;
                    const Spectrum sigma_t = m.mp.sigma_t();
                    const double x = rng.uniform() * maj;
                    if (x < m.mp.sigma_a[h]) { absorbed = true; addBeam(m.t, flux); return false; }
                    const Spectrum& sigma_s = m.mp.sigma_s;
                    if (x < sigma_t[h]) {
                        addBeam(m.t, flux);
                        if (!mis.collide(m, flight, sigma_t, &sigma_s, flux)) {
                            absorbed = true;
                            return false;
                        }
                        ev = m;
                        scattered = true;
                        return false;
                    }
                    const Spectrum before = flux;
                    if (!mis.collide(m, flight, sigma_t, nullptr, flux)) { absorbed = true; addBeam(m.t, flux); return false; }
                    // The weight changed: the piece so far carries the flux before it.
                    if (beams && (flux - before).maxValue() + (before - flux).maxValue() > 1e-6 * before.maxValue()) addBeam(m.t, before);
                    return true;
                }, beams ? nullptr : &flight);
                if (end == FlightEnd::Escaped) addBeam(tEnd, flux);  // (a beam's flight has no escape weight)
                absorbed |= end == FlightEnd::Truncated || (end == FlightEnd::Escaped && !mis.escape(flight.depth, flux));
            }
            if (absorbed) return;
            if (scattered) {
                const MediumProperties& mp = ev.mp;
                if (energy) energy[events >= 1 ? 1 : 0] += (flux * mp.sigma_s).average();
                if (events >= 1 && storedIn(stack) && !beamsIn(stack.innermost())) {
                    // The flux arriving here (Photon): the gather applies sigma_s p where it looks.
                    // The photon's weight grows as 1 / sigma_s where the medium is thin; a
                    // weight beyond float's range (sigma_s near 1e-38) is not stored.
                    Photon ph;
                    bool representable = true;
                    for (int c = 0; c < 3; ++c) {
                        ph.p[c] = static_cast<float>(ev.p[c]);
                        ph.dir[c] = static_cast<float>(ray.d[c]);
                        ph.power[c] = static_cast<float>(flux[c]);
                        representable &= std::isfinite(ph.power[c]);
                    }
                    ph.region = stack.innermost();
                    ph.radius = ph.region < 0 ? radiusCap(mp.sigma_t().maxValue()) : std::numeric_limits<float>::infinity();
                    if (representable) out->photons.push_back(ph);
                }
                ++events;
                if (++depth >= DeepRouletteDepth) {  // albedo 1 loses nothing: end deep photons too
                    if (!(rng.uniform() < DeepRouletteSurvival)) return;
                    flux /= DeepRouletteSurvival;
                }
                Vec3 w = mp.sampleScatter(ray.d, rng.uniform(), rng.uniform(), rng.uniform());
                double cosTheta = dot(ray.d, w), pdf = mp.scatterPdf(cosTheta);
                if (!(pdf > 0)) return;
                // flux carries 1/sigma_s (and the spectral MIS weights); the kernel brings sigma_s.
                flux *= mp.scatterKernel(cosTheta) / pdf;
                for (int c = 0; c < 3; ++c) if (!std::isfinite(flux[c])) flux[c] = 0;
                path.bounce({ev.p, w}, 0.0);
                continue;
            }
            if (!hasHit && tEnd < 1e30) {  // left a broken mesh through a hole
                path.leaveHole(stack, tEnd);
                ++crossings;
                continue;
            }
            if (!hasHit) return;
            const SurfaceMaterial& m = scene_.mesh(hit.mesh).material;
            SurfaceScatter s = scatterSurface(ray, hit, stack, rng, false);
            if (s.type == SurfaceScatter::Type::Absorbed) return;
            if (s.type == SurfaceScatter::Type::Pass) {
                ++crossings;
                path.passBoundary(s, hit.t);
                continue;
            }
            ++depth;
            if (m.kind == SurfaceMaterial::Kind::Lambertian) {
                ++events;
                // Russian roulette on the reflectance keeps photon power roughly constant.
                double q = std::clamp(s.weight.average(), 0.0, depth >= DeepRouletteDepth ? DeepRouletteSurvival : 1.0);
                if (rng.uniform() >= q) return;
                flux *= s.weight / q;
            } else {
                // The single-scattering pass cannot see through or via a dielectric (its shadow rays
                // stop there), so events after a specular interaction belong to the photon map.
                ++events;
                if (depth >= DeepRouletteDepth) {
                    if (!(rng.uniform() < DeepRouletteSurvival)) return;
                    flux /= DeepRouletteSurvival;
                }
                flux *= s.weight;
            }
            path.bounce(s.next, s.tMin);
        }
    }

    /// Counts the photons whose mean-free-path cap narrows their kernel below the pass radius r, and
    /// warns once per render when more than a tenth of them are narrowed below r / 100: there the
    /// multiple-scattering estimate is right on average but very noisy (often dark until many passes
    /// have run), so the picture must not look converged silently.
    uint64_t noteNarrowKernels(const std::vector<Photon>& photons, double r) {
        size_t capped = 0, narrow = 0;
        for (const Photon& ph : photons) {
            capped += ph.radius < r;
            narrow += ph.radius < 0.01 * r;
        }
        if (!warnedNarrow_ && narrow * 10 > photons.size()) {
            warnedNarrow_ = true;
            warn("photonMap integrator: " + std::to_string(100 * narrow / photons.size()) +
                 "% of the photons have kernels narrowed below 1/100 of the photon radius (" + std::to_string(r) +
                 ") by photonRadiusMfp (media whose mean free path is far below the radius), so multiple "
                 "scattering there stays noisy and dark until many photons have been traced. The path "
                 "tracer handles such optically thick media better.");
        }
        return capped;
    }

    /// Keeps the photon map within the memory budget: points and beams alike keep the share of their
    /// count that fits settings.photonMapBudgetBytes (at least one), chosen uniformly without
    /// replacement (a partial Fisher-Yates shuffle with a seeded stream), and their power is scaled by
    /// count / kept, so the estimate stays unbiased.
    uint64_t thinToBudget(int pass, int round, PhotonRecords* records) const {
        const size_t total = records->bytes(), budget = settings_.photonMapBudgetBytes;
        if (total <= budget) return 0;
        auto keep = [&](size_t n) { return std::max<size_t>(1, n * budget / total); };
        return thinToBudget(pass, round, &records->photons, keep(records->photons.size())) +
               thinToBudget(pass, round, &records->beams, keep(records->beams.size()));
    }
    template <typename Record>
    uint64_t thinToBudget(int pass, int round, std::vector<Record>* photons, size_t maxPhotons) const {
        size_t n = photons->size();
        if (n <= maxPhotons) return 0;
        Rng rng(hashKeys(0x5448494eULL, settings_.seed, pass, round));
        for (size_t i = 0; i < maxPhotons; ++i) {
            size_t j = i + std::min(n - i - 1, static_cast<size_t>(rng.uniform() * (n - i)));
            std::swap((*photons)[i], (*photons)[j]);
        }
        double scale = static_cast<double>(n) / maxPhotons;
        photons->resize(maxPhotons);
        photons->shrink_to_fit();
        for (Record& ph : *photons)
            for (float& c : ph.power) c = static_cast<float>(c * scale);
        uint64_t dropped = n - maxPhotons;
        if (!warnedBudget_.exchange(true))
            warn("photon map over its budget of " + std::to_string(settings_.photonMapBudgetBytes >> 20) + " MiB: " +
                 std::to_string(dropped) + " photons thinned (power rescaled; more noise, no bias)");
        return dropped;
    }

    void decidePasses(RenderStats& stats) {
        // A camera pass's own work (the automatic photon count), counted while nothing is decided:
        // share() then gives the combined integrator's short camera paths.
        if (cameraPilot_) cameraWork_ = cameraPilot_();
        passesDecided_ = true;
        stats.passesRun.push_back("camera");
        if (!scene_.hasMedia()) {
            stats.passesSkipped.push_back("single scattering: the scene has no media");
            stats.passesSkipped.push_back("multiple scattering (photons): the scene has no media");
            settings_.singleScattering = false;
            return;
        }
        if (cameraPaths_)
            stats.passesRun.push_back(openSegments_ ? "single scattering (marched in open media: combined)"
                                                    : "single scattering (path-traced: combined)");
        else if (settings_.singleScattering) stats.passesRun.push_back("single scattering");
        else stats.passesSkipped.push_back("single scattering: disabled by settings");
        if (scene_.hasEmissiveMedia() && emitters_.empty())
            warn("photonMap integrator: the emissive media lie outside the scene's bounds, so their scattered light is not photon-traced");
        if (!settings_.multipleScattering) { stats.passesSkipped.push_back("multiple scattering (photons): disabled by settings"); return; }
        if (sealedOnly_ && !scene_.hasSealedMeshes()) {
            stats.passesSkipped.push_back("multiple scattering (photons): combined with combinedPhotonShare 0 and no translucent "
                                          "object (the path tracer's paths carry all of it)");
            return;
        }
        if (!sourceDist_.size()) { stats.passesSkipped.push_back("multiple scattering (photons): no lights and no emissive media"); return; }
        double maxAlbedo = 0;
        for (const MediumPtr& m : scene_.desc().media) maxAlbedo = std::max(maxAlbedo, m->maxAlbedo());
        if (maxAlbedo == 0) { stats.passesSkipped.push_back("multiple scattering (photons): every medium has albedo 0"); return; }
        // Pilot: the energy reaching second and later scattering events relative to first events.
        PhotonRecords pilot;  // points and beams: their records key the PhotonCache
        uint64_t traced = 0;
        constexpr int PilotPhotons = 4096;
        double energy[2] = {0, 0};
        work::Count pilotWork;
        tracePhotons(-1, PilotPhotons, &pilot, &traced, energy, {}, nullptr, &pilotWork);
        // No first events but stored ones (light reaching the medium only through a dielectric or a
        // bounce) means everything is the photon map's: an infinite ratio.
        stats.multipleToSingleRatio = energy[0] > 0 ? energy[1] / energy[0] : (energy[1] > 0 ? Infinity : 0.0);
        if (energy[0] == 0 && energy[1] == 0) {
            stats.passesSkipped.push_back("multiple scattering (photons): no pilot photon scattered in a medium");
            return;
        }
        if (stats.multipleToSingleRatio < settings_.multipleThreshold) {
            stats.passesSkipped.push_back("multiple scattering (photons): pilot estimate of multiple/single energy " +
                                          std::to_string(stats.multipleToSingleRatio) + " is below multipleThreshold");
            return;
        }
        photonsEnabled_ = true;
        stats.passesRun.push_back("multiple scattering (photons)");
        if (settings_.photonBeams) {
            // Say where beams gave way to points (beamsIn).
            std::string points;
            if (!beamsIn(-1) && !scene_.desc().unboundedMedia.empty()) points = "the open media";
            for (size_t mi = 0; mi < scene_.desc().meshes.size(); ++mi)
                if (scene_.desc().meshes[mi].interiorMedium >= 0 && !beamsIn(static_cast<int>(mi)))
                    points += (points.empty() ? "" : ", ") + scene_.desc().meshes[mi].name;
            stats.passesRun.push_back(points.empty() ? "photon beams" : "photon beams; points in " + points +
                                                                            " (optically thick, translucent or with a phase peaked beyond HG g = 0.6)");
        }
        // Automatic count: the photon pass as costly as the camera pass, in work units (workCount.h)
        // measured by the two pilots, not by a clock, so the count is the same on every machine.
        stats.photonWork = pilotWork * (1.0 / PilotPhotons);
        stats.cameraWork = cameraWork_;
        if (cameraPilot_ && settings_.photonsPerPass == 0) {
            // Each stored photon or beam adds to every camera pass's gathers (candidates tested, their
            // lookups): the camera pilot again, with maps of the pilot's records at pass 0's radii.
            // Beams are long, so their gathers can cost more than their tracing (fog + spot at 320 x 240).
            PhotonRecords copy = pilot;  // the pilot's own records key the cache
            PhotonCache::Pass unused;
            buildMaps(std::move(copy), passRadius(0), passBeamRadius(0), &unused);
            work::Count gather = cameraPilot_() - cameraWork_;
            map_ = nullptr;
            beams_ = nullptr;
            stats.gatherWork = work::Count{std::max(0.0, gather.rays), std::max(0.0, gather.lookups), std::max(0.0, gather.gathers)} *
                               (1.0 / PilotPhotons);
        }
        double workPerPhoton = work::photonUnits(stats.photonWork, stats.gatherWork);
        double workPerCameraPass = cameraWork_.units();
        stats.photonWorkRatio = workPerCameraPass > 0 && workPerPhoton > 0 ? workPerCameraPass / workPerPhoton : 0.0;
        photonsPerPass_ = settings_.photonsPerPass > 0 ? settings_.photonsPerPass : autoPhotonsPerPass(stats.photonWorkRatio);
        if (cache_) {
            // An automatic count follows the cached maps' (a resized image keeps its photons), unless
            // those maps are not this scene's: then the count is this image's, as without a cache.
            int cached = cache_->photonsPerPass();
            if (settings_.photonsPerPass == 0 && cached > 0 && cache_->use(photonKey(cached, pilot))) {
                photonsPerPass_ = cached;
                resizedPhotons_ = cache_->resizedPhotonsPerPass();  // the same later count, once measured
            } else {
                cache_->use(photonKey(photonsPerPass_, pilot));
                cache_->setPhotonsPerPass(photonsPerPass_);
            }
        }
        stats.photonsPerPass = photonsPerPass_;
        measureNoise_ = settings_.photonsPerPass == 0 && resizedPhotons_ == 0;
        stats.photonsPerPassResized = resizedPhotons_;
    }

    /// What the photon passes of this render depend on besides the pass index: the photon settings
    /// and the pilot photons (PhotonCache): their records change with any light, medium, surface or
    /// bound they meet.
    uint64_t photonKey(int photonsPerPass, const PhotonRecords& pilot) const {
        auto bits = [](double x) {
            uint64_t u;
            std::memcpy(&u, &x, sizeof u);
            return u;
        };
        uint64_t h = hashKeys(settings_.seed, photonsPerPass, bits(radius_), bits(settings_.radiusAlpha),
                              bits(settings_.photonRadiusMfp), settings_.maxDepth, settings_.photonBeams, sealedOnly_,
                              settings_.photonMapBudgetBytes, pilot.photons.size(), pilot.beams.size(), sourceDist_.size(),
                              scene_.lights().size());
        // Every field of every record: 4-byte floats and ints with no padding between them.
        static_assert(sizeof(Photon) == 11 * sizeof(uint32_t) && sizeof(PhotonBeam) == 12 * sizeof(uint32_t));
        auto hashRecord = [&](const auto& record) {
            uint32_t w[sizeof(record) / sizeof(uint32_t)];
            std::memcpy(w, &record, sizeof w);
            for (uint32_t x : w) h = hashKeys(h, x);
        };
        for (const Photon& ph : pilot.photons) hashRecord(ph);
        for (const PhotonBeam& b : pilot.beams) hashRecord(b);
        return h;
    }

    double radius_, step_;
    PhotonAim aim_;  ///< where distant and dome light photons enter the scene
    Bounds3 sceneBox_;  ///< the scene's bounding sphere's box
    bool warnedNarrow_ = false;
    mutable std::atomic<bool> warnedBudget_{false};
    std::vector<int> pointLights_;
    Distribution1D extendedDist_;
    std::vector<Emitter> emitters_;
    Distribution1D sourceDist_;  ///< lights, then emitters_, by power
    std::vector<bool> beamRegions_;  ///< photonBeams: region + 1 -> beams there (beamsIn)
    bool hasExtended_ = false, hasMeshMedia_ = false, photonsEnabled_ = false, passesDecided_ = false;
    bool sealedOnly_ = false;  ///< combined with combinedPhotonShare 0: photons stored in translucent objects only
    const bool openSegments_;  ///< combined: camera segments in open media are this map's too (wholeSegment)
    std::shared_ptr<const PhotonMap> map_;  ///< this pass's map (traced, or kept in cache_)
    std::shared_ptr<const PhotonBeamMap> beams_;  ///< or its beams (photonBeams)
    std::shared_ptr<PhotonCache> cache_;
    int photonsPerPass_ = 0;  ///< settings.photonsPerPass, or the automatic count (decidePasses)
    int resizedPhotons_ = 0;  ///< the automatic count from pass PhotonNoisePasses on (0: photonsPerPass_)
    bool measureNoise_ = false;  ///< the automatic count is to be measured (photonNoiseMeasured)
    bool measuringNoise_ = false;  ///< this pass's gathers report their halves' difference
    std::unique_ptr<Integrator> cameraPaths_;  ///< integrator = combined: the path tracer's (PhotonEstimate)
    std::function<work::Count()> cameraPilot_;  ///< Renderer's camera-pass pilot (setCameraPilot)
    work::Count cameraWork_;  ///< the work of a camera pass without photons (cameraPilot_)
};

}  // namespace

std::unique_ptr<Integrator> makePhotonMapper(const Scene& scene, const RenderSettings& settings,
                                             std::shared_ptr<PhotonCache> cache, bool openMediaSegments) {
    return std::make_unique<PhotonMapper>(scene, settings, std::move(cache), openMediaSegments);
}

}  // namespace volphoton
