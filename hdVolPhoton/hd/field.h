// hdVolPhoton: OpenVDB field prims.
#ifndef HDVOLPHOTON_FIELD_H
#define HDVOLPHOTON_FIELD_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/field.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonField
///
/// An openvdbAsset bprim: Sync records filePath (resolved, per time sample: the scene delegate
/// evaluates time-varying paths at the current time), fieldName and fieldIndex in the scene
/// registry. Volumes that bind it are rebuilt through the edit gate when it changes.
class HdVolPhotonField final : public HdField
{
public:
    HdVolPhotonField(SdfPath const &id);
    ~HdVolPhotonField() override = default;

    void Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) override;
    void Finalize(HdRenderParam *renderParam) override;
    HdDirtyBits GetInitialDirtyBitsMask() const override;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_FIELD_H
