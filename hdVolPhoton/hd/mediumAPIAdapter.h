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
/// VolPhotonMediumAPI as a constant primvar of the same name, which HdSceneDelegate::Get() finds
/// (HdSceneIndexAdapterSceneDelegate looks keys up among primvars). With the legacy
/// UsdImagingDelegate the same Get() reaches the attribute directly, so the delegate reads media
/// the same way on both paths.
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
