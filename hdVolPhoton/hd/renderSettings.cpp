#include "hd/renderSettings.h"

#include "pxr/imaging/hd/renderDelegate.h"
#include "pxr/imaging/hd/tokens.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonRenderSettings::HdVolPhotonRenderSettings(SdfPath const &id, HdRenderDelegate *delegate)
    : HdRenderSettings(id), _delegate(delegate) {}

void HdVolPhotonRenderSettings::_Sync(HdSceneDelegate *, HdRenderParam *, HdDirtyBits const *dirtyBits) {
    if (!IsActive() || !(*dirtyBits & (DirtyActive | DirtyNamespacedSettings))) return;
    static TfToken const samplesPerPixel("volphoton:samplesPerPixel"), threads("volphoton:threads");
    for (auto const &[name, value] : GetNamespacedSettings()) {
        TfToken key(name);
        if (key == samplesPerPixel) key = HdRenderSettingsTokens->convergedSamplesPerPixel;
        else if (key == threads) key = HdRenderSettingsTokens->threadLimit;
        if (_delegate->GetRenderSetting(key) != value) _delegate->SetRenderSetting(key, value);
    }
}

PXR_NAMESPACE_CLOSE_SCOPE
