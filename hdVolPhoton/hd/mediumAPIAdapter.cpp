#include "hd/mediumAPIAdapter.h"

#include "pxr/imaging/hd/primvarSchema.h"
#include "pxr/imaging/hd/primvarsSchema.h"
#include "pxr/imaging/hd/retainedDataSource.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/usd/usd/attribute.h"
#include "pxr/usd/usd/prim.h"
#include "pxr/usdImaging/usdImaging/dataSourceAttribute.h"

PXR_NAMESPACE_OPEN_SCOPE

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
    for (UsdAttribute const &attr : prim.GetAttributes()) {
        if (!_IsMediumProperty(attr.GetName())) continue;
        names.push_back(attr.GetName());
        values.push_back(HdPrimvarSchema::Builder()
                             .SetPrimvarValue(UsdImagingDataSourceAttributeNew(attr, stageGlobals, prim.GetPath(),
                                                                               HdPrimvarsSchema::GetDefaultLocator().Append(attr.GetName())))
                             .SetInterpolation(HdPrimvarSchema::BuildInterpolationDataSource(HdPrimvarSchemaTokens->constant))
                             .Build());
    }
    if (names.empty()) return nullptr;
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
