#include "hd/rendererPlugin.h"

#include "pxr/imaging/hd/rendererPluginRegistry.h"

#include "hd/renderDelegate.h"

PXR_NAMESPACE_OPEN_SCOPE

TF_REGISTRY_FUNCTION(TfType) { HdRendererPluginRegistry::Define<HdVolPhotonRendererPlugin>(); }

HdRenderDelegate *HdVolPhotonRendererPlugin::CreateRenderDelegate() { return new HdVolPhotonRenderDelegate(); }

HdRenderDelegate *HdVolPhotonRendererPlugin::CreateRenderDelegate(HdRenderSettingsMap const &settingsMap) {
    return new HdVolPhotonRenderDelegate(settingsMap);
}

void HdVolPhotonRendererPlugin::DeleteRenderDelegate(HdRenderDelegate *renderDelegate) { delete renderDelegate; }

PXR_NAMESPACE_CLOSE_SCOPE
