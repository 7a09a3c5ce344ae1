#include "hd/volume.h"

#include "pxr/imaging/hd/sceneDelegate.h"

#include "hd/conversions.h"
#include "hd/renderParam.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonVolume::HdVolPhotonVolume(SdfPath const &id) : HdVolume(id) {}

HdDirtyBits HdVolPhotonVolume::GetInitialDirtyBitsMask() const {
    return HdChangeTracker::Clean | HdChangeTracker::InitRepr | HdChangeTracker::DirtyTransform |
           HdChangeTracker::DirtyVisibility | HdChangeTracker::DirtyPrimvar | HdChangeTracker::DirtyParams |
           HdChangeTracker::DirtyVolumeField;
}

void HdVolPhotonVolume::_InitRepr(TfToken const &reprToken, HdDirtyBits *) {
    if (std::find_if(_reprs.begin(), _reprs.end(), _ReprComparator(reprToken)) == _reprs.end())
        _reprs.emplace_back(reprToken, HdReprSharedPtr());
}

void HdVolPhotonVolume::Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits *dirtyBits,
                             TfToken const &) {
    SdfPath const &id = GetId();
    auto &registry = static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit();
    if (!sceneDelegate->GetVisible(id)) {
        registry.Remove(id);
        *dirtyBits &= ~HdChangeTracker::AllSceneDirtyBits;
        return;
    }
    HdVolPhoton_VolumeRecord rec;
    rec.objectToWorld = HdVolPhoton_ToAffine(sceneDelegate->GetTransform(id));
    if (!rec.objectToWorld.inverse()) {
        TF_WARN("%s: the transform is not invertible or not finite; volume skipped", id.GetText());
        registry.Remove(id);
        *dirtyBits &= ~HdChangeTracker::AllSceneDirtyBits;
        return;
    }
    for (HdVolumeFieldDescriptor const &f : sceneDelegate->GetVolumeFieldDescriptors(id)) {
        static const std::set<std::string> known = {"density", "temperature", "emission", "albedo"};
        if (!known.count(f.fieldName.GetString())) {
            TF_WARN("%s: field:%s is not used (hdVolPhoton reads density, temperature, emission, albedo)", id.GetText(),
                    f.fieldName.GetText());
            continue;
        }
        rec.fields[f.fieldName.GetString()] = f.fieldId;
    }
    // A Volume is always a medium (schema defaults without the API).
    rec.medium = HdVolPhoton_ReadMedium(sceneDelegate, id, /*isVolume=*/true, rec.fields.count("density") > 0,
                                        &rec.mediumSource)
                     .value_or(volphoton::translate::MediumParams());
    registry.SetVolume(id, std::move(rec));
    *dirtyBits &= ~HdChangeTracker::AllSceneDirtyBits;
}

void HdVolPhotonVolume::Finalize(HdRenderParam *renderParam) {
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().Remove(GetId());
}

PXR_NAMESPACE_CLOSE_SCOPE
