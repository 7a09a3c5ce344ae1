// hdVolPhoton: UsdLux lights.
#ifndef HDVOLPHOTON_LIGHT_H
#define HDVOLPHOTON_LIGHT_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/light.h"

#include "core/translate/record.h"

#include <optional>
#include <string>

PXR_NAMESPACE_OPEN_SCOPE

class HdSceneDelegate;

/// The UsdLux attributes the translation layer reads (translate::lightAttributeNames()) of the light
/// sprim `id`, through HdSceneDelegate::GetLightParamValue; the dome texture's authored asset path
/// in *textureAsset.
volphoton::translate::AttributeRecord HdVolPhoton_ReadLightRecord(HdSceneDelegate *sceneDelegate, SdfPath const &id,
                                                                   std::string *textureAsset = nullptr);

/// The same attributes of rprim `id` when it is a mesh light (LightAPI, e.g. MeshLightAPI, on a
/// Gprim), nullopt when it is not: off the UsdPrim on the legacy scene delegate (it answers light
/// parameters for light prims only), through GetLightParamValue on the scene-index path (where the
/// LightAPI adapter gives the mesh its light data).
std::optional<volphoton::translate::AttributeRecord> HdVolPhoton_ReadMeshLightRecord(HdSceneDelegate *sceneDelegate,
                                                                                    SdfPath const &id);

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
