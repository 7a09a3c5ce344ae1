// hdVolPhoton: materials (UsdPreviewSurface).
#ifndef HDVOLPHOTON_MATERIAL_H
#define HDVOLPHOTON_MATERIAL_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/material.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonMaterial
///
/// A material Sprim. Sync reads the UsdPreviewSurface node of the surface network
/// (diffuseColor, emissiveColor, opacity, opacityThreshold, ior, metallic: authored values only)
/// and turns it into the core's surface material by core/previewSurface.h's rules, the same the
/// usd-core front end applies. Meshes bound to it (GetMaterialId, and GeomSubsets of the
/// materialBind family through the topology) use it unless they bound a medium.
/// XXX: connected inputs (textures) are not read: they use their authored value or the
/// UsdPreviewSurface default (the usd-core front end does the same, with a warning).
/// Threading: Sync writes the scene registry through the edit gate.
class HdVolPhotonMaterial final : public HdMaterial
{
public:
    explicit HdVolPhotonMaterial(SdfPath const &id);
    void Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) override;
    void Finalize(HdRenderParam *renderParam) override;
    HdDirtyBits GetInitialDirtyBitsMask() const override { return AllDirty; }
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_MATERIAL_H
