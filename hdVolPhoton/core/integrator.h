// Render settings, statistics and the progressive renderer shared by both integrators.
//
// Render settings (the Hydra delegate exposes the same names as render-setting descriptors):
// | name                | type   | default    | units        | meaning                                          |
// |---------------------|--------|------------|--------------|--------------------------------------------------|
// | integrator          | enum   | pathTracer |              | pathTracer (unbiased), photonMap, combined (the   |
// |                     |        |            |              | path tracer with the photon map's multiple        |
// |                     |        |            |              | scattering, combinedPhotonShare), or auto:        |
// |                     |        |            |              | pathTracer or combined (photons in open media,    |
// |                     |        |            |              | points or beams, where they lead) per scene and   |
// |                     |        |            |              | image size by a pilot (chooseIntegrator)          |
// | width, height       | int    | 640, 360   | pixels       | image size                                        |
// | samplesPerPixel     | int    | 16         |              | passes; one camera sample per pixel per pass. With|
// |                     |        |            |              | noiseTarget: the passes every pixel gets before it|
// |                     |        |            |              | may stop (a time limit may end the render sooner) |
// | noiseTarget         | double | 0 (off)    | relative     | adaptive sampling: after samplesPerPixel passes a |
// |                     |        |            | error        | pixel stops once its estimated relative error and |
// |                     |        |            |              | its 8 neighbours' are at most this                |
// |                     |        |            |              | (Film::resolveRelativeError); the render stops    |
// |                     |        |            |              | when every pixel has                              |
// | timeLimit           | double | 0 (none)   | seconds      | no pass starts that would end past this much      |
// |                     |        |            |              | render time (photon and camera passes; at least   |
// |                     |        |            |              | one pass runs)                                    |
// | maxSamplesPerPixel  | int    | 4096       |              | with noiseTarget or timeLimit: the most passes    |
// |                     |        |            |              | (samples) any pixel gets                          |
// | maxDepth            | int    | 100000     |              | scattering/bounce events per path. The default is |
// |                     |        |            |              | a safety cap only (Russian roulette ends paths,   |
// |                     |        |            |              | deep ones too: integratorBase.h): unbiased. A     |
// |                     |        |            |              | lower value is an artistic control and BIASED     |
// |                     |        |            |              | (dense bright media, e.g. clouds, milk, marble,   |
// |                     |        |            |              | render too dark)                                  |
// | rouletteDepth       | int    | 3          |              | events before Russian roulette may end a path     |
// |                     |        |            |              | (one whose throughput fell below 0.1:             |
// |                     |        |            |              | RouletteWeight, integratorBase.h)                 |
// | seed                | uint64 | 0          |              | every random stream hashes (pixel, the pixel's    |
// |                     |        |            |              | sample index, seed)                               |
// | stratifiedDims      | int    | 580        |              | dimensions per camera sample taken from scrambled |
// |                     |        |            |              | Sobol' points over the passes (Rng::stratify); the|
// |                     |        |            |              | path tracer gives each path segment the same 36   |
// |                     |        |            |              | (Rng::startSegment): 580 covers 16 segments.      |
// |                     |        |            |              | 0: independent random numbers throughout          |
// | threads             | int    | 0          |              | 0: all cores                                      |
// | photonsPerPass      | int    | 0 (auto)   |              | photonMap: photons traced per pass. auto: as many |
// |                     |        |            |              | as cost one camera pass, tracing and gathers      |
// |                     |        |            |              | (pilots count work, not time), in [4096, 1e6]     |
// |                     |        |            |              | (autoPhotonsPerPass); after PhotonNoisePasses (2) |
// |                     |        |            |              | passes raised, up to 8x, where the photon map's   |
// |                     |        |            |              | measured noise outweighs its cost (PhotonMapper,  |
// |                     |        |            |              | "how many photons"); or the counts of the maps a  |
// |                     |        |            |              | PhotonCache keeps                                 |
// | initialRadius       | double | 0 (auto)   | scene units  | photonMap: beam radius of pass 0 (auto: 1/100 of  |
// |                     |        |            |              | the media's diameter, Scene::mediaRadius, else of |
// |                     |        |            |              | the scene's)                                      |
// | radiusAlpha         | double | 0.7        |              | photonMap: r_{i+1}^2 = r_i^2 (i+alpha)/(i+1), i   |
// |                     |        |            |              | counting 1e5 photons traced (passRadius)          |
// | photonRadiusMfp     | double | 8          | mean free    | photonMap: a photon's radius is at most this many |
// |                     |        |            | paths        | mean free paths (1/max sigma_t) at the photon,    |
// |                     |        |            |              | for media not bounded by a closed mesh (inside one|
// |                     |        |            |              | gathering stops at the mesh); 0: no cap           |
// | combinedPhotonShare | double | -1 (auto)  | [0, 1], -1   | combined: the photon map's share w of the light   |
// |                     |        |            |              | scattered more than once at a camera path's vertex|
// |                     |        |            |              | in open media (inside translucent objects it is   |
// |                     |        |            |              | 1); the path goes on for the rest with probability|
// |                     |        |            |              | 1 - w. 0: the path tracer's in open media (photons|
// |                     |        |            |              | only for translucent objects). -1 (auto): where   |
// |                     |        |            |              | auto's pilot picks the photon map, camera segments|
// |                     |        |            |              | in open media are the photon map's (its march's   |
// |                     |        |            |              | single scattering, its gather with auto's points  |
// |                     |        |            |              | or beams), else 0 (Renderer); in renders of 16    |
// |                     |        |            |              | passes and up (or progressive) with photonsPerPass|
// |                     |        |            |              | 0, passes 1-2 use the photons, 3-4 the path tracer|
// |                     |        |            |              | and the cheaper renders the rest (the measured    |
// |                     |        |            |              | choice, Renderer::decideTrial)                    |
// | photonBeams         | bool   | false      |              | photonMap: multiple scattering from photon beams  |
// |                     |        |            |              | (beam x beam 1D, short beams: photonBeams.h), not |
// |                     |        |            |              | photon points, where media are optically thin     |
// |                     |        |            |              | (points in regions thicker than 100, in           |
// |                     |        |            |              | translucent objects and where a phase is peaked   |
// |                     |        |            |              | beyond HG g = 0.6); the beams' radius shrinks as  |
// |                     |        |            |              | r (i+alpha)/(i+1). false: points everywhere       |
// | marchStep           | double | 0 (auto)   | scene units  | photonMap: single-scattering step (auto: 1/256 of |
// |                     |        |            |              | the media's diameter, else of the scene's)        |
// | singleScattering    | bool   | true       |              | photonMap: run the single-scattering pass         |
// | multipleScattering  | bool   | true       |              | photonMap: run the photon (multiple) pass         |
// | multipleThreshold   | double | 1e-3       |              | photonMap: skip photons when a pilot estimates the|
// |                     |        |            |              | multiple/single energy ratio below this           |
// | transmittanceCutoff | double | 0          |              | deterministic early termination (BIASED)          |
// | photonMapBudgetBytes| size_t | 1 GiB      | bytes        | photonMap: memory cap of one pass's photon map;   |
// |                     |        |            |              | beyond it photons are thinned at random, their    |
// |                     |        |            |              | power scaled up (unbiased), and the stats say so  |
// | maxGridVoxels       | uint64 | 2^30       | voxels       | VDB grids with more active voxels are refused     |
// |                     |        |            |              | (warned; the volume is skipped); 0: no cap        |
// | guideAovs           | bool   | false      |              | fill the albedo and normal AOVs (denoiser guides) |
// |                     |        |            |              | from one extra first-vertex ray per sample (its   |
// |                     |        |            |              | own random stream: the beauty is unchanged)       |
// | domeVisibleToCamera | bool   | true       |              | false: camera rays that escape (straight through  |
// |                     |        |            |              | media and index-matched boundaries) see black and |
// |                     |        |            |              | alpha 0; the dome still lights the scene (Hydra's |
// |                     |        |            |              | domeLightCameraVisibility)                        |
//
// AOVs: the light-path split is decided by the first vertex of the camera path other than an
// index-matched medium boundary:
//  - emission: volume emission reached along the first segment;
//  - single:   light from a light source scattered once at a first vertex in a medium;
//  - multiple: everything else that first scatters in a medium (light scattered twice or more,
//              scattered volume emission, light scattered in the medium after a surface bounce);
//  - surface:  everything whose first vertex is a surface (lambertian or dielectric), plus lights and
//              the environment seen directly through the media.
// beauty = single + multiple + emission + surface, in both integrators.
// With guideAovs, two more for a denoiser (Integrator::firstVertexGuides, the same for both
// integrators): albedo and normal at the first non-specular vertex of the camera path (index-matched
// boundaries are crossed and smooth dielectrics followed along the reflection or refraction Fresnel
// picks; then a lambertian surface gives its albedo and its normal turned to the camera, a medium
// collision the single-scattering albedo sigma_s / sigma_t and the normal -ray direction, a light or
// the sky its radiance clamped to [0, 1] and -ray direction).
#pragma once

#include <algorithm>
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/film.h"
#include "core/scene.h"
#include "core/transmittance.h"
#include "core/sampling.h"
#include "core/workCount.h"

namespace volphoton {

struct RenderSettings {
    /// Auto: pathTracer or combined, chosen per scene by a pilot of camera rays (chooseIntegrator).
    /// Combined: the path tracer's camera paths with the photon map's estimate of multiple scattering
    /// along their medium segments (PhotonEstimate, integratorBase.h), weighted by combinedPhotonShare.
    enum class Integrator { PathTracer, PhotonMap, Auto, Combined };
    Integrator integrator = Integrator::PathTracer;
    int width = 640, height = 360;
    int samplesPerPixel = 16;
    double noiseTarget = 0;
    double timeLimit = 0;
    int maxSamplesPerPixel = 4096;
    /// noiseTarget or timeLimit set: passes go on past samplesPerPixel (Renderer::finished()).
    bool progressive() const { return noiseTarget > 0 || timeLimit > 0; }
    /// A safety cap, not a truncation: no furnace or slab test sees it (Russian roulette ends paths
    /// long before; DeepRouletteDepth in integratorBase.h ends even lossless ones).
    static constexpr int DefaultMaxDepth = 100000;
    int maxDepth = DefaultMaxDepth;
    int rouletteDepth = 3;
    uint64_t seed = 0;
    int threads = 0;
    int photonsPerPass = 0;
    double initialRadius = 0;
    double radiusAlpha = 0.7;
    double photonRadiusMfp = 8;
    bool photonBeams = false;
    double combinedPhotonShare = -1;  ///< -1: automatic (resolved by the Renderer from auto's pilot)
    int stratifiedDims = 580;  // camera + 16 segments of Rng::SegmentDims
    double marchStep = 0;
    bool singleScattering = true;
    bool multipleScattering = true;
    double multipleThreshold = 1e-3;
    double transmittanceCutoff = 0;
    size_t photonMapBudgetBytes = size_t(1) << 30;
    bool domeVisibleToCamera = true;
    bool guideAovs = false;
    /// Grid-size cap applied when front ends load VDB grids (GridMediumDesc::maxActiveVoxels); 0 = none.
    std::uint64_t maxGridVoxels = std::uint64_t(1) << 30;
};

/// What ran, what was skipped and why, and how long each part took.
struct RenderStats {
    int passes = 0;
    uint64_t cameraSamples = 0;
    uint64_t photonsTraced = 0;
    uint64_t photonsStored = 0;
    double seconds = 0, photonSeconds = 0, cameraSeconds = 0;
    double photonRadius = 0;
    int photonsPerPass = 0;          ///< photonMap: the count used (settings' or automatic; of the first passes where it was resized), 0 without photons
    /// An automatic count's size from pass PhotonNoisePasses on, measured by the first passes (at least
    /// photonsPerPass; 0: not measured)
    int photonsPerPassResized = 0;
    /// The photon map's share of a camera sample's variance in the measurement passes (-1: not measured)
    double photonVarianceShare = -1;
    /// combined with the automatic photon share: the measured choice between its photons and the path
    /// tracer (Renderer, "the measured choice"): each side's variance of a sample times the work of a
    /// pass (work units, workCount.h), lower is better; 0: not measured
    double measuredPhotonCost = 0, measuredPathTracerCost = 0;
    /// photonMap: photons whose tracing and gathers cost as much as a camera pass (pilots; 0: not measured)
    double photonWorkRatio = 0;
    /// photonMap pilots: rays and lookups of a camera pass without photons, of tracing a photon, and
    /// the gathers a stored photon adds to a camera pass
    work::Count cameraWork, photonWork, gatherWork;
    int photonPassesReused = 0;      ///< photon passes taken from a PhotonCache instead of traced
    uint64_t photonsReused = 0;      ///< photons in those passes' maps
    double multipleToSingleRatio = -1;  ///< pilot estimate (photonMap), -1 if not measured
    size_t photonMapBytes = 0;
    uint64_t photonsThinned = 0;  ///< photons dropped to stay within photonMapBudgetBytes
    uint64_t photonsRadiusCapped = 0;  ///< stored photons whose kernel the photonRadiusMfp cap narrowed
    /// Adaptive sampling (noiseTarget): pixels still sampled after the last pass, and the median of
    /// Film::resolveRelativeError over the image (-1 before 2 passes).
    uint64_t activePixels = 0;
    double medianRelativeError = -1;
    /// Why the render stopped: "samplesPerPixel", "noiseTarget", "timeLimit", "maxSamplesPerPixel"
    /// ("" while running or when cancelled).
    std::string stopReason;
    std::vector<std::string> passesRun;
    std::vector<std::string> passesSkipped;  ///< "name: reason"
    /// The integrator that renders ("pathTracer" / "photonMap" / "combined") and, for integrator = auto, why.
    std::string integratorUsed, integratorReason;
    bool cancelled = false;
};

/// What integrator = auto renders a scene with, and why (RenderStats::integratorReason).
struct IntegratorChoice {
    RenderSettings::Integrator integrator = RenderSettings::Integrator::PathTracer;
    std::string reason;
    /// Translucent objects in view and a delta light: the path tracer would miss that light inside.
    bool photonsOnly = false;
    /// The photon map leads the path tracer on the open media in view: the choice is combined, whose
    /// automatic share (combinedPhotonShare -1) makes their camera segments the photon map's.
    bool openMediaByPhotons = false;
    /// Those segments gather photon beams (RenderSettings::photonBeams): thin, point-lit open media, and
    /// high-albedo media in images of 128 x 128 pixels and up.
    bool photonBeams = false;
};
/// integrator = auto: a pilot of 32 x 24 camera rays through the image finds what the view is made of:
/// translucent objects (closed dielectric meshes with a medium inside, which next-event estimation
/// cannot reach), open media, or neither. The combined integrator renders views with any translucent
/// object in them: it takes photons inside translucent objects, where the photon map leads the path
/// tracer at equal time (both subsurface benchmark scenes) and where a delta light's light arrives only
/// as photons (photonsOnly), and the path tracer's paths elsewhere (on the ball behind a fog bank it
/// leads both). Open media alone: the photon map with photon beams where they are optically thin (mean
/// majorant optical depth below 1 along the pilot rays that cross them) and every light is point-like
/// (point, spot, sphere: fog + spot, benchmark scene 4). Other open media by the image's size, since
/// the photon map gains on the path tracer as pixels share its photons: from 128 x 128 pixels the
/// photon map in thin media (points) and in media of albedo >= 0.95 (beams), from 256 x 256 in media
/// of albedo >= 0.85 (points), whatever opaque surfaces fill the rest of the view; the path tracer
/// otherwise (README, "Which integrator"). Where the photon map leads on open media the choice is
/// combined with openMediaByPhotons: its camera segments there are the photon map's (same estimators,
/// level with photonMap at equal time) and its paths light surfaces with MIS.
/// Renders long enough for the measured choice (samplesPerPixel >= MinTrialRenderPasses or progressive,
/// automatic photon count and share) get the photons on open media wherever they may lead (thin or
/// albedo >= 0.95 at any size, >= 0.85 from 128 x 128, any from 256 x 256) or a point or spot light
/// lights them (pointLitMedia), and the Renderer's trial decides (Renderer, "the measured choice").
IntegratorChoice chooseIntegrator(const Scene& scene, const RenderSettings& settings);
/// A point or spot light (a delta light with a position) in a scene with media. The path tracer's
/// estimate of light scattered more than once has unbounded variance there: a vertex at distance r
/// from the light gets 1/r^2 from its shadow ray and vertices fall near the light in proportion to
/// r^2 dr, so the second moment grows as the integral of dr / r^2 (Kulla and Fajardo 2012 sample
/// single scattering equiangularly for this; the vertices of longer paths keep it). Two passes'
/// spread cannot measure an infinite variance, so the measured choice leaves such scenes to photons.
bool pointLitMedia(const Scene& scene);

using ProgressCallback = std::function<void(int passDone, int passTotal)>;
using CancelCallback = std::function<bool()>;

class Integrator;
class PhotonCache;

/// The automatic photon count (photonsPerPass = 0) from `balance`, the photons whose tracing and
/// gathers cost as much as one camera pass without photons (RenderStats::photonWorkRatio: work units,
/// core/workCount.h, of a camera pass over those of a photon, both counted by deterministic pilots, so
/// the count is the same on every machine; a photon's gathers are what a stored photon adds to the
/// camera pilot): PhotonShare x balance, at least one tracing batch (MinAutoPhotons) and at most
/// MaxAutoPhotons (about 100 MB of photon map). With gathers the cost of a pass is C + (c + g)P, so
/// the argument below holds with c + g for c; as g grows with the pixels, the count stops growing
/// with them once gathers dominate (fog + spot's beams at 320 x 240: 48k a pass, where tracing alone
/// gave 594k whose gathers took 8.5x the rest of the camera pass; equal-time RMSE 0.30x; the README,
/// "Photon maps: how many photons", has the figures).
/// Why equal cost: the time to a given noise with P photons a pass is proportional to
/// (a/P + b)(C + cP) (a/P: the photon map's variance, b: the camera side's, C and cP the two passes'
/// costs), least at P = sqrt(aC/(bc)) = balance x sqrt(r), r = a/(b balance) the photons' share of
/// the variance at equal cost. r is not known before rendering and ranges widely: 11 on
/// testenv/test_adaptive.py's slab (photon noise dominates), about 0.04 on the fog + spot benchmark
/// scene (the single-scattering march dominates). Equal cost is at most 1.3x (slab) and 1.45x (fog)
/// slower than the best split for either; twice the balance would be 1.05x and 2.1x. So passes
/// start at equal cost, and the first PhotonNoisePasses measure r and raise the count (below).
/// The former fixed 1e5 made a 4 x 4-pixel check 14x slower (vdb_cloud, 64 passes: 3.45 s of photons
/// against 0.24 s at 4096).
constexpr int MinAutoPhotons = 4096, MaxAutoPhotons = 1000000;
/// The automatic count is then measured over PhotonNoisePasses passes and raised by at most
/// MaxPhotonGrowth x where the photon map's noise outweighs its cost (PhotonMapper, "how many photons"),
/// the camera side's share of a sample's variance taken as at least 1 / CameraShareFloor of it (the
/// difference of two measured variances, noisy where the photons are nearly all of it).
constexpr int PhotonNoisePasses = 2, MaxPhotonGrowth = 8;
constexpr double CameraShareFloor = 64;
/// The measured choice (Renderer): combined's first PhotonNoisePasses passes (its photons) are
/// followed by TrialPasses passes of the path tracer, and the one whose variance x work is lower
/// renders the rest; only in renders of at least MinTrialRenderPasses passes (or progressive ones),
/// where the loser's few samples weigh little.
constexpr int TrialPasses = 2, MinTrialRenderPasses = 16;
/// Settings the measured choice applies to: the automatic photon count (whose measurement passes are
/// the photons' side of the trial) and share, and at least MinTrialRenderPasses passes to come
/// (samplesPerPixel; maxSamplesPerPixel for progressive renders).
inline bool measuresChoice(const RenderSettings& s) {
    return s.photonsPerPass == 0 && s.combinedPhotonShare < 0 &&
           (s.progressive() ? s.maxSamplesPerPixel : s.samplesPerPixel) >= MinTrialRenderPasses;
}
constexpr double PhotonShare = 1.0;
inline int autoPhotonsPerPass(double balance) {
    if (!(balance > 0)) return MinAutoPhotons;
    return static_cast<int>(std::clamp(PhotonShare * balance, double(MinAutoPhotons), double(MaxAutoPhotons)));
}

/// \class Renderer
/// Progressive rendering of a Scene into a Film: each pass adds one sample per pixel (after a photon
/// pass for the photon-map integrator). Tiles run in parallel with TBB; the cancel callback is polled
/// per tile and per photon batch. Same settings -> bit-identical film. Pass 0 also fills the film's id
/// images from each pixel's centre ray (pixelIds()). The pixel that images a point or spot light
/// in a medium samples positions around that image (lightPixels_).
///
/// Adaptive sampling (settings.noiseTarget > 0), the same for every front end: every pixel gets
/// samplesPerPixel passes; after each later pass a pixel keeps sampling only while its estimated
/// relative error (Film::resolveRelativeError) or one of its 8 neighbours' is above the target (the
/// neighbourhood keeps a lone lucky estimate from stopping a noisy region). A pixel's random stream and
/// Sobol' index are its own sample count, so a pixel's k-th sample is the same with or without
/// adaptivity. Stopping on the pixel's own estimate is the usual practice (Cycles, RenderMan, Arnold)
/// and not unbiased in the strict sense (the count depends on the samples); the shift it causes is
/// below the noise of the tests that look for it: a dome-lit cube with both integrators, the airlight
/// closed form (core adaptive_test.cpp), the furnace image mean (4 standard errors: 0.13%) and the slab
/// (testenv/test_adaptive.py). finished() says when to stop: samplesPerPixel passes
/// without noiseTarget or timeLimit; otherwise the noise target met everywhere, the time limit, or
/// maxSamplesPerPixel passes.
class Renderer {
public:
    /// `photonCache`: photon maps kept from earlier renders of the same scene content (PhotonCache;
    /// the photon-map integrator only), filled by this one; null: none.
    Renderer(std::shared_ptr<const Scene> scene, const RenderSettings& settings,
             std::shared_ptr<PhotonCache> photonCache = nullptr);
    ~Renderer();
    /// Runs one more pass; returns false if cancelled.
    bool renderPass(const CancelCallback& cancel = {});
    /// A coarse preview for interactive front ends (the first frame after a restart): one path-traced
    /// sample from the centre pixel of every block x block pixel block, written to every pixel of the
    /// block in `preview` (cleared first; the film's size), ids included. The renderer's own film,
    /// pass count and stats are untouched, so the progressive result is bit-identical with or without
    /// previews. Path traced whatever the integrator: no photon pass to wait for. False if cancelled.
    bool renderPreview(int block, Film& preview, const CancelCallback& cancel = {}) const;
    /// Runs passes until finished(); progress(passes done, estimated passes in all) after each.
    RenderStats render(const ProgressCallback& progress = {}, const CancelCallback& cancel = {});
    /// True when the next pass would be past the stopping rule above (stats().stopReason says which).
    bool finished();
    /// The passes the whole render is expected to take: samplesPerPixel, or for adaptive and
    /// time-limited renders an estimate from the error and time so far (for progress bars).
    int estimatedPasses() const;
    /// Per-pixel estimated relative error (Film::resolveRelativeError), rows top to bottom.
    std::vector<float> relativeError() const { return film_.resolveRelativeError(); }
    const Film& film() const { return film_; }
    const RenderStats& stats() const { return stats_; }
    const RenderSettings& settings() const { return settings_; }

    /// Ids of what the centre ray of pixel (x, y) meets first: the first surface that is not an
    /// index-matched medium boundary; where there is none, the first medium boundary it crossed (so a
    /// fog box is reported where it is seen against the background). Media bounded by their own
    /// bounds (Hydra volumes, atmospheres) report nothing.
    PixelIds pixelIds(const Camera& camera, int x, int y) const;

private:
    std::shared_ptr<const Scene> scene_;
    RenderSettings settings_;
    Film film_;
    RenderStats stats_;
    std::unique_ptr<Integrator> integrator_;
    int pass_ = 0;
    /// Adaptive sampling: 1 where the pixel is still sampled (all 1 until samplesPerPixel passes).
    std::vector<uint8_t> active_;
    double lastPassSeconds_ = 0;  ///< the last pass's seconds: the time the next is expected to take
    bool usesPhotons_ = false;  ///< the photon-map integrator renders (the scene has media)
    /// The photon-noise measurement passes (Integrator::measuresPhotonNoise): each pixel's first sample
    /// (the beauty's channel average; NaN: none), freed after them, and the sums over the pixels of the
    /// squared photonSplit and of the two samples' spread (x1 - x0)^2 / 2, with their pixel counts.
    std::vector<float> photonNoiseFirst_;
    struct PhotonNoiseSums {
        double photon = 0, whole = 0;
        int64_t photonPixels = 0, wholePixels = 0;
        /// The trial's: the squared difference of a pixel's two path-traced samples' mean and its
        /// two photon samples' mean (Renderer, "the measured choice")
        double difference = 0, differenceSum = 0, photonMeanSum = 0;  ///< sums of d^2, d, the photon mean
        int64_t differencePixels = 0;
    };
    PhotonNoiseSums photonNoise_;
    int photonNoisePasses_ = 0;
    /// The measured choice (combined with the automatic share, renderPass): Photons while combined's
    /// measurement passes run, PathTracer while the path tracer's trial passes run, then Done (or
    /// Off: not measured).
    enum class Trial { Off, Photons, PathTracer, Done };
    Trial trial_ = Trial::Off;
    std::unique_ptr<Integrator> trialPathTracer_;  ///< the path tracer of the trial passes
    PhotonNoiseSums trialSpread_;  ///< the trial passes' spread (whole, wholePixels) and difference
    std::vector<float> trialPhotonMean_;  ///< each pixel's mean of its two photon samples (NaN: none)
    int trialPassesRun_ = 0;  ///< the path tracer's trial passes run (not film passes: decideTrial)
    double photonPassSeconds_ = 0;  ///< a photon pass's expected seconds once the count is resized
    std::shared_ptr<PhotonCache> photonCache_;
    int integratorPass_ = 0;  ///< passes integrator_ has begun (its photon passes' index)
    /// The path tracer renders from the next pass on (the trial's outcome, or a cache's): `why`.
    void switchToPathTracer(std::unique_ptr<Integrator> pathTracer, const std::string& why);
    /// After the trial passes: compares the two sides and keeps the better.
    void decideTrial();
    /// Pixels whose footprint holds the image of a point-like light (Light::equiangularCenter) in a
    /// scene with media, sorted by pixel index: their camera samples take positions from
    /// samplePixelAroundPoint (sampling.h), whose variance stays bounded where the medium's scattered
    /// light grows as 1/h towards the light. Empty without media, lights in view or with a thin lens.
    struct LightPixel {
        size_t index;
        ImagePoint light;  ///< the light's image
        bool operator<(size_t i) const { return index < i; }
    };
    std::vector<LightPixel> lightPixels_;
    /// Camera samples a light pixel takes per pass (one for every other pixel): its estimate stays
    /// the noisiest of the image even with bounded weights (a spot's cone lights a wedge around its
    /// image), and it is one pixel, so its samples cost nothing against the pass.
    static constexpr int LightPixelSamples = 16;
    /// The light image in pixel (x, y)'s footprint, or null.
    const ImagePoint* lightPixel(int x, int y) const;
    /// The work (core/workCount.h) of one camera pass, from deterministic camera samples at the
    /// centres of a 16 x 16 grid over the image.
    work::Count cameraPilotWork(const Integrator& integrator) const;
    /// After a pass: the active mask and the error statistics from the film.
    void updateAdaptive();
};

}  // namespace volphoton
