// Integrator 1: the unbiased volumetric path tracer (the reference).
//
// Free flights come from sampleFreeFlight(), drawn by the path's hero channel from its own majorant
// (in homogeneous and exponential media its own sigma_t: no null collisions); the event at each
// tentative collision is real with probability sigma_t / sigma_maj of the hero, absorption and
// scattering merged into one real collision that always scatters, and every channel is weighted by
// spectral MIS over the path (Miller, Georgiev and Jarosz 2019; SpectralMis, integratorBase.h), which keeps every
// RGB channel unbiased with weights bounded by the albedo. It replaced spectral tracking with
// history-aware probabilities under the channels' largest majorant (Kutz, Habel, Li and Novak 2017,
// sec. 5): per-sample variance on the marble figurine (benchmark scene 9) 0.69x at 1.09x the CPU time
// (tools/bench/README.md, "Hero channels"). (An analog absorption
// event, ending the path with probability ~ sigma_a / sigma_t, had 2.4x Mitsuba's per-sample variance
// on benchmark scene 1; the albedo as a weight plus roulette is what Mitsuba's volpath does.) Volume emission along each
// segment is estimated by ratio tracking over the whole segment (ratioTrackedEmission), apart from
// where the path's flight scatters: 4.1x lower per-sample variance than collecting beta * emission /
// sigma_maj at the flight's own tentative collisions (pbrt-v4's estimator) on benchmark scene 6, 6.2x
// with its own sampler dimensions, at 1.5x the time per sample (tools/bench/README.md).
// Direct light: next-event estimation with shadow transmittance (closed form where the media have one,
// else ratio tracking), combined with phase/BSDF sampling by MIS (power heuristic) for lights with
// extent, emissive meshes included (Scene::instanceLight: their hits are weighted by emitterDensity). Point, spot and sphere lights add a second strategy on every segment in a medium:
// equiangular sampling of the distance towards the light's centre (Kulla and Fajardo 2012),
// combined with the NEE at real collisions by one-sample MIS over distance (balance heuristic
// against the free-flight density). For sphere lights the light-sampled half of the direction MIS
// is split between the two distance strategies and the phase-sampled half stays with free flights,
// so every (distance, direction) pair's weights still sum to one. The other lights (distant, domes,
// area and mesh lights) have a second strategy too in scenes with a distant light and media with
// closed-form transmittance (segmentLightSample): a light sample at a distance drawn from the
// flight's density conditioned on the segment, taken always on thin segments and seldom on thick
// ones, so a sky the flight mostly crosses without colliding still sees its sun on every segment.
// From a medium collision the flight is sampled before the surfaces ahead are searched, and the
// search ends where it stopped (EarlyFlight; Mitsuba 3's volpath shortens its rays so in homogeneous
// media): inside a translucent object 0.86x the time per sample on benchmark scene 9 and 0.92x on 8
// (tools/bench/README.md). Not where the segment's end is needed first: emission, the equiangular
// sample and combined's photon share estimate the whole segment up to the surface.
// integrator = combined runs these camera paths with a PhotonEstimate (photonMapper.cpp): every
// segment in a medium adds the photon map's gather weighted by share w, and a path scattering there
// goes on with probability 1 - w (else only to the light its next direction may hit: the vertex's
// direct light keeps its MIS); where the photons take whole segments (PhotonEstimate::wholeSegment:
// inside translucent objects, and open media under combined's automatic share where the photon map
// leads) a segment is the photon map's camera segment, its transmittance a weight, no collision sampled.
#include "core/freeFlight.h"
#include "core/integratorBase.h"

namespace volphoton {
namespace {

enum class Branch { Undecided, Medium, Surface };

class PathTracer final : public Integrator {
public:
    PathTracer(const Scene& scene, const RenderSettings& settings, const PhotonEstimate* photons)
        : Integrator(scene, settings), photons_(photons) {
        for (const LightPtr& l : scene.lights()) {
            std::optional<Vec3> position = l->equiangularCenter();
            pointLight_.push_back(position.has_value());
            pointLightPosition_.push_back(position.value_or(Vec3()));
            hasPointLights_ |= position.has_value();
            // A distant light (a sun: at infinity, not the dome) turns the segment-light strategy on.
            segmentLights_ |= !position && !l->extent() && !l->isDome();
        }
    }

    PathRadiance Li(const Ray& cameraRay, double nearClip, double farClip, Rng& rng) const override {
        PathRadiance out;
        PathRay path{cameraRay, nearClip, farClip, nearClip};
        auto& [ray, tMin, tMax, mediumFrom, lightsFrom] = path;
        Spectrum beta(1.0);
        MediumStack stack = cameraStack_;
        Branch branch = Branch::Undecided;
        bool specular = true;  // the previous vertex cannot be light-sampled (camera, mirror, refraction)
        double prevPdf = 0;
        Vec3 prevVertex;  // the last scattering vertex (for the light-sampling density of emitter hits)
        bool prevSurface = false;  // that vertex is a surface's (whose next-event estimation samples every light)
        int depth = 0, crossings = 0;
        bool firstSegment = true;
        bool lightHitIsSingle = false;  // a light hit right after the first medium vertex is single scattering
        // integrator = combined: the photon map's share of multiply scattered light in the current
        // media (PhotonEstimate). A path `ending` has left a medium vertex whose light scattered more
        // than once the photons took (probability share): it follows the phase-sampled direction only
        // to the light it may hit (that vertex's direct light, MIS-weighted against its next-event
        // estimate as always), through media and index-matched boundaries, and collects nothing else.
        double photonShare = 0;
        bool ending = false;
        bool fromCollision = false;  // the ray starts at a medium collision (inside the media of `stack`)

        auto add = [&](const Spectrum& L, bool singleCandidate) {
            if (branch == Branch::Undecided) out.surface += L;  // lights/environment seen directly
            else if (branch == Branch::Surface) out.surface += L;
            else if (singleCandidate) out.single += L;
            else out.multiple += L;
        };
        // Light gathered along a segment in a medium: on the camera's own segment it goes to
        // `firstSegmentAov` (single, emission or multiple), later by the branch as add() decides.
        auto addAlong = [&](Spectrum& firstSegmentAov, const Spectrum& L) {
            if (branch == Branch::Undecided) firstSegmentAov += L;
            else add(L, false);
        };

        // Per segment, but built once (a MediumEvent holds a MediumProperties of MaxLobes lobes):
        // the collision where the path scatters (read only when `scattered`), the flight sampled first.
        MediumEvent scatter;
        EarlyFlight early;
        SpectralMis mis;
        mis.hero = rng.pathChoice(3);
        SpectralFlight flight;  // the hero's flights
        flight.channel = mis.hero;
        double segmentCollisionP = 0, segmentTake = 0;  // segmentLight: the flight's collision probability, the strategy's
        for (int segment = 0;; ++segment) {
            rng.startSegment(segment);
            // Medium interaction along [mediumFrom, tEnd].
            bool scattered = false, absorbed = false;
            MediumAggregate media;
            Ray local{ray.at(mediumFrom), ray.d};
            if (scene_.hasMedia()) media = scene_.mediaFor(stack);
            bool emissive = false, photonSegment = false, sealed = false;
            if (media.size()) {
                emissive = media.isEmissive();
                photonShare = photons_ && !ending ? photons_->share(stack) : 0.0;
                // Inside a translucent object the photons take everything scattered (no vertex
                // there can sample a light), and in open media where combined's automatic share
                // gives them the segment: it is the photon map's camera segment (its march's single
                // scattering in open media, the gather, then the transmittance as a weight) and no
                // collision is sampled.
                photonSegment = photonShare >= 1 && photons_->wholeSegment(stack);
                // Inside a dielectric no shadow ray can leave, neither the equiangular sample nor the
                // collisions' next-event estimate it is weighed against is taken (both return zero).
                sealed = scene_.sealedFromLights(stack);
            }
            const bool equiangular = media.size() && hasPointLights_ && !ending && !photonSegment && !sealed;
            // From a medium collision, where nothing but the flight needs the segment's end (the
            // equiangular and segment-light samples, emission and combined's photon share estimate
            // the whole segment, up to the surface), the flight comes first and the search ends where
            // it stopped (EarlyFlight).
            bool flightFirst = media.size() && fromCollision && !equiangular && !emissive && photonShare == 0 && !photonSegment;
            // The other lights' second strategy (segmentLightSample), in media with closed-form
            // transmittance. Where the flight could come first, only if the majorant's optical depth
            // to the ray's end (surfaces aside: known before the search) is below SegmentLightDepth:
            // flights in dense media keep their order.
            const double rayLength = std::isinf(tMax) ? 1e30 : tMax - mediumFrom;
            double depthToRayEnd = -1;  // the majorant's optical depth over rayLength, where known
            const bool segmentLight =
                media.size() && segmentLights_ && !ending && !photonSegment && !sealed && media.hasClosedFormDepth() &&
                (!flightFirst || (depthToRayEnd = majorantDepth(media, local, rayLength, SegmentLightDepth)) < SegmentLightDepth);
            flightFirst &= !segmentLight;
            if (flightFirst) {
                rng.event(Rng::Event::Flight);
                flyEarly(media, local, rayLength, beta, mis, rng, &early, &scatter);
            }
            const bool collidedEarly = flightFirst && early.stop == EarlyFlight::Stop::Collided;
            PathSegment ahead = nextSegment(path, stack, firstSegment, collidedEarly ? mediumFrom + early.t : Infinity);
            const double tEnd = ahead.tEnd;
            if (firstSegment && ahead.hasHit) out.depth = ahead.hit.t;
            const double length = std::isinf(tEnd) ? 1e30 : tEnd - mediumFrom;
            // One tentative collision of the camera path's flight; false when it stopped there.
            auto collide = [&](const MediumEvent& e, double from) {
                Collision c = spectralTracking(e, flight, beta, mis, rng);
                if (c == Collision::Null) return true;
                if (c == Collision::Scatter) {
                    scatter = e;
                    scatter.t += from;
                    scattered = true;
                } else {
                    absorbed = true;
                }
                return false;
            };
            Support support;
            if (media.size()) {
                if (equiangular) {
                    support = mediaSupport(media, local, length);
                    rng.event(Rng::Event::Equiangular);
                    addAlong(out.single, equiangularPointLight(media, local, support, stack, beta, rng));
                }
                if (segmentLight) {
                    rng.event(Rng::Event::SegmentLight);
                    double depth = length == rayLength ? depthToRayEnd : -1;
                    addAlong(out.single, segmentLightSample(media, local, length, depth, stack, beta, rng, &segmentCollisionP, &segmentTake));
                }
                if (emissive && !ending) {
                    rng.event(Rng::Event::Emission);
                    addAlong(out.emission, beta * ratioTrackedEmission(media, local, length, rng));
                }
                if (photonSegment) {
                    // No flight is sampled: the march's offset and first light samples take the
                    // flight's stratified dimensions (PCG32 otherwise; 1.4x the photon map's RMSE
                    // on fog + spot, whose camera paths draw every dimension in order).
                    rng.event(Rng::Event::Flight);
                    PhotonEstimate::Along a = photons_->along(media, local, length, stack, rng);
                    addAlong(out.single, beta * a.single);
                    addAlong(out.multiple, beta * a.multiple);
                    out.photonSplit += beta * a.multipleSplit;
                    if (firstSegment && (a.interacted || !a.multiple.isBlack())) out.alpha = 1;
                    beta *= a.T;
                    absorbed = beta.isBlack();
                } else {
                    const Spectrum betaSegment = beta;
                    if (flightFirst) {
                        if (collidedEarly && tEnd == mediumFrom + early.t) {
                            // Nothing met before the flight stopped: its collision (in `scatter`) stands.
                            beta = early.beta;
                            mis = early.mis;
                            if (early.scattered) {
                                scatter.t += mediumFrom;
                                scattered = true;
                            } else {
                                absorbed = true;
                            }
                        } else {
                            // The segment ends first: the null collisions before its end, then
                            // (where the flight stopped early and the segment goes on) the rest of
                            // the flight from there, a free flight being memoryless.
                            double last = early.restoreBefore(length, &beta, &mis);
                            if (early.stop == EarlyFlight::Stop::Bailed && early.t < length) {
                                const double from = mediumFrom + early.t;
                                FlightEnd end = sampleFreeFlight(
                                    media, Ray{local.at(early.t), local.d}, length - early.t, rng,
                                    [&](const MediumEvent& e) { return collide(e, from); }, &flight);
                                absorbed |= end == FlightEnd::Truncated || (end == FlightEnd::Escaped && !mis.escape(flight.depth, beta));
                            } else if (early.chromatic) {
                                // No tentative collision of the hero between the last null and the end.
                                absorbed |= !mis.escape(channelMajorantDepth(media, local, last, length), beta);
                            }
                        }
                    } else {
                        rng.event(Rng::Event::Flight);
                        FlightEnd end = sampleFreeFlight(
                            media, local, length, rng, [&](const MediumEvent& e) { return collide(e, mediumFrom); }, &flight);
                        absorbed |= end == FlightEnd::Truncated || (end == FlightEnd::Escaped && !mis.escape(flight.depth, beta));
                    }
                    if (photonShare > 0) {
                        // The photons' estimate along the whole segment, whatever the flight did:
                        // it and the continuation from a collision (below) estimate the same light.
                        PhotonEstimate::Along a = photons_->along(media, local, length, stack, rng);
                        addAlong(out.multiple, betaSegment * a.multiple * photonShare);
                        out.photonSplit += betaSegment * a.multipleSplit * photonShare;
                    }
                }
            }
            if (absorbed) break;
            if (scattered && ending) break;
            if (scattered) {
                if (firstSegment) out.alpha = 1;
                if (++depth > settings_.maxDepth) break;
                bool firstVertex = branch == Branch::Undecided;
                if (firstVertex) branch = Branch::Medium;
                const MediumProperties& mp = scatter.mp;
                Vec3 p = scatter.p;
                // Next-event estimation (none inside a dielectric that no shadow ray can leave).
                rng.event(Rng::Event::Light);
                PhaseAt phase{mp, ray.d};
                DirectSample ds = sealed ? DirectSample{} : sampleDirect(p, rng, &phase);
                if (ds.light >= 0 && ds.ls.pdf > 0 && !ds.ls.Li.isBlack()) {
                    double cosTheta = dot(ray.d, ds.ls.wi);
                    Spectrum f = mp.scatterKernel(cosTheta);
                    if (!f.isBlack()) {
                        Spectrum T = shadowTransmittance(p, ds.ls.wi, ds.ls.dist, stack, rng);
                        double lightDensity = ds.pickProb * ds.ls.pdf;
                        double w = ds.ls.isDelta ? 1.0 : powerHeuristic(lightDensity, mp.scatterPdf(cosTheta));
                        if (isPointLight(ds.light)) {  // MIS over distance with the equiangular strategy
                            double tLocal = scatter.t - mediumFrom;
                            double pd = distanceDensity(media, local, tLocal);
                            double pe = equiangularPdf(ds.light, local, support, tLocal);
                            w *= pd / (pd + pe);
                        } else if (segmentLight) {  // and with the segment-light strategy
                            w *= segmentCollisionP / (segmentCollisionP + segmentTake);
                        }
                        add(beta * f * T * ds.ls.Li * (w / lightDensity), firstVertex);
                    }
                }
                // integrator = combined: the photons took `share` of the light scattered here more than
                // once; the path goes on for the rest with probability 1 - share (unit weight), else
                // only to the light its next direction may hit.
                if (photonShare > 0) {
                    if (photonShare >= 1) ending = true;
                    else {
                        rng.event(Rng::Event::Roulette);
                        ending = rng.uniform() < photonShare;
                    }
                }
                // Phase sampling.
                rng.event(Rng::Event::Scatter);
                auto [s1, s2] = rng.uniform2();
                double uLobe = rng.uniform();
                Vec3 w = mp.sampleScatter(ray.d, uLobe, s1, s2);
                double cosTheta = dot(ray.d, w);
                double pdf = mp.scatterPdf(cosTheta);
                if (!(pdf > 0)) break;
                beta *= mp.scatterKernel(cosTheta) / pdf;
                prevPdf = pdf;
                prevVertex = p;
                prevSurface = false;
                specular = false;
                path.bounce({p, w}, 0.0);
                fromCollision = true;
                firstSegment = false;
                lightHitIsSingle = firstVertex;
                if (!roulette(beta, depth, rng)) break;
                continue;
            }
            fromCollision = false;
            if (ahead.leavesHole()) {
                path.leaveHole(stack, ahead.leakExit);
                continue;
            }
            bool lightWasSingle = lightHitIsSingle;
            lightHitIsSingle = false;
            // Reached a light, a surface, or escaped.
            if (ahead.reachesLight()) {
                auto addLight = [&](int light, const Spectrum& Le, double lightPdf) {
                    double pick = prevSurface ? surfaceLightPickProb(light) : mediumLightPickProb(light);
                    // A constant dome after a medium vertex: that vertex sampled it by its phase
                    // function, whose density in this direction is prevPdf (mediumSamplesDomeByPhase).
                    if (!prevSurface && mediumSamplesDomeByPhase(light)) lightPdf = prevPdf;
                    double w = specular ? 1.0 : powerHeuristic(prevPdf, pick * lightPdf);
                    add(beta * Le * w, lightWasSingle);
                };
                if (std::isinf(ahead.tLight)) {  // escaped: every light at infinity
                    lightsAtInfinity(ray, firstSegment, addLight);
                    break;
                }
                // Through the light, as shadow rays and photons go (Integrator::hitLight).
                addLight(ahead.light, ahead.lightLe, ahead.lightPdf);
                if (firstSegment) out.alpha = 1;
                path.passLight(ahead.tLight);
                lightHitIsSingle = lightWasSingle;
                continue;
            }
            if (!ahead.hasHit) break;
            if (firstSegment) out.alpha = 1;
            // An emissive mesh is a light too: its hit is weighted against sampling it from the
            // previous vertex (power heuristic), as lights with extent are above.
            Spectrum Le = surfaceEmission(ray, ahead.hit);
            if (!Le.isBlack()) {
                double w = specular ? 1.0 : powerHeuristic(prevPdf, emitterDensity(prevVertex, ahead.hit, prevSurface));
                add(beta * Le * w, lightWasSingle);
            }
            // An ending path crosses index-matched boundaries only: it looks for its vertex's direct light.
            if (ending && scene_.mesh(ahead.hit.mesh).material.kind != SurfaceMaterial::Kind::Boundary) break;
            // Surface light goes to `surface` when the surface is the first vertex (branch Undecided
            // or Surface), else to `multiple`.
            SurfaceScatter s;
            SurfaceStep step = cameraSurfaceHit(path, ahead.hit, stack, beta, depth, crossings, rng, /*mis=*/true,
                                                [&](const Spectrum& L) { add(L, false); }, &s);
            if (step == SurfaceStep::Crossed) continue;
            if (step == SurfaceStep::Stop) break;
            if (branch == Branch::Undecided) branch = Branch::Surface;
            specular = s.type == SurfaceScatter::Type::Specular;
            if (!specular) prevPdf = std::abs(dot(s.next.d, ahead.hit.ns)) * InvPi;
            prevVertex = ahead.hit.p;
            prevSurface = true;
            firstSegment = false;
            if (!roulette(beta, depth, rng)) break;
        }
        return out;
    }

private:
    struct Support {
        double a = 0, b = 0;  ///< first and last t where the segment's media may be non-zero
    };

    bool isPointLight(int i) const { return i >= 0 && pointLight_[i]; }

    enum class Collision { Null, Scatter, Absorb };
    /// One tentative collision of the hero's flight (sf: each channel's majorant there and its optical
    /// depth since the previous event), with beta and mis.r updated: a real collision scatters with
    /// the albedo as a weight (sigma_s in the phase kernel) instead of ending the path with probability
    /// sigma_a / sigma_t; Russian roulette ends low-throughput paths later. Real with probability
    /// sigma_t / sigma_maj of the hero (SpectralMis::collide weighs every channel; in grey media
    /// without further work).
    static Collision spectralTracking(const MediumEvent& e, const SpectralFlight& sf, Spectrum& beta, SpectralMis& mis, Rng& rng) {
        const Spectrum sigma_t = e.mp.sigma_t();
        const int h = mis.hero;
        const double majH = sf.chromatic ? sf.sigmaMaj[h] : e.sigmaMaj;
        const bool real = rng.uniform() * majH < sigma_t[h];
        if (real && e.mp.sigma_s.isBlack()) return Collision::Absorb;
        if (!mis.collide(e, sf, sigma_t, real ? &sigma_t : nullptr, beta)) return Collision::Absorb;
        return real ? Collision::Scatter : Collision::Null;
    }

    /// A flight sampled before the surfaces ahead are searched, from a medium collision (Mitsuba 3's
    /// volpath does so in homogeneous media and shortens the ray to the sampled distance): the search
    /// then ends at the flight's collision, in a dense medium far nearer than the next surface, which
    /// shortens Embree's traversal. Its null collisions are logged, for the throughput at a surface
    /// met first. It stops early (Bailed) when the log is full (a run of null collisions: a loose
    /// majorant, or a channel the medium hardly stops); the flight goes on from there once the
    /// segment's end is known (a free flight is memoryless).
    struct EarlyFlight {
        enum class Stop { None, Collided, Bailed };
        static constexpr int MaxNulls = 16;
        Stop stop = Stop::None;
        double t = Infinity;     ///< where it stopped (along the local ray)
        bool scattered = false;  ///< Collided: it scatters (else it absorbs)
        Spectrum beta;           ///< the throughput after its last event
        SpectralMis mis;         ///< and the path's spectral MIS ratios
        bool chromatic = false;  ///< it met channels of different majorants (SpectralFlight::chromatic)
        int nulls = 0;
        double nullT[MaxNulls];
        double nullBeta[MaxNulls][3], nullR[MaxNulls][3];  // not Spectrum: no zeroing of the log on every segment

        /// The throughput and MIS ratios after the null collisions before distance t (unchanged
        /// where there are none); returns the last one's distance (0 if none).
        double restoreBefore(double t, Spectrum* beta, SpectralMis* m) const {
            int i = 0;
            while (i < nulls && nullT[i] < t) ++i;
            if (i == 0) return 0;
            *beta = Spectrum(nullBeta[i - 1][0], nullBeta[i - 1][1], nullBeta[i - 1][2]);
            m->r = Spectrum(nullR[i - 1][0], nullR[i - 1][1], nullR[i - 1][2]);
            return nullT[i - 1];
        }
    };
    /// Samples *f from scratch; a collision it stops at goes to *collision (t along `local`).
    static void flyEarly(const Medium& media, const Ray& local, double length, const Spectrum& beta,
                         const SpectralMis& mis, Rng& rng, EarlyFlight* f, MediumEvent* collision) {
        f->stop = EarlyFlight::Stop::None;
        f->t = Infinity;
        f->beta = beta;
        f->mis = mis;
        f->nulls = 0;
        SpectralFlight flight;
        flight.channel = mis.hero;
        sampleFreeFlight(media, local, length, rng, [&](const MediumEvent& e) {
            Collision c = spectralTracking(e, flight, f->beta, f->mis, rng);
            f->t = e.t;
            if (c != Collision::Null) {
                f->stop = EarlyFlight::Stop::Collided;
                f->scattered = c == Collision::Scatter;
                *collision = e;
                return false;
            }
            f->nullT[f->nulls] = e.t;
            for (int k = 0; k < 3; ++k) {
                f->nullBeta[f->nulls][k] = f->beta[k];
                f->nullR[f->nulls][k] = f->mis.r[k];
            }
            if (++f->nulls == EarlyFlight::MaxNulls) {
                f->stop = EarlyFlight::Stop::Bailed;
                return false;
            }
            return true;
        }, &flight);
        f->chromatic = flight.chromatic;
    }

    static constexpr double EmissionRouletteBelow = 0.2;
    /// The emission along the whole segment, integral of T(0, t) emission(t) dt, by ratio tracking:
    /// at every tentative collision emission / sigma_maj weighted by the running transmittance
    /// estimate (the product of sigma_n / sigma_maj so far), to the segment's end, independent of
    /// where the path's own flight scatters (both estimators are unbiased, so their sum is). Russian
    /// roulette on the running transmittance below 0.2 keeps dense media from being walked to the end.
    static Spectrum ratioTrackedEmission(const Medium& media, const Ray& ray, double length, Rng& rng) {
        Spectrum L, T(1.0);
        sampleFreeFlight(media, ray, length, rng, [&](const MediumEvent& e) {
            if (!e.mp.emission.isBlack()) L += T * e.mp.emission / e.sigmaMaj;
            for (int c = 0; c < 3; ++c) T[c] *= std::max(0.0, 1 - e.mp.sigma_t()[c] / e.sigmaMaj);
            double m = T.maxValue();
            if (m < EmissionRouletteBelow) {
                double q = m / EmissionRouletteBelow;
                if (!(rng.uniform() < q)) return false;
                T /= q;
            }
            return true;
        });
        return L;
    }

    static Support mediaSupport(const Medium& media, const Ray& ray, double length) {
        Support s{Infinity, 0};
        media.majorants(ray, 0.0, length, [&](const MajorantSegment& seg) {
            s.a = std::min(s.a, seg.tMin);
            s.b = std::max(s.b, seg.tMax);
            return true;
        });
        return s;
    }

    /// The density MIS assigns to distance sampling at t: sigma_maj(t) exp(-tau_maj(0, t)), the
    /// tentative-collision density of the free-flight routine. Any deterministic positive function
    /// keeps the one-sample MIS unbiased (the weights sum to one); this one follows the real density
    /// closely where the majorant is tight.
    static double distanceDensity(const Medium& media, const Ray& ray, double t) {
        double tau = 0, sigma = 0;
        media.majorants(ray, 0.0, t * (1 + 1e-12) + 1e-300, [&](const MajorantSegment& seg) {
            double end = std::min(seg.tMax, t);
            double len = end - seg.tMin;
            if (len < 0) return false;
            tau += seg.opticalDepth(len);
            if (t < seg.tMax || seg.tMax >= t * (1 - 1e-12)) sigma = seg.sigmaMaj * std::exp(-seg.decay * len);
            return t >= seg.tMax;
        });
        return sigma * std::exp(-tau);
    }

    /// The part of the segment's support the light can reach (Light::litInterval: a spot's cone):
    /// equiangular sampling keeps to it, so a narrow beam crossed far from the light's nearest point
    /// is not missed (the fog around testenv/fog_spotlight.usda's beam was lit by rare, large
    /// samples: 53% of a pixel's multiple scattering came from its 10 largest of 4096 samples).
    Support litSupport(int light, const Ray& ray, const Support& s) const {
        double t0, t1;
        scene_.lights()[light]->litInterval(ray, &t0, &t1);
        return {std::max(s.a, t0), std::min(s.b, t1)};
    }

    /// Equiangular density (Kulla and Fajardo 2012) of t in the lit part [a, b] of the support for
    /// the point light `light`.
    double equiangularPdf(int light, const Ray& ray, const Support& support, double t) const {
        Support s = litSupport(light, ray, support);
        if (!(s.b > s.a) || t < s.a || t > s.b) return 0;
        Vec3 lp = pointLightPosition_[light];
        double delta = dot(lp - ray.o, ray.d), D = length(lp - ray.at(delta));
        if (D < 1e-9 * (1 + std::abs(delta))) return std::isinf(s.b) || s.b > 1e29 ? 0.0 : 1 / (s.b - s.a);
        double thA = std::atan2(s.a - delta, D), thB = std::atan2(s.b - delta, D);
        return D / ((thB - thA) * (D * D + (t - delta) * (t - delta)));
    }

    /// The equiangular strategy: one point light picked as at a collision (mediumLightPickProb: a
    /// sphere light's direction weights against the collisions' and the continuation's take that
    /// pick), one distance along the segment, camera-side transmittance by ratio tracking, MIS weight
    /// against distance sampling.
    Spectrum equiangularPointLight(const Medium& media, const Ray& ray, const Support& support, const MediumStack& stack,
                                   const Spectrum& beta, Rng& rng) const {
        double pick;
        size_t li = mediumLightDist_.sampleDiscrete(rng.uniform(), &pick);
        double u = rng.uniform();
        auto [u1, u2] = rng.uniform2();
        if (!isPointLight(static_cast<int>(li))) return {};
        Support s = litSupport(static_cast<int>(li), ray, support);
        if (!(s.b > s.a)) return {};
        Vec3 lp = pointLightPosition_[li];
        double delta = dot(lp - ray.o, ray.d), D = length(lp - ray.at(delta));
        double t;
        if (D < 1e-9 * (1 + std::abs(delta))) {
            if (s.b > 1e29) return {};
            t = s.a + u * (s.b - s.a);
        } else {
            double thA = std::atan2(s.a - delta, D), thB = std::atan2(s.b - delta, D);
            t = delta + D * std::tan(thA + u * (thB - thA));
        }
        double pe = equiangularPdf(static_cast<int>(li), ray, support, t);
        if (!(pe > 0) || !std::isfinite(t)) return {};
        Vec3 p = ray.at(t);
        MediumProperties mp = media.properties(p);
        if (mp.sigma_s.isBlack()) return {};
        LightSample ls = scene_.lights()[li]->sample(p, u1, u2);
        if (!(ls.pdf > 0) || ls.Li.isBlack()) return {};
        Spectrum f = mp.scatterKernel(dot(ray.d, ls.wi));
        if (f.isBlack()) return {};
        Spectrum Tcam = transmittance(media, ray, t, rng, transmittance_);
        if (Tcam.isBlack()) return {};
        Spectrum Tsh = shadowTransmittance(p, ls.wi, ls.dist, stack, rng);
        double pd = distanceDensity(media, ray, t);
        // Distance MIS against free flights; for a sphere light also the direction MIS against phase
        // sampling, which (from distance-sampled vertices only) still covers its half of each pair.
        double w = pe / (pe + pd);
        if (!ls.isDelta) w *= powerHeuristic(pick * ls.pdf, mp.scatterPdf(dot(ray.d, ls.wi)));
        return beta * Tcam * f * Tsh * ls.Li * (w / (pick * ls.pdf * pe));
    }

    /// The segment-light strategy is taken with probability min(1, e^(SegmentLightAlways - tau)) on a
    /// segment of majorant optical depth tau (always up to 3, P = 0.95), and not at all past
    /// SegmentLightDepth (e^-6 = 0.0025 there).
    static constexpr double SegmentLightAlways = 3, SegmentLightDepth = 9;
    /// The segment-light strategy for lights that are not point-like (distant lights, domes, area and
    /// mesh lights), so that a segment the flight crosses without colliding (most of a thin medium's:
    /// the sky) still samples the light: one light picked as at a collision (sampleDirect; a point
    /// light picked gives nothing: picking among the others alone measured no better on scene 10), at a
    /// distance drawn from the collisions' distance density (distanceDensity) conditioned on the
    /// segment (sampleConditionedFlight), i.e. that density over P, the probability that the flight
    /// collides within the segment. Taken with probability c (*take; see SegmentLightAlways), its
    /// density is c times that, so the balance heuristic over distance gives the collisions'
    /// next-event estimate P / (P + c) and this one c / (P + c), everywhere on the segment (*P
    /// returns P). c is 1 on thin segments, where the flight seldom collides; on thick ones it falls
    /// as 1 - P = e^-tau, which keeps the cost near one light sample per segment and the second
    /// moment bounded where the majorant is loose (a chromatic medium's thin channels: there the
    /// transmittance to the camera exceeds the majorant's e^-tau(t) >= e^-tau, and c is at most
    /// e^3 e^-tau). Point lights are the equiangular strategy's. Used in scenes with a distant light
    /// (a sun: no path's continuation finds a sharp one, so only collisions saw it) and media with
    /// closed-form transmittance; measured as per-sample variance x CPU time per pass against the
    /// path tracer without it: benchmark scene 5 (a sunlit atmosphere) 0.70x, scene 1 (a cube under a
    /// dome alone, which the continuations find by phase sampling) 1.24x, the VDB cloud (ratio-tracked
    /// transmittances) 1.41x (tools/bench/README.md, "Light sampled along the segment").
    /// depth: the majorant's optical depth over the segment where known, else negative.
    Spectrum segmentLightSample(const Medium& media, const Ray& ray, double length, double depth, const MediumStack& stack,
                                const Spectrum& beta, Rng& rng, double* P, double* take) const {
        double u = rng.uniform();
        double tau = depth >= 0 ? depth : majorantDepth(media, ray, length, SegmentLightDepth);
        *P = -std::expm1(-tau);
        *take = tau < SegmentLightDepth ? std::min(1.0, std::exp(SegmentLightAlways - tau)) : 0.0;
        if (!(u < *take)) return {};
        ConditionedFlight c = sampleConditionedFlight(media, ray, length, *P, u / *take);
        if (!(c.density > 0) || !std::isfinite(c.t)) return {};
        Vec3 p = ray.at(c.t);
        MediumProperties mp = media.properties(p);
        if (mp.sigma_s.isBlack()) return {};
        PhaseAt phase{mp, ray.d};
        DirectSample ds = sampleDirect(p, rng, &phase);
        if (ds.light < 0 || isPointLight(ds.light) || !(ds.ls.pdf > 0) || ds.ls.Li.isBlack()) return {};
        double cosTheta = dot(ray.d, ds.ls.wi);
        Spectrum f = mp.scatterKernel(cosTheta);
        if (f.isBlack()) return {};
        Spectrum Tcam = transmittance(media, ray, c.t, rng, transmittance_);
        if (Tcam.isBlack()) return {};
        Spectrum Tsh = shadowTransmittance(p, ds.ls.wi, ds.ls.dist, stack, rng);
        double lightDensity = ds.pickProb * ds.ls.pdf;
        // For lights with extent the direction MIS against phase sampling, whose half stays with the
        // collisions (as for the equiangular strategy).
        double w = ds.ls.isDelta ? 1.0 : powerHeuristic(lightDensity, mp.scatterPdf(cosTheta));
        return beta * Tcam * f * Tsh * ds.ls.Li * (w / (lightDensity * c.density * (*P + *take)));
    }

    const PhotonEstimate* photons_;
    std::vector<bool> pointLight_;
    std::vector<Vec3> pointLightPosition_;
    bool hasPointLights_ = false;
    bool segmentLights_ = false;  ///< the scene has a distant light: segmentLightSample is used

    bool roulette(Spectrum& beta, int depth, Rng& rng) const {
        if (depth < settings_.rouletteDepth) return true;
        double p = rouletteSurvival(beta.maxValue(), depth);
        if (p >= 1) return true;
        rng.event(Rng::Event::Roulette);
        if (!(rng.uniform() < p)) return false;
        beta /= p;
        return true;
    }
};

}  // namespace

std::unique_ptr<Integrator> makePathTracer(const Scene& scene, const RenderSettings& settings, const PhotonEstimate* photons) {
    return std::make_unique<PathTracer>(scene, settings, photons);
}

}  // namespace volphoton
