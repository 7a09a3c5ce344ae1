#include "hd/mesh.h"

#include <map>

#include "pxr/base/tf/diagnostic.h"
#include "pxr/imaging/hd/meshUtil.h"
#include "pxr/imaging/hd/renderIndex.h"
#include "pxr/imaging/hd/sceneDelegate.h"
#include "pxr/imaging/hd/tokens.h"

#include "hd/conversions.h"
#include "hd/instancer.h"
#include "hd/light.h"
#include "hd/renderParam.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonMesh::HdVolPhotonMesh(SdfPath const &id) : HdMesh(id) {}

HdDirtyBits HdVolPhotonMesh::GetInitialDirtyBitsMask() const {
    return HdChangeTracker::Clean | HdChangeTracker::InitRepr | HdChangeTracker::DirtyPoints |
           HdChangeTracker::DirtyTopology | HdChangeTracker::DirtyTransform | HdChangeTracker::DirtyVisibility |
           HdChangeTracker::DirtyPrimvar | HdChangeTracker::DirtyInstancer | HdChangeTracker::DirtyInstanceIndex |
           HdChangeTracker::DirtyParams | HdChangeTracker::DirtyMaterialId;
}

HdDirtyBits HdVolPhotonMesh::_PropagateDirtyBits(HdDirtyBits bits) const { return bits; }

void HdVolPhotonMesh::_InitRepr(TfToken const &reprToken, HdDirtyBits *) {
    // One representation: the core ray traces the triangles whatever the repr asks for.
    if (std::find_if(_reprs.begin(), _reprs.end(), _ReprComparator(reprToken)) == _reprs.end())
        _reprs.emplace_back(reprToken, HdReprSharedPtr());
}

void HdVolPhotonMesh::Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits,
                           TfToken const &) {
    SdfPath const &id = GetId();
    HdVolPhoton_MeshRecord rec;
    rec.mesh.name = id.GetString();
    rec.primId = GetPrimId();

    VtValue pointsValue = sceneDelegate->Get(id, HdTokens->points);
    VtVec3fArray points = pointsValue.IsHolding<VtVec3fArray>() ? pointsValue.UncheckedGet<VtVec3fArray>() : VtVec3fArray();
    for (GfVec3f const &p : points) rec.mesh.points.push_back({p[0], p[1], p[2]});

    HdMeshTopology topology = GetMeshTopology(sceneDelegate);
    HdMeshUtil meshUtil(&topology, id);
    VtVec3iArray triangles;
    VtIntArray primitiveParams;
    meshUtil.ComputeTriangleIndices(&triangles, &primitiveParams);
    // Faces bound to a material by a GeomSubset: their triangles become a part of their own.
    std::map<int, size_t> faceSubset;
    for (HdGeomSubset const &subset : topology.GetGeomSubsets()) {
        if (subset.type != HdGeomSubset::TypeFaceSet || subset.materialId.IsEmpty()) continue;
        rec.subsets.push_back({subset.materialId, {}, {}});
        for (int face : subset.indices) faceSubset[face] = rec.subsets.size() - 1;
    }
    size_t dropped = 0;
    for (size_t i = 0; i < triangles.size(); ++i) {
        GfVec3i const &t = triangles[i];
        bool valid = true;
        for (int k = 0; k < 3; ++k) valid &= t[k] >= 0 && static_cast<size_t>(t[k]) < points.size();
        if (!valid) { ++dropped; continue; }
        int face = i < primitiveParams.size() ? HdMeshUtil::DecodeFaceIndexFromCoarseFaceParam(primitiveParams[i])
                                              : static_cast<int>(i);
        if (!faceSubset.empty()) {
            auto it = faceSubset.find(face);
            if (it != faceSubset.end()) {
                HdVolPhoton_SubsetRecord &sub = rec.subsets[it->second];
                sub.indices.insert(sub.indices.end(), {uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
                sub.faces.push_back(face);
                continue;
            }
        }
        rec.mesh.indices.insert(rec.mesh.indices.end(), {uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
        rec.mesh.triangleElements.push_back(face);
    }
    if (dropped) TF_WARN("%s: %zu triangles index points out of range; dropped", id.GetText(), dropped);
    for (volphoton::Vec3 const &p : rec.mesh.points)
        if (!volphoton::isFinite(p)) {
            TF_WARN("%s.points: non-finite point; mesh skipped", id.GetText());
            rec.mesh.indices.clear();
            rec.mesh.triangleElements.clear();
            break;
        }

    VtValue color = sceneDelegate->Get(id, HdTokens->displayColor);
    if (color.IsHolding<VtVec3fArray>() && !color.UncheckedGet<VtVec3fArray>().empty())
        rec.mesh.material.albedo = HdVolPhoton_ToSpectrum(color.UncheckedGet<VtVec3fArray>()[0]);
    else if (color.IsHolding<GfVec3f>())
        rec.mesh.material.albedo = HdVolPhoton_ToSpectrum(color.UncheckedGet<GfVec3f>());
    // displayColor is the albedo of a mesh (or GeomSubset) without a material; a bound
    // UsdPreviewSurface material (material.cpp) replaces it when the scene is built (sceneRegistry.cpp).

    rec.materialId = sceneDelegate->GetMaterialId(id);
    if (auto medium = HdVolPhoton_ReadMedium(sceneDelegate, id, /*isVolume=*/false, /*hasDensityField=*/false,
                                             &rec.mediumSource)) {
        rec.hasMedium = true;
        rec.medium = *medium;
    }

    // The instancer id is only known after _UpdateInstancer (a prototype's first Sync included).
    _UpdateInstancer(sceneDelegate, dirtyBits);
    if (sceneDelegate->GetVisible(id)) {
        GfMatrix4d objectToWorld = sceneDelegate->GetTransform(id);
        SdfPath const &instancerId = GetInstancerId();
        if (instancerId.IsEmpty()) {
            rec.instances.push_back(HdVolPhoton_ToAffine(objectToWorld));
        } else {
            HdInstancer::_SyncInstancerAndParents(sceneDelegate->GetRenderIndex(), instancerId);
            auto *instancer = static_cast<HdVolPhotonInstancer *>(sceneDelegate->GetRenderIndex().GetInstancer(instancerId));
            if (instancer)
                for (GfMatrix4d const &m : instancer->ComputeInstanceTransforms(id))
                    rec.instances.push_back(HdVolPhoton_ToAffine(objectToWorld * m));
        }
        size_t singular = 0;
        for (volphoton::Affine const &a : rec.instances) singular += !a.inverse();
        if (singular) TF_WARN("%s: %zu instance transforms are not invertible or not finite; those are skipped", id.GetText(), singular);
    }

    // A mesh light (MeshLightAPI): its surface emits what the translation layer makes of its UsdLux
    // attributes (core/translate/light.h, kind "mesh"; inputs:normalize divides by the world area
    // under the first instance's transform, as the usd-core front end does).
    if (!rec.hasMedium && !rec.instances.empty())
        if (auto lightRecord = HdVolPhoton_ReadMeshLightRecord(sceneDelegate, id)) {
            volphoton::translate::LightContext context;
            context.kind = "mesh";
            context.typeName = "Mesh";
            context.lightToWorld = rec.instances[0];
            context.meshArea = volphoton::translate::meshWorldArea(rec.mesh.points, rec.mesh.indices, rec.instances[0]);
            for (HdVolPhoton_SubsetRecord const &subset : rec.subsets)
                context.meshArea += volphoton::translate::meshWorldArea(rec.mesh.points, subset.indices, rec.instances[0]);
            volphoton::translate::Diagnostics diagnostics;
            volphoton::translate::LightResult light = volphoton::translate::translateLight(*lightRecord, context, diagnostics);
            HdVolPhoton_Report(diagnostics);
            if (light.kind == "mesh") rec.meshLight = std::move(light);
        }

    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().SetMesh(id, std::move(rec));
    *dirtyBits &= ~HdChangeTracker::AllSceneDirtyBits;
}

void HdVolPhotonMesh::Finalize(HdRenderParam *renderParam) {
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().Remove(GetId());
}

PXR_NAMESPACE_CLOSE_SCOPE
