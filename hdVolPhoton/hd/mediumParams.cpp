#include "hd/mediumParams.h"

#include "core/presets.h"

#include "pxr/base/tf/diagnostic.h"
#include "pxr/imaging/hd/sceneDelegate.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

PXR_NAMESPACE_OPEN_SCOPE

namespace {

template <typename T>
bool _Get(HdSceneDelegate *sd, SdfPath const &id, char const *name, T *out) {
    VtValue v = sd->Get(id, TfToken(name));
    if (v.IsHolding<T>()) {
        *out = v.UncheckedGet<T>();
        return true;
    }
    // Attributes authored with a neighbouring type (double vs float) still count.
    if (!v.IsEmpty() && v.CanCast<T>()) {
        *out = v.Cast<T>().template UncheckedGet<T>();
        return true;
    }
    return false;
}

float _Clamp(SdfPath const &id, char const *name, float v, float lo, float hi, float fallback) {
    if (!std::isfinite(v)) {
        TF_WARN("%s.%s: %g is not finite; using %g", id.GetText(), name, v, fallback);
        return fallback;
    }
    if (v < lo || v > hi) {
        float c = std::min(hi, std::max(lo, v));
        TF_WARN("%s.%s: %g is outside [%g, %g]; clamped to %g", id.GetText(), name, v, lo, hi, c);
        return c;
    }
    return v;
}

GfVec3f _ClampColor(SdfPath const &id, char const *name, GfVec3f v, float lo, float hi, GfVec3f fallback) {
    for (int i = 0; i < 3; ++i)
        v[i] = _Clamp(id, name, v[i], lo, hi, fallback[i]);
    return v;
}

volphoton::Spectrum _Spectrum(GfVec3f const &v) { return {v[0], v[1], v[2]}; }

}  // namespace

std::optional<HdVolPhoton_MediumParams> HdVolPhoton_ReadMediumParams(HdSceneDelegate *sd, SdfPath const &id) {
    HdVolPhoton_MediumParams p;
    // The API's attributes all have fallbacks, so density is present exactly when the API is applied.
    if (!_Get(sd, id, "volphoton:density", &p.density)) return std::nullopt;
    p.density = _Clamp(id, "volphoton:density", p.density, 0.0f, 1e30f, 1.0f);
    if (_Get(sd, id, "volphoton:albedo", &p.albedo))
        p.albedo = _ClampColor(id, "volphoton:albedo", p.albedo, 0.0f, 1.0f, GfVec3f(0.8f));
    if (_Get(sd, id, "volphoton:extinctionColor", &p.extinctionColor))
        p.extinctionColor = _ClampColor(id, "volphoton:extinctionColor", p.extinctionColor, 0.0f, 1e30f, GfVec3f(1.0f));
    if (_Get(sd, id, "volphoton:emission", &p.emission))
        p.emission = _ClampColor(id, "volphoton:emission", p.emission, 0.0f, 1e30f, GfVec3f(0.0f));
    _Get(sd, id, "volphoton:emissionScale", &p.emissionScale);
    _Get(sd, id, "volphoton:temperatureScale", &p.temperatureScale);
    _Get(sd, id, "volphoton:phase", &p.phase);
    if (_Get(sd, id, "volphoton:phase:g", &p.g))
        p.g = _Clamp(id, "volphoton:phase:g", p.g, -0.99999f, 0.99999f, 0.0f);
    float k;
    if (_Get(sd, id, "volphoton:phase:k", &k))
        p.k = _Clamp(id, "volphoton:phase:k", k, -0.99999f, 0.99999f, 0.0f);
    if (_Get(sd, id, "volphoton:phase:x", &p.x))
        p.x = _Clamp(id, "volphoton:phase:x", p.x, -1.0f, 1.0f, 0.0f);
    _Get(sd, id, "volphoton:phase:table", &p.table);
    _Get(sd, id, "volphoton:densityMode", &p.densityMode);
    _Get(sd, id, "volphoton:exponential:a", &p.expA);
    p.expA = _Clamp(id, "volphoton:exponential:a", p.expA, 0.0f, 1e30f, 1.0f);
    _Get(sd, id, "volphoton:exponential:b", &p.expB);
    p.expB = _Clamp(id, "volphoton:exponential:b", p.expB, 0.0f, 1e30f, 1.0f);
    GfVec3f up;
    // The attribute has no fallback. The scene-index path of OpenUSD 24.08 reports it unauthored as
    // (0, 0, 0), so a zero vector means "unauthored" (+Y) without a warning on either path.
    if (_Get(sd, id, "volphoton:exponential:up", &up) && up != GfVec3f(0.0f)) {
        if (up.GetLength() > 0 && std::isfinite(up.GetLength())) p.expUp = up;
        else TF_WARN("%s.volphoton:exponential:up: a non-finite vector; using +Y", id.GetText());
    }
    _Get(sd, id, "volphoton:exponential:origin", &p.expOrigin);
    if (_Get(sd, id, "volphoton:ior", &p.ior)) p.ior = _Clamp(id, "volphoton:ior", p.ior, 1.0f, 10.0f, 1.0f);
    GfVec3f lo, hi;
    if (_Get(sd, id, "volphoton:bounds:min", &lo) && _Get(sd, id, "volphoton:bounds:max", &hi)) {
        if (lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]) p.bounds = std::make_pair(lo, hi);
        else TF_WARN("%s.volphoton:bounds:min: bounds:min is not below bounds:max; ignored", id.GetText());
    }
    _Get(sd, id, "volphoton:preset", &p.preset);
    if (!p.preset.IsEmpty() && !volphoton::findSubsurfacePreset(p.preset.GetString())) {
        TF_WARN("%s.volphoton:preset: unknown preset '%s' (known: %s); using density, albedo and extinctionColor",
                id.GetText(), p.preset.GetText(), volphoton::subsurfacePresetNames().c_str());
        p.preset = TfToken();
    }
    if (_Get(sd, id, "volphoton:sceneUnitsPerMm", &p.sceneUnitsPerMm))
        p.sceneUnitsPerMm = _Clamp(id, "volphoton:sceneUnitsPerMm", p.sceneUnitsPerMm, 1e-30f, 1e30f, 1.0f);
    return p;
}

volphoton::PhasePtr HdVolPhoton_BuildPhase(HdVolPhoton_MediumParams const &p, SdfPath const &id) {
    using namespace volphoton;
    std::string kind = p.phase.GetString();
    try {
        if (kind == "isotropic") return makeIsotropicPhase();
        if (kind == "linear") return makeLinearPhase(p.x);
        if (kind == "rayleigh") return makeRayleighPhase();
        if (kind == "lambertianSphere") return makeLambertianSpherePhase();
        if (kind == "henyeyGreenstein") return makeHenyeyGreensteinPhase(p.g);
        if (kind == "schlick") return makeSchlickPhase(p.k ? *p.k : schlickKFromG(p.g));
        if (kind == "tabulated") return makeTabulatedPhase(std::vector<double>(p.table.begin(), p.table.end()));
        if (kind == "mixture") {
            // XXX: the lobes of VolPhotonPhaseLobeAPI are read by the usd-core front end only.
            TF_WARN("%s.volphoton:phase: mixtures are not read by the Hydra delegate yet; using "
                    "henyeyGreenstein(g)", id.GetText());
            return makeHenyeyGreensteinPhase(p.g);
        }
        TF_WARN("%s.volphoton:phase: unknown phase '%s'; using isotropic", id.GetText(), kind.c_str());
    } catch (std::exception const &e) {
        TF_WARN("%s.volphoton:phase: %s; using isotropic", id.GetText(), e.what());
    }
    return makeIsotropicPhase();
}

volphoton::MediumCoefficients HdVolPhoton_BuildCoefficients(HdVolPhoton_MediumParams const &p, SdfPath const &id) {
    volphoton::PhasePtr phase = HdVolPhoton_BuildPhase(p, id);
    volphoton::Spectrum extinction = _Spectrum(p.extinctionColor), albedo = _Spectrum(p.albedo);
    double density = p.density;
    if (volphoton::SubsurfacePreset const *preset = p.preset.IsEmpty() ? nullptr : volphoton::findSubsurfacePreset(p.preset.GetString())) {
        // The measured material, as the usd-core front end maps it (volphoton/presets.py).
        try {
            volphoton::PresetCoefficients c = volphoton::presetCoefficients(*preset, p.sceneUnitsPerMm, phase->meanCosine());
            volphoton::Spectrum sigma_t = c.sigma_s + c.sigma_a;
            density = sigma_t.maxValue();
            for (int i = 0; i < 3; ++i) {
                extinction[i] = density > 0 ? sigma_t[i] / density : 0.0;
                albedo[i] = sigma_t[i] > 0 ? c.sigma_s[i] / sigma_t[i] : 0.0;
            }
        } catch (std::exception const &e) {
            TF_WARN("%s.volphoton:preset: %s; using density, albedo and extinctionColor", id.GetText(), e.what());
        }
    }
    return volphoton::MediumCoefficients::fromAlbedo(density, extinction, albedo, _Spectrum(p.emission) * p.emissionScale,
                                                     phase);
}

PXR_NAMESPACE_CLOSE_SCOPE
