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
/// render thread then calls Render(), which runs core passes until a stop is requested or, in a
/// batch render, samplesPerPixel is reached, writing resolved AOVs into the bound render buffers
/// after every pass under the framebuffer lock. Pausing is honoured between passes.
///
/// Batch or interactive (HdVolPhotonRenderDelegate::IsInteractive, enableInteractive): a batch
/// render (usdrecord) stops where the core's stopping rule says (volphoton::Renderer::finished():
/// samplesPerPixel passes, or with volphoton:noiseTarget / volphoton:timeLimit the noise target met
/// everywhere, the time limit or maxSamplesPerPixel) and then reports converged; an interactive one
/// (usdview) does the same when a noise target or time limit is set, and otherwise keeps adding
/// passes until it is stopped or restarted and never reports converged, so the viewer keeps drawing.
/// Stats: numCompletedSamples (usdview's HUD key) = passes; activePixels, medianRelativeError,
/// stopReason (RenderStats); percentDone where the render has an end.
///
/// Interactive restarts: before the first pass, when the last full pass took longer than
/// PreviewAfterSeconds (or no pass was timed yet), a coarse preview (volphoton::Renderer::renderPreview:
/// one path-traced sample per block x block pixels, the block chosen so the preview costs about
/// PreviewTargetSeconds) is written to the buffers. It is not part of the accumulation: the first
/// full pass overwrites it and the converged image is the same as without it (usdrecord's final
/// image never shows it). Stats: framesWritten counts buffer updates since the restart, previewBlock
/// is the block of the preview shown (0: none). HDVOLPHOTON_PREVIEW=0 (debug knob) turns previews off.
///
/// Photon maps (the photon-map integrator) survive restarts that change only what photons do not see:
/// the camera, the image size, the AOVs (SetScene's keepPhotons). One volphoton::PhotonCache is kept
/// until the scene or the render settings change; each restart's photon passes are taken from it
/// while it has them (bit-identical to tracing them again). Stats: photonPassesReused, photonsReused.
/// photonsUnseen: the render pass turned the photon pass off because no bound AOV shows multiple
/// scattering; passesSkipped says so.
class HdVolPhoton_Renderer
{
public:
    void SetScene(std::shared_ptr<volphoton::Scene const> scene, volphoton::RenderSettings const &settings,
                  GfMatrix4d const &projection, HdRenderPassAovBindingVector const &aovBindings, bool interactive,
                  bool keepPhotons, bool photonsUnseen = false);
    void Render(HdRenderThread *renderThread);
    bool IsConverged() const;
    VtDictionary GetStats() const;

    static constexpr double PreviewAfterSeconds = 0.03, PreviewTargetSeconds = 0.01;

private:
    /// Writes the film into the bound render buffers, marked converged or not.
    void _WriteAovs(volphoton::Film const &film, bool converged);
    /// Block size of the preview before the first pass; 1: no preview.
    int _PreviewBlock() const;

    std::shared_ptr<volphoton::Scene const> _scene;
    std::shared_ptr<volphoton::PhotonCache> _photonCache;  ///< photon maps of the scene content
    bool _photonsUnseen = false;
    volphoton::RenderSettings _settings;
    GfMatrix4d _projection{1.0};
    HdRenderPassAovBindingVector _aovBindings;
    mutable std::mutex _statsMutex;
    volphoton::RenderStats _stats;
    bool _converged = false;
    bool _interactive = false;  ///< passes go on past samplesPerPixel until stopped
    int _framesWritten = 0, _previewBlock = 0;
    int _estimatedPasses = 0;  ///< volphoton::Renderer::estimatedPasses() after the last pass
    bool _previewEnabled = true;
    double _lastPassSeconds = -1;  ///< render thread only; kept across restarts (-1: none timed yet)
};

PXR_NAMESPACE_CLOSE_SCOPE

#endif  // HDVOLPHOTON_RENDERER_H
