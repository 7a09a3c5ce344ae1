#include "hd/light.h"

#include "pxr/base/gf/vec3f.h"
#include "pxr/base/tf/diagnostic.h"
#include "pxr/base/tf/stringUtils.h"
#include "pxr/imaging/hd/sceneDelegate.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/usd/sdf/assetPath.h"
#include "pxr/usd/usdLux/lightAPI.h"

#include "hd/conversions.h"
#include "hd/mediumParams.h"
#include "core/translate/light.h"
#include "hd/renderParam.h"

#include <cmath>
#include <cstring>

PXR_NAMESPACE_OPEN_SCOPE

using namespace volphoton;

HdVolPhotonLight::HdVolPhotonLight(SdfPath const &id, TfToken const &lightType) : HdLight(id), _lightType(lightType) {}

HdDirtyBits HdVolPhotonLight::GetInitialDirtyBitsMask() const { return AllDirty; }

namespace {
/// A light parameter by its UsdLux name. The legacy scene delegate answers to the attribute name
/// ("inputs:intensity"); the scene-index path (24.08) to the name without the "inputs:" prefix.
VtValue _LightParam(HdSceneDelegate *sd, SdfPath const &id, char const *name) {
    VtValue v = sd->GetLightParamValue(id, TfToken(name));
    if (v.IsEmpty() && std::strncmp(name, "inputs:", 7) == 0) v = sd->GetLightParamValue(id, TfToken(name + 7));
    return v;
}

}  // namespace

translate::AttributeRecord HdVolPhoton_ReadLightRecord(HdSceneDelegate *sd, SdfPath const &id, std::string *textureAsset) {
    // A parameter is present when the prim has the attribute (e.g. the shaping inputs only with
    // ShapingAPI applied).
    translate::AttributeRecord record;
    record.primPath = id.GetString();
    for (std::string const &name : translate::lightAttributeNames()) {
        VtValue v = _LightParam(sd, id, name.c_str());
        if (v.IsEmpty()) continue;
        if (v.IsHolding<SdfAssetPath>()) {
            SdfAssetPath const &a = v.UncheckedGet<SdfAssetPath>();
            if (name == "inputs:texture:file" && textureAsset) *textureAsset = a.GetAssetPath();
            record.values[name] = a.GetResolvedPath();
            continue;
        }
        record.values[name] = HdVolPhoton_ToAttrValue(v);
    }
    return record;
}

std::optional<translate::AttributeRecord> HdVolPhoton_ReadMeshLightRecord(HdSceneDelegate *sd, SdfPath const &id) {
    UsdTimeCode time;
    if (UsdPrim prim = HdVolPhoton_FindUsdPrim(sd, id, &time)) {
        if (!prim.HasAPI<UsdLuxLightAPI>()) return std::nullopt;
        translate::AttributeRecord record;
        record.primPath = id.GetString();
        for (std::string const &name : translate::lightAttributeNames()) {
            VtValue v;
            if (UsdAttribute attr = prim.GetAttribute(TfToken(name)); attr && attr.Get(&v, time) && !v.IsEmpty())
                record.values[name] = HdVolPhoton_ToAttrValue(v);
        }
        return record;
    }
    if (_LightParam(sd, id, "inputs:intensity").IsEmpty()) return std::nullopt;
    return HdVolPhoton_ReadLightRecord(sd, id);
}

namespace {
/// UsdImagingGLEngine's lighting state (usdrecord's and usdview's camera "headlight", a GL-era preview
/// light under /_UsdImaging_<renderer>_...) is not part of the scene: the standalone front end does
/// not see it either, so the two would not render the same picture. It follows the camera, so it is
/// synced on every camera move: it must not touch the scene (the edit gate would restart the render
/// as a scene edit and drop the photon maps a camera move keeps).
bool _IsEngineLight(SdfPath const &id) { return TfStringStartsWith(id.GetString(), "/_UsdImaging_"); }
}  // namespace

void HdVolPhotonLight::Sync(HdSceneDelegate *sd, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) {
    SdfPath const &id = GetId();
    *dirtyBits = Clean;
    if (_IsEngineLight(id)) return;
    auto &registry = static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit();
    if (!sd->GetVisible(id)) {
        registry.SetLight(id, nullptr);
        return;
    }
    // The UsdLux attributes the translation layer reads (core/translate/light.h has the rules,
    // shared with the usd-core front end).
    std::string textureAsset;
    translate::AttributeRecord record = HdVolPhoton_ReadLightRecord(sd, id, &textureAsset);
    translate::LightContext context;
    context.kind = _lightType == HdPrimTypeTokens->distantLight ? "distant"
                 : _lightType == HdPrimTypeTokens->sphereLight ? "sphere"
                 : _lightType == HdPrimTypeTokens->rectLight   ? "rect"
                 : _lightType == HdPrimTypeTokens->diskLight   ? "disk"
                 : _lightType == HdPrimTypeTokens->domeLight   ? "dome"
                                                                : "";
    context.typeName = _lightType.GetString();
    context.lightToWorld = HdVolPhoton_ToAffine(sd->GetTransform(id));
    context.textureAssetPath = textureAsset;
    VtValue filters = sd->GetLightParamValue(id, HdTokens->filters);
    context.hasFilters = filters.IsHolding<SdfPathVector>() && !filters.UncheckedGet<SdfPathVector>().empty();
    translate::Diagnostics diagnostics;
    LightPtr light = translate::translateLight(record, context, diagnostics).light;
    HdVolPhoton_Report(diagnostics);
    registry.SetLight(id, light);
}

void HdVolPhotonLight::Finalize(HdRenderParam *renderParam) {
    if (_IsEngineLight(GetId())) return;  // never in the scene
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().Remove(GetId());
}

PXR_NAMESPACE_CLOSE_SCOPE
