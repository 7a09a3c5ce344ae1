// hdVolPhoton: the renderer plug-in (display name "VolPhoton").
#ifndef HDVOLPHOTON_RENDERER_PLUGIN_H
#define HDVOLPHOTON_RENDERER_PLUGIN_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/rendererPlugin.h"

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonRendererPlugin
///
/// Registered with HdRendererPluginRegistry; usdview and usdrecord find it by the display name
/// "VolPhoton" in plugInfo.json and create HdVolPhotonRenderDelegate through it.
class HdVolPhotonRendererPlugin final : public HdRendererPlugin
{
public:
    HdVolPhotonRendererPlugin() = default;
    ~HdVolPhotonRendererPlugin() override = default;
    HdRenderDelegate *CreateRenderDelegate() override;
    HdRenderDelegate *CreateRenderDelegate(HdRenderSettingsMap const &settingsMap) override;
    void DeleteRenderDelegate(HdRenderDelegate *renderDelegate) override;
    bool IsSupported(bool gpuEnabled = true) const override { return true; }
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_RENDERER_PLUGIN_H
