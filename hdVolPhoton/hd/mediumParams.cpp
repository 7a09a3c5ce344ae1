#include "hd/mediumParams.h"

#include "pxr/base/gf/half.h"
#include "pxr/base/gf/vec3d.h"
#include "pxr/base/gf/vec3f.h"
#include "pxr/base/gf/vec3h.h"
#include "pxr/base/tf/diagnostic.h"
#include "pxr/base/tf/stringUtils.h"
#include "pxr/base/vt/array.h"
#include "pxr/imaging/hd/renderIndex.h"
#include "pxr/imaging/hd/sceneDelegate.h"
#include "pxr/usd/sdf/assetPath.h"
#include "pxr/usd/usd/attribute.h"
#include "pxr/usd/usd/schemaRegistry.h"
#include "pxr/usd/usdGeom/gprim.h"
#include "pxr/usd/usdGeom/metrics.h"
#include "pxr/usd/usdVol/volume.h"
#include "pxr/usdImaging/usdImaging/delegate.h"
#include "pxr/usdImaging/usdImaging/primAdapter.h"

PXR_NAMESPACE_OPEN_SCOPE

using namespace volphoton;
using volphoton::translate::AttrValue;

namespace {

template <class A>
std::vector<double> _ToList(A const &a) {
    return std::vector<double>(a.begin(), a.end());
}

/// UsdImagingPrimAdapter's protected _GetPrim/_GetStage reach the legacy delegate's UsdPrims; this
/// adapter is never registered or populated, it only borrows that access for one read.
class _PrimAccess final : public UsdImagingPrimAdapter
{
public:
    UsdPrim Prim(SdfPath const &usdPath) const { return _GetPrim(usdPath); }
    SdfPath Populate(UsdPrim const &, UsdImagingIndexProxy *, UsdImagingInstancerContext const *) override { return {}; }
    void TrackVariability(UsdPrim const &, SdfPath const &, HdDirtyBits *, UsdImagingInstancerContext const *) const override {}
    void UpdateForTime(UsdPrim const &, SdfPath const &, UsdTimeCode, HdDirtyBits,
                       UsdImagingInstancerContext const *) const override {}
    HdDirtyBits ProcessPropertyChange(UsdPrim const &, SdfPath const &, TfToken const &) override { return 0; }
    void MarkDirty(UsdPrim const &, SdfPath const &, HdDirtyBits, UsdImagingIndexProxy *) override {}

protected:
    void _RemovePrim(SdfPath const &, UsdImagingIndexProxy *) override {}
};

}  // namespace

AttrValue HdVolPhoton_ToAttrValue(VtValue const &v) {
    if (v.IsHolding<bool>()) return v.UncheckedGet<bool>();
    if (v.IsHolding<int>()) return int64_t(v.UncheckedGet<int>());
    if (v.IsHolding<unsigned int>()) return int64_t(v.UncheckedGet<unsigned int>());
    if (v.IsHolding<int64_t>()) return v.UncheckedGet<int64_t>();
    if (v.IsHolding<uint64_t>()) return int64_t(v.UncheckedGet<uint64_t>());
    if (v.IsHolding<float>()) return double(v.UncheckedGet<float>());
    if (v.IsHolding<double>()) return v.UncheckedGet<double>();
    if (v.IsHolding<GfHalf>()) return double(v.UncheckedGet<GfHalf>());
    if (v.IsHolding<GfVec3f>()) {
        GfVec3f const &x = v.UncheckedGet<GfVec3f>();
        return Vec3(x[0], x[1], x[2]);
    }
    if (v.IsHolding<GfVec3d>()) {
        GfVec3d const &x = v.UncheckedGet<GfVec3d>();
        return Vec3(x[0], x[1], x[2]);
    }
    if (v.IsHolding<GfVec3h>()) {
        GfVec3h const &x = v.UncheckedGet<GfVec3h>();
        return Vec3(x[0], x[1], x[2]);
    }
    if (v.IsHolding<TfToken>()) return v.UncheckedGet<TfToken>().GetString();
    if (v.IsHolding<std::string>()) return v.UncheckedGet<std::string>();
    if (v.IsHolding<SdfAssetPath>()) {
        SdfAssetPath const &a = v.UncheckedGet<SdfAssetPath>();
        return a.GetResolvedPath().empty() ? a.GetAssetPath() : a.GetResolvedPath();
    }
    if (v.IsHolding<VtFloatArray>()) return _ToList(v.UncheckedGet<VtFloatArray>());
    if (v.IsHolding<VtDoubleArray>()) return _ToList(v.UncheckedGet<VtDoubleArray>());
    if (v.IsHolding<VtIntArray>()) return _ToList(v.UncheckedGet<VtIntArray>());
    if (v.IsHolding<VtHalfArray>()) return _ToList(v.UncheckedGet<VtHalfArray>());
    return translate::Unusable{v.GetTypeName()};
}

namespace {
UsdImagingDelegate *_LegacyDelegate(HdSceneDelegate *sd, SdfPath const &id) {
    if (!sd || id.IsEmpty()) return nullptr;
    // With scene-index emulation (OpenUSD's default) the prims see HdSceneIndexAdapterSceneDelegate;
    // the render index still answers with the UsdImagingDelegate that inserted the rprim.
    auto *usd = dynamic_cast<UsdImagingDelegate *>(sd);
    return usd ? usd : dynamic_cast<UsdImagingDelegate *>(sd->GetRenderIndex().GetSceneDelegateForRprim(id));
}

UsdPrim _PrimOf(UsdImagingDelegate *usd, SdfPath const &id) {
    _PrimAccess access;
    access.SetDelegate(usd);
    return access.Prim(usd->GetScenePrimPath(id, 0, nullptr));
}

bool _MightVaryInTime(UsdPrim const &prim) {
    for (UsdAttribute const &attr : prim.GetAttributes())
        if (TfStringStartsWith(attr.GetName().GetString(), "volphoton:") && attr.ValueMightBeTimeVarying()) return true;
    return false;
}
}  // namespace

UsdPrim HdVolPhoton_FindUsdPrim(HdSceneDelegate *sd, SdfPath const &id, UsdTimeCode *time) {
    UsdImagingDelegate *usd = _LegacyDelegate(sd, id);
    if (!usd) return UsdPrim();
    if (time) *time = usd->GetTime();
    return _PrimOf(usd, id);
}

bool HdVolPhoton_MediumSource::IsStale() const { return delegate && delegate->GetTime() != time; }

std::optional<translate::MediumParams> HdVolPhoton_RereadMedium(HdVolPhoton_MediumSource &source) {
    source.time = source.delegate->GetTime();
    UsdPrim prim = _PrimOf(source.delegate, source.id);
    if (!prim) return std::nullopt;
    HdVolPhoton_MediumInput in = HdVolPhoton_ReadMediumInput(prim, source.time);
    in.context.hasDensityField = source.hasDensityField;
    translate::Diagnostics diagnostics;
    std::optional<translate::MediumParams> params = translate::readMedium(in.record, in.context, diagnostics);
    HdVolPhoton_Report(diagnostics);
    return params;
}

HdVolPhoton_MediumInput HdVolPhoton_ReadMediumInput(UsdPrim const &prim, UsdTimeCode time) {
    HdVolPhoton_MediumInput in;
    in.record.primPath = prim.GetPath().GetString();
    for (UsdAttribute const &attr : prim.GetAttributes()) {
        std::string const &name = attr.GetName().GetString();
        if (!TfStringStartsWith(name, "volphoton:")) continue;
        VtValue v;
        if (!attr.Get(&v, time) || v.IsEmpty()) continue;
        in.record.values[name] = HdVolPhoton_ToAttrValue(v);
        if (attr.HasAuthoredValue()) in.record.authored.insert(name);
    }
    translate::MediumContext &c = in.context;
    c.isVolume = prim.IsA<UsdVolVolume>();
    c.isGprim = prim.IsA<UsdGeomGprim>();
    c.typeName = prim.GetTypeName().GetString();
    static std::string const lobePrefix = "VolPhotonPhaseLobeAPI:";
    for (TfToken const &s : prim.GetAppliedSchemas()) {
        if (s == "VolPhotonMediumAPI") c.hasApi = true;
        else if (TfStringStartsWith(s.GetString(), lobePrefix)) c.lobeNames.push_back(s.GetString().substr(lobePrefix.size()));
    }
    c.schemaRegistered = UsdSchemaRegistry::GetInstance().FindAppliedAPIPrimDefinition(TfToken("VolPhotonMediumAPI")) != nullptr;
    c.stageUp = UsdGeomGetStageUpAxis(prim.GetStage()) == UsdGeomTokens->z ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
    return in;
}

std::optional<translate::MediumParams> HdVolPhoton_ReadMedium(HdSceneDelegate *sd, SdfPath const &id, bool isVolume,
                                                              bool hasDensityField, HdVolPhoton_MediumSource *source) {
    UsdTimeCode time = UsdTimeCode::Default();
    HdVolPhoton_MediumInput in;
    if (source) *source = HdVolPhoton_MediumSource();
    if (UsdPrim prim = HdVolPhoton_FindUsdPrim(sd, id, &time)) {
        in = HdVolPhoton_ReadMediumInput(prim, time);
        if (source && _MightVaryInTime(prim))
            *source = HdVolPhoton_MediumSource{_LegacyDelegate(sd, id), id, isVolume, hasDensityField, time};
    } else {
        // Scene-index path: the primvars of HdVolPhotonMediumAPIAdapter (present when the API is applied).
        in.record.primPath = id.GetString();
        in.context.isVolume = isVolume;
        in.context.isGprim = !isVolume;
        for (HdPrimvarDescriptor const &pv : sd->GetPrimvarDescriptors(id, HdInterpolationConstant)) {
            std::string const &name = pv.name.GetString();
            if (!TfStringStartsWith(name, "volphoton:")) continue;
            VtValue v = sd->Get(id, pv.name);
            if (name == HDVOLPHOTON_MEDIUM_LOBES && v.IsHolding<VtTokenArray>()) {
                for (TfToken const &t : v.UncheckedGet<VtTokenArray>()) in.context.lobeNames.push_back(t.GetString());
            } else if (name == HDVOLPHOTON_MEDIUM_STAGE_UP && v.IsHolding<GfVec3d>()) {
                GfVec3d const &u = v.UncheckedGet<GfVec3d>();
                in.context.stageUp = Vec3(u[0], u[1], u[2]);
            } else if (name == HDVOLPHOTON_MEDIUM_AUTHORED && v.IsHolding<VtTokenArray>()) {
                in.context.hasApi = true;
                for (TfToken const &t : v.UncheckedGet<VtTokenArray>()) in.record.authored.insert(t.GetString());
            } else if (!v.IsEmpty()) {
                in.record.values[name] = HdVolPhoton_ToAttrValue(v);
            }
        }
    }
    in.context.hasDensityField = hasDensityField;
    translate::Diagnostics diagnostics;
    std::optional<translate::MediumParams> params = translate::readMedium(in.record, in.context, diagnostics);
    HdVolPhoton_Report(diagnostics);
    return params;
}

void HdVolPhoton_Report(translate::Diagnostics const &diagnostics) {
    for (translate::Diagnostic const &d : diagnostics.list()) TF_WARN("hdVolPhoton: %s", d.text().c_str());
}

PXR_NAMESPACE_CLOSE_SCOPE
