#include "hd/renderPass.h"

#include "pxr/base/tf/diagnostic.h"
#include "pxr/imaging/hd/camera.h"
#include "pxr/imaging/hd/renderPassState.h"

#include "hd/conversions.h"
#include "hd/renderDelegate.h"
#include "hd/renderParam.h"
#include "hd/renderBuffer.h"
#include "hd/renderer.h"

PXR_NAMESPACE_OPEN_SCOPE

HdVolPhotonRenderPass::HdVolPhotonRenderPass(HdRenderIndex *index, HdRprimCollection const &collection,
                                             HdVolPhotonRenderDelegate *delegate, HdRenderThread *renderThread,
                                             HdVolPhoton_Renderer *renderer, std::atomic<int> *sceneVersion)
    : HdRenderPass(index, collection), _delegate(delegate), _renderThread(renderThread), _renderer(renderer),
      _sceneVersion(sceneVersion) {}

HdVolPhotonRenderPass::~HdVolPhotonRenderPass() { _renderThread->StopRender(); }

bool HdVolPhotonRenderPass::IsConverged() const { return _started && _renderer->IsConverged(); }

void HdVolPhotonRenderPass::_Execute(HdRenderPassStateSharedPtr const &state, TfTokenVector const &) {
    HdCamera const *camera = state->GetCamera();
    if (!camera) return;
    CameraUtilFraming const &framing = state->GetFraming();
    int width, height;
    if (framing.IsValid()) {
        width = framing.dataWindow.GetWidth();
        height = framing.dataWindow.GetHeight();
    } else {
        GfVec4f vp = state->GetViewport();
        width = static_cast<int>(vp[2]);
        height = static_cast<int>(vp[3]);
    }
    if (width <= 0 || height <= 0) return;
    GfMatrix4d view = state->GetWorldToViewMatrix(), proj = state->GetProjectionMatrix();
    HdRenderPassAovBindingVector const &aovs = state->GetAovBindings();
    // Media with time-varying volphoton:* attributes follow the scene delegate's time (UsdImaging
    // does not re-sync them): re-read them through the edit gate, which restarts the render.
    auto *renderParam = static_cast<HdVolPhotonRenderParam *>(_delegate->GetRenderParam());
    if (renderParam->GetRegistry().HasStaleMedia()) renderParam->AcquireSceneForEdit().RefreshTimeVaryingMedia();
    int version = _sceneVersion->load();
    unsigned int settingsVersion = _delegate->GetRenderSettingsVersion();
    bool aovsChanged = aovs.size() != _aovBindings.size();
    for (size_t i = 0; !aovsChanged && i < aovs.size(); ++i)
        aovsChanged = aovs[i].aovName != _aovBindings[i].aovName || aovs[i].renderBuffer != _aovBindings[i].renderBuffer;
    if (_started && version == _lastSceneVersion && settingsVersion == _lastSettingsVersion && view == _viewMatrix &&
        proj == _projMatrix && width == _width && height == _height && !aovsChanged)
        return;

    _renderThread->StopRender();
    // Photons see neither the camera nor the image: a restart for those keeps the photon maps. So does
    // a settings change: the maps are keyed by the settings photons depend on and by pilot photons
    // (PhotonCache::use, PhotonMapper's photonKey), so switching photonMap <-> combined reuses them and
    // a changed photon setting traces them again.
    bool const keepPhotons = _started && version == _lastSceneVersion;
    _lastSceneVersion = version;
    _lastSettingsVersion = settingsVersion;
    _viewMatrix = view;
    _projMatrix = proj;
    _width = width;
    _height = height;
    _aovBindings = aovs;

    volphoton::CameraDesc cam;
    cam.cameraToWorld = HdVolPhoton_ToAffine(view.GetInverse());
    bool perspective = proj[3][3] == 0.0;
    if (perspective) {
        cam.projection = volphoton::CameraDesc::Projection::Perspective;
        cam.tanHalfFovX = 1.0 / proj[0][0];
        float fStop = camera->GetFStop(), focus = camera->GetFocusDistance();
        if (fStop > 0 && focus > 0) {
            cam.lensRadius = camera->GetFocalLength() / (2.0 * fStop);
            cam.focusDistance = focus;
        }
    } else {
        cam.projection = volphoton::CameraDesc::Projection::Orthographic;
        cam.orthoWidth = 2.0 / proj[0][0];
    }
    GfRange1f clip = camera->GetClippingRange();
    cam.nearClip = std::max(0.0f, clip.GetMin());
    cam.farClip = clip.GetMax() > clip.GetMin() ? clip.GetMax() : volphoton::Infinity;

    auto *param = static_cast<HdVolPhotonRenderParam *>(_delegate->GetRenderParam());
    volphoton::RenderSettings settings = _delegate->GetCoreSettings();
    std::shared_ptr<volphoton::Scene const> scene;
    try {
        scene = std::make_shared<volphoton::Scene>(param->GetRegistry().BuildSceneDesc(cam, settings.maxGridVoxels));
    } catch (std::exception const &e) {
        TF_WARN("hdVolPhoton: the scene cannot be built: %s", e.what());
        return;
    }
    settings.width = width;
    settings.height = height;
    // The denoiser guides cost a ray per sample: traced only when an albedo or normal AOV is bound.
    for (HdRenderPassAovBinding const &b : aovs)
        if (b.aovName == "albedo" || b.aovName == HdAovTokens->normal) settings.guideAovs = true;
    // Photons feed only the AOVs holding multiply scattered light (the beauty, multiple, surface): with
    // none of them bound (a depth or id pass), no photon pass runs.
    bool photonsShown = aovs.empty();
    for (HdRenderPassAovBinding const &b : aovs)
        photonsShown |= b.aovName == HdAovTokens->color || b.aovName == "multiple" || b.aovName == "surface";
    bool const photonsUnseen = !photonsShown && settings.multipleScattering;
    if (photonsUnseen) settings.multipleScattering = false;
    for (HdRenderPassAovBinding const &b : aovs)
        if (b.renderBuffer) {
            auto *buffer = static_cast<HdVolPhotonRenderBuffer *>(b.renderBuffer);
            if (buffer->GetWidth() != static_cast<unsigned>(width) || buffer->GetHeight() != static_cast<unsigned>(height))
                buffer->Allocate(GfVec3i(width, height, 1), buffer->GetFormat(), false);
            buffer->SetConverged(false);
        }
    _renderer->SetScene(scene, settings, proj, aovs, _delegate->IsInteractive(), keepPhotons, photonsUnseen);
    _renderThread->StartRender();
    _started = true;
}

PXR_NAMESPACE_CLOSE_SCOPE
