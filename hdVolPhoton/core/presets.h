// Measured subsurface-scattering materials (the `volphoton:preset` schema attribute): the one table
// both front ends use. Source: Jensen, Marschner, Levoy and Hanrahan 2001, "A Practical Model for
// Subsurface Light Transport", table 2 (reduced scattering sigma_s' and absorption sigma_a per RGB
// channel in 1/mm, measured at relative index eta = 1.3), checked against pbrt-v4's copy
// (SubsurfaceParameterTable in src/pbrt/media.cpp). The mapping, documented with the table in
// hdVolPhoton/python/volphoton/presets.py and schemas/README.md:
//     sigma_s = sigma_s' / (1 - g) / u,   sigma_a = sigma_a / u      (1 / scene unit)
// with g the mean cosine of the prim's phase function and u = volphoton:sceneUnitsPerMm.
#pragma once

#include <string>
#include <vector>

#include "core/math.h"

namespace volphoton {

struct SubsurfacePreset {
    const char* name;
    double sigmaSPrime[3];  ///< reduced scattering coefficient, 1/mm, RGB
    double sigmaA[3];       ///< absorption coefficient, 1/mm, RGB
};

constexpr double MeasuredPresetIor = 1.3;

/// Every preset, in name order.
const std::vector<SubsurfacePreset>& subsurfacePresets();
/// The preset called name, or nullptr.
const SubsurfacePreset* findSubsurfacePreset(const std::string& name);
/// "apple, chicken1, ..." (for error messages).
std::string subsurfacePresetNames();

struct PresetCoefficients {
    Spectrum sigma_s, sigma_a;  ///< 1 / scene unit
};
/// The mapping above. Throws std::invalid_argument for sceneUnitsPerMm <= 0 or g outside (-1, 1).
PresetCoefficients presetCoefficients(const SubsurfacePreset& preset, double sceneUnitsPerMm, double g);

}  // namespace volphoton
