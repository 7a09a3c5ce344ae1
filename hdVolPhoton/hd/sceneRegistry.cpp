#include "hd/sceneRegistry.h"

#include "pxr/base/tf/diagnostic.h"

#include "core/exponentialMedium.h"
#include "core/translate/medium.h"
#include "core/gridMedium.h"
#include "core/translate/volume.h"

#include <sstream>

PXR_NAMESPACE_OPEN_SCOPE

using namespace volphoton;

void HdVolPhoton_SceneRegistry::SetMesh(SdfPath const &id, HdVolPhoton_MeshRecord record) {
    std::lock_guard<std::mutex> lock(_mutex);
    _meshes[id] = std::move(record);
}
void HdVolPhoton_SceneRegistry::SetVolume(SdfPath const &id, HdVolPhoton_VolumeRecord record) {
    std::lock_guard<std::mutex> lock(_mutex);
    _volumes[id] = std::move(record);
}
void HdVolPhoton_SceneRegistry::SetField(SdfPath const &id, HdVolPhoton_FieldRecord record) {
    std::lock_guard<std::mutex> lock(_mutex);
    _fields[id] = std::move(record);
}
void HdVolPhoton_SceneRegistry::SetLight(SdfPath const &id, LightPtr light) {
    std::lock_guard<std::mutex> lock(_mutex);
    if (light) _lights[id] = std::move(light);
    else _lights.erase(id);
}
void HdVolPhoton_SceneRegistry::SetMaterial(SdfPath const &id, HdVolPhoton_MaterialRecord record) {
    std::lock_guard<std::mutex> lock(_mutex);
    _materials[id] = std::move(record);
}
void HdVolPhoton_SceneRegistry::Remove(SdfPath const &id) {
    std::lock_guard<std::mutex> lock(_mutex);
    _materials.erase(id);
    _meshes.erase(id);
    _volumes.erase(id);
    _fields.erase(id);
    _lights.erase(id);
}
bool HdVolPhoton_SceneRegistry::HasStaleMedia() const {
    std::lock_guard<std::mutex> lock(_mutex);
    for (auto const &[id, rec] : _meshes)
        if (rec.mediumSource.IsStale()) return true;
    for (auto const &[id, rec] : _volumes)
        if (rec.mediumSource.IsStale()) return true;
    return false;
}

void HdVolPhoton_SceneRegistry::RefreshTimeVaryingMedia() {
    std::lock_guard<std::mutex> lock(_mutex);
    for (auto &[id, rec] : _meshes)
        if (rec.mediumSource.IsStale()) {
            auto medium = HdVolPhoton_RereadMedium(rec.mediumSource);
            rec.hasMedium = medium.has_value();
            if (medium) rec.medium = *medium;
        }
    for (auto &[id, rec] : _volumes)
        if (rec.mediumSource.IsStale())
            rec.medium = HdVolPhoton_RereadMedium(rec.mediumSource).value_or(volphoton::translate::MediumParams());
}

size_t HdVolPhoton_SceneRegistry::GetMeshCount() const {
    std::lock_guard<std::mutex> lock(_mutex);
    return _meshes.size();
}
size_t HdVolPhoton_SceneRegistry::GetVolumeCount() const {
    std::lock_guard<std::mutex> lock(_mutex);
    return _volumes.size();
}
size_t HdVolPhoton_SceneRegistry::GetLightCount() const {
    std::lock_guard<std::mutex> lock(_mutex);
    return _lights.size();
}

MediumPtr HdVolPhoton_SceneRegistry::_GridMedium(SdfPath const &id, HdVolPhoton_VolumeRecord const &rec,
                                                std::uint64_t maxGridVoxels, translate::Diagnostics &diagnostics) const {
    // The synced field Bprims as the translation layer reads them (core/translate/volume.h has the rules).
    std::vector<translate::GridFieldInput> fields;
    std::string densityPrim;
    for (auto const &[slot, fieldId] : rec.fields) {
        auto f = _fields.find(fieldId);
        if (f != _fields.end()) {
            fields.push_back({slot, f->second.primPath, f->second.filePath, f->second.fieldName, f->second.fieldIndex});
            if (slot == "density") densityPrim = f->second.primPath;
        } else if (slot == "density") {
            diagnostics.error(id.GetString(), "field:density", "the density field prim was not synced; volume skipped");
        }
    }
    std::optional<GridMediumDesc> g =
        translate::gridMediumFromFields(id.GetString(), rec.medium, rec.objectToWorld, fields, maxGridVoxels, diagnostics);
    if (!g) return nullptr;
    // Grids are cached across rebuilds by everything that shapes them: every medium parameter
    // (translate::mediumKey), the file, the grids, the cap and the transform.
    std::ostringstream key;
    key.precision(17);
    key << translate::mediumKey(rec.medium) << '|' << g->filePath << '|' << g->densityGrid << '|' << g->temperatureGrid
        << '|' << g->emissionGrid << '|' << g->albedoGrid << '|' << g->maxActiveVoxels << '|';
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) key << g->objectToWorld.m[r][c] << ',';
    auto cached = _gridCache.find(key.str());
    if (cached != _gridCache.end()) return cached->second;
    MediumPtr medium = translate::loadGridMediumReported(id.GetString(), densityPrim, *g, diagnostics);
    if (medium) _gridCache[key.str()] = medium;
    return medium;
}

SceneDesc HdVolPhoton_SceneRegistry::BuildSceneDesc(CameraDesc const &camera, std::uint64_t maxGridVoxels) const {
    std::lock_guard<std::mutex> lock(_mutex);
    SceneDesc d;
    d.camera = camera;
    for (auto const &[id, rec] : _meshes) {
        if (rec.instances.empty()) continue;
        // The mesh's own faces, then one part per material-bound GeomSubset (media ignore subsets).
        std::vector<std::pair<SdfPath, MeshDesc>> parts{{rec.materialId, rec.mesh}};
        for (HdVolPhoton_SubsetRecord const &subset : rec.subsets) {
            if (rec.hasMedium) {
                MeshDesc &whole = parts[0].second;
                whole.indices.insert(whole.indices.end(), subset.indices.begin(), subset.indices.end());
                whole.triangleElements.insert(whole.triangleElements.end(), subset.faces.begin(), subset.faces.end());
                continue;
            }
            MeshDesc part = rec.mesh;
            part.name = id.GetString() + ":" + subset.materialId.GetName();
            part.indices = subset.indices;
            part.triangleElements = subset.faces;
            parts.push_back({subset.materialId, std::move(part)});
        }
        for (auto &[materialId, mesh] : parts) {
            if (mesh.indices.empty()) continue;
            if (!rec.hasMedium && !materialId.IsEmpty()) {
                auto m = _materials.find(materialId);
                if (m != _materials.end() && m->second.valid) {
                    if (!m->second.material) continue;  // cut out or fully transparent: not rendered
                    mesh.material = *m->second.material;
                }
            }
            if (rec.meshLight) mesh.material = translate::meshLightSurface(*rec.meshLight, mesh.material);
            if (rec.hasMedium) {
                // The medium lives in the space of the first instance (media are not instanced).
                translate::Diagnostics diagnostics;
                MediumPtr medium = translate::buildProceduralMedium(rec.medium, rec.instances[0], /*useBounds=*/false, diagnostics);
                HdVolPhoton_Report(diagnostics);
                if (medium) {
                    d.media.push_back(medium);
                    mesh.interiorMedium = static_cast<int>(d.media.size()) - 1;
                    mesh.material.kind = rec.medium.ior > 1.0 ? SurfaceMaterial::Kind::Dielectric : SurfaceMaterial::Kind::Boundary;
                    mesh.material.ior = rec.medium.ior;
                }
            }
            d.meshes.push_back(std::move(mesh));
            int index = static_cast<int>(d.meshes.size()) - 1;
            // The ids hdEmbree reports: the rprim's prim id and the instance's index (0 when not instanced).
            for (size_t i = 0; i < rec.instances.size(); ++i)
                d.instances.push_back({index, rec.instances[i], rec.primId, static_cast<int>(i)});
        }
    }
    for (auto const &[id, rec] : _volumes) {
        translate::MediumParams const &p = rec.medium;
        translate::Diagnostics diagnostics;
        MediumPtr medium;
        if (p.densityMode == "field") {
            medium = _GridMedium(id, rec, maxGridVoxels, diagnostics);
        } else {
            medium = translate::buildProceduralMedium(p, rec.objectToWorld, /*useBounds=*/true, diagnostics);
        }
        HdVolPhoton_Report(diagnostics);
        if (!medium) continue;
        d.media.push_back(medium);
        d.unboundedMedia.push_back(static_cast<int>(d.media.size()) - 1);
    }
    for (auto const &[id, light] : _lights) d.lights.push_back(light);
    return d;
}

PXR_NAMESPACE_CLOSE_SCOPE
