// hdVolPhoton: triangle meshes (and, through VolPhotonMediumAPI, the closed surfaces that bound media).
#ifndef HDVOLPHOTON_MESH_H
#define HDVOLPHOTON_MESH_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/mesh.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonMesh
///
/// Sync (parallel, one thread per prim) pulls points, topology (triangulated by HdMeshUtil, which
/// honours the orientation), transform, visibility, instancing, displayColor and the medium schema
/// into a plain HdVolPhoton_MeshRecord and hands it to the scene registry through the render
/// param's edit gate. Nothing here touches the core's BVH: the render pass rebuilds the core scene
/// from the registry when the scene version changed. Finalize removes the record.
class HdVolPhotonMesh final : public HdMesh
{
public:
    HF_MALLOC_TAG_NEW("new HdVolPhotonMesh");
    HdVolPhotonMesh(SdfPath const &id);
    ~HdVolPhotonMesh() override = default;

    HdDirtyBits GetInitialDirtyBitsMask() const override;
    void Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits,
              TfToken const &reprToken) override;
    void Finalize(HdRenderParam *renderParam) override;

protected:
    HdDirtyBits _PropagateDirtyBits(HdDirtyBits bits) const override;
    void _InitRepr(TfToken const &reprToken, HdDirtyBits *dirtyBits) override;

private:
    HdVolPhotonMesh(HdVolPhotonMesh const &) = delete;
    HdVolPhotonMesh &operator=(HdVolPhotonMesh const &) = delete;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_MESH_H
