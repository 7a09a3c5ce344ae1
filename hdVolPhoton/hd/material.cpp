#include "hd/material.h"

#include "pxr/base/gf/vec3f.h"
#include "pxr/base/tf/diagnostic.h"
#include "pxr/imaging/hd/sceneDelegate.h"
#include "pxr/imaging/hd/tokens.h"

#include "core/previewSurface.h"
#include "hd/conversions.h"
#include "hd/renderParam.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonMaterial::HdVolPhotonMaterial(SdfPath const &id) : HdMaterial(id) {}

namespace {
template <typename T>
bool _Input(HdMaterialNode const &node, char const *name, T *out) {
    auto it = node.parameters.find(TfToken(name));
    if (it == node.parameters.end()) return false;
    VtValue v = it->second;
    if (!v.IsHolding<T>() && v.CanCast<T>()) v = v.Cast<T>();
    if (!v.IsHolding<T>()) return false;
    *out = v.UncheckedGet<T>();
    return true;
}
}  // namespace

void HdVolPhotonMaterial::Sync(HdSceneDelegate *sd, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) {
    SdfPath const &id = GetId();
    HdVolPhoton_MaterialRecord rec;
    VtValue resource = sd->GetMaterialResource(id);
    HdMaterialNode const *surface = nullptr;
    if (resource.IsHolding<HdMaterialNetworkMap>()) {
        HdMaterialNetworkMap const &networks = resource.UncheckedGet<HdMaterialNetworkMap>();
        auto it = networks.map.find(HdMaterialTerminalTokens->surface);
        if (it != networks.map.end())
            for (HdMaterialNode const &node : it->second.nodes)
                if (node.identifier == TfToken("UsdPreviewSurface")) surface = &node;
    }
    if (!surface) {
        TF_WARN("%s: no UsdPreviewSurface in the surface network (only UsdPreviewSurface is supported); its meshes "
                "use displayColor", id.GetText());
    } else {
        volphoton::PreviewSurfaceInputs in;
        GfVec3f color;
        if (_Input(*surface, "diffuseColor", &color)) in.diffuseColor = HdVolPhoton_ToSpectrum(color);
        if (_Input(*surface, "emissiveColor", &color)) in.emissiveColor = HdVolPhoton_ToSpectrum(color);
        float value;
        if (_Input(*surface, "opacity", &value)) in.opacity = value;
        if (_Input(*surface, "opacityThreshold", &value)) in.opacityThreshold = value;
        if (_Input(*surface, "metallic", &value)) in.metallic = value;
        in.iorAuthored = _Input(*surface, "ior", &value);
        if (in.iorAuthored) in.ior = value;
        std::vector<volphoton::PreviewSurfaceNote> notes;
        rec.material = volphoton::previewSurfaceMaterial(in, &notes);
        rec.valid = true;
        for (volphoton::PreviewSurfaceNote const &n : notes)
            TF_WARN("%s.inputs:%s: %s", surface->path.GetText(), n.input.c_str(), n.message.c_str());
    }
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().SetMaterial(id, rec);
    *dirtyBits = Clean;
}

void HdVolPhotonMaterial::Finalize(HdRenderParam *renderParam) {
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().Remove(GetId());
}

PXR_NAMESPACE_CLOSE_SCOPE
