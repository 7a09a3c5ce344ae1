// hdVolPhoton: UsdImaging adapter that publishes VolPhotonMediumAPI to Hydra's scene indices.
#ifndef HDVOLPHOTON_MEDIUM_API_ADAPTER_H
#define HDVOLPHOTON_MEDIUM_API_ADAPTER_H

#include "pxr/pxr.h"
#include "pxr/usdImaging/usdImaging/apiSchemaAdapter.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonMediumAPIAdapter
///
/// With UsdImaging's scene-index path, attributes an adapter does not publish never reach the
/// render delegate. This API-schema adapter publishes every `volphoton:*` attribute of a prim with
/// VolPhotonMediumAPI that has a value as a constant primvar of the same name, plus the applied lobe
/// instances, the stage's up axis and the authored names (hd/mediumParams.h), which
/// HdVolPhoton_ReadMedium collects into the translation layer's record. With the legacy
/// UsdImagingDelegate the delegate reads the UsdPrim itself, so both paths hand the translation
/// layer the same record.
class HdVolPhotonMediumAPIAdapter final : public UsdImagingAPISchemaAdapter
{
public:
    using BaseAdapter = UsdImagingAPISchemaAdapter;

    HdContainerDataSourceHandle GetImagingSubprimData(UsdPrim const &prim, TfToken const &subprim,
                                                      TfToken const &appliedInstanceName,
                                                      UsdImagingDataSourceStageGlobals const &stageGlobals) override;

    HdDataSourceLocatorSet InvalidateImagingSubprim(UsdPrim const &prim, TfToken const &subprim,
                                                    TfToken const &appliedInstanceName, TfTokenVector const &properties,
                                                    UsdImagingPropertyInvalidationType invalidationType) override;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_MEDIUM_API_ADAPTER_H
