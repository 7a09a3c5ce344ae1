#include "hd/field.h"

#include "pxr/base/tf/diagnostic.h"
#include "pxr/imaging/hd/sceneDelegate.h"
#include "pxr/usd/sdf/assetPath.h"

#include "hd/renderParam.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonField::HdVolPhotonField(SdfPath const &id) : HdField(id) {}

HdDirtyBits HdVolPhotonField::GetInitialDirtyBitsMask() const { return DirtyTransform | DirtyParams; }

void HdVolPhotonField::Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) {
    SdfPath const &id = GetId();
    HdVolPhoton_FieldRecord rec;
    rec.primPath = id.GetString();
    VtValue path = sceneDelegate->Get(id, HdFieldTokens->filePath);
    if (path.IsHolding<SdfAssetPath>()) {
        SdfAssetPath const &asset = path.UncheckedGet<SdfAssetPath>();
        rec.filePath = asset.GetResolvedPath().empty() ? asset.GetAssetPath() : asset.GetResolvedPath();
        if (asset.GetResolvedPath().empty())
            TF_WARN("%s.filePath: cannot resolve @%s@; the volumes that use it will be skipped", id.GetText(),
                    asset.GetAssetPath().c_str());
    }
    VtValue name = sceneDelegate->Get(id, HdFieldTokens->fieldName);
    if (name.IsHolding<TfToken>()) rec.fieldName = name.UncheckedGet<TfToken>().GetString();
    VtValue index = sceneDelegate->Get(id, TfToken("fieldIndex"));
    if (index.IsHolding<int>()) rec.fieldIndex = index.UncheckedGet<int>();
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().SetField(id, std::move(rec));
    *dirtyBits = Clean;
}

void HdVolPhotonField::Finalize(HdRenderParam *renderParam) {
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().Remove(GetId());
}

PXR_NAMESPACE_CLOSE_SCOPE
