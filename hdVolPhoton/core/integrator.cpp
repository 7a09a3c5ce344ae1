#include <tbb/blocked_range2d.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "core/diagnostics.h"
#include "core/freeFlight.h"
#include "core/integratorBase.h"
#include "core/photonCache.h"
#include "core/workCount.h"

namespace volphoton {

Integrator::Integrator(const Scene& scene, const RenderSettings& settings) : scene_(scene), settings_(settings) {
    transmittance_.cutoff = settings.transmittanceCutoff;
    std::vector<double> power;
    for (const LightPtr& l : scene.lights()) power.push_back(l->power(scene.radius()).average());
    if (!power.empty()) lightDist_ = Distribution1D(power);
    // Medium vertices: constant domes count at MediumDomePickScale of their power (integratorBase.h).
    std::vector<double> mediumPower = power;
    for (size_t i = 0; i < mediumPower.size(); ++i)
        if (mediumSamplesDomeByPhase(static_cast<int>(i))) mediumPower[i] *= MediumDomePickScale;
    if (!mediumPower.empty()) mediumLightDist_ = Distribution1D(mediumPower);
    cameraStack_ = scene.stackAt(Camera(scene.desc().camera, 1, 1).position());
}

DirectSample Integrator::sampleDirect(const Vec3& p, Rng& rng, const PhaseAt* phase) const {
    DirectSample d;
    const Distribution1D& dist = phase ? mediumLightDist_ : lightDist_;
    if (!dist.size()) return d;
    size_t i = dist.sampleDiscrete(rng.uniform(), &d.pickProb);
    auto [u1, u2] = rng.uniform2();
    d.light = static_cast<int>(i);
    const Light& light = *scene_.lights()[i];
    if (phase && mediumSamplesDomeByPhase(d.light)) {
        d.ls.wi = phase->mp.sampleScatter(phase->d, rng.uniform(), u1, u2);
        d.ls.pdf = phase->mp.scatterPdf(dot(phase->d, d.ls.wi));
        double domePdf;
        if (!light.intersect({p, d.ls.wi}, Infinity, &d.ls.dist, &d.ls.Li, &domePdf)) d.ls.pdf = 0;
        return d;
    }
    d.ls = light.sample(p, u1, u2);
    return d;
}

bool Integrator::hitLight(const Ray& ray, double tFrom, double tMax, double* t, Spectrum* Le, double* pdf, int* light,
                          bool cameraRay) const {
    bool found = false;
    for (size_t i = 0; i < scene_.lights().size(); ++i) {
        if (hiddenFromCamera(*scene_.lights()[i], cameraRay)) continue;
        double th;
        Spectrum L;
        double p;
        // A light passed (th <= tFrom) is not met again: the same ray gives the same distance.
        if (scene_.lights()[i]->intersect(ray, tMax, &th, &L, &p) && th > tFrom && (!found || th < *t)) {
            found = true;
            *t = th;
            *Le = L;
            *pdf = p;
            *light = static_cast<int>(i);
            if (!std::isinf(th)) tMax = th;
        }
    }
    return found;
}

void Integrator::lightsAtInfinity(const Ray& ray, bool cameraRay,
                                  FunctionRef<void(int light, const Spectrum& Le, double pdf)> f) const {
    for (size_t i = 0; i < scene_.lights().size(); ++i) {
        const Light& light = *scene_.lights()[i];
        if (hiddenFromCamera(light, cameraRay)) continue;
        double t, pdf;
        Spectrum Le;
        if (light.intersect(ray, Infinity, &t, &Le, &pdf) && std::isinf(t)) f(static_cast<int>(i), Le, pdf);
    }
}

Spectrum Integrator::shadowTransmittance(const Vec3& p, const Vec3& w, double dist, MediumStack stack, Rng& rng,
                                         double tMin) const {
    Spectrum T(1.0);
    Ray ray{p, w};
    double travelled = 0;
    for (int crossings = 0; crossings < 64; ++crossings) {
        SurfaceHit hit;
        double remaining = dist - travelled;
        // Short of the far end by its float precision (a light sample on a surface is not occluded
        // by that surface).
        double tMax = remaining * (1 - 1e-7) - (std::isinf(remaining) ? 0.0 : Scene::floatError(ray.at(remaining)));
        bool blocked = scene_.intersect(ray, tMin, tMax, &hit);
        double segment = blocked ? hit.t : remaining;
        if (scene_.hasMedia()) {
            MediumAggregate media = scene_.mediaFor(stack);
            if (media.size()) T *= transmittance(media, ray, std::isinf(segment) ? 1e30 : segment, rng, transmittance_);
            if (T.isBlack()) return T;
        }
        if (!blocked) return T;
        if (scene_.mesh(hit.mesh).material.kind != SurfaceMaterial::Kind::Boundary) return Spectrum(0.0);
        stack.toggle(hit.mesh);
        travelled += hit.t;
        ray.o = hit.p;
        tMin = scene_.spawnTMin(hit, w);
    }
    return Spectrum(0.0);
}

double Integrator::leakDistance(const MediumStack& stack, const Ray& ray) const {
    int mesh = stack.innermost();
    if (mesh < 0) return Infinity;
    // A closed mesh has no hole: the path already crossed it unnoticed (a grazing internal reflection
    // whose chord to the far side is shorter than the spawn offset) and is outside. Leave it here.
    if (scene_.meshClosed(mesh)) return 0;
    static std::atomic<bool> warned{false};
    if (!warned.exchange(true))
        warn("mesh '" + scene_.mesh(mesh).name + "' bounds a medium but is not closed: rays leave it through a hole; "
             "its medium is cut at the mesh's bounding box");
    return scene_.exitDistance(mesh, ray);
}

PathSegment Integrator::nextSegment(const PathRay& path, const MediumStack& stack, bool cameraRay,
                                    double within) const {
    PathSegment seg;
    const bool limited = within < path.tMax;
    const double tMax = limited ? within : path.tMax;
    seg.hasHit = scene_.intersect(path.ray, path.tMin, tMax, &seg.hit);
    seg.tEnd = seg.hasHit ? seg.hit.t : tMax;
    seg.hasLight = hitLight(path.ray, path.lightsFrom, seg.hasHit || limited ? seg.tEnd : Infinity, &seg.tLight, &seg.lightLe,
                            &seg.lightPdf, &seg.light, cameraRay);
    if (seg.hasLight && !std::isinf(seg.tLight)) seg.tEnd = std::min(seg.tEnd, seg.tLight);
    // A limited search that meets nothing inside a closed mesh is no sign of a crossing missed
    // (leakDistance): the origin is inside, and so is everything up to `within`.
    const int around = stack.innermost();
    seg.leakExit = seg.hasHit || (limited && around >= 0 && scene_.meshClosed(around)) ? Infinity
                                                                                     : leakDistance(stack, path.ray);
    if (seg.leakExit < seg.tEnd) seg.tEnd = seg.leakExit;
    return seg;
}

void Integrator::firstVertexGuides(const Ray& cameraRay, double nearClip, double farClip, Rng& rng, Spectrum* albedo,
                                   Spectrum* normal) const {
    *albedo = Spectrum(0.0);
    *normal = Spectrum(0.0);
    PathRay path{cameraRay, nearClip, farClip, nearClip};
    MediumStack stack = cameraStack_;
    auto facing = [&](const Vec3& n) { *normal = Spectrum(n.x, n.y, n.z); };
    for (int crossings = 0; crossings < MaxBoundaryCrossings; ++crossings) {
        PathSegment ahead = nextSegment(path, stack, /*cameraRay=*/true);
        if (scene_.hasMedia()) {
            MediumAggregate media = scene_.mediaFor(stack);
            if (media.size()) {
                Ray local{path.ray.at(path.mediumFrom), path.ray.d};
                bool collided = false;
                double length = std::isinf(ahead.tEnd) ? 1e30 : ahead.tEnd - path.mediumFrom;
                sampleFreeFlight(media, local, length, rng, [&](const MediumEvent& e) {
                    Spectrum sigma_t = e.mp.sigma_t();
                    if (rng.uniform() * e.sigmaMaj >= sigma_t.average()) return true;  // a null collision
                    for (int c = 0; c < 3; ++c) (*albedo)[c] = sigma_t[c] > 0 ? e.mp.sigma_s[c] / sigma_t[c] : 0.0;
                    collided = true;
                    return false;
                });
                if (collided) return facing(-path.ray.d);
            }
        }
        if (ahead.leavesHole()) {
            path.leaveHole(stack, ahead.leakExit);
            continue;
        }
        if (ahead.reachesLight()) {
            for (int c = 0; c < 3; ++c) (*albedo)[c] = std::clamp(ahead.lightLe[c], 0.0, 1.0);
            return facing(-path.ray.d);
        }
        if (!ahead.hasHit) return;
        const SurfaceMaterial& m = scene_.mesh(ahead.hit.mesh).material;
        if (m.kind == SurfaceMaterial::Kind::Lambertian) {
            *albedo = m.albedo;
            return facing(dot(ahead.hit.ns, path.ray.d) > 0 ? -ahead.hit.ns : ahead.hit.ns);
        }
        // A boundary is crossed; a smooth dielectric is specular: the guides come from the first
        // non-specular vertex after it, along the reflection or refraction Fresnel picks.
        SurfaceScatter s = scatterSurface(path.ray, ahead.hit, stack, rng, /*radianceMode=*/true);
        if (m.kind == SurfaceMaterial::Kind::Boundary) path.passBoundary(s, ahead.hit.t);
        else path.bounce(s.next, s.tMin);
    }
}

bool pointLitMedia(const Scene& scene) {
    return scene.hasMedia() && std::any_of(scene.lights().begin(), scene.lights().end(),
                                           [](const LightPtr& l) { return l->isDelta() && l->pointPosition().has_value(); });
}

IntegratorChoice chooseIntegrator(const Scene& scene, const RenderSettings& settings) {
    using I = RenderSettings::Integrator;
    if (!scene.hasMedia()) return {I::PathTracer, "the scene has no media"};
    // Which camera rays first meet a translucent object, and which cross a medium on the way: each
    // pilot ray walks through medium boundaries (index-matched meshes that only bound a medium, as
    // shadow rays do) to the first surface that is not one.
    constexpr int PilotW = 32, PilotH = 24, MaxCrossings = 16;
    const CameraDesc& cd = scene.desc().camera;
    Camera camera(cd, std::max(1, settings.width), std::max(1, settings.height));
    const MediumStack cameraStack = scene.stackAt(camera.position());
    int translucent = 0, media = 0, surfaces = 0;  // surfaces: opaque (lambertian) ones
    double depthSum = 0;  // over the rays that cross media: their majorant optical depth, capped at DepthCap
    double albedo = 0;    // the largest single-scattering albedo of the media they cross
    constexpr double DepthCap = 4, ThinDepth = 1;
    // Open media: the photon map from SmallImagePixels (128^2) in thin media or at albedo HighAlbedo
    // and up, from LargeImagePixels (256^2) at albedo MidAlbedo and up (measurements below).
    constexpr double SmallImagePixels = 128 * 128, LargeImagePixels = 256 * 256, HighAlbedo = 0.95, MidAlbedo = 0.85;
    for (int j = 0; j < PilotH; ++j)
        for (int i = 0; i < PilotW; ++i) {
            double tMin, tMax;
            Ray ray = camera.generateRay((i + 0.5) * camera.width() / PilotW, (j + 0.5) * camera.height() / PilotH, 0.5, 0.5,
                                         &tMin, &tMax);
            MediumStack stack = cameraStack;
            bool crossesMedia = false;
            double depth = 0;
            for (int crossing = 0; crossing < MaxCrossings; ++crossing) {
                SurfaceHit hit;
                bool hasHit = scene.intersect(ray, tMin, tMax, &hit);
                double tEnd = hasHit ? hit.t : std::min(tMax, 1e30);
                MediumAggregate segmentMedia = scene.mediaFor(stack);
                if (segmentMedia.size() && depth < DepthCap)
                    segmentMedia.majorants(ray, tMin, tEnd, [&](const MajorantSegment& seg) {
                        if (seg.sigmaMaj > 0) albedo = std::max(albedo, segmentMedia.maxAlbedo());
                        crossesMedia |= seg.sigmaMaj > 0;
                        depth += seg.opticalDepth(seg.tMax - seg.tMin);
                        return depth < DepthCap;
                    });
                if (!hasHit) break;
                if (scene.mesh(hit.mesh).material.kind != SurfaceMaterial::Kind::Boundary) {
                    translucent += scene.meshTranslucent(hit.mesh) && !stack.contains(hit.mesh);
                    surfaces += scene.mesh(hit.mesh).material.kind == SurfaceMaterial::Kind::Lambertian;
                    break;
                }
                stack.toggle(hit.mesh);
                ray.o = hit.p;
                if (!std::isinf(tMax)) tMax -= hit.t;
                tMin = scene.spawnTMin(hit, ray.d);
            }
            media += crossesMedia;
            if (crossesMedia) depthSum += std::min(depth, DepthCap);
        }
    auto percent = [](int n) { return std::to_string((100 * n + PilotW * PilotH / 2) / (PilotW * PilotH)) + "%"; };
    std::string view = "translucent objects cover " + percent(translucent) + " of the view, open media " + percent(media) +
                       ", opaque surfaces " + percent(surfaces);
    if (translucent > 0 && scene.hasDeltaLight())
        return {I::Combined, view + "; a point, spot or sharp distant light reaches inside translucent objects only as photons, "
                "which the combined integrator takes there (the path tracer's paths elsewhere)", true};
    if (translucent > 0)
        return {I::Combined, view + "; the combined integrator takes photons inside translucent objects, where they lead the "
                "path tracer, and the path tracer's paths elsewhere"};
    // Thin open media lit only by point-like lights: photon beams (beam x beam, photonBeams.h) inform
    // every camera ray that passes near a photon's flight, where the path tracer's collisions are few
    // and its light paths long; fog + spot (benchmark scene 4) 0.11x-0.24x the path tracer's RMSE at
    // equal time from 80x60 to 320x240.
    double meanDepth = media > 0 ? depthSum / media : 0;
    const bool thin = meanDepth < ThinDepth;
    bool pointLit = !scene.lights().empty() && !scene.hasEmissiveMedia() &&
                    std::all_of(scene.lights().begin(), scene.lights().end(),
                                [](const LightPtr& l) { return l->equiangularCenter().has_value(); });
    char depthText[96];
    std::snprintf(depthText, sizeof depthText, ", mean optical depth %.2g along them, albedo up to %.2g", meanDepth, albedo);
    if (media > 0) view += depthText;
    // Where the photon map leads on open media: combined, whose camera segments there are the photon
    // map's (openMediaByPhotons), measured level with photonMap at equal time (dense cloud 1.00x,
    // fog + spot 1.02x, atmosphere 0.93x, VDB cloud at 320 x 240 1.00x: README, "Which integrator"),
    // and whose paths keep MIS at surfaces.
    auto byPhotons = [&](const std::string& why, bool beams) {
        IntegratorChoice choice{I::Combined, view + "; " + why};
        choice.openMediaByPhotons = true;
        choice.photonBeams = beams;
        return choice;
    };
    if (media > 0 && thin && pointLit)
        return byPhotons("optically thin open media lit only by point, spot or sphere lights, where photon beams lead the path tracer",
                         true);
    // Other open media: the photon map's error at equal time falls against the path tracer's as the
    // image grows (each photon serves the camera rays of every pixel near it; the path tracer's
    // samples per pixel fall with the pixel count), the more so the more the light scatters. Measured
    // photon map / path tracer at 80x60, 160x120, 320x240, 640x480, equal time (README, "Which
    // integrator"): thin air under the sun (benchmark scene 5) 0.93, 0.49, 0.37 with points; albedo
    // 0.99 (scene 3) 0.95, 0.62, 0.53, 0.24 with beams; albedo 0.9 (scene 2) 1.78, 1.01, 0.67, 0.37
    // with points; albedo 0.8 (scene 1) 4.06, 2.25, 1.69, 0.84 with points; emissive soot of albedo
    // 0.25 (scene 6) 0.84, 0.75, 0.92 with beams. The thresholds leave a margin for longer renders,
    // where the photon map's kernel bias weighs more (at 32 s the 160x120 ratios were 1.1x-1.4x those
    // at 4 s).
    // Opaque surfaces in view do not change this: combined's paths light them with MIS (photonMap's
    // camera paths, without it, had 2x the path tracer's RMSE on benchmark scene 7). The dense cloud
    // before a wall filling the view (160 x 120, 3 seeds of 4 s; README, "Which integrator"): combined
    // 0.92x the path tracer with the cloud on 40% of the view, 1.01x with it on 7%.
    const double pixels = double(std::max(1, settings.width)) * std::max(1, settings.height);
    std::string size = std::to_string(settings.width) + " x " + std::to_string(settings.height) + " pixels";
    // A render long enough for the measured choice (Renderer: combined's automatic share and photon
    // count, MinTrialRenderPasses passes or a progressive render) tries the photons wherever the
    // photon map may lead, and keeps them only where they measure cheaper than the path tracer's
    // paths: thin media and media of albedo HighAlbedo and up at any size (the atmosphere's photon map
    // led at 80 x 60, 0.7x-0.9x the path tracer's RMSE; the dense cloud's was level), albedo MidAlbedo
    // and up from SmallImagePixels, any medium from LargeImagePixels (the cube's, albedo 0.8, led at
    // 640 x 480). Below those the path tracer led by 1.6x-7.8x (the VDB cloud, the cube, emissive
    // smoke at 80 x 60), and a trial's photon passes cost 8-15% of a 4 s render there. Points, or
    // beams where the media scatter light many times (as the rule below for 128 x 128 and up).
    // Point and spot lights are not measured: near one, the path tracer's variance is unbounded
    // (pointLitMedia), so their photons are kept.
    const bool measured = measuresChoice(settings);
    const bool mayLead = thin || albedo >= HighAlbedo || (albedo >= MidAlbedo && pixels >= SmallImagePixels) ||
                         pixels >= LargeImagePixels;
    if (media > 0 && measured && pointLitMedia(scene))
        return byPhotons("a point or spot light lights these open media, where the path tracer's variance is unbounded",
                         !thin && albedo >= HighAlbedo);
    if (media > 0 && measured && mayLead)
        return byPhotons("photons tried on these open media at " + size + ", kept if they measure cheaper than the path tracer",
                         !thin && albedo >= HighAlbedo);
    if (media > 0 && pixels >= SmallImagePixels && (thin || albedo >= HighAlbedo))
        return byPhotons("at " + size + " the photon map leads the path tracer in " +
                             (thin ? "optically thin media" : "media that scatter light many times (high albedo)"),
                         !thin);
    if (media > 0 && pixels >= LargeImagePixels && albedo >= MidAlbedo)
        return byPhotons("at " + size + " the photon map leads the path tracer in media of this albedo", false);
    return {I::PathTracer, view + "; the path tracer leads on these open media at " + size};
}

Renderer::Renderer(std::shared_ptr<const Scene> scene, const RenderSettings& settings, std::shared_ptr<PhotonCache> photonCache)
    : scene_(std::move(scene)), settings_(settings), film_(settings.width, settings.height) {
    if (settings_.samplesPerPixel < 0) throw std::invalid_argument("render settings: samplesPerPixel must be >= 0");
    if (settings_.maxDepth < 0) throw std::invalid_argument("render settings: maxDepth must be >= 0");
    if (settings_.photonsPerPass < 0) throw std::invalid_argument("render settings: photonsPerPass must be >= 0");
    if (!(settings_.radiusAlpha > 0 && settings_.radiusAlpha <= 1)) throw std::invalid_argument("render settings: radiusAlpha must be in (0, 1]");
    if (settings_.stratifiedDims < 0) throw std::invalid_argument("render settings: stratifiedDims must be >= 0");
    if (!(settings_.photonRadiusMfp >= 0)) throw std::invalid_argument("render settings: photonRadiusMfp must be >= 0");
    if (!(settings_.combinedPhotonShare >= 0 && settings_.combinedPhotonShare <= 1) && settings_.combinedPhotonShare != -1)
        throw std::invalid_argument("render settings: combinedPhotonShare must be in [0, 1], or -1 (auto)");
    if (!(settings_.noiseTarget >= 0) || !(settings_.timeLimit >= 0) || settings_.maxSamplesPerPixel < 1)
        throw std::invalid_argument("render settings: noiseTarget and timeLimit must be >= 0, maxSamplesPerPixel >= 1");
    active_.assign(static_cast<size_t>(settings_.width) * settings_.height, 1);
    stats_.activePixels = active_.size();
    // The integrator that renders: the one asked for, or auto's choice (settings_ keeps "auto").
    RenderSettings resolved = settings_;
    std::optional<IntegratorChoice> choice;
    if (settings_.integrator == RenderSettings::Integrator::Auto) {
        choice = chooseIntegrator(*scene_, settings_);
        resolved.integrator = choice->integrator;
        resolved.photonBeams |= choice->photonBeams;
        stats_.integratorReason = choice->reason;
    }
    const bool combined = resolved.integrator == RenderSettings::Integrator::Combined;
    bool openMediaSegments = false;
    if (combined && resolved.combinedPhotonShare < 0) {
        // combinedPhotonShare auto: where auto's pilot finds the photon map leading on open media
        // (openMediaByPhotons), camera segments in open media are the photon map's (its march's single
        // scattering and its gather, with auto's points or beams); elsewhere the path tracer's paths
        // carry open media (share 0).
        // Surfaces, emission and translucent objects are combined's either way. Share 1 alone (the
        // photons' multiple scattering, the path tracer's single) measured 0.995x the photon map's RMSE
        // on the dense cloud but 2.0x on the atmosphere, where single scattering is most of the light
        // (README, "Which integrator").
        if (!choice) choice = chooseIntegrator(*scene_, settings_);
        openMediaSegments = choice->openMediaByPhotons;
        resolved.combinedPhotonShare = openMediaSegments ? 1 : 0;
        resolved.photonBeams |= openMediaSegments && choice->photonBeams;
        // auto's own reason stands where it chose combined for translucent objects
        if (settings_.integrator == RenderSettings::Integrator::Combined || openMediaSegments)
            stats_.integratorReason = std::string(openMediaSegments ? "open media by the photon map" : "open media by the path tracer") +
                                      (openMediaSegments && resolved.photonBeams ? " (beams)" : "") + ": " + choice->reason;
    }
    // The PhotonMapper renders photonMap and combined (its camera paths are the path tracer's then).
    bool photonMapper = resolved.integrator == RenderSettings::Integrator::PhotonMap || combined;
    if (resolved.integrator == RenderSettings::Integrator::PathTracer && settings_.integrator != RenderSettings::Integrator::Auto &&
        scene_->hasMedia()) {
        // The path tracer cannot carry a delta light's light through a refracting surface (shadow
        // rays stop at dielectrics): say so rather than render translucent objects without it. The
        // pilot runs only where the scene has both (not on every restart of every scene).
        bool translucentMesh = false;
        for (size_t i = 0; i < scene_->desc().meshes.size(); ++i) translucentMesh |= scene_->meshTranslucent(static_cast<int>(i));
        IntegratorChoice choice = scene_->hasDeltaLight() && translucentMesh ? chooseIntegrator(*scene_, settings_) : IntegratorChoice{};
        if (choice.photonsOnly)
            warn("pathTracer integrator: " + choice.reason.substr(0, choice.reason.find(';')) +
                 ", and the light of point, spot and sharp distant lights reaches inside them only as photons: it is "
                 "missing there (use integrator combined, photonMap or auto, or lights with extent)");
    }
    if (photonMapper && !scene_->hasMedia()) {
        // Without media the photon map has nothing to add: both of its passes would be skipped and its
        // camera paths (light sampling only, no MIS) are noisier than the path tracer's on the same
        // surfaces (2x the RMSE on benchmark scene 7). Same answer, so the path tracer renders it.
        photonMapper = false;
        stats_.passesSkipped.push_back("single scattering: the scene has no media");
        stats_.passesSkipped.push_back("multiple scattering (photons): the scene has no media");
        stats_.passesSkipped.push_back("photon-map camera paths: the scene has no media, so the path tracer renders it");
    }
    usesPhotons_ = photonMapper;
    stats_.integratorUsed = photonMapper ? (combined ? "combined" : "photonMap") : "pathTracer";
    // The measured choice (renderPass): combined with the automatic share measures its photons against
    // the path tracer, unless a delta light reaches translucent objects only as photons, a point or spot
    // light lights the media (pointLitMedia), the photon count is the settings' (then its noise is not
    // measured either), or the render is too short for it.
    if (photonMapper && combined && measuresChoice(settings_) && !(choice && choice->photonsOnly) && !pointLitMedia(*scene_))
        trial_ = Trial::Photons;
    photonCache_ = photonCache;
    integrator_ = photonMapper ? makePhotonMapper(*scene_, resolved, std::move(photonCache), openMediaSegments) : makePathTracer(*scene_, settings_);
    if (scene_->hasMedia()) {
        Camera camera(scene_->desc().camera, settings_.width, settings_.height);
        for (const LightPtr& light : scene_->lights()) {
            std::optional<Vec3> c = light->equiangularCenter();
            double px, py;
            if (!c || !camera.project(*c, &px, &py)) continue;
            size_t index = static_cast<size_t>(py) * settings_.width + static_cast<size_t>(px);
            auto at = std::lower_bound(lightPixels_.begin(), lightPixels_.end(), index);
            if (at == lightPixels_.end() || at->index != index) lightPixels_.insert(at, {index, {px, py}});
        }
    }
    if (!scene_->hasMedia()) stats_.passesSkipped.push_back("volumes: the scene has no media");
    if (scene_->hasMedia() && !scene_->hasEmissiveMedia()) stats_.passesSkipped.push_back("volume emission: no medium emits");
}

Renderer::~Renderer() = default;

namespace {

/// Caps TBB's parallelism at settings.threads (> 0) for as long as the returned object lives.
std::unique_ptr<tbb::global_control> limitThreads(const RenderSettings& settings) {
    if (settings.threads <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, settings.threads);
}

/// One camera sample of pixel (x, y): a jittered position in it and the integrator's radiance.
/// false (and an empty result) when a numerical accident made the radiance non-finite or negative:
/// such a sample must never reach a film.
/// guides: also the denoiser guides of the same camera ray, from their own stream (guideRng), so
/// that the beauty is the same with or without them.
/// around: the pixel images a point-like light (Renderer::lightPixels_): its position comes from
/// samplePixelAroundPoint, and the radiance (and alpha) carry that sample's weight.
bool cameraSample(const Integrator& integrator, const Camera& camera, int x, int y, Rng& rng, PathRadiance* L,
                  Rng* guideRng = nullptr, const ImagePoint* around = nullptr) {
    double tMin, tMax;
    Ray ray;
    double weight = 1;
    if (around) {
        double u0 = rng.uniform(), u1 = rng.uniform();
        PixelPosition pos = samplePixelAroundPoint(x, y, *around, u0, u1);
        double l0 = rng.uniform(), l1 = rng.uniform();
        ray = camera.generateRay(pos.x, pos.y, l0, l1, &tMin, &tMax);
        weight = pos.weight;
    } else {
        ray = camera.generateRay(x + rng.uniform(), y + rng.uniform(), rng.uniform(), rng.uniform(), &tMin, &tMax);
    }
    // weight 0: a polar position outside the pixel, a sample of value 0 (its guides still count).
    *L = weight > 0 ? integrator.Li(ray, tMin, tMax, rng) : PathRadiance();
    if (weight != 1) {
        for (Spectrum* part : {&L->single, &L->multiple, &L->emission, &L->surface}) *part *= weight;
        L->alpha *= weight;
    }
    if (guideRng) integrator.firstVertexGuides(ray, tMin, tMax, *guideRng, &L->albedo, &L->normal);
    if (L->beauty().isFinite() && L->beauty().minValue() >= 0) return true;
    *L = PathRadiance();
    return false;
}

}  // namespace

const ImagePoint* Renderer::lightPixel(int x, int y) const {
    if (lightPixels_.empty()) return nullptr;  // most scenes: nothing to look up
    size_t index = static_cast<size_t>(y) * settings_.width + x;
    auto it = std::lower_bound(lightPixels_.begin(), lightPixels_.end(), index);
    return it != lightPixels_.end() && it->index == index ? &it->light : nullptr;
}

work::Count Renderer::cameraPilotWork(const Integrator& integrator) const {
    // One sample at the centre of each cell of a 16 x 16 grid over the image (fewer where the image
    // is smaller): every row and column band is seen (a stride through the pixel index fell on 16
    // columns at 320 wide).
    const int w = settings_.width, h = settings_.height;
    const int nx = std::min(16, w), ny = std::min(16, h);
    Camera camera(scene_->desc().camera, w, h);
    work::Snapshot before = work::snapshot();
    for (int gy = 0; gy < ny; ++gy)
        for (int gx = 0; gx < nx; ++gx) {
            Rng rng(hashKeys(0x50494c4fULL, settings_.seed, gy * nx + gx));
            PathRadiance L;
            cameraSample(integrator, camera, (2 * gx + 1) * w / (2 * nx), (2 * gy + 1) * h / (2 * ny), rng, &L);
        }
    return work::since(before) * (double(w) * h / (nx * ny));
}

bool Renderer::renderPass(const CancelCallback& cancel) {
    auto start = std::chrono::steady_clock::now();
    auto threads = limitThreads(settings_);
    // The photon map's automatic photon count weighs a camera pass's work (deterministic pilot, run
    // by beginPass on this thread: work is counted per thread) against a photon's.
    if (pass_ == 0 && usesPhotons_ && settings_.photonsPerPass == 0) integrator_->setCameraPilot([this] { return cameraPilotWork(*integrator_); });
    // The path tracer's trial passes (the measured choice) leave the photon integrator alone.
    const bool trialPass = trial_ == Trial::PathTracer;
    if (!trialPass) {
        if (!integrator_->beginPass(integratorPass_, stats_, cancel)) {
            stats_.cancelled = true;
            return false;
        }
        ++integratorPass_;
    }
    if (pass_ == 0 && trial_ == Trial::Photons) {
        // A render that follows cached maps follows their measured choice too; one whose photon count
        // is not measured (photons skipped, or a cache's count) is not compared either.
        PhotonCache::Choice cached = photonCache_ ? photonCache_->measuredChoice() : PhotonCache::Choice::Unmeasured;
        if (cached == PhotonCache::Choice::PathTracer)
            switchToPathTracer(makePathTracer(*scene_, settings_), "the path tracer, as measured by an earlier render of these photon maps");
        else if (cached == PhotonCache::Choice::Photons || !integrator_->measuresPhotonNoise())
            trial_ = Trial::Off;
    }
    auto photonsDone = std::chrono::steady_clock::now();
    Camera camera(scene_->desc().camera, settings_.width, settings_.height);
    std::atomic<bool> cancelled{false};
    static_assert(PhotonNoisePasses == 2 && TrialPasses == 2, "the spread of two samples: (x1 - x0)^2 / 2");
    const bool measureNoise = !trialPass && integrator_->measuresPhotonNoise() && photonNoisePasses_ < PhotonNoisePasses;
    // Which of its two samples this pass gives a pixel's spread: the photon measurement's or the trial's.
    const int spreadSample = measureNoise ? photonNoisePasses_ : trialPass ? trialPassesRun_ : -1;
    if (spreadSample == 0) photonNoiseFirst_.assign(active_.size(), std::numeric_limits<float>::quiet_NaN());
    if (measureNoise && spreadSample == 0 && trial_ == Trial::Photons)
        trialPhotonMean_.assign(active_.size(), std::numeric_limits<float>::quiet_NaN());
    const Integrator& integrator = trialPass ? *trialPathTracer_ : *integrator_;
    const int tile = 16;
    int tilesX = (settings_.width + tile - 1) / tile, tilesY = (settings_.height + tile - 1) / tile;
    // Per tile (each tile is one thread's at a time), summed in tile order below: the same on any
    // number of threads.
    std::vector<PhotonNoiseSums> noiseTiles(spreadSample >= 0 ? size_t(tilesX) * tilesY : 0);
    tbb::parallel_for(tbb::blocked_range2d<int>(0, tilesY, 0, tilesX), [&](const tbb::blocked_range2d<int>& r) {
        for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty)
            for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx) {
                if (cancelled.load(std::memory_order_relaxed) || (cancel && cancel())) {
                    cancelled = true;
                    return;
                }
                for (int y = ty * tile; y < std::min(settings_.height, (ty + 1) * tile); ++y)
                    for (int x = tx * tile; x < std::min(settings_.width, (tx + 1) * tile); ++x) {
                        if (!active_[static_cast<size_t>(y) * settings_.width + x]) continue;
                        const ImagePoint* light = lightPixel(x, y);
                        if (trialPass && light) continue;  // left out of the measurement, so not rendered
                        for (int k = 0, n = light ? LightPixelSamples : 1; k < n; ++k) {
                            // The pixel's own sample index (= pass_ unless adaptive sampling skipped it);
                            // a trial pass's are the next ones, which the pass after the trial renders again.
                            uint32_t sample = film_.samples(x, y) + (trialPass ? uint32_t(trialPassesRun_) : 0u);
                            Rng rng(hashKeys(x, y, settings_.seed), sample);
                            rng.stratify(sample, hashKeys(0x51534d43ULL, x, y, settings_.seed), settings_.stratifiedDims);
                            PathRadiance L;
                            Rng guideRng(hashKeys(x, y, settings_.seed, 0x6775696465ULL), sample);  // "guide"
                            if (!cameraSample(integrator, camera, x, y, rng, &L, settings_.guideAovs ? &guideRng : nullptr, light)) {
                                // never on the film: dropped, and reported
                                static std::atomic<int> reported{0};
                                if (reported++ < 5) warn("dropped a non-finite or negative sample at pixel " + std::to_string(x) + "," + std::to_string(y));
                            } else if (spreadSample >= 0 && !light && L.photonSplit.isFinite()) {
                                // One sample a pass (light pixels, with several, are left out).
                                PhotonNoiseSums& sums = noiseTiles[size_t(ty) * tilesX + tx];
                                const double split = L.photonSplit.average(), value = L.beauty().average();
                                sums.photon += split * split;
                                ++sums.photonPixels;
                                float& first = photonNoiseFirst_[static_cast<size_t>(y) * settings_.width + x];
                                if (spreadSample == 0) {
                                    first = static_cast<float>(value);
                                } else if (!std::isnan(first)) {
                                    sums.whole += 0.5 * (value - first) * (value - first);
                                    ++sums.wholePixels;
                                    const size_t i = static_cast<size_t>(y) * settings_.width + x;
                                    if (measureNoise && !trialPhotonMean_.empty()) {
                                        trialPhotonMean_[i] = 0.5f * (first + static_cast<float>(value));
                                    } else if (trialPass && !std::isnan(trialPhotonMean_[i])) {
                                        const double d = 0.5 * (first + value) - trialPhotonMean_[i];
                                        sums.difference += d * d;
                                        sums.differenceSum += d;
                                        sums.photonMeanSum += trialPhotonMean_[i];
                                        ++sums.differencePixels;
                                    }
                                }
                            }
                            if (!trialPass) film_.add(x, y, L);
                        }
                        if (pass_ == 0) film_.setIds(x, y, pixelIds(camera, x, y));
                    }
            }
    });
    if (!cancelled && trialPass) {
        ++trialPassesRun_;  // not a pass of the film's: pass_, stats_.passes and the samples stand
    } else if (!cancelled) {
        stats_.cameraSamples += stats_.activePixels;
        for (const LightPixel& p : lightPixels_) stats_.cameraSamples += active_[p.index] ? LightPixelSamples - 1 : 0;
        ++pass_;
        ++stats_.passes;
    }
    if (!cancelled) {
        PhotonNoiseSums& spread = measureNoise ? photonNoise_ : trialSpread_;
        for (const PhotonNoiseSums& t : noiseTiles) {
            spread.photon += t.photon;
            spread.photonPixels += t.photonPixels;
            spread.whole += t.whole;
            spread.wholePixels += t.wholePixels;
            spread.difference += t.difference;
            spread.differenceSum += t.differenceSum;
            spread.photonMeanSum += t.photonMeanSum;
            spread.differencePixels += t.differencePixels;
        }
        if (measureNoise && ++photonNoisePasses_ == PhotonNoisePasses) {
            // The photon map's share of a sample's variance and the whole, to the integrator, which
            // sizes its later photon passes by them (PhotonMapper, "how many photons").
            photonNoiseFirst_ = {};
            const PhotonNoiseSums& n = photonNoise_;
            if (n.photonPixels > 0 && n.wholePixels > 0)
                integrator_->photonNoiseMeasured(n.photon / n.photonPixels, n.whole / n.wholePixels, n.wholePixels, stats_);
            if (trial_ == Trial::Photons) {
                trial_ = n.photonPixels > 0 && n.wholePixels > 0 ? Trial::PathTracer : Trial::Off;
                if (trial_ == Trial::PathTracer) trialPathTracer_ = makePathTracer(*scene_, settings_);
            }
        }
        if (!trialPass) updateAdaptive();  // timed with the pass: the time limit counts it
    }
    auto end = std::chrono::steady_clock::now();
    stats_.photonSeconds += std::chrono::duration<double>(photonsDone - start).count();
    stats_.cameraSeconds += std::chrono::duration<double>(end - photonsDone).count();
    stats_.seconds += std::chrono::duration<double>(end - start).count();
    lastPassSeconds_ = std::chrono::duration<double>(end - start).count();
    // The next photon pass's photons, where the measurement just raised their count, take that much
    // longer (the pass after the trial's, if the photons win it).
    if (pass_ == PhotonNoisePasses && !trialPass && !cancelled) {
        photonPassSeconds_ = lastPassSeconds_;
        if (stats_.photonsPerPassResized > stats_.photonsPerPass && stats_.photonsPerPass > 0)
            photonPassSeconds_ += std::chrono::duration<double>(photonsDone - start).count() *
                                  (double(stats_.photonsPerPassResized) / stats_.photonsPerPass - 1);
        if (trial_ != Trial::PathTracer) lastPassSeconds_ = photonPassSeconds_;
    }
    if (!cancelled && trialPass && trialPassesRun_ == TrialPasses) decideTrial();
    if (cancelled) {
        stats_.cancelled = true;
        return false;
    }
    return true;
}

// ---- the measured choice ---------------------------------------------------------------------
// combined with the automatic share renders with photons where auto's pilot finds them leading
// (translucent objects, and open media where the image is large enough), a guess from the view. The
// render measures it instead: its first PhotonNoisePasses passes (which also size the photon count)
// are followed by TrialPasses passes of the path tracer, and each side's cost to a given noise, the
// variance of a sample times the work of a pass, decides which renders the rest. The photons' side is
// taken at the resized count: b + a P0 / P1 (a: the photon map's share of the variance measured at
// P0 photons, b the rest, floored as in PhotonMapper) times the work of a camera pass plus P1 photons;
// the path tracer's its two passes' spread times its camera pilot's work. Work in deterministic units
// (workCount.h), not seconds, so the choice and the image are the same on every machine. Both sides'
// variance comes from a pixel's two samples, whose Sobol' points are a stratified pair, so both are
// overstated alike. The kernel's bias is not in the comparison (it falls with the passes).
// Two samples cannot show a variance made of rare events: a path tracer that finds a small light only
// by chance (seen through a dielectric, where no shadow ray reaches it) has two samples of 0 in most
// pixels, a spread near 0 and an enormous variance (TheMeasuredChoiceKeepsTheCheaperSide: 600x the
// photons' at equal time). Its mean betrays it: the light it missed. So the path tracer is taken only
// where its trial image's mean is within ShortfallTolerance (the photons' kernel bias) plus 4 standard
// errors of the photon passes' mean.
// The trial's path-traced samples never reach the film, and its passes are not the film's (pass_,
// stats.passes and cameraSamples leave them out; their time counts): where the photons win, two
// noisier samples among a photon render's few, costly passes would cost it (the atmosphere at 80 x 60
// runs 37 passes in 4 s; with its two path-traced ones in the film its RMSE was 1.6x the photon
// map's), and where the path tracer wins it renders the same two samples again (the same sample
// indices). A render stopped during the trial (a time limit) holds the photons' passes alone.
void Renderer::decideTrial() {
    constexpr double ShortfallTolerance = 0.02;
    const PhotonNoiseSums& n = photonNoise_;
    const PhotonNoiseSums& t = trialSpread_;
    const double s = n.photon / n.photonPixels, v = n.whole / n.wholePixels;
    const double p0 = stats_.photonsPerPass, p1 = std::max(p0, double(stats_.photonsPerPassResized));
    const double photonVariance = std::max(v - s, v / CameraShareFloor) + s * p0 / p1;
    const double photonWork = stats_.cameraWork.units() + p1 * work::photonUnits(stats_.photonWork, stats_.gatherWork);
    const double pathVariance = t.wholePixels > 0 ? t.whole / t.wholePixels : Infinity;
    const double pathWork = cameraPilotWork(*trialPathTracer_).units();
    stats_.measuredPhotonCost = photonVariance * photonWork;
    stats_.measuredPathTracerCost = pathVariance * pathWork;
    // The two images' means over the pixels that have both (d: a pixel's path-traced mean minus its
    // photon mean), and the standard error of their difference from the pixels' spread of d.
    const double pixels = double(std::max<int64_t>(t.differencePixels, 1));
    const double photonMean = t.photonMeanSum / pixels, shortfall = -t.differenceSum / pixels;
    const double error = std::sqrt(std::max(0.0, t.difference / pixels - shortfall * shortfall) / pixels);
    const bool fallsShort = shortfall > ShortfallTolerance * std::abs(photonMean) + 4 * error;
    photonNoiseFirst_ = {};
    trialPhotonMean_ = {};
    char text[320];
    int at = std::snprintf(text, sizeof text, "measured on passes 1-%d: variance x work a pass %.3g with photons, %.3g with the path tracer (%.2fx)",
                           PhotonNoisePasses + TrialPasses, stats_.measuredPhotonCost, stats_.measuredPathTracerCost,
                           stats_.measuredPathTracerCost / stats_.measuredPhotonCost);
    if (fallsShort && at > 0 && at < int(sizeof text))
        std::snprintf(text + at, sizeof text - at, ", but its image %.1f%% darker than the photons' (light it finds only by chance)",
                      100 * shortfall / std::max(photonMean, 1e-300));
    if (!fallsShort && stats_.measuredPathTracerCost < stats_.measuredPhotonCost) {
        if (photonCache_) photonCache_->setMeasuredChoice(PhotonCache::Choice::PathTracer);
        switchToPathTracer(std::move(trialPathTracer_), std::string(text) + ": the path tracer renders the rest");
        return;
    }
    if (photonCache_) photonCache_->setMeasuredChoice(PhotonCache::Choice::Photons);
    trial_ = Trial::Done;
    trialPathTracer_.reset();
    stats_.passesRun.push_back(std::string(text) + ": combined renders the rest");
    stats_.integratorReason += "; " + std::string(text) + ": combined kept";
    lastPassSeconds_ = photonPassSeconds_;
}

void Renderer::switchToPathTracer(std::unique_ptr<Integrator> pathTracer, const std::string& why) {
    integrator_ = std::move(pathTracer);  // frees the photon maps (a cache keeps its own)
    trial_ = Trial::Done;
    usesPhotons_ = false;
    stats_.integratorUsed = "pathTracer";
    stats_.integratorReason += (stats_.integratorReason.empty() ? "" : "; ") + why;
    stats_.passesRun.push_back("path tracer: " + why);
}

void Renderer::updateAdaptive() {
    if (!settings_.progressive() && pass_ < settings_.samplesPerPixel) return;  // only the stats at the end need it
    std::vector<float> error = film_.resolveRelativeError();
    std::vector<float> sorted = error;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    float median = sorted[sorted.size() / 2];
    stats_.medianRelativeError = std::isinf(median) ? -1.0 : median;
    if (settings_.noiseTarget <= 0 || pass_ < settings_.samplesPerPixel) return;
    // A pixel stays active while it or a neighbour is above the target.
    const int w = settings_.width, h = settings_.height;
    uint64_t count = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool above = false;
            for (int dy = -1; dy <= 1 && !above; ++dy)
                for (int dx = -1; dx <= 1 && !above; ++dx) {
                    int nx = x + dx, ny = y + dy;
                    if (nx >= 0 && ny >= 0 && nx < w && ny < h) above = !(error[size_t(ny) * w + nx] <= settings_.noiseTarget);
                }
            active_[size_t(y) * w + x] = above;
            count += above;
        }
    stats_.activePixels = count;
}

bool Renderer::finished() {
    const char* reason = nullptr;
    if (!settings_.progressive()) {
        if (pass_ >= settings_.samplesPerPixel) reason = "samplesPerPixel";
    } else if (settings_.noiseTarget > 0 && pass_ >= settings_.samplesPerPixel && stats_.activePixels == 0) {
        reason = "noiseTarget";
    } else if (pass_ >= settings_.maxSamplesPerPixel) {
        reason = "maxSamplesPerPixel";
    } else if (settings_.timeLimit > 0 && pass_ > 0 && stats_.seconds + lastPassSeconds_ > settings_.timeLimit) {
        reason = "timeLimit";
    }
    if (reason) stats_.stopReason = reason;
    return reason != nullptr;
}

int Renderer::estimatedPasses() const {
    if (!settings_.progressive()) return settings_.samplesPerPixel;
    double estimate = settings_.maxSamplesPerPixel;
    if (settings_.timeLimit > 0 && pass_ > 0 && stats_.seconds > 0)
        estimate = std::min(estimate, pass_ * settings_.timeLimit / stats_.seconds);
    if (settings_.noiseTarget > 0 && stats_.medianRelativeError > 0) {
        // Error falls as 1/sqrt(passes): the median pixel's passes to the target, at least the minimum.
        double ratio = stats_.medianRelativeError / settings_.noiseTarget;
        estimate = std::min(estimate, std::max<double>(settings_.samplesPerPixel, pass_ * ratio * ratio));
    }
    return std::max(pass_ + (stats_.stopReason.empty() ? 1 : 0), static_cast<int>(std::ceil(estimate)));
}

bool Renderer::renderPreview(int block, Film& preview, const CancelCallback& cancel) const {
    if (block < 1 || preview.width() != settings_.width || preview.height() != settings_.height)
        throw std::invalid_argument("preview: block must be >= 1 and the film the render's size");
    auto threads = limitThreads(settings_);
    preview.clear();
    std::unique_ptr<Integrator> pathTracer = makePathTracer(*scene_, settings_);
    Camera camera(scene_->desc().camera, settings_.width, settings_.height);
    int blocksX = (settings_.width + block - 1) / block, blocksY = (settings_.height + block - 1) / block;
    std::atomic<bool> cancelled{false};
    // A stream no pass uses (passes count up from 0), so the preview shares no samples with them.
    const uint64_t previewStream = ~uint64_t(0);
    tbb::parallel_for(tbb::blocked_range2d<int>(0, blocksY, 0, blocksX), [&](const tbb::blocked_range2d<int>& r) {
        if (cancelled.load(std::memory_order_relaxed) || (cancel && cancel())) {
            cancelled = true;
            return;
        }
        for (int by = r.rows().begin(); by < r.rows().end(); ++by)
            for (int bx = r.cols().begin(); bx < r.cols().end(); ++bx) {
                int x0 = bx * block, y0 = by * block;
                int x1 = std::min(settings_.width, x0 + block), y1 = std::min(settings_.height, y0 + block);
                int cx = (x0 + x1 - 1) / 2, cy = (y0 + y1 - 1) / 2;
                Rng rng(hashKeys(cx, cy, settings_.seed), previewStream);
                PathRadiance L;
                cameraSample(*pathTracer, camera, cx, cy, rng, &L);  // a dropped sample leaves the block black
                PixelIds ids = pixelIds(camera, cx, cy);
                for (int y = y0; y < y1; ++y)
                    for (int x = x0; x < x1; ++x) {
                        preview.add(x, y, L);
                        preview.setIds(x, y, ids);
                    }
            }
    });
    return !cancelled;
}

PixelIds Renderer::pixelIds(const Camera& camera, int x, int y) const {
    double tMin, tMax;
    Ray ray = camera.generateRay(x + 0.5, y + 0.5, 0.0, 0.0, &tMin, &tMax);
    PixelIds boundary;
    for (int crossings = 0; crossings < 64; ++crossings) {
        SurfaceHit hit;
        if (!scene_->intersect(ray, tMin, tMax, &hit)) break;
        const MeshDesc& mesh = scene_->mesh(hit.mesh);
        const InstanceDesc& inst = scene_->desc().instances[hit.instance];
        PixelIds ids{inst.objectId, inst.instanceId,
                     mesh.triangleElements.empty() ? hit.triangle : mesh.triangleElements[hit.triangle]};
        if (mesh.material.kind != SurfaceMaterial::Kind::Boundary) return ids;
        if (boundary.object < 0) boundary = ids;
        // Straight on through the boundary, as PathRay::passBoundary does.
        ray = {hit.p, ray.d};
        if (!std::isinf(tMax)) tMax -= hit.t;
        tMin = scene_->spawnTMin(hit, ray.d);
    }
    return boundary;
}

RenderStats Renderer::render(const ProgressCallback& progress, const CancelCallback& cancel) {
    while (!finished()) {
        if (!renderPass(cancel)) break;
        if (progress) progress(pass_, estimatedPasses());
    }
    return stats_;
}

}  // namespace volphoton
