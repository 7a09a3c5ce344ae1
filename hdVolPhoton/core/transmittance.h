// Transmittance estimators along a ray segment (shadow rays, camera-ray attenuation).
//
// | setting              | type   | default    | meaning                                                        |
// |----------------------|--------|------------|----------------------------------------------------------------|
// | mode                 | enum   | ClosedForm | ClosedForm: exp(-tau) where every medium has a closed form,    |
// |                      |        |            | else ratio tracking. RatioTracking: always (unbiased).         |
// |                      |        |            | RayMarching: jittered stratified Riemann sum (BIASED).          |
// | rouletteThreshold    | double | 0.05       | ratio tracking: below this max-channel T, Russian roulette      |
// |                      |        |            | kills with probability 0.75 and rescales survivors (unbiased)  |
// | cutoff               | double | 0          | deterministic: T below this returns 0 (BIASED; 0 disables). The |
// |                      |        |            | bias is at most `cutoff` per query; tools/bench_core measures it|
// | marchStep            | double | 0.1        | RayMarching step length in scene units                          |
#pragma once

#include "core/medium.h"
#include "core/rng.h"

namespace volphoton {

enum class TransmittanceMode { ClosedForm, RatioTracking, RayMarching };

struct TransmittanceSettings {
    TransmittanceMode mode = TransmittanceMode::ClosedForm;
    double rouletteThreshold = 0.05;
    double cutoff = 0.0;
    double marchStep = 0.1;
};

/// Estimate of the per-channel transmittance exp(-int_0^tMax sigma_t) along ray. Unbiased except in
/// the modes and settings marked BIASED above. Never NaN: an infinite optical depth gives 0.
Spectrum transmittance(const Medium& medium, const Ray& ray, double tMax, Rng& rng,
                       const TransmittanceSettings& settings = {});

/// Ratio tracking (Novak et al. 2014) through sampleFreeFlight(), with the roulette of the settings.
Spectrum ratioTrackingTransmittance(const Medium& medium, const Ray& ray, double tMax, Rng& rng,
                                    const TransmittanceSettings& settings = {});

/// Jittered ray marching: the stratified Riemann sum of sigma_t with one random offset per query
/// (the seed's single-scattering pass). BIASED: exp of an unbiased sum is not an unbiased exp.
Spectrum marchedTransmittance(const Medium& medium, const Ray& ray, double tMax, Rng& rng, double step);

}  // namespace volphoton
