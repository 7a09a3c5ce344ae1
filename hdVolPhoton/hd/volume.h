// hdVolPhoton: UsdVol volumes.
#ifndef HDVOLPHOTON_VOLUME_H
#define HDVOLPHOTON_VOLUME_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/volume.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonVolume
///
/// Sync pulls the volume's field bindings (GetVolumeFieldDescriptors: density, temperature,
/// emission, albedo -> field prim paths), its transform and the medium schema (a Volume without
/// VolPhotonMediumAPI renders with the schema defaults, never as a surface) into an
/// HdVolPhoton_VolumeRecord for the scene registry. The VDB itself is read when the render pass
/// builds the core scene (HdVolPhotonField only records where it is).
class HdVolPhotonVolume final : public HdVolume
{
public:
    HdVolPhotonVolume(SdfPath const &id);
    ~HdVolPhotonVolume() override = default;

    HdDirtyBits GetInitialDirtyBitsMask() const override;
    void Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits,
              TfToken const &reprToken) override;
    void Finalize(HdRenderParam *renderParam) override;

protected:
    HdDirtyBits _PropagateDirtyBits(HdDirtyBits bits) const override { return bits; }
    void _InitRepr(TfToken const &reprToken, HdDirtyBits *dirtyBits) override;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_VOLUME_H
