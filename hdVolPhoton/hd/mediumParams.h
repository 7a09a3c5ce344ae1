// hdVolPhoton: what the delegate hands the translation layer (core/translate/medium.h) for a prim
// with VolPhotonMediumAPI or a Volume: its volphoton:* attributes, the applied lobe instances, the
// stage's up axis. The rules themselves are the core's, the same the usd-core front end applies.
//
// Where the values come from:
//  * the legacy scene delegate (UsdImagingDelegate, OpenUSD 24.08's default for usdrecord/usdview,
//    seen by the prims through scene-index emulation): the UsdPrim itself (HdVolPhoton_FindUsdPrim),
//    read exactly as the usd-core front end reads it;
//  * the scene-index path: the primvars HdVolPhotonMediumAPIAdapter publishes (every volphoton:*
//    attribute, plus volphoton:__lobes, volphoton:__stageUp and volphoton:__authored).
#ifndef HDVOLPHOTON_MEDIUM_PARAMS_H
#define HDVOLPHOTON_MEDIUM_PARAMS_H

#include "pxr/pxr.h"
#include "pxr/base/vt/value.h"
#include "pxr/usd/sdf/path.h"
#include "pxr/usd/usd/prim.h"
#include "pxr/usd/usd/timeCode.h"

#include "core/translate/medium.h"

#include <optional>

PXR_NAMESPACE_OPEN_SCOPE

class HdSceneDelegate;
class UsdImagingDelegate;

/// The extra primvars the scene-index adapter publishes beside the attributes.
#define HDVOLPHOTON_MEDIUM_LOBES "volphoton:__lobes"
#define HDVOLPHOTON_MEDIUM_STAGE_UP "volphoton:__stageUp"
#define HDVOLPHOTON_MEDIUM_AUTHORED "volphoton:__authored"

/// A Vt value as the translation layer takes it (TfToken, std::string and resolved asset paths as
/// text; float/double/half as double; 3-vectors as Vec3; numeric arrays as lists).
volphoton::translate::AttrValue HdVolPhoton_ToAttrValue(VtValue const &value);

/// Record and context of a prim, read off the UsdPrim (what both UsdImaging paths start from).
struct HdVolPhoton_MediumInput {
    volphoton::translate::AttributeRecord record;
    volphoton::translate::MediumContext context;
};
HdVolPhoton_MediumInput HdVolPhoton_ReadMediumInput(UsdPrim const &prim, UsdTimeCode time);

/// Where a medium read through the legacy UsdImagingDelegate came from, kept when any of its
/// volphoton:* attributes may vary in time: UsdImaging does not track the variability of attributes
/// it does not know, so a time change would not re-sync the prim. The render pass re-reads such
/// media when the delegate's time moves (HdVolPhoton_SceneRegistry::RefreshTimeVaryingMedia).
struct HdVolPhoton_MediumSource {
    UsdImagingDelegate *delegate = nullptr;
    SdfPath id;
    bool isVolume = false;
    bool hasDensityField = false;
    UsdTimeCode time;
    /// True when the delegate now renders another time than the one read.
    bool IsStale() const;
};

/// The validated medium of rprim `id` (a Volume when isVolume, else a Gprim), or nullopt when it is
/// not a medium. Diagnostics become TF_WARNs naming prim and attribute. `source` (optional) is set
/// when the medium may vary in time (its delegate is null otherwise).
std::optional<volphoton::translate::MediumParams> HdVolPhoton_ReadMedium(HdSceneDelegate *sceneDelegate, SdfPath const &id,
                                                                         bool isVolume, bool hasDensityField,
                                                                         HdVolPhoton_MediumSource *source = nullptr);

/// Reads the medium of `source` again at its delegate's current time (and updates source.time).
std::optional<volphoton::translate::MediumParams> HdVolPhoton_RereadMedium(HdVolPhoton_MediumSource &source);

/// The UsdPrim behind rprim `id` when it was inserted by the legacy UsdImagingDelegate (directly or
/// through scene-index emulation; HdRenderIndex::GetSceneDelegateForRprim), invalid otherwise, and
/// the time that delegate renders.
UsdPrim HdVolPhoton_FindUsdPrim(HdSceneDelegate *sceneDelegate, SdfPath const &id, UsdTimeCode *time = nullptr);

/// Sends translation diagnostics to the Tf diagnostic system ("hdVolPhoton: error: /prim.attr: ...").
void HdVolPhoton_Report(volphoton::translate::Diagnostics const &diagnostics);

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_MEDIUM_PARAMS_H
