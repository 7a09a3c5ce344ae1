#include "hd/renderDelegate.h"

#include "pxr/base/tf/diagnostic.h"
#include "pxr/imaging/hd/camera.h"
#include "pxr/imaging/hd/resourceRegistry.h"
#include "pxr/imaging/hd/tokens.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/diagnostics.h"
#include "core/translate/settings.h"
#include "hd/mediumParams.h"
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
    // One descriptor per entry of the core's settings table (core/translate/settings.h), keyed by
    // its Hydra key (HdRenderSettingsTokens where Hydra has one). Choices are strings, which
    // usdview's settings dialog shows as a text field.
    for (volphoton::translate::SettingInfo const &info : volphoton::translate::renderSettingsTable()) {
        volphoton::translate::AttrValue def = info.defaultValue();
        VtValue value;
        switch (info.type) {
        case volphoton::translate::SettingType::Bool: value = VtValue(std::get<bool>(def)); break;
        case volphoton::translate::SettingType::Int:
            value = VtValue(static_cast<int>(std::min<int64_t>(std::get<int64_t>(def), std::numeric_limits<int>::max())));
            break;
        case volphoton::translate::SettingType::Double: value = VtValue(static_cast<float>(std::get<double>(def))); break;
        case volphoton::translate::SettingType::Choice: value = VtValue(std::get<std::string>(def)); break;
        }
        _settingDescriptors.push_back({info.label, TfToken(info.hydraKey), value});
    }
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
    // Every table setting, whatever numeric type it arrived as (descriptors, usdview's dialog, a
    // RenderSettings prim), validated by the same rules as the usd-core front end's.
    volphoton::translate::Diagnostics diagnostics;
    for (volphoton::translate::SettingInfo const &info : volphoton::translate::renderSettingsTable()) {
        VtValue v = GetRenderSetting(TfToken(info.hydraKey));
        if (v.IsEmpty()) continue;
        volphoton::translate::applySetting(s, info.name, HdVolPhoton_ToAttrValue(v), diagnostics, "render settings");
    }
    HdVolPhoton_Report(diagnostics);
    // usdrecord hides domes from the camera unless --enableDomeLightVisibility; usdview shows them.
    s.domeVisibleToCamera = GetRenderSetting<bool>(HdRenderSettingsTokens->domeLightCameraVisibility, true);
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
    // The light-path split and the denoiser guides (albedo; normal is Hydra's world-space "normal").
    for (char const *split : {"single", "multiple", "emission", "surface", "albedo", "normal"})
        if (name == split) return HdAovDescriptor(HdFormatFloat32Vec3, false, VtValue(GfVec3f(0.0f)));
    return HdAovDescriptor();
}

PXR_NAMESPACE_CLOSE_SCOPE
