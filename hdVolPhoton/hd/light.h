// hdVolPhoton: UsdLux lights.
#ifndef HDVOLPHOTON_LIGHT_H
#define HDVOLPHOTON_LIGHT_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/light.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonLight
///
/// Distant, sphere (point, spot with ShapingAPI), rect, disk and dome lights. Sync converts the
/// UsdLux parameters into a core light with the same unit rules as the usd-core front end
/// (hdVolPhoton/python/volphoton/usdscene.py): s = intensity * 2^exposure * color; normalize divides
/// area lights by their world area and makes a distant light's s its irradiance.
class HdVolPhotonLight final : public HdLight
{
public:
    HdVolPhotonLight(SdfPath const &id, TfToken const &lightType);
    ~HdVolPhotonLight() override = default;

    void Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) override;
    void Finalize(HdRenderParam *renderParam) override;
    HdDirtyBits GetInitialDirtyBitsMask() const override;

private:
    TfToken _lightType;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_LIGHT_H
