#include "hd/renderSettings.h"

#include "pxr/imaging/hd/renderDelegate.h"
#include "pxr/imaging/hd/tokens.h"

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
    static TfToken const samplesPerPixel("volphoton:samplesPerPixel"), threads("volphoton:threads");
    for (auto const &[name, value] : GetNamespacedSettings()) {
        TfToken key(name);
        if (key == samplesPerPixel) key = HdRenderSettingsTokens->convergedSamplesPerPixel;
        else if (key == threads) key = HdRenderSettingsTokens->threadLimit;
        if (_delegate->GetRenderSetting(key) != value) _delegate->SetRenderSetting(key, value);
    }
}

PXR_NAMESPACE_CLOSE_SCOPE
