#include "hd/sceneRegistry.h"

#include "pxr/base/tf/diagnostic.h"

#include "core/exponentialMedium.h"
#include "core/gridMedium.h"
#include "core/vdbGuard.h"

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

namespace {

Bounds3 _WorldBox(std::pair<GfVec3f, GfVec3f> const &b, Affine const &xf) {
    Bounds3 out;
    for (int c = 0; c < 8; ++c) {
        Vec3 p(c & 1 ? b.second[0] : b.first[0], c & 2 ? b.second[1] : b.first[1], c & 4 ? b.second[2] : b.first[2]);
        out.extend(xf.point(p));
    }
    return out;
}

/// A procedural medium (constant or exponential) for prim `id`, in world space.
MediumPtr _ProceduralMedium(HdVolPhoton_MediumParams const &p, Affine const &xf, Bounds3 const &bounds, SdfPath const &id) {
    MediumCoefficients c = HdVolPhoton_BuildCoefficients(p, id);
    if (p.densityMode == TfToken("exponential")) {
        GfVec3f up = p.expUp ? *p.expUp : GfVec3f(0, 1, 0);
        Vec3 worldUp = xf.vector(Vec3(up[0], up[1], up[2]));
        Vec3 origin = xf.point(Vec3(p.expOrigin[0], p.expOrigin[1], p.expOrigin[2]));
        return std::make_shared<ExponentialMedium>(c, p.expA, p.expB, origin, worldUp, bounds);
    }
    if (!p.densityMode.IsEmpty() && p.densityMode != TfToken("constant") && p.densityMode != TfToken("field"))
        TF_WARN("%s.volphoton:densityMode: unknown mode '%s'; using constant", id.GetText(), p.densityMode.GetText());
    return std::make_shared<HomogeneousMedium>(c, bounds);
}

}  // namespace

SceneDesc HdVolPhoton_SceneRegistry::BuildSceneDesc(CameraDesc const &camera) const {
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
            if (rec.hasMedium) {
                try {
                    // The medium lives in the space of the first instance (media are not instanced).
                    d.media.push_back(_ProceduralMedium(rec.medium, rec.instances[0], infiniteBounds(), id));
                    mesh.interiorMedium = static_cast<int>(d.media.size()) - 1;
                    mesh.material.kind = rec.medium.ior > 1.0f ? SurfaceMaterial::Kind::Dielectric : SurfaceMaterial::Kind::Boundary;
                    mesh.material.ior = rec.medium.ior;
                } catch (std::exception const &e) {
                    TF_WARN("%s: medium ignored: %s", id.GetText(), e.what());
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
        HdVolPhoton_MediumParams const &p = rec.medium;
        bool hasDensityField = rec.fields.count("density") > 0;
        TfToken mode = p.densityMode.IsEmpty() ? TfToken(hasDensityField ? "field" : "constant") : p.densityMode;
        try {
            MediumPtr medium;
            if (mode == TfToken("field")) {
                if (!hasDensityField) {
                    TF_WARN("%s.volphoton:densityMode: 'field' but no density field is bound; volume skipped", id.GetText());
                    continue;
                }
                auto fieldRecord = [&](char const *name) -> HdVolPhoton_FieldRecord const * {
                    auto it = rec.fields.find(name);
                    if (it == rec.fields.end()) return nullptr;
                    auto f = _fields.find(it->second);
                    return f == _fields.end() ? nullptr : &f->second;
                };
                HdVolPhoton_FieldRecord const *density = fieldRecord("density");
                if (!density) {
                    TF_WARN("%s: the density field prim %s was not synced; volume skipped", id.GetText(),
                            rec.fields.at("density").GetText());
                    continue;
                }
                GridMediumDesc g;
                g.filePath = density->filePath;
                g.densityGrid = density->fieldName.empty() ? "density" : density->fieldName;
                for (auto [slot, target] : {std::pair<char const *, std::string *>{"temperature", &g.temperatureGrid},
                                            {"emission", &g.emissionGrid}, {"albedo", &g.albedoGrid}}) {
                    if (HdVolPhoton_FieldRecord const *f = fieldRecord(slot)) {
                        if (f->filePath != density->filePath)
                            TF_WARN("%s: field '%s' is in another file than the density; ignored", id.GetText(), slot);
                        else *target = f->fieldName;
                    }
                }
                g.densityScale = p.density;
                g.extinctionColor = {p.extinctionColor[0], p.extinctionColor[1], p.extinctionColor[2]};
                g.albedo = {p.albedo[0], p.albedo[1], p.albedo[2]};
                g.emission = {p.emission[0], p.emission[1], p.emission[2]};
                g.emissionScale = p.emissionScale;
                g.temperatureScale = p.temperatureScale;
                g.phase = HdVolPhoton_BuildPhase(p, id);
                g.objectToWorld = rec.objectToWorld;
                std::ostringstream key;  // grids are cached across rebuilds by everything that shapes them
                key << id << '|' << g.filePath << '|' << g.densityGrid << '|' << g.temperatureGrid << '|' << g.emissionGrid
                    << '|' << g.albedoGrid << '|' << g.densityScale << '|' << p.albedo << '|' << p.extinctionColor << '|'
                    << p.emission << '|' << g.emissionScale << '|' << g.temperatureScale << '|' << p.phase << p.g << '|';
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 4; ++c) key << g.objectToWorld.m[r][c] << ',';
                auto cached = _gridCache.find(key.str());
                if (cached != _gridCache.end()) {
                    medium = cached->second;
                } else {
                    // The reader guard (core/vdbGuard.h): a file that would crash or hang the reader
                    // is probed in a separate process and skipped here, not loaded into the host.
                    if (std::optional<std::string> problem = vdbCrashCheck(g)) {
                        TF_WARN("%s.filePath: field:density of %s (file %s): %s; volume skipped",
                                rec.fields.at("density").GetText(), id.GetText(), g.filePath.c_str(), problem->c_str());
                        continue;
                    }
                    medium = loadGridMedium(g);
                    _gridCache[key.str()] = medium;
                }
            } else {
                Bounds3 bounds = p.bounds ? _WorldBox(*p.bounds, rec.objectToWorld) : infiniteBounds();
                medium = _ProceduralMedium(p, rec.objectToWorld, bounds, id);
            }
            d.media.push_back(medium);
            d.unboundedMedia.push_back(static_cast<int>(d.media.size()) - 1);
        } catch (std::exception const &e) {
            TF_WARN("%s: volume skipped: %s", id.GetText(), e.what());
        }
    }
    for (auto const &[id, light] : _lights) d.lights.push_back(light);
    return d;
}

PXR_NAMESPACE_CLOSE_SCOPE
