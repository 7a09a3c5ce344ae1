// hdVolPhoton: the render pass.
#ifndef HDVOLPHOTON_RENDER_PASS_H
#define HDVOLPHOTON_RENDER_PASS_H

#include "pxr/pxr.h"
#include "pxr/base/gf/matrix4d.h"
#include "pxr/imaging/hd/renderPass.h"
#include "pxr/imaging/hd/renderThread.h"

#include <atomic>

PXR_NAMESPACE_OPEN_SCOPE

class HdVolPhotonRenderDelegate;
class HdVolPhoton_Renderer;

/// \class HdVolPhotonRenderPass
///
/// Only detects change and restarts (hdEmbree's pattern): on every Execute it compares the camera
/// matrices, image size, AOV bindings, scene version and render-settings version with those of the
/// running render; when any differs it stops the render thread, rebuilds the core scene from the
/// scene registry, hands it to the renderer driver and starts rendering again.
class HdVolPhotonRenderPass final : public HdRenderPass
{
public:
    HdVolPhotonRenderPass(HdRenderIndex *index, HdRprimCollection const &collection, HdVolPhotonRenderDelegate *delegate,
                          HdRenderThread *renderThread, HdVolPhoton_Renderer *renderer, std::atomic<int> *sceneVersion);
    ~HdVolPhotonRenderPass() override;

    bool IsConverged() const override;

protected:
    void _Execute(HdRenderPassStateSharedPtr const &renderPassState, TfTokenVector const &renderTags) override;

private:
    HdVolPhotonRenderDelegate *_delegate;
    HdRenderThread *_renderThread;
    HdVolPhoton_Renderer *_renderer;
    std::atomic<int> *_sceneVersion;
    int _lastSceneVersion = -1;
    unsigned int _lastSettingsVersion = ~0u;
    GfMatrix4d _viewMatrix{0.0}, _projMatrix{0.0};
    int _width = 0, _height = 0;
    HdRenderPassAovBindingVector _aovBindings;
    bool _started = false;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_RENDER_PASS_H
