#include "hd/renderDelegate.h"

#include "pxr/base/tf/diagnostic.h"
#include "pxr/imaging/hd/camera.h"
#include "pxr/imaging/hd/resourceRegistry.h"
#include "pxr/imaging/hd/tokens.h"

#include <algorithm>
#include <cmath>

#include "core/diagnostics.h"
#include "hd/field.h"
#include "hd/instancer.h"
#include "hd/light.h"
#include "hd/material.h"
#include "hd/mesh.h"
#include "hd/renderBuffer.h"
#include "hd/renderParam.h"
#include "hd/renderPass.h"
#include "hd/renderSettings.h"
#include "hd/volume.h"

PXR_NAMESPACE_OPEN_SCOPE

TF_DEFINE_PUBLIC_TOKENS(HdVolPhotonRenderSettingsTokens, HDVOLPHOTON_RENDER_SETTINGS_TOKENS);

namespace {
// The bprim type UsdVolImaging gives OpenVDBAsset prims (UsdVolImagingTokens->openvdbAsset).
TfToken const &_OpenvdbAsset() {
    static TfToken t("openvdbAsset");
    return t;
}
TfTokenVector const &_Rprims() {
    static TfTokenVector v = {HdPrimTypeTokens->mesh, HdPrimTypeTokens->volume};
    return v;
}
TfTokenVector const &_Sprims() {
    static TfTokenVector v = {HdPrimTypeTokens->camera,     HdPrimTypeTokens->distantLight, HdPrimTypeTokens->sphereLight,
                              HdPrimTypeTokens->rectLight, HdPrimTypeTokens->diskLight,    HdPrimTypeTokens->domeLight,
                              HdPrimTypeTokens->material};
    return v;
}
TfTokenVector const &_Bprims() {
    static TfTokenVector v = {HdPrimTypeTokens->renderBuffer, HdPrimTypeTokens->renderSettings, _OpenvdbAsset()};
    return v;
}
bool _IsLight(TfToken const &t) {
    return t == HdPrimTypeTokens->distantLight || t == HdPrimTypeTokens->sphereLight || t == HdPrimTypeTokens->rectLight ||
           t == HdPrimTypeTokens->diskLight || t == HdPrimTypeTokens->domeLight;
}
}  // namespace

HdVolPhotonRenderDelegate::HdVolPhotonRenderDelegate() : HdRenderDelegate() { _Initialize(); }

HdVolPhotonRenderDelegate::HdVolPhotonRenderDelegate(HdRenderSettingsMap const &settingsMap)
    : HdRenderDelegate(settingsMap) {
    _Initialize();
}

void HdVolPhotonRenderDelegate::_Initialize() {
    // Core warnings (clamped voxels, bad files) reach the user as Tf warnings.
    volphoton::setDiagnosticSink([](volphoton::Severity severity, std::string const &message) {
        if (severity == volphoton::Severity::Info) TF_STATUS("hdVolPhoton: %s", message.c_str());
        else TF_WARN("hdVolPhoton: %s", message.c_str());
    });
    _resourceRegistry = std::make_shared<HdResourceRegistry>();
    _renderParam = std::make_unique<HdVolPhotonRenderParam>(&_renderThread, &_sceneVersion);
    volphoton::RenderSettings d;
    auto add = [&](char const *name, TfToken const &key, VtValue const &value) {
        _settingDescriptors.push_back({name, key, value});
    };
    // A std::string, not a TfToken: usdview's settings dialog has no widget for a token.
    add("Integrator (pathTracer, photonMap)", HdVolPhotonRenderSettingsTokens->integrator, VtValue(HdVolPhotonRenderSettingsTokens->pathTracer.GetString()));
    add("Samples per pixel", HdRenderSettingsTokens->convergedSamplesPerPixel, VtValue(d.samplesPerPixel));
    add("Thread limit (0: all cores)", HdRenderSettingsTokens->threadLimit, VtValue(d.threads));
    add("Max depth", HdVolPhotonRenderSettingsTokens->maxDepth, VtValue(d.maxDepth));
    add("Photons per pass", HdVolPhotonRenderSettingsTokens->photonsPerPass, VtValue(d.photonsPerPass));
    add("Initial photon radius (0: auto)", HdVolPhotonRenderSettingsTokens->initialRadius, VtValue(static_cast<float>(d.initialRadius)));
    add("Single scattering pass", HdVolPhotonRenderSettingsTokens->singleScattering, VtValue(d.singleScattering));
    add("Multiple scattering pass", HdVolPhotonRenderSettingsTokens->multipleScattering, VtValue(d.multipleScattering));
    add("Seed", HdVolPhotonRenderSettingsTokens->seed, VtValue(static_cast<int>(d.seed)));
    add("Russian roulette depth", HdVolPhotonRenderSettingsTokens->rouletteDepth, VtValue(d.rouletteDepth));
    add("Stratified dimensions (0: independent)", HdVolPhotonRenderSettingsTokens->stratifiedDims, VtValue(d.stratifiedDims));
    add("Photon radius reduction (alpha)", HdVolPhotonRenderSettingsTokens->radiusAlpha, VtValue(static_cast<float>(d.radiusAlpha)));
    add("Photon radius cap (mean free paths)", HdVolPhotonRenderSettingsTokens->photonRadiusMfp, VtValue(static_cast<float>(d.photonRadiusMfp)));
    add("March step (0: auto)", HdVolPhotonRenderSettingsTokens->marchStep, VtValue(static_cast<float>(d.marchStep)));
    add("Multiple-scattering threshold", HdVolPhotonRenderSettingsTokens->multipleThreshold, VtValue(static_cast<float>(d.multipleThreshold)));
    add("Transmittance cut-off (biased)", HdVolPhotonRenderSettingsTokens->transmittanceCutoff, VtValue(static_cast<float>(d.transmittanceCutoff)));
    _PopulateDefaultSettings(_settingDescriptors);
    _renderThread.SetRenderCallback([this]() { _renderer.Render(&_renderThread); });
    _renderThread.StartThread();
}

HdVolPhotonRenderDelegate::~HdVolPhotonRenderDelegate() {
    _renderThread.StopThread();
    volphoton::setDiagnosticSink({});
}

volphoton::RenderSettings HdVolPhotonRenderDelegate::GetCoreSettings() const {
    volphoton::RenderSettings s;
    // A string (the descriptor, usdview's dialog) or a token (a RenderSettings prim's attribute).
    VtValue integratorValue = GetRenderSetting(HdVolPhotonRenderSettingsTokens->integrator);
    std::string integrator = HdVolPhotonRenderSettingsTokens->pathTracer.GetString();
    if (integratorValue.IsHolding<std::string>()) integrator = integratorValue.UncheckedGet<std::string>();
    else if (integratorValue.IsHolding<TfToken>()) integrator = integratorValue.UncheckedGet<TfToken>().GetString();
    else if (!integratorValue.IsEmpty())
        TF_WARN("hdVolPhoton: render setting %s has type %s; using pathTracer", HdVolPhotonRenderSettingsTokens->integrator.GetText(),
                integratorValue.GetTypeName().c_str());
    if (integrator == HdVolPhotonRenderSettingsTokens->photonMap.GetString()) {
        s.integrator = volphoton::RenderSettings::Integrator::PhotonMap;
    } else {
        if (integrator != HdVolPhotonRenderSettingsTokens->pathTracer.GetString())
            TF_WARN("hdVolPhoton: render setting %s = \"%s\" is neither pathTracer nor photonMap; using pathTracer",
                    HdVolPhotonRenderSettingsTokens->integrator.GetText(), integrator.c_str());
        s.integrator = volphoton::RenderSettings::Integrator::PathTracer;
    }
    s.samplesPerPixel = std::max(1, GetRenderSetting<int>(HdRenderSettingsTokens->convergedSamplesPerPixel, s.samplesPerPixel));
    s.threads = std::max(0, GetRenderSetting<int>(HdRenderSettingsTokens->threadLimit, s.threads));
    s.maxDepth = std::max(0, GetRenderSetting<int>(HdVolPhotonRenderSettingsTokens->maxDepth, s.maxDepth));
    s.photonsPerPass = std::max(0, GetRenderSetting<int>(HdVolPhotonRenderSettingsTokens->photonsPerPass, s.photonsPerPass));
    s.initialRadius = std::max(0.0f, GetRenderSetting<float>(HdVolPhotonRenderSettingsTokens->initialRadius, 0.0f));
    s.singleScattering = GetRenderSetting<bool>(HdVolPhotonRenderSettingsTokens->singleScattering, true);
    s.multipleScattering = GetRenderSetting<bool>(HdVolPhotonRenderSettingsTokens->multipleScattering, true);
    // usdrecord hides domes from the camera unless --enableDomeLightVisibility; usdview shows them.
    s.domeVisibleToCamera = GetRenderSetting<bool>(HdRenderSettingsTokens->domeLightCameraVisibility, true);
    s.seed = static_cast<uint64_t>(std::max(0, GetRenderSetting<int>(HdVolPhotonRenderSettingsTokens->seed, 0)));
    // The numeric settings below come from RenderSettings prims as whatever type was authored.
    auto number = [this](TfToken const &key, double fallback, double lo, double hi) {
        VtValue v = GetRenderSetting(key);
        double x = fallback;
        if (v.CanCast<double>()) x = v.Cast<double>().UncheckedGet<double>();  // Vt's numeric casts
        else if (!v.IsEmpty()) TF_WARN("hdVolPhoton: render setting %s has type %s; using %g", key.GetText(), v.GetTypeName().c_str(), fallback);
        if (!(x >= lo && x <= hi)) {
            double c = std::isnan(x) ? fallback : std::clamp(x, lo, hi);
            TF_WARN("hdVolPhoton: render setting %s = %g is outside [%g, %g]; using %g", key.GetText(), x, lo, hi, c);
            x = c;
        }
        return x;
    };
    constexpr double Big = 1e9;
    s.rouletteDepth = static_cast<int>(number(HdVolPhotonRenderSettingsTokens->rouletteDepth, s.rouletteDepth, 0, Big));
    s.stratifiedDims = static_cast<int>(number(HdVolPhotonRenderSettingsTokens->stratifiedDims, s.stratifiedDims, 0, 4096));
    s.radiusAlpha = number(HdVolPhotonRenderSettingsTokens->radiusAlpha, s.radiusAlpha, 1e-6, 1);
    s.photonRadiusMfp = number(HdVolPhotonRenderSettingsTokens->photonRadiusMfp, s.photonRadiusMfp, 0, Big);
    s.marchStep = number(HdVolPhotonRenderSettingsTokens->marchStep, s.marchStep, 0, Big);
    s.multipleThreshold = number(HdVolPhotonRenderSettingsTokens->multipleThreshold, s.multipleThreshold, 0, Big);
    s.transmittanceCutoff = number(HdVolPhotonRenderSettingsTokens->transmittanceCutoff, s.transmittanceCutoff, 0, 1);
    return s;
}

bool HdVolPhotonRenderDelegate::IsInteractive() const {
    return GetRenderSetting<bool>(HdRenderSettingsTokens->enableInteractive, true);
}

HdRenderParam *HdVolPhotonRenderDelegate::GetRenderParam() const { return _renderParam.get(); }
TfTokenVector const &HdVolPhotonRenderDelegate::GetSupportedRprimTypes() const { return _Rprims(); }
TfTokenVector const &HdVolPhotonRenderDelegate::GetSupportedSprimTypes() const { return _Sprims(); }
TfTokenVector const &HdVolPhotonRenderDelegate::GetSupportedBprimTypes() const { return _Bprims(); }
HdResourceRegistrySharedPtr HdVolPhotonRenderDelegate::GetResourceRegistry() const { return _resourceRegistry; }
HdRenderSettingDescriptorList HdVolPhotonRenderDelegate::GetRenderSettingDescriptors() const { return _settingDescriptors; }
TfTokenVector HdVolPhotonRenderDelegate::GetRenderSettingsNamespaces() const { return {TfToken("volphoton")}; }

VtDictionary HdVolPhotonRenderDelegate::GetRenderStats() const {
    VtDictionary stats = _renderer.GetStats();
    stats["meshes"] = VtValue(static_cast<uint64_t>(_renderParam->GetRegistry().GetMeshCount()));
    stats["volumes"] = VtValue(static_cast<uint64_t>(_renderParam->GetRegistry().GetVolumeCount()));
    stats["lights"] = VtValue(static_cast<uint64_t>(_renderParam->GetRegistry().GetLightCount()));
    stats["sceneVersion"] = VtValue(_sceneVersion.load());
    return stats;
}

bool HdVolPhotonRenderDelegate::Pause() {
    _renderThread.PauseRender();
    return true;
}
bool HdVolPhotonRenderDelegate::Resume() {
    _renderThread.ResumeRender();
    return true;
}
bool HdVolPhotonRenderDelegate::Stop(bool blocking) {
    _renderThread.StopRender();
    return true;
}
bool HdVolPhotonRenderDelegate::Restart() {
    ++_sceneVersion;  // the next Execute rebuilds and starts again
    return true;
}

HdRenderPassSharedPtr HdVolPhotonRenderDelegate::CreateRenderPass(HdRenderIndex *index, HdRprimCollection const &collection) {
    return std::make_shared<HdVolPhotonRenderPass>(index, collection, this, &_renderThread, &_renderer, &_sceneVersion);
}

HdInstancer *HdVolPhotonRenderDelegate::CreateInstancer(HdSceneDelegate *delegate, SdfPath const &id) {
    return new HdVolPhotonInstancer(delegate, id);
}
void HdVolPhotonRenderDelegate::DestroyInstancer(HdInstancer *instancer) { delete instancer; }

HdRprim *HdVolPhotonRenderDelegate::CreateRprim(TfToken const &typeId, SdfPath const &rprimId) {
    if (typeId == HdPrimTypeTokens->mesh) return new HdVolPhotonMesh(rprimId);
    if (typeId == HdPrimTypeTokens->volume) return new HdVolPhotonVolume(rprimId);
    TF_CODING_ERROR("hdVolPhoton: unknown rprim type %s", typeId.GetText());
    return nullptr;
}
void HdVolPhotonRenderDelegate::DestroyRprim(HdRprim *rPrim) { delete rPrim; }

HdSprim *HdVolPhotonRenderDelegate::CreateSprim(TfToken const &typeId, SdfPath const &sprimId) {
    if (typeId == HdPrimTypeTokens->camera) return new HdCamera(sprimId);
    if (_IsLight(typeId)) return new HdVolPhotonLight(sprimId, typeId);
    if (typeId == HdPrimTypeTokens->material) return new HdVolPhotonMaterial(sprimId);
    TF_CODING_ERROR("hdVolPhoton: unknown sprim type %s", typeId.GetText());
    return nullptr;
}
HdSprim *HdVolPhotonRenderDelegate::CreateFallbackSprim(TfToken const &typeId) {
    if (typeId == HdPrimTypeTokens->camera) return new HdCamera(SdfPath::EmptyPath());
    if (_IsLight(typeId)) return new HdVolPhotonLight(SdfPath::EmptyPath(), typeId);
    if (typeId == HdPrimTypeTokens->material) return new HdVolPhotonMaterial(SdfPath::EmptyPath());
    return nullptr;
}
void HdVolPhotonRenderDelegate::DestroySprim(HdSprim *sPrim) { delete sPrim; }

HdBprim *HdVolPhotonRenderDelegate::CreateBprim(TfToken const &typeId, SdfPath const &bprimId) {
    if (typeId == HdPrimTypeTokens->renderBuffer) return new HdVolPhotonRenderBuffer(bprimId);
    if (typeId == _OpenvdbAsset()) return new HdVolPhotonField(bprimId);
    if (typeId == HdPrimTypeTokens->renderSettings) return new HdVolPhotonRenderSettings(bprimId, this, &_sawActiveSettings);
    TF_CODING_ERROR("hdVolPhoton: unknown bprim type %s", typeId.GetText());
    return nullptr;
}
HdBprim *HdVolPhotonRenderDelegate::CreateFallbackBprim(TfToken const &typeId) {
    if (typeId == HdPrimTypeTokens->renderBuffer) return new HdVolPhotonRenderBuffer(SdfPath::EmptyPath());
    if (typeId == _OpenvdbAsset()) return new HdVolPhotonField(SdfPath::EmptyPath());
    if (typeId == HdPrimTypeTokens->renderSettings) return new HdVolPhotonRenderSettings(SdfPath::EmptyPath(), this, &_sawActiveSettings);
    return nullptr;
}
void HdVolPhotonRenderDelegate::DestroyBprim(HdBprim *bPrim) { delete bPrim; }

HdAovDescriptor HdVolPhotonRenderDelegate::GetDefaultAovDescriptor(TfToken const &name) const {
    if (name == HdAovTokens->color) return HdAovDescriptor(HdFormatFloat32Vec4, false, VtValue(GfVec4f(0.0f)));
    if (name == HdAovTokens->depth) return HdAovDescriptor(HdFormatFloat32, false, VtValue(1.0f));
    if (name == HdAovTokens->primId || name == HdAovTokens->instanceId || name == HdAovTokens->elementId)
        return HdAovDescriptor(HdFormatInt32, false, VtValue(-1));
    for (char const *split : {"single", "multiple", "emission", "surface"})
        if (name == split) return HdAovDescriptor(HdFormatFloat32Vec3, false, VtValue(GfVec3f(0.0f)));
    return HdAovDescriptor();
}

PXR_NAMESPACE_CLOSE_SCOPE
