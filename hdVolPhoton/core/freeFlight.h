// The one free-flight routine. Every estimator (camera paths, shadow rays, photons, transmittance)
// samples distances through sampleFreeFlight(); none walks majorants on its own (pbrt-v4's SampleT_maj
// shape, with a scalar majorant). Below it, the same density conditioned on a collision within the
// segment (sampleConditionedFlight, by the same inversion, for the path tracer's segment-light
// strategy) and the majorant's optical depth it needs (majorantDepth).
//
// Within a majorant segment the majorant is sigma(t) = sigma0 e^{-k (t - t0)}, whose optical depth
// from t0 is tau(s) = sigma0 s (1 - e^{-k s})/(k s). Tentative collisions are drawn by inverting it:
//   s = -log(1 - tau k / sigma0) / k  = (tau / sigma0) * L(tau k / sigma0),  L(x) = -log1p(-x)/x,
// which is exact for k = 0 (L = 1) and has no solution when tau k / sigma0 >= 1: the ray never
// accumulates tau before t -> infinity (it leaves a decaying atmosphere), so the segment is passed.
//
// The majorant is scalar: it bounds sigma_t in every channel. Chromatic media are then unbiased
// without averaging: callers weight by per-channel ratios (sigma_n,c / sigma_maj for ratio tracking).
// Where a medium knows each channel's own majorant (MajorantSegment::channelScale), a flight of one
// hero channel (SpectralFlight: the path tracer's spectral MIS) draws from that channel's.
#pragma once

#include "core/medium.h"
#include "core/rng.h"

namespace volphoton {

/// A tentative collision: position, local coefficients and the majorant that produced it.
struct MediumEvent {
    double t;
    Vec3 p;
    MediumProperties mp;
    double sigmaMaj;
};

/// Distance s at which the majorant's optical depth from the current point reaches tau, or infinity
/// when it never does. sigma is the majorant at the current point, decay its exponential rate.
inline double invertMajorantDepth(double tau, double sigma, double decay) {
    if (!(sigma > 0)) return Infinity;
    double s = tau / sigma;
    if (decay == 0) return s;
    double x = s * decay;
    if (x >= 1) return Infinity;
    return x == 0 ? s : s * (-std::log1p(-x) / x);
}

/// How a free flight ended.
enum class FlightEnd {
    Escaped,    ///< reached tMax
    Stopped,    ///< the callback returned false (a real scattering or absorption)
    Truncated,  ///< gave up after MaxTentativeCollisions: treat as opaque (see below)
};

/// Upper bound on tentative collisions in one flight. A loose majorant over an enormous density (a
/// VDB of 1e7 or 3e38 voxels next to empty ones) would otherwise take billions of steps: a hang on
/// bad input. Past it the flight is declared opaque, which biases only such pathological media;
/// warnTruncatedFlight() says so the first time.
constexpr int64_t MaxTentativeCollisions = int64_t(1) << 20;
void warnTruncatedFlight();

/// What a flight looks up at each tentative collision: the full coefficients, or (Extinction) sigma_t
/// alone, which the event's mp then carries as sigma_a (no lobes, no emission): for estimators that
/// use nothing else (ratio tracking: 31% of a dense cloud's render time; Extinction there made the
/// dense cloud's CPU time per pass 0.95x, the VDB cloud's and the emissive smoke's unchanged).
enum class FlightLookup { Properties, Extinction };

/// A flight of one hero channel (the path tracer's spectral MIS): its tentative collisions come from
/// that channel's own majorant, channelScale[channel] x the scalar one (MajorantSegment), and the
/// routine reports every channel's majorant, and its optical depth since the previous event, for
/// the weights. Where all channels share the majorant (grids) the flight is the scalar one.
struct SpectralFlight {
    int channel = 0;   ///< in: the hero channel
    bool chromatic = false;  ///< out: a segment it entered had channels of different majorants; until
                             ///< then the two below are not kept (every channel has the scalar majorant)
    Spectrum depth;    ///< out: each channel's majorant optical depth since the previous event (or the
                       ///< flight's start): at each event up to it, after an escape up to tMax
    Spectrum sigmaMaj; ///< out: each channel's majorant at the event
};

/// Draws tentative collisions along ray over (0, tMax) through `medium`'s majorants, calling
/// callback(const MediumEvent&) -> bool at each, in increasing t. The callback returns false to stop
/// (a real scattering or absorption). With `spectral`, the collisions are its channel's (above); the
/// event's sigmaMaj is still the scalar majorant.
template <FlightLookup Lookup = FlightLookup::Properties, typename Callback>
FlightEnd sampleFreeFlight(const Medium& medium, const Ray& ray, double tMax, Rng& rng, Callback&& callback,
                           SpectralFlight* spectral = nullptr) {
    if (spectral) {
        spectral->depth = Spectrum(0.0);
        spectral->chromatic = false;
    }
    FlightEnd end = FlightEnd::Escaped;
    int64_t events = 0;
    auto lookup = [&medium](const Vec3& p) {
        if constexpr (Lookup == FlightLookup::Properties) {
            return medium.properties(p);
        } else {
            MediumProperties mp;
            mp.sigma_a = medium.extinction(p);
            return mp;
        }
    };
    medium.majorants(ray, 0.0, tMax, [&](const MajorantSegment& seg) {
        double t = seg.tMin;
        double sigma = seg.sigmaMaj;
        // The hero channel's share of the scalar majorant (1 without `spectral`).
        double heroScale = 1.0;
        if (spectral) {
            heroScale = seg.channelScale[spectral->channel];
            spectral->chromatic |= !(seg.channelScale[0] == seg.channelScale[1] && seg.channelScale[1] == seg.channelScale[2]);
        }
        while (true) {
            // Exp(1). uniform() < 1 keeps it finite, and 1 - u is exact (u is a multiple of 2^-53,
            // Rng::uniform): log(1 - u) is log1p(-u) to rounding, at half its cost (9.5% of a dense
            // cloud's render time went to log1p here).
            double tau = -std::log(1.0 - rng.uniform());
            double dt = invertMajorantDepth(tau, sigma * heroScale, seg.decay);
            if (!(dt < seg.tMax - t)) {  // passed the segment: on to the next one
                if (spectral && spectral->chromatic) {
                    MajorantSegment rest{t, seg.tMax, sigma, seg.decay};
                    spectral->depth += seg.channelScale * rest.opticalDepth(seg.tMax - t);
                }
                return true;
            }
            if (++events > MaxTentativeCollisions) {
                warnTruncatedFlight();
                end = FlightEnd::Truncated;
                return false;
            }
            t += dt;
            if (seg.decay != 0) sigma = std::min(seg.sigmaMaj * std::exp(-seg.decay * (t - seg.tMin)), 1e300);
            const bool chromatic = spectral && spectral->chromatic;
            if (chromatic) {
                spectral->depth += seg.channelScale * (tau / heroScale);
                spectral->sigmaMaj = seg.channelScale * sigma;
            }
            const Vec3 p = ray.at(t);
            MediumEvent event{t, p, lookup(p), sigma};
            const bool goOn = callback(event);
            if (chromatic) spectral->depth = Spectrum(0.0);
            if (!goOn) {
                end = FlightEnd::Stopped;
                return false;
            }
        }
    });
    return end;
}

/// The majorant's optical depth over (0, tMax), or a value >= stopAt once it reaches that (the walk
/// stops there).
inline double majorantDepth(const Medium& medium, const Ray& ray, double tMax, double stopAt) {
    double total = 0;
    medium.majorants(ray, 0.0, tMax, [&](const MajorantSegment& seg) {
        total += seg.opticalDepth(std::min(seg.tMax, tMax) - seg.tMin);
        return total < stopAt;
    });
    return total;
}

/// Each channel's majorant optical depth over (t0, t1) (MajorantSegment::channelScale).
inline Spectrum channelMajorantDepth(const Medium& medium, const Ray& ray, double t0, double t1) {
    Spectrum total(0.0);
    medium.majorants(ray, t0, t1, [&](const MajorantSegment& seg) {
        double a = std::max(seg.tMin, t0), b = std::min(seg.tMax, t1);
        if (b > a) {
            double sigma = seg.decay == 0 ? seg.sigmaMaj : seg.sigmaMaj * std::exp(-seg.decay * (a - seg.tMin));
            total += seg.channelScale * MajorantSegment{a, b, sigma, seg.decay}.opticalDepth(b - a);
        }
        return true;
    });
    return total;
}

/// A distance drawn from the free-flight routine's tentative-collision density conditioned on a
/// collision within (0, tMax): p(t) = sigma_maj(t) e^{-tau_maj(0, t)} / P, where P = 1 -
/// e^{-tau_maj(0, tMax)} (majorantDepth) is the probability that the first tentative collision falls
/// there (the "forced" or conditional distance sampling of e.g. Cycles' volume direct light). t is
/// infinite where P = 0.
struct ConditionedFlight {
    double t = Infinity;
    double density = 0;  ///< p(t)
};
inline ConditionedFlight sampleConditionedFlight(const Medium& medium, const Ray& ray, double tMax, double P, double u) {
    ConditionedFlight f;
    if (!(P > 0)) return f;
    // The optical depth of the sampled point, inverted within the majorant segment holding it.
    double tau = -std::log1p(-u * P), left = tau;
    medium.majorants(ray, 0.0, tMax, [&](const MajorantSegment& seg) {
        double len = std::min(seg.tMax, tMax) - seg.tMin;
        double depth = seg.opticalDepth(len);
        if (left >= depth) {
            left -= depth;
            return true;
        }
        double s = std::min(invertMajorantDepth(left, seg.sigmaMaj, seg.decay), len);
        f.t = seg.tMin + s;
        f.density = seg.sigmaMaj * std::exp(-seg.decay * s - tau) / P;
        return false;
    });
    return f;
}

}  // namespace volphoton
