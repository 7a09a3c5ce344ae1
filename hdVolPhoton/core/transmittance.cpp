#include "core/transmittance.h"

#include "core/freeFlight.h"

#include <atomic>

#include "core/diagnostics.h"

namespace volphoton {

void warnTruncatedFlight() {
    static std::atomic<bool> warned{false};
    if (!warned.exchange(true))
        warn("a free flight met over " + std::to_string(MaxTentativeCollisions) +
             " tentative collisions (a medium far denser than its majorant grid resolves, e.g. extreme "
             "voxel values); such flights are treated as opaque");
}

Spectrum transmittance(const Medium& medium, const Ray& ray, double tMax, Rng& rng,
                       const TransmittanceSettings& settings) {
    switch (settings.mode) {
        case TransmittanceMode::ClosedForm:
            if (std::optional<Spectrum> tau = medium.opticalDepth(ray, 0.0, tMax)) {
                Spectrum T = exp(-*tau);  // exp(-inf) = 0, so an opaque path is 0, not NaN
                return T.maxValue() < settings.cutoff ? Spectrum(0.0) : T;
            }
            return ratioTrackingTransmittance(medium, ray, tMax, rng, settings);
        case TransmittanceMode::RatioTracking:
            return ratioTrackingTransmittance(medium, ray, tMax, rng, settings);
        case TransmittanceMode::RayMarching: {
            Spectrum T = marchedTransmittance(medium, ray, tMax, rng, settings.marchStep);
            return T.maxValue() < settings.cutoff ? Spectrum(0.0) : T;
        }
    }
    return Spectrum(0.0);
}

Spectrum ratioTrackingTransmittance(const Medium& medium, const Ray& ray, double tMax, Rng& rng,
                                    const TransmittanceSettings& settings) {
    Spectrum T(1.0);
    FlightEnd end = sampleFreeFlight<FlightLookup::Extinction>(medium, ray, tMax, rng, [&](const MediumEvent& e) {
        Spectrum sigma_t = e.mp.sigma_t();
        for (int c = 0; c < 3; ++c) T[c] *= std::max(0.0, 1.0 - sigma_t[c] / e.sigmaMaj);
        double Tmax = T.maxValue();
        if (Tmax <= 0 || Tmax < settings.cutoff) {
            T = Spectrum(0.0);
            return false;
        }
        if (Tmax < settings.rouletteThreshold) {
            constexpr double q = 0.75;
            if (rng.uniform() < q) {
                T = Spectrum(0.0);
                return false;
            }
            T /= 1 - q;
        }
        return true;
    });
    return end == FlightEnd::Truncated ? Spectrum(0.0) : T;
}

Spectrum marchedTransmittance(const Medium& medium, const Ray& ray, double tMax, Rng& rng, double step) {
    Spectrum tau;
    double offset = rng.uniform();
    // March only where the majorants say the medium may be non-zero: empty space costs nothing.
    medium.majorants(ray, 0.0, tMax, [&](const MajorantSegment& seg) {
        double length = seg.tMax - seg.tMin;
        // At most MaxSteps per segment: a step too small for the scene is lengthened, never a hang.
        constexpr double MaxSteps = 1e5;
        int n = static_cast<int>(std::clamp(std::ceil(length / step), 1.0, MaxSteps));
        double dt = length / n;
        for (int i = 0; i < n; ++i) tau += medium.properties(ray.at(seg.tMin + (i + offset) * dt)).sigma_t() * dt;
        return true;
    });
    return exp(-tau);
}

}  // namespace volphoton
