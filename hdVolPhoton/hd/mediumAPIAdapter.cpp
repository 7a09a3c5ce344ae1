#include "hd/mediumAPIAdapter.h"

#include "pxr/imaging/hd/primvarSchema.h"
#include "pxr/imaging/hd/primvarsSchema.h"
#include "pxr/imaging/hd/retainedDataSource.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/usd/usd/attribute.h"
#include "pxr/usd/usd/prim.h"
#include "pxr/usdImaging/usdImaging/dataSourceAttribute.h"

#include "hd/mediumParams.h"

PXR_NAMESPACE_OPEN_SCOPE

using volphoton::Vec3;

TF_REGISTRY_FUNCTION(TfType) {
    using Adapter = HdVolPhotonMediumAPIAdapter;
    TfType t = TfType::Define<Adapter, TfType::Bases<Adapter::BaseAdapter>>();
    t.SetFactory<UsdImagingAPISchemaAdapterFactory<Adapter>>();
}

namespace {
bool _IsMediumProperty(TfToken const &name) { return TfStringStartsWith(name.GetString(), "volphoton:"); }
}  // namespace

HdContainerDataSourceHandle HdVolPhotonMediumAPIAdapter::GetImagingSubprimData(
    UsdPrim const &prim, TfToken const &subprim, TfToken const &, UsdImagingDataSourceStageGlobals const &stageGlobals) {
    if (!subprim.IsEmpty()) return nullptr;
    TfTokenVector names;
    std::vector<HdDataSourceBaseHandle> values;
    auto add = [&](TfToken const &name, HdDataSourceBaseHandle value) {
        names.push_back(name);
        values.push_back(HdPrimvarSchema::Builder()
                             .SetPrimvarValue(HdSampledDataSource::Cast(value))
                             .SetInterpolation(HdPrimvarSchema::BuildInterpolationDataSource(HdPrimvarSchemaTokens->constant))
                             .Build());
    };
    VtTokenArray authored;
    for (UsdAttribute const &attr : prim.GetAttributes()) {
        if (!_IsMediumProperty(attr.GetName()) || !attr.HasValue()) continue;
        if (attr.HasAuthoredValue()) authored.push_back(attr.GetName());
        add(attr.GetName(), UsdImagingDataSourceAttributeNew(attr, stageGlobals, prim.GetPath(),
                                                             HdPrimvarsSchema::GetDefaultLocator().Append(attr.GetName())));
    }
    // What the translation layer needs beside the values (see hd/mediumParams.h).
    HdVolPhoton_MediumInput in = HdVolPhoton_ReadMediumInput(prim, UsdTimeCode::Default());
    VtTokenArray lobes;
    for (std::string const &l : in.context.lobeNames) lobes.push_back(TfToken(l));
    Vec3 const &up = in.context.stageUp;
    add(TfToken(HDVOLPHOTON_MEDIUM_LOBES), HdRetainedTypedSampledDataSource<VtTokenArray>::New(lobes));
    add(TfToken(HDVOLPHOTON_MEDIUM_STAGE_UP), HdRetainedTypedSampledDataSource<GfVec3d>::New(GfVec3d(up.x, up.y, up.z)));
    add(TfToken(HDVOLPHOTON_MEDIUM_AUTHORED), HdRetainedTypedSampledDataSource<VtTokenArray>::New(authored));
    return HdRetainedContainerDataSource::New(
        HdPrimvarsSchema::GetSchemaToken(), HdRetainedContainerDataSource::New(names.size(), names.data(), values.data()));
}

HdDataSourceLocatorSet HdVolPhotonMediumAPIAdapter::InvalidateImagingSubprim(UsdPrim const &, TfToken const &subprim,
                                                                             TfToken const &, TfTokenVector const &properties,
                                                                             UsdImagingPropertyInvalidationType) {
    HdDataSourceLocatorSet dirty;
    if (!subprim.IsEmpty()) return dirty;
    for (TfToken const &p : properties)
        if (_IsMediumProperty(p)) dirty.insert(HdPrimvarsSchema::GetDefaultLocator().Append(p));
    return dirty;
}

PXR_NAMESPACE_CLOSE_SCOPE
