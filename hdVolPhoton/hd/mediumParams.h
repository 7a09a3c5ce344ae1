// hdVolPhoton: VolPhotonMediumAPI attributes as the delegate reads them from a scene delegate, and
// their translation into core media. The same names, defaults and rules as schemas/README.md and
// the usd-core front end (hdVolPhoton/python/volphoton/schema.py).
#ifndef HDVOLPHOTON_MEDIUM_PARAMS_H
#define HDVOLPHOTON_MEDIUM_PARAMS_H

#include "pxr/pxr.h"
#include "pxr/base/gf/vec3f.h"
#include "pxr/base/tf/token.h"
#include "pxr/base/vt/array.h"
#include "pxr/usd/sdf/path.h"

#include "core/homogeneousMedium.h"

#include <optional>

PXR_NAMESPACE_OPEN_SCOPE

class HdSceneDelegate;

/// The medium schema's values for one prim (defaults as in the schema).
struct HdVolPhoton_MediumParams {
    float density = 1.0f;
    GfVec3f albedo{0.8f, 0.8f, 0.8f};
    GfVec3f extinctionColor{1.0f, 1.0f, 1.0f};
    GfVec3f emission{0.0f, 0.0f, 0.0f};
    float emissionScale = 1.0f;
    float temperatureScale = 1.0f;
    TfToken phase{"henyeyGreenstein"};
    float g = 0.0f;
    std::optional<float> k;  ///< Schlick; derived from g when not authored
    float x = 0.0f;
    VtFloatArray table;
    TfToken densityMode;     ///< empty: field when a density field is bound, else constant
    float expA = 1.0f, expB = 1.0f;
    std::optional<GfVec3f> expUp;  ///< default: +Y (Hydra does not carry the stage's up axis)
    GfVec3f expOrigin{0.0f, 0.0f, 0.0f};
    float ior = 1.0f;
    std::optional<std::pair<GfVec3f, GfVec3f>> bounds;
    TfToken preset;              ///< measured material (core/presets.h); replaces density, albedo, extinctionColor
    float sceneUnitsPerMm = 1.0f;
};

/// Reads the `volphoton:*` attributes of prim `id` through HdSceneDelegate::Get(), which reaches
/// them in both UsdImaging paths: the scene delegate's attribute fallback and, with scene indices,
/// the primvars the VolPhotonMediumAPI adapter publishes. Returns nullopt when the prim does not
/// carry the API. Out-of-range values are clamped with a TF_WARN naming prim and attribute.
std::optional<HdVolPhoton_MediumParams> HdVolPhoton_ReadMediumParams(HdSceneDelegate *sceneDelegate,
                                                                     SdfPath const &id);

/// Phase function of the parameters; unknown tokens warn and fall back to isotropic.
volphoton::PhasePtr HdVolPhoton_BuildPhase(HdVolPhoton_MediumParams const &params, SdfPath const &id);

/// sigma_t = density * extinctionColor, sigma_s = albedo * sigma_t, emission, phase.
volphoton::MediumCoefficients HdVolPhoton_BuildCoefficients(HdVolPhoton_MediumParams const &params,
                                                            SdfPath const &id);

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_MEDIUM_PARAMS_H
