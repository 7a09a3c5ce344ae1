// VolPhotonMediumAPI / VolPhotonPhaseLobeAPI attributes -> core media: the one reader and validator
// both front ends call (schemas/README.md documents the attributes; this file is where their
// defaults, ranges and rules live).
//
// | attribute                        | default          | valid                | when invalid                      |
// |----------------------------------|------------------|----------------------|-----------------------------------|
// | volphoton:density                | 1                | >= 0                 | clamped (warning); NaN: default   |
// | volphoton:albedo                 | (0.8, 0.8, 0.8)  | [0, 1] per channel   | clamped (warning)                 |
// | volphoton:extinctionColor        | (1, 1, 1)        | >= 0 per channel     | clamped (warning)                 |
// | volphoton:emission               | (0, 0, 0)        | >= 0 per channel     | clamped (warning)                 |
// | volphoton:emissionScale          | 1                | >= 0                 | clamped (warning)                 |
// | volphoton:temperatureScale       | 1                | >= 0                 | clamped (warning)                 |
// | volphoton:phase                  | henyeyGreenstein | PhaseKinds           | default (error)                   |
// | volphoton:phase:g                | 0                | (-1, 1)              | clamped to +-GLimit (warning)     |
// | volphoton:phase:k                | k(g)=1.55g-0.55g^3 | (-1, 1)            | clamped to +-GLimit (warning)     |
// | volphoton:phase:x                | 0                | [-1, 1]              | clamped (warning)                 |
// | volphoton:phase:table            | none             | >= 2 values, >= 0, not all 0 | isotropic / zeroed (error)  |
// | volphoton:densityMode            | field if a density field is bound, else constant | field, constant, exponential | derived (error) |
// | volphoton:exponential:a, :b      | 1, 1             | >= 0                 | clamped (warning)                 |
// | volphoton:exponential:up         | the stage's up axis | non-zero, finite  | stage up (error)                  |
// | volphoton:exponential:origin     | (0, 0, 0)        | finite               | default (error)                   |
// | volphoton:ior                    | 1                | >= 1 (Gprims only)   | clamped (warning)                 |
// | volphoton:preset                 | ""               | subsurfacePresetNames() | authored coefficients (error)  |
// | volphoton:sceneUnitsPerMm        | 1                | > 0                  | default (error)                   |
// | volphoton:bounds:min, :max       | none (unbounded) | both, min <= max, Volumes only | ignored (error/warning) |
// | volphoton:lobe:<name>:weight     | 1                | >= 0, some > 0       | clamped / isotropic (error)       |
// | volphoton:lobe:<name>:phase, :g, :k, :x, :table | as the medium's, no mixture | as above          |
//
// Mapping to the core (mediumCoefficients): sigma_t = density * extinctionColor, sigma_s = albedo *
// sigma_t, emission * emissionScale; a preset replaces density, albedo and extinctionColor
// (core/presets.h). Exponential media: origin and up go to world space with the prim's transform,
// b is divided by the world length of up so the profile follows the prim's scale.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/gridMedium.h"
#include "core/homogeneousMedium.h"
#include "core/medium.h"
#include "core/phase.h"
#include "core/translate/record.h"

namespace volphoton::translate {

/// |g| and |k| are clamped to this (the phase functions' own limit).
constexpr double GLimit = 0.99999;

/// The values of volphoton:phase, in schema order ("mixture" last; lobes take all but it).
const std::vector<std::string>& phaseKinds();
/// The values of volphoton:densityMode.
const std::vector<std::string>& densityModes();
/// One schema attribute the reader understands: its name and fallback (nullopt: none; unauthored
/// means "derived": k from g, densityMode from the fields, up from the stage, no table, no bounds).
/// schemas/generatedSchema.usda must declare the same fallbacks (testenv/test_schema.py checks).
struct AttributeInfo {
    std::string name;
    std::optional<AttrValue> fallback;
};
/// VolPhotonMediumAPI's attributes in schema order, and VolPhotonPhaseLobeAPI's by base name
/// ("weight", "phase", ...).
const std::vector<AttributeInfo>& mediumAttributes();
const std::vector<AttributeInfo>& lobeProperties();
/// "volphoton:lobe:<lobe>:<property>"
std::string lobeAttribute(const std::string& lobe, const std::string& property);

/// A phase function; `lobes` is only filled for "mixture". `k` is always set (authored or k(g)).
struct PhaseParams {
    std::string kind = "henyeyGreenstein";
    double g = 0, k = 0, x = 0;
    std::vector<double> table;
    std::vector<std::pair<double, PhaseParams>> lobes;  ///< (weight, lobe)
};

/// A medium prim's validated parameters (every value usable; see the table above).
struct MediumParams {
    std::string primPath;
    double density = 1;
    Spectrum albedo{0.8, 0.8, 0.8};
    Spectrum extinctionColor{1, 1, 1};
    Spectrum emission{0, 0, 0};
    double emissionScale = 1, temperatureScale = 1;
    PhaseParams phase;
    std::string densityMode = "constant";
    double expA = 1, expB = 1;
    Vec3 expUp{0, 1, 0};
    Vec3 expOrigin{0, 0, 0};
    double ior = 1;
    std::string preset;
    double sceneUnitsPerMm = 1;
    std::optional<std::pair<Vec3, Vec3>> bounds;  ///< prim space
};

/// What the front end knows about the prim beyond its attributes.
struct MediumContext {
    bool isVolume = false;          ///< a UsdVolVolume (always a medium)
    bool isGprim = false;           ///< a UsdGeomGprim (a medium when the API is applied)
    bool hasApi = false;            ///< VolPhotonMediumAPI is applied
    bool schemaRegistered = true;   ///< the schema plug-in is known (else: built-in defaults, warned)
    std::string typeName;           ///< the prim's type name, for messages
    bool hasDensityField = false;   ///< a usable field:density relationship is bound
    Vec3 stageUp{0, 1, 0};          ///< the stage's up axis (UsdGeomGetStageUpAxis)
    std::vector<std::string> lobeNames;  ///< applied VolPhotonPhaseLobeAPI instances, in order
};

/// Reads and validates the medium of one prim. nullopt when the prim is not a medium (neither a
/// Volume nor carrying the API; a warning when volphoton:* attributes are authored on it anyway).
std::optional<MediumParams> readMedium(const AttributeRecord& record, const MediumContext& context,
                                       Diagnostics& diagnostics);

/// The core phase function (validated parameters cannot fail).
PhasePtr buildPhase(const PhaseParams& phase);

/// density, extinctionColor and albedo after the preset (an unusable preset is an error and the
/// authored values are kept).
struct EffectiveCoefficients {
    double density;
    Spectrum extinctionColor, albedo;
};
EffectiveCoefficients effectiveCoefficients(const MediumParams& params, Diagnostics& diagnostics);

/// The coefficients of a procedural medium: effectiveCoefficients, emission * emissionScale, phase.
MediumCoefficients mediumCoefficients(const MediumParams& params, Diagnostics& diagnostics);

/// A constant or exponential medium in world space ("homogeneous"/"exponential" in *kind). With
/// useBounds (Volumes), volphoton:bounds become a world-space box. nullptr (error reported) when the
/// transform degenerates the exponential axis or the core refuses the parameters.
MediumPtr buildProceduralMedium(const MediumParams& params, const Affine& objectToWorld, bool useBounds,
                                Diagnostics& diagnostics, std::string* kind = nullptr);

/// A GridMediumDesc with every medium parameter set (coefficients after the preset, emission,
/// scales, phase, transform); the caller sets the file, the grid names and the voxel cap.
GridMediumDesc gridMediumDesc(const MediumParams& params, const Affine& objectToWorld, Diagnostics& diagnostics);

/// A text that differs whenever any parameter differs (cache keys).
std::string mediumKey(const MediumParams& params);

}  // namespace volphoton::translate
