#include "hd/renderer.h"

#include "pxr/base/tf/diagnostic.h"
#include "pxr/base/tf/getenv.h"
#include "pxr/base/vt/array.h"
#include "pxr/base/vt/types.h"
#include "pxr/imaging/hd/tokens.h"

#include "core/photonCache.h"
#include "hd/renderBuffer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

PXR_NAMESPACE_OPEN_SCOPE

using namespace volphoton;

void HdVolPhoton_Renderer::SetScene(std::shared_ptr<Scene const> scene, RenderSettings const &settings,
                                    GfMatrix4d const &projection, HdRenderPassAovBindingVector const &aovBindings,
                                    bool interactive, bool keepPhotons, bool photonsUnseen) {
    _scene = std::move(scene);
    _photonsUnseen = photonsUnseen;
    if (!keepPhotons || !_photonCache) _photonCache = std::make_shared<PhotonCache>();
    _settings = settings;
    _projection = projection;
    _aovBindings = aovBindings;
    _interactive = interactive;
    std::lock_guard<std::mutex> lock(_statsMutex);
    _stats = RenderStats();
    _converged = false;
    _framesWritten = _previewBlock = _estimatedPasses = 0;
    _previewEnabled = TfGetenvBool("HDVOLPHOTON_PREVIEW", true);  // debug knob, read per restart
}

bool HdVolPhoton_Renderer::IsConverged() const {
    std::lock_guard<std::mutex> lock(_statsMutex);
    return _converged;
}

VtDictionary HdVolPhoton_Renderer::GetStats() const {
    std::lock_guard<std::mutex> lock(_statsMutex);
    VtDictionary d;
    d["passes"] = VtValue(_stats.passes);
    d["samplesPerPixel"] = VtValue(_stats.passes);
    d["numCompletedSamples"] = VtValue(_stats.passes);  // shown by usdview's HUD (GPU stats)
    d["cameraSamples"] = VtValue(static_cast<uint64_t>(_stats.cameraSamples));
    d["photonsTraced"] = VtValue(static_cast<uint64_t>(_stats.photonsTraced));
    d["photonsStored"] = VtValue(static_cast<uint64_t>(_stats.photonsStored));
    d["photonRadius"] = VtValue(_stats.photonRadius);
    d["photonsPerPass"] = VtValue(_stats.photonsPerPass);
    d["photonsPerPassResized"] = VtValue(_stats.photonsPerPassResized);
    d["measuredPhotonCost"] = VtValue(_stats.measuredPhotonCost);
    d["measuredPathTracerCost"] = VtValue(_stats.measuredPathTracerCost);
    d["photonPassesReused"] = VtValue(_stats.photonPassesReused);
    d["photonsReused"] = VtValue(static_cast<uint64_t>(_stats.photonsReused));
    d["totalSeconds"] = VtValue(_stats.seconds);
    d["photonSeconds"] = VtValue(_stats.photonSeconds);
    d["cameraSeconds"] = VtValue(_stats.cameraSeconds);
    d["passesRun"] = VtValue(VtStringArray(_stats.passesRun.begin(), _stats.passesRun.end()));
    VtStringArray skipped(_stats.passesSkipped.begin(), _stats.passesSkipped.end());
    if (_photonsUnseen)
        for (std::string &s : skipped)
            if (s == "multiple scattering (photons): disabled by settings")
                s = "multiple scattering (photons): no bound AOV shows it (color, multiple, surface)";
    d["passesSkipped"] = VtValue(skipped);
    d["integratorUsed"] = VtValue(_stats.integratorUsed);
    d["integratorReason"] = VtValue(_stats.integratorReason);
    d["framesWritten"] = VtValue(_framesWritten);
    d["previewBlock"] = VtValue(_previewBlock);
    d["activePixels"] = VtValue(static_cast<uint64_t>(_stats.activePixels));
    d["medianRelativeError"] = VtValue(_stats.medianRelativeError);
    d["stopReason"] = VtValue(_stats.stopReason);
    if (!_interactive || _settings.progressive())
        d["percentDone"] = VtValue(_converged ? 100.0 : _estimatedPasses > 0 ? 100.0 * _stats.passes / _estimatedPasses : 0.0);
    return d;
}

void HdVolPhoton_Renderer::Render(HdRenderThread *thread) {
    if (!_scene) return;
    std::unique_ptr<Renderer> renderer;
    try {
        renderer = std::make_unique<Renderer>(_scene, _settings, _photonCache);
    } catch (std::exception const &e) {
        TF_WARN("hdVolPhoton: cannot render: %s", e.what());
        return;
    }
    auto cancel = [thread]() { return thread->IsStopRequested(); };
    auto waitWhilePaused = [thread]() {
        while (thread->IsPauseRequested() && !thread->IsStopRequested())
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
    };
    if (int block = _PreviewBlock(); block > 1) {
        waitWhilePaused();
        Film preview(_settings.width, _settings.height);
        if (!renderer->renderPreview(block, preview, cancel)) return;
        {
            std::lock_guard<std::mutex> lock(_statsMutex);
            _previewBlock = block;
            ++_framesWritten;
        }
        auto fb = thread->LockFramebuffer();
        _WriteAovs(preview, /*converged=*/false);
    }
    // A batch render ends where the core's stopping rule says (samplesPerPixel, or the noise target,
    // time limit or sample cap); an interactive one too when a noise target or time limit is set,
    // otherwise it goes on until stopped.
    bool const stops = !_interactive || _settings.progressive();
    bool complete = stops && renderer->finished();
    while (!complete) {
        waitWhilePaused();
        double before = renderer->stats().seconds;
        if (!renderer->renderPass(cancel)) break;
        _lastPassSeconds = renderer->stats().seconds - before;
        complete = stops && renderer->finished();
        {
            std::lock_guard<std::mutex> lock(_statsMutex);
            _stats = renderer->stats();
            _estimatedPasses = renderer->estimatedPasses();
            ++_framesWritten;
        }
        auto fb = thread->LockFramebuffer();
        _WriteAovs(renderer->film(), complete);
    }
    // Converged only once every pass is written and the core renderer (and its worker threads' work)
    // is gone: a host such as usdrecord writes the image and exits as soon as it hears it. (The flag
    // used to be raised before the last pass was written, so the host could read the pass before
    // it and exit while this thread was still writing.)
    renderer.reset();
    if (complete) {
        std::lock_guard<std::mutex> lock(_statsMutex);
        _converged = true;
    }
}

int HdVolPhoton_Renderer::_PreviewBlock() const {
    // Unknown cost (the first render): a 4 x 4 block. Otherwise about PreviewTargetSeconds, as the
    // preview costs a pass / block^2; a fast pass needs no preview (it would only flash blocks).
    if (!_previewEnabled) return 1;
    int block = 4;
    if (_lastPassSeconds >= 0) {
        if (_lastPassSeconds < PreviewAfterSeconds) return 1;
        block = std::clamp(static_cast<int>(std::ceil(std::sqrt(_lastPassSeconds / PreviewTargetSeconds))), 2, 8);
    }
    // Too small an image for blocks to help.
    return std::min(_settings.width, _settings.height) >= 4 * block ? block : 1;
}

void HdVolPhoton_Renderer::_WriteAovs(Film const &film, bool converged) {
    for (HdRenderPassAovBinding const &b : _aovBindings) {
        auto *buffer = static_cast<HdVolPhotonRenderBuffer *>(b.renderBuffer);
        if (!buffer || buffer->GetWidth() != static_cast<unsigned>(film.width()) ||
            buffer->GetHeight() != static_cast<unsigned>(film.height()))
            continue;
        TfToken const &name = b.aovName;
        if (name == HdAovTokens->color) {
            std::vector<float> alpha = film.resolveAlpha();
            buffer->WriteFloats(film.resolveRgb(Film::Beauty), 3, 1.0f, &alpha);
        } else if (name == HdAovTokens->depth) {
            // Hydra wants depth in [0, 1] after the projection; the core stores the ray distance t.
            std::vector<float> t = film.resolveDepth(), depth(t.size(), 1.0f);
            bool perspective = _projection[3][3] == 0.0;
            for (int y = 0; y < film.height(); ++y)
                for (int x = 0; x < film.width(); ++x) {
                    size_t i = static_cast<size_t>(y) * film.width() + x;
                    if (!std::isfinite(t[i])) continue;
                    double sx = (2.0 * (x + 0.5) / film.width() - 1.0) / _projection[0][0];
                    double sy = (1.0 - 2.0 * (y + 0.5) / film.height()) / _projection[1][1];
                    double z = perspective ? -t[i] / std::sqrt(1 + sx * sx + sy * sy) : -t[i];
                    double clipZ = _projection[2][2] * z + _projection[3][2], clipW = _projection[2][3] * z + _projection[3][3];
                    depth[i] = static_cast<float>(std::clamp(0.5 * (clipZ / clipW) + 0.5, 0.0, 1.0));
                }
            buffer->WriteFloats(depth, 1);
        } else if (name == HdAovTokens->primId) {
            // What the pixel-centre ray met first (Renderer::pixelIds): the rprim's prim id, its
            // instance index and authored face, as hdEmbree reports them; -1 where it met nothing.
            buffer->WriteInts(film.resolveIds(Film::ObjectId));
        } else if (name == HdAovTokens->instanceId) {
            buffer->WriteInts(film.resolveIds(Film::InstanceId));
        } else if (name == HdAovTokens->elementId) {
            buffer->WriteInts(film.resolveIds(Film::ElementId));
        } else {
            static const std::pair<char const *, Film::Aov> split[] = {
                {"single", Film::Single}, {"multiple", Film::Multiple}, {"emission", Film::Emission}, {"surface", Film::Surface},
                {"albedo", Film::Albedo}, {"normal", Film::Normal}};
            for (auto const &[aov, which] : split)
                if (name == aov) buffer->WriteFloats(film.resolveRgb(which), 3);
        }
        buffer->SetConverged(converged);
    }
}

PXR_NAMESPACE_CLOSE_SCOPE
