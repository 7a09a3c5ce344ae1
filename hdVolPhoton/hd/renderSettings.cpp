#include "hd/renderSettings.h"

#include "pxr/imaging/hd/renderDelegate.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/base/tf/diagnostic.h"
#include "pxr/base/tf/stringUtils.h"

#include "core/translate/settings.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonRenderSettings::HdVolPhotonRenderSettings(SdfPath const &id, HdRenderDelegate *delegate,
                                                     std::atomic<bool> *sawActive)
    : HdRenderSettings(id), _delegate(delegate), _sawActive(sawActive) {}

void HdVolPhotonRenderSettings::_Sync(HdSceneDelegate *, HdRenderParam *, HdDirtyBits const *dirtyBits) {
    // OpenUSD 24.08's UsdImagingGLEngine does not mark the prim named by usdrecord's
    // --renderSettingsPrimPath active on either scene path (active stays false), so an inactive
    // prim is applied too unless one that is active has been seen.
    // XXX: with several settings prims and none active, the last one synced wins.
    if (IsActive()) *_sawActive = true;
    if ((!IsActive() && *_sawActive) || !(*dirtyBits & (DirtyActive | DirtyNamespacedSettings))) return;
    // volphoton:<name> -> the table entry's Hydra key (convergedSamplesPerPixel, threadLimit, or
    // volphoton:<name> itself); names not in the table are warned about and dropped.
    for (auto const &[name, value] : GetNamespacedSettings()) {
        std::string const &n = name;
        volphoton::translate::SettingInfo const *info =
            TfStringStartsWith(n, "volphoton:") ? volphoton::translate::findSetting(n.substr(10)) : nullptr;
        if (!info) {
            TF_WARN("hdVolPhoton: %s.%s: unknown render setting", GetId().GetText(), n.c_str());
            continue;
        }
        TfToken key(info->hydraKey);
        if (_delegate->GetRenderSetting(key) != value) _delegate->SetRenderSetting(key, value);
    }
}

PXR_NAMESPACE_CLOSE_SCOPE
