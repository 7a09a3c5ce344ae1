#include "core/translate/settings.h"

#include <algorithm>
#include <cmath>

namespace volphoton::translate {

namespace {

bool asNumber(const AttrValue& v, double* out) {
    if (auto i = std::get_if<int64_t>(&v)) return *out = double(*i), true;
    if (auto d = std::get_if<double>(&v)) return *out = *d, true;
    return false;
}

double num(const AttrValue& v) {
    double x = 0;
    asNumber(v, &x);
    if (auto b = std::get_if<bool>(&v)) x = *b;
    return x;
}

SettingInfo intSetting(const char* name, double lo, double hi, const char* flag, const char* hydraKey, const char* label,
                       const char* units, const char* meaning, int RenderSettings::*field) {
    return {name, SettingType::Int, lo, hi, {}, flag, hydraKey, label, units, meaning,
            [field](const RenderSettings& s) { return AttrValue(int64_t(s.*field)); },
            [field](RenderSettings& s, const AttrValue& v) { s.*field = int(num(v)); }};
}

SettingInfo doubleSetting(const char* name, double lo, double hi, const char* flag, const char* label, const char* units,
                          const char* meaning, double RenderSettings::*field) {
    return {name, SettingType::Double, lo, hi, {}, flag, std::string("volphoton:") + name, label, units, meaning,
            [field](const RenderSettings& s) { return AttrValue(s.*field); },
            [field](RenderSettings& s, const AttrValue& v) { s.*field = num(v); }};
}

SettingInfo boolSetting(const char* name, const char* flag, const char* label, const char* meaning,
                        bool RenderSettings::*field) {
    return {name, SettingType::Bool, 0, 1, {}, flag, std::string("volphoton:") + name, label, "", meaning,
            [field](const RenderSettings& s) { return AttrValue(s.*field); },
            [field](RenderSettings& s, const AttrValue& v) { s.*field = num(v) != 0; }};
}

std::vector<SettingInfo> makeTable() {
    using RS = RenderSettings;
    constexpr double Big = 1e9;
    std::vector<SettingInfo> t;
    t.push_back({"integrator", SettingType::Choice, 0, 0, {"pathTracer", "photonMap", "combined", "auto"}, "--integrator",
                 "volphoton:integrator", "Integrator", "",
                 "pathTracer (unbiased volumetric path tracer), photonMap (single-scattering march + volume photon map), "
                 "combined (path-traced camera paths with the photon map's multiple scattering) "
                 "or auto (pathTracer, or combined with photon points or beams in open media where they lead, per scene "
                 "and image size from a pilot of camera rays; the stats say which and why)",
                 [](const RS& s) { return AttrValue(integratorName(s.integrator)); },
                 [](RS& s, const AttrValue& v) { parseIntegrator(std::get<std::string>(v), &s.integrator); }});
    t.push_back(intSetting("samplesPerPixel", 1, Big, "--spp", "convergedSamplesPerPixel", "Samples per pixel", "",
                           "passes; one camera sample per pixel per pass (with a noise target: the passes every pixel "
                           "gets before it may stop)", &RS::samplesPerPixel));
    t.push_back(doubleSetting("noiseTarget", 0, 1e3, "--noise-target", "Noise target (0: off)", "relative error",
                              "adaptive sampling: after samplesPerPixel passes, pixels stop once their estimated "
                              "relative error (and their neighbours') is at most this, e.g. 0.03", &RS::noiseTarget));
    t.push_back(doubleSetting("timeLimit", 0, Big, "--time-limit", "Time limit (0: none)", "seconds",
                              "render time limit: no pass starts that would end past it (at least one pass)",
                              &RS::timeLimit));
    t.push_back(intSetting("maxSamplesPerPixel", 1, Big, "--max-spp", "volphoton:maxSamplesPerPixel",
                           "Max samples per pixel (noise target, time limit)", "",
                           "with a noise target or time limit: the most passes any pixel gets",
                           &RS::maxSamplesPerPixel));
    t.push_back(intSetting("maxDepth", 0, Big, "--max-depth", "volphoton:maxDepth", "Max depth", "events",
                           "scattering/bounce events per path; the default is a safety cap (unbiased), lower values are "
                           "an artistic control and BIASED (dense bright media darken)", &RS::maxDepth));
    t.push_back(intSetting("rouletteDepth", 0, Big, "", "volphoton:rouletteDepth", "Russian roulette depth", "events",
                           "events before Russian roulette may end a path", &RS::rouletteDepth));
    t.push_back({"seed", SettingType::Int, 0, 9.2e18, {}, "--seed", "volphoton:seed", "Seed", "",
                 "every random stream hashes (pixel, the pixel's sample index, seed)",
                 [](const RS& s) { return AttrValue(int64_t(s.seed)); },
                 [](RS& s, const AttrValue& v) { s.seed = uint64_t(num(v)); }});
    t.push_back(intSetting("threads", 0, 4096, "--threads", "threadLimit", "Thread limit (0: all cores)", "",
                           "render threads; 0: all cores", &RS::threads));
    t.push_back(intSetting("photonsPerPass", 0, Big, "--photons", "volphoton:photonsPerPass", "Photons per pass (0: auto)", "",
                           "photonMap: photons traced per pass (0: as many as cost one camera pass, in [4096, 1e6], raised up to 8x "
                           "after 2 passes where the photon map's measured noise outweighs its cost)", &RS::photonsPerPass));
    t.push_back(doubleSetting("initialRadius", 0, Big, "", "Initial photon radius (0: auto)", "scene units",
                              "photonMap: beam radius of pass 0 (0: 1/100 of the media's diameter)", &RS::initialRadius));
    t.push_back(doubleSetting("radiusAlpha", 1e-6, 1, "", "Photon radius reduction (alpha)", "",
                              "photonMap: r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1), i counting 1e5 photons traced",
                              &RS::radiusAlpha));
    t.push_back(doubleSetting("photonRadiusMfp", 0, Big, "", "Photon radius cap (mean free paths)", "mean free paths",
                              "photonMap: a photon's radius is at most this many mean free paths (0: no cap)",
                              &RS::photonRadiusMfp));
    t.push_back(doubleSetting("combinedPhotonShare", -1, 1, "", "Combined: photon share (-1: auto)", "",
                              "combined: the photon map's share of the light scattered more than once at a camera "
                              "path's vertex in open media (1 inside translucent objects); the path goes on for the "
                              "rest with probability 1 - share (0: the path tracer's in open media; -1: where auto's pilot "
                              "finds the photon map leading there, its single and multiple scattering in open media, "
                              "else 0; in renders of 16 passes and up with automatic photons, passes 1-2 use the photons, "
                              "3-4 the path tracer, and the cheaper renders the rest)",
                              &RS::combinedPhotonShare));
    t.push_back(boolSetting("photonBeams", "", "Photon beams",
                            "photonMap: multiple scattering from photon beams (beam x beam 1D) instead of photon points where media are "
                            "optically thin (points where thicker than 100, in translucent objects and where a phase is peaked beyond "
                            "Henyey-Greenstein g = 0.6)",
                            &RS::photonBeams));
    t.push_back(intSetting("stratifiedDims", 0, 4096, "", "volphoton:stratifiedDims", "Stratified dimensions (0: independent)",
                           "", "dimensions per camera sample taken from scrambled Sobol' points; the path tracer gives each path segment the same 36 (580: 16 segments; 0: independent)",
                           &RS::stratifiedDims));
    t.push_back(doubleSetting("marchStep", 0, Big, "", "March step (0: auto)", "scene units",
                              "photonMap: single-scattering step (0: 1/256 of the media's diameter)", &RS::marchStep));
    t.push_back(boolSetting("singleScattering", "", "Single scattering pass", "photonMap: run the single-scattering pass",
                            &RS::singleScattering));
    t.push_back(boolSetting("multipleScattering", "", "Multiple scattering pass", "photonMap: run the photon (multiple) pass",
                            &RS::multipleScattering));
    t.push_back(doubleSetting("multipleThreshold", 0, Big, "", "Multiple-scattering threshold", "",
                              "photonMap: skip photons when a pilot estimates multiple/single below this",
                              &RS::multipleThreshold));
    t.push_back(boolSetting("guideAovs", "", "Denoiser guide AOVs (albedo, normal)",
                            "fill the albedo and normal AOVs a denoiser uses (one extra first-vertex ray per sample; "
                            "the CLI's --denoise turns it on)", &RS::guideAovs));
    t.push_back(doubleSetting("transmittanceCutoff", 0, 1, "", "Transmittance cut-off (biased)", "",
                              "deterministic early termination below this transmittance (BIASED; 0: off)",
                              &RS::transmittanceCutoff));
    t.push_back({"maxGridVoxels", SettingType::Int, 0, 1.8e19, {}, "--max-grid-voxels", "volphoton:maxGridVoxels",
                 "Max grid voxels (0: no cap)", "voxels", "VDB grids with more active voxels are refused (0: no cap)",
                 [](const RS& s) { return AttrValue(int64_t(std::min<uint64_t>(s.maxGridVoxels, INT64_MAX))); },
                 [](RS& s, const AttrValue& v) { s.maxGridVoxels = uint64_t(num(v)); }});
    return t;
}

}  // namespace

const std::vector<SettingInfo>& renderSettingsTable() {
    static const std::vector<SettingInfo> table = makeTable();
    return table;
}

const SettingInfo* findSetting(const std::string& name) {
    for (const SettingInfo& s : renderSettingsTable())
        if (s.name == name) return &s;
    return nullptr;
}

std::string integratorName(RenderSettings::Integrator i) {
    switch (i) {
    case RenderSettings::Integrator::PhotonMap: return "photonMap";
    case RenderSettings::Integrator::Auto: return "auto";
    case RenderSettings::Integrator::Combined: return "combined";
    default: return "pathTracer";
    }
}

bool parseIntegrator(const std::string& text, RenderSettings::Integrator* out) {
    if (text == "pathTracer" || text == "pathtracer") return *out = RenderSettings::Integrator::PathTracer, true;
    if (text == "photonMap" || text == "photonmap") return *out = RenderSettings::Integrator::PhotonMap, true;
    if (text == "auto") return *out = RenderSettings::Integrator::Auto, true;
    if (text == "combined") return *out = RenderSettings::Integrator::Combined, true;
    return false;
}

bool applySetting(RenderSettings& settings, const std::string& name, const AttrValue& value, Diagnostics& d,
                  const std::string& prim) {
    const SettingInfo* info = findSetting(name);
    std::string attr = "volphoton:" + name;
    if (!info) {
        std::string known;
        for (const SettingInfo& s : renderSettingsTable()) known += (known.empty() ? "" : ", ") + s.name;
        d.warn(prim, attr, "unknown render setting (known: " + known + ")");
        return false;
    }
    auto unusable = [&](const std::string& what) {
        d.error(prim, attr, "unusable value " + formatValue(value) + " (" + what + "); ignored");
        return false;
    };
    switch (info->type) {
    case SettingType::Choice: {
        auto s = std::get_if<std::string>(&value);
        RenderSettings::Integrator i;
        std::string list;
        for (const std::string& c : info->choices) list += (list.empty() ? "" : ", ") + c;
        if (!s || !parseIntegrator(*s, &i)) return unusable("one of " + list);
        info->set(settings, AttrValue(integratorName(i)));
        return true;
    }
    case SettingType::Bool: {
        if (std::holds_alternative<bool>(value)) {
            info->set(settings, value);
            return true;
        }
        if (auto i = std::get_if<int64_t>(&value); i && (*i == 0 || *i == 1)) {
            info->set(settings, AttrValue(*i != 0));
            return true;
        }
        return unusable("a bool");
    }
    case SettingType::Int:
    case SettingType::Double: {
        double x;
        bool isInt = info->type == SettingType::Int;
        if (!asNumber(value, &x) || !std::isfinite(x)) return unusable(isInt ? "an integer" : "a finite number");
        if (isInt && x != std::floor(x)) return unusable("an integer");
        if (x < info->min || x > info->max) {
            double c = std::clamp(x, info->min, info->max);
            d.warn(prim, attr, name + " = " + formatNumber(x) + " is outside [" + formatNumber(info->min) + ", " +
                                   formatNumber(info->max) + "]; clamped to " + formatNumber(c));
            x = c;
        }
        info->set(settings, isInt ? AttrValue(int64_t(x)) : AttrValue(x));
        return true;
    }
    }
    return false;
}

}  // namespace volphoton::translate
