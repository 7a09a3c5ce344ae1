// hdVolPhoton: the render param, which holds the one edit gate of the delegate.
#ifndef HDVOLPHOTON_RENDER_PARAM_H
#define HDVOLPHOTON_RENDER_PARAM_H

#include "pxr/pxr.h"
#include "pxr/imaging/hd/renderDelegate.h"
#include "pxr/imaging/hd/renderThread.h"

#include "hd/sceneRegistry.h"

#include <atomic>

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhotonRenderParam
///
/// Handed to every prim's Sync and Finalize. AcquireSceneForEdit() is the one edit gate (as in
/// hdEmbree): it stops the render thread and bumps the scene version before a prim changes the
/// scene registry, so the render pass rebuilds the core scene (BVH, media, photon maps) from that
/// version instead of patching anything in place.
class HdVolPhotonRenderParam final : public HdRenderParam
{
public:
    HdVolPhotonRenderParam(HdRenderThread *renderThread, std::atomic<int> *sceneVersion)
        : _renderThread(renderThread), _sceneVersion(sceneVersion) {}

    HdVolPhoton_SceneRegistry &AcquireSceneForEdit() {
        _renderThread->StopRender();
        ++(*_sceneVersion);
        return _registry;
    }

    /// Read access for the render pass (the render thread is stopped while it builds the scene).
    HdVolPhoton_SceneRegistry const &GetRegistry() const { return _registry; }

private:
    HdRenderThread *_renderThread;
    std::atomic<int> *_sceneVersion;
    HdVolPhoton_SceneRegistry _registry;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_RENDER_PARAM_H
