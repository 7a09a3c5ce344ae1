// hdVolPhoton: point instancers.
#ifndef HDVOLPHOTON_INSTANCER_H
#define HDVOLPHOTON_INSTANCER_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/instancer.h"
#include "pxr/base/vt/array.h"
#include "pxr/base/gf/matrix4d.h"
#include "pxr/base/gf/quath.h"
#include "pxr/base/gf/vec3f.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonInstancer
///
/// Pulls the instance transform primvars (hydra:instanceTransforms, -Translations, -Rotations,
/// -Scales) in Sync, and composes the per-instance world transforms a prototype asks for with
/// ComputeInstanceTransforms(), including nested instancers. Meshes call it during their own Sync.
class HdVolPhotonInstancer final : public HdInstancer
{
public:
    HdVolPhotonInstancer(HdSceneDelegate *delegate, SdfPath const &id);
    ~HdVolPhotonInstancer() override;

    void Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) override;

    /// World transforms of every instance of `prototypeId` (already including the instancer's own
    /// transform and its parents').
    VtMatrix4dArray ComputeInstanceTransforms(SdfPath const &prototypeId);

private:
    VtMatrix4dArray _transforms;
    VtArray<GfVec3f> _translations;
    VtArray<GfQuath> _rotations;
    VtArray<GfVec3f> _scales;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_INSTANCER_H
