// hdVolPhoton: the plain descriptions Hydra prims sync into, and their translation into the core's
// SceneDesc. No Hydra prim types here: the prims parse, this assembles.
#ifndef HDVOLPHOTON_SCENE_REGISTRY_H
#define HDVOLPHOTON_SCENE_REGISTRY_H

#include "pxr/pxr.h"
#include "pxr/usd/sdf/path.h"

#include "core/scene.h"
#include "hd/mediumParams.h"
#include "core/translate/light.h"

#include <map>
#include <optional>
#include <mutex>

PXR_NAMESPACE_OPEN_SCOPE

/// A GeomSubset with a material binding: its triangles (3 vertex indices each) and their authored faces.
struct HdVolPhoton_SubsetRecord {
    SdfPath materialId;
    std::vector<uint32_t> indices;
    std::vector<int> faces;  ///< one per triangle
};

/// A mesh as synced: object-space triangles, one world transform per instance, its surface and,
/// when it carries VolPhotonMediumAPI, the medium it bounds.
struct HdVolPhoton_MeshRecord {
    volphoton::MeshDesc mesh;                  ///< object space (triangleElements: authored faces); interiorMedium set by the registry
    std::vector<volphoton::Affine> instances;  ///< world transforms (one when not instanced)
    int primId = -1;  ///< HdRprim::GetPrimId(): what the primId AOV reports (instanceId: index into instances)
    bool hasMedium = false;
    volphoton::translate::MediumParams medium;
    HdVolPhoton_MediumSource mediumSource;  ///< set when the medium may vary in time (legacy path)
    SdfPath materialId;  ///< bound material of the faces in no subset
    std::vector<HdVolPhoton_SubsetRecord> subsets;
    /// A mesh light (MeshLightAPI; only on meshes without a medium, see mesh.cpp): applied to its
    /// materials when the scene is built (translate::meshLightSurface).
    std::optional<volphoton::translate::LightResult> meshLight;
};

/// A material as synced: valid when it had a UsdPreviewSurface; material empty = not rendered.
struct HdVolPhoton_MaterialRecord {
    bool valid = false;
    std::optional<volphoton::SurfaceMaterial> material;
};

/// An OpenVDB field prim (openvdbAsset): where its grid is.
struct HdVolPhoton_FieldRecord {
    std::string primPath;  ///< the OpenVDBAsset prim, for messages
    std::string filePath;
    std::string fieldName;
    int fieldIndex = -1;  ///< -1 when not authored
};

/// A volume as synced: its medium parameters, transform and the field prims it binds by name
/// (density, temperature, emission, albedo).
struct HdVolPhoton_VolumeRecord {
    volphoton::translate::MediumParams medium;
    HdVolPhoton_MediumSource mediumSource;  ///< set when the medium may vary in time (legacy path)
    volphoton::Affine objectToWorld;
    std::map<std::string, SdfPath> fields;
};

/// \class HdVolPhoton_SceneRegistry
///
/// Everything the prims have synced, keyed by prim path. Prims write to it only through
/// HdVolPhotonRenderParam::AcquireSceneForEdit(); Sync runs in parallel, so each write takes the
/// registry's lock. BuildSceneDesc() runs on the render pass thread while rendering is stopped.
class HdVolPhoton_SceneRegistry
{
public:
    void SetMesh(SdfPath const &id, HdVolPhoton_MeshRecord record);
    void SetVolume(SdfPath const &id, HdVolPhoton_VolumeRecord record);
    void SetField(SdfPath const &id, HdVolPhoton_FieldRecord record);
    void SetLight(SdfPath const &id, volphoton::LightPtr light);
    void SetMaterial(SdfPath const &id, HdVolPhoton_MaterialRecord record);
    void Remove(SdfPath const &id);

    /// Translates everything into the core's description: loads VDB grids (cached by file, grid
    /// and parameters), builds media and lights. Problems become TF_WARN messages naming the prim,
    /// and the prim is left out; the rest still renders.
    /// maxGridVoxels: the grid-size cap (RenderSettings::maxGridVoxels).
    volphoton::SceneDesc BuildSceneDesc(volphoton::CameraDesc const &camera, std::uint64_t maxGridVoxels) const;

    /// True when a medium whose attributes vary in time was read at another time than its scene
    /// delegate now renders (UsdImaging would not re-sync it: see HdVolPhoton_MediumSource).
    bool HasStaleMedia() const;
    /// Re-reads those media (call through the edit gate, which restarts the render).
    void RefreshTimeVaryingMedia();

    /// Counts for render stats.
    size_t GetMeshCount() const;
    size_t GetVolumeCount() const;
    size_t GetLightCount() const;

private:
    /// The grid medium of a field-mode volume (cached), or null with the reason in diagnostics.
    volphoton::MediumPtr _GridMedium(SdfPath const &id, HdVolPhoton_VolumeRecord const &rec, std::uint64_t maxGridVoxels,
                                     volphoton::translate::Diagnostics &diagnostics) const;

    mutable std::mutex _mutex;
    std::map<SdfPath, HdVolPhoton_MeshRecord> _meshes;
    std::map<SdfPath, HdVolPhoton_VolumeRecord> _volumes;
    std::map<SdfPath, HdVolPhoton_FieldRecord> _fields;
    std::map<SdfPath, volphoton::LightPtr> _lights;
    std::map<SdfPath, HdVolPhoton_MaterialRecord> _materials;
    mutable std::map<std::string, volphoton::MediumPtr> _gridCache;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_SCENE_REGISTRY_H
