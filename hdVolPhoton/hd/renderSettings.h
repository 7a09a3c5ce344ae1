// hdVolPhoton: the UsdRender settings prim.
#ifndef HDVOLPHOTON_RENDER_SETTINGS_H
#define HDVOLPHOTON_RENDER_SETTINGS_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/renderSettings.h"

#include <atomic>

PXR_NAMESPACE_OPEN_SCOPE

class HdRenderDelegate;

/// \class HdVolPhotonRenderSettings
///
/// The Bprim of a UsdRenderSettings prim (usdrecord's `--renderSettingsPrimPath`, usdview's
/// active settings prim; both scene paths of OpenUSD 24.08). When it is the active one (or none is:
/// see _Sync), its
/// `volphoton:*` attributes (the namespaced settings Hydra filters with the delegate's
/// GetRenderSettingsNamespaces) become the delegate's render settings, with the same names and
/// meanings as the standalone front end reads from the same prim:
///
/// | RenderSettings attribute     | delegate setting                                  |
/// |------------------------------|---------------------------------------------------|
/// | volphoton:samplesPerPixel    | convergedSamplesPerPixel (HdRenderSettingsTokens) |
/// | volphoton:threads            | threadLimit (HdRenderSettingsTokens)              |
/// | volphoton:<other>            | volphoton:<other> (see renderDelegate.h's table)  |
///
/// SetRenderSetting bumps the delegate's settings version, so the render pass restarts.
/// Threading: Sync runs on Hydra's sync thread; it only calls SetRenderSetting.
class HdVolPhotonRenderSettings final : public HdRenderSettings
{
public:
    /// sawActive: the delegate's flag, shared by its settings prims (see _Sync).
    HdVolPhotonRenderSettings(SdfPath const &id, HdRenderDelegate *delegate, std::atomic<bool> *sawActive);

protected:
    void _Sync(HdSceneDelegate *sceneDelegate, HdRenderParam *renderParam, HdDirtyBits const *dirtyBits) override;

private:
    HdRenderDelegate *_delegate;
    std::atomic<bool> *_sawActive;  ///< an active settings prim of this delegate was synced
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_RENDER_SETTINGS_H
