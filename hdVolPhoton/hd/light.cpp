#include "hd/light.h"

#include "pxr/base/gf/vec3f.h"
#include "pxr/base/tf/diagnostic.h"
#include "pxr/base/tf/stringUtils.h"
#include "pxr/imaging/hd/sceneDelegate.h"
#include "pxr/imaging/hd/tokens.h"
#include "pxr/usd/sdf/assetPath.h"

#include "hd/conversions.h"
#include "hd/renderParam.h"

#include <cmath>
#include <cstring>

PXR_NAMESPACE_OPEN_SCOPE

using namespace volphoton;

HdVolPhotonLight::HdVolPhotonLight(SdfPath const &id, TfToken const &lightType) : HdLight(id), _lightType(lightType) {}

HdDirtyBits HdVolPhotonLight::GetInitialDirtyBitsMask() const { return AllDirty; }

namespace {
/// A light parameter by its UsdLux name. The legacy scene delegate answers to the attribute name
/// ("inputs:intensity"); the scene-index path (24.08) to the name without the "inputs:" prefix.
VtValue _LightParam(HdSceneDelegate *sd, SdfPath const &id, char const *name) {
    VtValue v = sd->GetLightParamValue(id, TfToken(name));
    if (v.IsEmpty() && std::strncmp(name, "inputs:", 7) == 0) v = sd->GetLightParamValue(id, TfToken(name + 7));
    return v;
}

template <typename T>
T _Param(HdSceneDelegate *sd, SdfPath const &id, char const *name, T fallback) {
    VtValue v = _LightParam(sd, id, name);
    if (v.IsHolding<T>()) return v.UncheckedGet<T>();
    if (!v.IsEmpty() && v.CanCast<T>()) return v.Cast<T>().template UncheckedGet<T>();
    return fallback;
}
}  // namespace

void HdVolPhotonLight::Sync(HdSceneDelegate *sd, HdRenderParam *renderParam, HdDirtyBits *dirtyBits) {
    SdfPath const &id = GetId();
    auto &registry = static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit();
    *dirtyBits = Clean;
    // UsdImagingGLEngine's lighting state (usdrecord's and usdview's camera "headlight", a GL-era
    // preview light under /_UsdImaging_<renderer>_...) is not part of the scene: the standalone
    // front end does not see it either, so the two would not render the same picture.
    if (TfStringStartsWith(id.GetString(), "/_UsdImaging_")) {
        registry.SetLight(id, nullptr);
        return;
    }
    if (!sd->GetVisible(id)) {
        registry.SetLight(id, nullptr);
        return;
    }
    float intensity = _Param(sd, id, "inputs:intensity", 1.0f), exposure = _Param(sd, id, "inputs:exposure", 0.0f);
    GfVec3f color = _Param(sd, id, "inputs:color", GfVec3f(1.0f));
    bool normalize = _Param(sd, id, "inputs:normalize", false);
    Spectrum s = HdVolPhoton_ToSpectrum(color) * (intensity * std::exp2(exposure));
    if (!s.isFinite() || s.minValue() < 0) {
        TF_WARN("%s.inputs:intensity: intensity, exposure and color give a negative or non-finite emission; light off", id.GetText());
        registry.SetLight(id, nullptr);
        return;
    }
    Affine xf = HdVolPhoton_ToAffine(sd->GetTransform(id));
    if (!xf.inverse()) {
        TF_WARN("%s: the transform is not invertible or not finite; light off", id.GetText());
        registry.SetLight(id, nullptr);
        return;
    }
    double scale = std::cbrt(std::abs(xf.determinant()));
    LightPtr light;
    try {
        if (_lightType == HdPrimTypeTokens->distantLight) {
            double half = 0.5 * _Param(sd, id, "inputs:angle", 0.53f) * M_PI / 180;
            Spectrum E = (normalize || half == 0) ? s : s * (M_PI * std::sin(half) * std::sin(half));
            light = makeDistantLight(volphoton::normalize(xf.vector(Vec3(0, 0, -1))), half, E);
        } else if (_lightType == HdPrimTypeTokens->sphereLight) {
            double r = _Param(sd, id, "inputs:radius", 0.5f) * scale;
            Spectrum L = normalize && r > 0 ? s / (4 * M_PI * r * r) : s;
            bool point = _Param(sd, id, "treatAsPoint", false) || r == 0;
            Spectrum emitted = point ? (r > 0 ? L * (M_PI * r * r) : s) : L;
            double radius = point ? 0.0 : r;
            float cone = _Param(sd, id, "inputs:shaping:cone:angle", 180.0f);
            if (cone < 180.0f) {
                light = makeSpotLight(xf.point(Vec3()), radius, emitted, volphoton::normalize(xf.vector(Vec3(0, 0, -1))), cone * M_PI / 180,
                                      _Param(sd, id, "inputs:shaping:cone:softness", 0.0f));
            } else {
                light = makeSphereLight(xf.point(Vec3()), radius, emitted);
            }
        } else if (_lightType == HdPrimTypeTokens->rectLight || _lightType == HdPrimTypeTokens->diskLight) {
            bool rect = _lightType == HdPrimTypeTokens->rectLight;
            double w = _Param(sd, id, "inputs:width", 1.0f), h = _Param(sd, id, "inputs:height", 1.0f);
            double r = _Param(sd, id, "inputs:radius", 0.5f);
            double area = (rect ? w * h : M_PI * r * r) * length(cross(xf.vector(Vec3(1, 0, 0)), xf.vector(Vec3(0, 1, 0))));
            Spectrum L = normalize && area > 0 ? s / area : s;
            light = rect ? makeRectLight(xf, w, h, L) : makeDiskLight(xf, r, L);
        } else if (_lightType == HdPrimTypeTokens->domeLight) {
            LatLongImage image;
            VtValue tex = _LightParam(sd, id, "inputs:texture:file");
            if (tex.IsHolding<SdfAssetPath>() && !tex.UncheckedGet<SdfAssetPath>().GetAssetPath().empty()) {
                SdfAssetPath const &a = tex.UncheckedGet<SdfAssetPath>();
                try {
                    image = loadLatLongExr(a.GetResolvedPath().empty() ? a.GetAssetPath() : a.GetResolvedPath());
                } catch (std::exception const &e) {
                    TF_WARN("%s.inputs:texture:file: %s; the dome is constant", id.GetText(), e.what());
                }
            }
            light = makeDomeLight(s, std::move(image), xf);
        } else {
            TF_WARN("%s: %s lights are not supported", id.GetText(), _lightType.GetText());
        }
    } catch (std::exception const &e) {
        TF_WARN("%s: light off: %s", id.GetText(), e.what());
    }
    registry.SetLight(id, light);
}

void HdVolPhotonLight::Finalize(HdRenderParam *renderParam) {
    static_cast<HdVolPhotonRenderParam *>(renderParam)->AcquireSceneForEdit().Remove(GetId());
}

PXR_NAMESPACE_CLOSE_SCOPE
