// hdVolPhoton: the render-thread driver between Hydra and the core renderer.
#ifndef HDVOLPHOTON_RENDERER_H
#define HDVOLPHOTON_RENDERER_H

#include "pxr/pxr.h"
#include "pxr/base/gf/matrix4d.h"
#include "pxr/base/vt/dictionary.h"
#include "pxr/imaging/hd/aov.h"
#include "pxr/imaging/hd/renderThread.h"

#include "core/integrator.h"

#include <memory>
#include <mutex>

PXR_NAMESPACE_OPEN_SCOPE

/// \class HdVolPhoton_Renderer
///
/// Not a Hydra prim: the render pass hands it a built core scene, settings, the camera's
/// projection (for the depth AOV) and the AOV bindings while the render thread is stopped; the
/// render thread then calls Render(), which runs core passes until samplesPerPixel is reached or a
/// stop is requested, writing resolved AOVs into the bound render buffers after every pass under
/// the framebuffer lock. Pausing is honoured between passes.
class HdVolPhoton_Renderer
{
public:
    void SetScene(std::shared_ptr<volphoton::Scene const> scene, volphoton::RenderSettings const &settings,
                  GfMatrix4d const &projection, HdRenderPassAovBindingVector const &aovBindings);
    void Render(HdRenderThread *renderThread);
    bool IsConverged() const;
    VtDictionary GetStats() const;

private:
    void _WriteAovs(volphoton::Film const &film);

    std::shared_ptr<volphoton::Scene const> _scene;
    volphoton::RenderSettings _settings;
    GfMatrix4d _projection{1.0};
    HdRenderPassAovBindingVector _aovBindings;
    mutable std::mutex _statsMutex;
    volphoton::RenderStats _stats;
    bool _converged = false;
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_RENDERER_H
