#include "core/translate/medium.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/exponentialMedium.h"
#include "core/presets.h"

namespace volphoton::translate {

namespace {
// (fallbacks come from mediumAttributes(), defined below)
const AttrValue& fallbackOf(const std::vector<AttributeInfo>& table, const std::string& name) {
    for (const AttributeInfo& a : table)
        if (a.name == name && a.fallback) return *a.fallback;
    throw std::logic_error("no fallback for " + name);
}
double fallbackNumber(const std::string& name) { return std::get<double>(fallbackOf(mediumAttributes(), name)); }
Spectrum fallbackColor(const std::string& name) {
    const Vec3& v = std::get<Vec3>(fallbackOf(mediumAttributes(), name));
    return {v.x, v.y, v.z};
}
}  // namespace

namespace {

constexpr char MediumApi[] = "VolPhotonMediumAPI";
constexpr char LobeApi[] = "VolPhotonPhaseLobeAPI";

std::string shortName(const std::string& attr) {
    size_t p = attr.rfind(':');
    return p == std::string::npos ? attr : attr.substr(p + 1);
}

std::string join(const std::vector<std::string>& v, const char* sep = ", ") {
    std::string out;
    for (size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
    return out;
}

bool asNumber(const AttrValue& v, double* out) {
    if (auto b = std::get_if<bool>(&v)) return *out = *b, true;
    if (auto i = std::get_if<int64_t>(&v)) return *out = double(*i), true;
    if (auto d = std::get_if<double>(&v)) return *out = *d, true;
    return false;
}

bool asTriple(const AttrValue& v, double out[3]) {
    if (auto p = std::get_if<Vec3>(&v)) {
        out[0] = p->x, out[1] = p->y, out[2] = p->z;
        return true;
    }
    if (auto a = std::get_if<std::vector<double>>(&v); a && a->size() == 3) {
        std::copy(a->begin(), a->end(), out);
        return true;
    }
    return false;
}

/// Validating reads of one prim's attributes (the rules of the table in medium.h).
class Reader {
public:
    Reader(const AttributeRecord& r, Diagnostics& d) : rec_(r), diag_(d), path_(r.primPath) {}

    void error(const std::string& attr, const std::string& msg) { diag_.error(path_, attr, msg); }
    void warn(const std::string& attr, const std::string& msg) { diag_.warn(path_, attr, msg); }
    const AttrValue* raw(const std::string& name) const { return rec_.find(name); }
    bool authored(const std::string& name) const { return rec_.isAuthored(name); }

    /// A float in [lo, hi] (open ends when asked); outside -> clamped to clampLo/clampHi with a
    /// warning; unusable -> the default with an error.
    double scalar(const std::string& name, double def, std::optional<double> lo = {}, std::optional<double> hi = {},
                  bool loOpen = false, bool hiOpen = false, std::optional<double> clampLo = {},
                  std::optional<double> clampHi = {}) {
        const AttrValue* v = raw(name);
        if (!v) return def;
        double x;
        if (!asNumber(*v, &x)) {
            error(name, "expected a float, got " + formatValue(*v) + "; using the default " + formatNumber(def));
            return def;
        }
        std::string s = shortName(name);
        if (!std::isfinite(x)) {
            error(name, s + " = " + formatNumber(x) + " is not a finite number; using the default " + formatNumber(def));
            return def;
        }
        bool below = lo && (loOpen ? x <= *lo : x < *lo);
        bool above = hi && (hiOpen ? x >= *hi : x > *hi);
        if (below || above) {
            double target = below ? clampLo.value_or(*lo) : clampHi.value_or(*hi);
            std::string what;
            if (hi)
                what = std::string("is outside ") + (loOpen ? "(" : "[") + formatNumber(*lo) + ", " + formatNumber(*hi) +
                       (hiOpen ? ")" : "]");
            else if (*lo == 0.0 && !loOpen)
                what = "is negative";
            else
                what = std::string("is ") + (loOpen ? "not above " : "below ") + formatNumber(*lo);
            warn(name, s + " = " + formatNumber(x) + " " + what + "; clamped to " + formatNumber(target));
            x = target;
        }
        return x;
    }

    /// A float that must be > 0 (a scale).
    double positive(const std::string& name, double def) {
        double v = scalar(name, def);
        if (v <= 0.0) {
            error(name, shortName(name) + " = " + formatNumber(v) + " is not > 0; using the default " + formatNumber(def));
            return def;
        }
        return v;
    }

    /// A finite 3-vector, or the default (nullopt: none) with an error.
    std::optional<Vec3> vec3(const std::string& name, std::optional<Vec3> def) {
        const AttrValue* v = raw(name);
        if (!v) return def;
        std::string fallback = def ? "using the default " + formatVec3(*def) : "ignored";
        double t[3];
        if (!asTriple(*v, t)) {
            error(name, "expected 3 floats, got " + formatValue(*v) + "; " + fallback);
            return def;
        }
        Vec3 r(t[0], t[1], t[2]);
        if (!isFinite(r)) {
            error(name, shortName(name) + " = " + formatVec3(r) + " is not finite; " + fallback);
            return def;
        }
        return r;
    }

    /// A colour with components in [0, hi] (hi none: [0, inf)).
    Spectrum color(const std::string& name, const Spectrum& def, std::optional<double> hi) {
        const AttrValue* v = raw(name);
        if (!v) return def;
        double t[3];
        Vec3 d(def[0], def[1], def[2]);
        if (!asTriple(*v, t)) {
            error(name, "expected a color3f, got " + formatValue(*v) + "; using the default " + formatVec3(d));
            return def;
        }
        std::string s = shortName(name);
        if (!(std::isfinite(t[0]) && std::isfinite(t[1]) && std::isfinite(t[2]))) {
            Vec3 was(t[0], t[1], t[2]);
            for (int i = 0; i < 3; ++i)
                if (!std::isfinite(t[i])) t[i] = def[i];
            error(name, s + " = " + formatVec3(was) + " has non-finite components; replaced by the default: " +
                            formatVec3(Vec3(t[0], t[1], t[2])));
        }
        double c[3];
        bool changed = false;
        for (int i = 0; i < 3; ++i) {
            c[i] = std::max(t[i], 0.0);
            if (hi) c[i] = std::min(c[i], *hi);
            changed |= c[i] != t[i];
        }
        if (changed)
            warn(name, s + " = " + formatVec3(Vec3(t[0], t[1], t[2])) + " has components outside " +
                           (hi ? "[0, " + formatNumber(*hi) + "]" : std::string(">= 0")) + "; clamped to " +
                           formatVec3(Vec3(c[0], c[1], c[2])));
        return {c[0], c[1], c[2]};
    }

    std::optional<std::string> token(const std::string& name) {
        const AttrValue* v = raw(name);
        if (!v) return std::nullopt;
        if (auto s = std::get_if<std::string>(v)) return *s;
        std::string f = formatValue(*v);
        return f;
    }

    std::optional<std::vector<double>> floatArray(const std::string& name) {
        const AttrValue* v = raw(name);
        if (!v) return std::nullopt;
        if (auto a = std::get_if<std::vector<double>>(v)) return *a;
        if (auto p = std::get_if<Vec3>(v)) return std::vector<double>{p->x, p->y, p->z};
        error(name, "expected a float[], got " + formatValue(*v) + "; ignored");
        return std::nullopt;
    }

    /// kind/g/k/x/table of the medium or of one lobe (attribute names in `names`).
    PhaseParams phase(const std::map<std::string, std::string>& names, const std::string& defKind,
                      const std::vector<std::string>& allowed, const std::string& what) {
        const std::string& kindAttr = names.at("phase");
        std::string kind = token(kindAttr).value_or(defKind);
        if (std::find(allowed.begin(), allowed.end(), kind) == allowed.end()) {
            const auto& all = phaseKinds();
            if (std::find(all.begin(), all.end(), kind) != all.end())
                error(kindAttr, what + " cannot be '" + kind + "'; using " + defKind);
            else
                error(kindAttr, "unknown phase '" + kind + "' (expected one of " + join(allowed) + "); using " + defKind);
            kind = defKind;
        }
        PhaseParams p;
        p.kind = kind;
        p.g = scalar(names.at("g"), 0.0, -1.0, 1.0, true, true, -GLimit, GLimit);
        // A derived k is clamped silently: k(g) slightly exceeds 1 just below g = 1.
        double kFromG = std::clamp(schlickKFromG(p.g), -GLimit, GLimit);
        p.k = raw(names.at("k")) ? scalar(names.at("k"), kFromG, -1.0, 1.0, true, true, -GLimit, GLimit) : kFromG;
        p.x = scalar(names.at("x"), 0.0, -1.0, 1.0);
        p.table = floatArray(names.at("table")).value_or(std::vector<double>{});
        if (kind != "tabulated") return p;
        const std::string& tattr = names.at("table");
        if (p.table.size() < 2) {
            error(tattr, "tabulated phase needs at least 2 values, got " + std::to_string(p.table.size()) +
                             "; using isotropic");
            p.kind = "isotropic";
            return p;
        }
        auto indices = [](const std::vector<double>& t, auto pred) {
            std::vector<std::string> out;
            for (size_t i = 0; i < t.size(); ++i)
                if (pred(t[i]) && out.size() < 8) out.push_back(std::to_string(i));
            return out;
        };
        auto bad = indices(p.table, [](double v) { return !std::isfinite(v); });
        if (!bad.empty()) {
            error(tattr, "table has non-finite values at indices " + join(bad) + "; set to 0");
            for (double& v : p.table)
                if (!std::isfinite(v)) v = 0;
        }
        auto neg = indices(p.table, [](double v) { return v < 0; });
        if (!neg.empty()) {
            warn(tattr, "table has negative values at indices " + join(neg) + "; clamped to 0");
            for (double& v : p.table) v = std::max(v, 0.0);
        }
        if (std::none_of(p.table.begin(), p.table.end(), [](double v) { return v > 0; })) {
            error(tattr, "table is all zero and cannot be normalised; using isotropic");
            p.kind = "isotropic";
        }
        return p;
    }

    PhaseParams mediumPhase(const std::vector<std::string>& lobeNames) {
        std::map<std::string, std::string> names = {{"phase", "volphoton:phase"},
                                                    {"g", "volphoton:phase:g"},
                                                    {"k", "volphoton:phase:k"},
                                                    {"x", "volphoton:phase:x"},
                                                    {"table", "volphoton:phase:table"}};
        PhaseParams desc = phase(names, "henyeyGreenstein", phaseKinds(), "volphoton:phase");
        if (desc.kind != "mixture") {
            if (!lobeNames.empty())
                warn("volphoton:phase", "phase is '" + desc.kind + "', so the applied " + LobeApi + " lobes " +
                                            join(lobeNames) + " are ignored (set phase to mixture to use them)");
            return desc;
        }
        if (lobeNames.empty()) {
            error("volphoton:phase", std::string("phase is mixture but no ") + LobeApi + " lobe is applied; using isotropic");
            desc.kind = "isotropic";
            return desc;
        }
        std::vector<std::string> lobeKinds(phaseKinds().begin(), phaseKinds().end() - 1);
        std::vector<std::pair<double, PhaseParams>> lobes;
        for (const std::string& lobe : lobeNames) {
            std::map<std::string, std::string> ln;
            for (const char* p : {"phase", "g", "k", "x", "table"}) ln[p] = lobeAttribute(lobe, p);
            double weight = scalar(lobeAttribute(lobe, "weight"), 1.0, 0.0);
            lobes.emplace_back(weight, phase(ln, "henyeyGreenstein", lobeKinds, "a mixture lobe"));
        }
        if (std::none_of(lobes.begin(), lobes.end(), [](const auto& l) { return l.first > 0; })) {
            error("volphoton:phase", "phase is mixture but all lobe weights (" + join(lobeNames) + ") are 0; using isotropic");
            desc.kind = "isotropic";
            return desc;
        }
        desc.lobes = std::move(lobes);
        return desc;
    }

    std::optional<std::pair<Vec3, Vec3>> bounds(const MediumContext& ctx) {
        auto lo = vec3("volphoton:bounds:min", std::nullopt);
        auto hi = vec3("volphoton:bounds:max", std::nullopt);
        if (!lo && !hi) return std::nullopt;
        if (!lo || !hi) {
            std::string given = lo ? "volphoton:bounds:min" : "volphoton:bounds:max";
            std::string missing = lo ? "volphoton:bounds:max" : "volphoton:bounds:min";
            warn(given, missing + " is not authored (or not usable), so the bounds are ignored");
            return std::nullopt;
        }
        if (lo->x > hi->x || lo->y > hi->y || lo->z > hi->z) {
            error("volphoton:bounds:min", "bounds:min " + formatVec3(*lo) + " is not <= bounds:max " + formatVec3(*hi) +
                                              " on every axis; bounds ignored");
            return std::nullopt;
        }
        if (!ctx.isVolume) {
            warn("volphoton:bounds:min", "bounds are ignored on a " + typeName(ctx) + " (its surface bounds the medium)");
            return std::nullopt;
        }
        return std::make_pair(*lo, *hi);
    }

    static std::string typeName(const MediumContext& ctx) {
        return ctx.typeName.empty() ? "typeless prim" : ctx.typeName;
    }

    MediumParams read(const MediumContext& ctx) {
        if (ctx.hasApi && !ctx.schemaRegistered)
            warn("", std::string(MediumApi) + " is applied but the volPhoton schema plug-in is not registered (set "
                     "PXR_PLUGINPATH_NAME to hdVolPhoton's plugInfo directory); using the built-in defaults");
        MediumParams m;
        m.primPath = path_;
        m.density = scalar("volphoton:density", fallbackNumber("volphoton:density"), 0.0);
        m.albedo = color("volphoton:albedo", fallbackColor("volphoton:albedo"), 1.0);
        m.extinctionColor = color("volphoton:extinctionColor", fallbackColor("volphoton:extinctionColor"), std::nullopt);
        m.emission = color("volphoton:emission", fallbackColor("volphoton:emission"), std::nullopt);
        m.emissionScale = scalar("volphoton:emissionScale", fallbackNumber("volphoton:emissionScale"), 0.0);
        m.temperatureScale = scalar("volphoton:temperatureScale", fallbackNumber("volphoton:temperatureScale"), 0.0);
        m.phase = mediumPhase(ctx.lobeNames);

        bool hasField = ctx.isVolume && ctx.hasDensityField;
        std::string derived = hasField ? "field" : "constant";
        std::optional<std::string> mode = token("volphoton:densityMode");
        const auto& modes = densityModes();
        if (!mode) {
            mode = derived;
        } else if (std::find(modes.begin(), modes.end(), *mode) == modes.end()) {
            error("volphoton:densityMode", "unknown densityMode '" + *mode + "' (expected one of " + join(modes) +
                                               "); using " + derived);
            mode = derived;
        } else if (*mode == "field" && !hasField) {
            std::string why = ctx.isVolume ? "no usable field:density relationship (targeting an OpenVDBAsset) is bound"
                                           : "the prim is a " + typeName(ctx) + ", not a UsdVolVolume with a density field";
            error("volphoton:densityMode", "densityMode is field but " + why + "; using constant");
            mode = "constant";
        }
        m.densityMode = *mode;

        m.expA = scalar("volphoton:exponential:a", fallbackNumber("volphoton:exponential:a"), 0.0);
        m.expB = scalar("volphoton:exponential:b", fallbackNumber("volphoton:exponential:b"), 0.0);
        std::optional<Vec3> up = vec3("volphoton:exponential:up", std::nullopt);
        if (!up) {
            m.expUp = ctx.stageUp;
        } else if (length(*up) == 0.0) {
            error("volphoton:exponential:up",
                  "up = (0, 0, 0) has no direction; using the stage's up axis " + formatVec3(ctx.stageUp));
            m.expUp = ctx.stageUp;
        } else {
            m.expUp = normalize(*up);
        }
        m.expOrigin = *vec3("volphoton:exponential:origin", Vec3(0, 0, 0));

        m.ior = scalar("volphoton:ior", fallbackNumber("volphoton:ior"), 1.0);
        if (ctx.isVolume && authored("volphoton:ior") && m.ior != 1.0)
            warn("volphoton:ior", "ior is ignored on a Volume (only a Gprim's surface refracts)");
        m.preset = token("volphoton:preset").value_or("");
        m.sceneUnitsPerMm = positive("volphoton:sceneUnitsPerMm", fallbackNumber("volphoton:sceneUnitsPerMm"));
        m.bounds = bounds(ctx);
        return m;
    }

private:
    const AttributeRecord& rec_;
    Diagnostics& diag_;
    std::string path_;
};

}  // namespace

const std::vector<std::string>& phaseKinds() {
    static const std::vector<std::string> k = {"isotropic", "linear",  "rayleigh",  "lambertianSphere",
                                               "henyeyGreenstein", "schlick", "tabulated", "mixture"};
    return k;
}

const std::vector<std::string>& densityModes() {
    static const std::vector<std::string> m = {"field", "constant", "exponential"};
    return m;
}

const std::vector<AttributeInfo>& mediumAttributes() {
    static const std::vector<AttributeInfo> t = {
        {"volphoton:density", 1.0},
        {"volphoton:albedo", Vec3(0.8, 0.8, 0.8)},
        {"volphoton:extinctionColor", Vec3(1, 1, 1)},
        {"volphoton:emission", Vec3(0, 0, 0)},
        {"volphoton:emissionScale", 1.0},
        {"volphoton:temperatureScale", 1.0},
        {"volphoton:phase", std::string("henyeyGreenstein")},
        {"volphoton:phase:g", 0.0},
        {"volphoton:phase:k", std::nullopt},
        {"volphoton:phase:x", 0.0},
        {"volphoton:phase:table", std::nullopt},
        {"volphoton:densityMode", std::nullopt},
        {"volphoton:exponential:a", 1.0},
        {"volphoton:exponential:b", 1.0},
        {"volphoton:exponential:up", std::nullopt},
        {"volphoton:exponential:origin", Vec3(0, 0, 0)},
        {"volphoton:ior", 1.0},
        {"volphoton:preset", std::string("")},
        {"volphoton:sceneUnitsPerMm", 1.0},
        {"volphoton:bounds:min", std::nullopt},
        {"volphoton:bounds:max", std::nullopt},
    };
    return t;
}

const std::vector<AttributeInfo>& lobeProperties() {
    static const std::vector<AttributeInfo> t = {{"weight", 1.0},        {"phase", std::string("henyeyGreenstein")},
                                                 {"g", 0.0},             {"k", std::nullopt},
                                                 {"x", 0.0},             {"table", std::nullopt}};
    return t;
}


std::string lobeAttribute(const std::string& lobe, const std::string& property) {
    return "volphoton:lobe:" + lobe + ":" + property;
}

std::optional<MediumParams> readMedium(const AttributeRecord& record, const MediumContext& ctx, Diagnostics& diag) {
    Reader reader(record, diag);
    if (!ctx.isVolume && !ctx.hasApi) {
        std::vector<std::string> stray;
        for (const std::string& name : record.authored)
            if (name.rfind("volphoton:", 0) == 0) stray.push_back(name);
        if (!stray.empty()) {
            std::sort(stray.begin(), stray.end());
            bool more = stray.size() > 4;
            stray.resize(std::min<size_t>(stray.size(), 4));
            reader.warn("", "has " + join(stray) + (more ? ", ..." : "") + " authored but " + MediumApi +
                                " is not applied, so it is not a medium (apply the API)");
        }
        return std::nullopt;
    }
    if (ctx.hasApi && !ctx.isVolume && !ctx.isGprim)
        reader.warn("", std::string(MediumApi) + " is applied to a " + Reader::typeName(ctx) +
                            "; it only applies to Volume and Gprim prims");
    return reader.read(ctx);
}

PhasePtr buildPhase(const PhaseParams& p) {
    const std::string& k = p.kind;
    if (k == "isotropic") return makeIsotropicPhase();
    if (k == "linear") return makeLinearPhase(p.x);
    if (k == "rayleigh") return makeRayleighPhase();
    if (k == "lambertianSphere") return makeLambertianSpherePhase();
    if (k == "schlick") return makeSchlickPhase(p.k);
    if (k == "tabulated") return makeTabulatedPhase(p.table);
    if (k == "mixture") {
        std::vector<std::pair<double, PhasePtr>> lobes;
        for (const auto& [w, lobe] : p.lobes) lobes.emplace_back(w, buildPhase(lobe));
        return makeMixturePhase(lobes);
    }
    return makeHenyeyGreensteinPhase(p.g);
}

EffectiveCoefficients effectiveCoefficients(const MediumParams& m, Diagnostics& diag) {
    EffectiveCoefficients c{m.density, m.extinctionColor, m.albedo};
    if (m.preset.empty()) return c;
    const SubsurfacePreset* preset = findSubsurfacePreset(m.preset);
    const std::string keep = "; using the authored density, albedo and extinctionColor";
    if (!preset) {
        diag.error(m.primPath, "volphoton:preset",
                   "unknown preset '" + m.preset + "' (valid: " + subsurfacePresetNames() + ")" + keep);
        return c;
    }
    try {
        // sigma_s = sigma_s' / (1 - g): g is the mean cosine of the prim's phase function.
        PresetCoefficients pc = presetCoefficients(*preset, m.sceneUnitsPerMm, buildPhase(m.phase)->meanCosine());
        Spectrum sigma_t = pc.sigma_s + pc.sigma_a;
        c.density = sigma_t.maxValue();
        for (int i = 0; i < 3; ++i) {
            c.extinctionColor[i] = c.density > 0 ? sigma_t[i] / c.density : 0.0;
            c.albedo[i] = sigma_t[i] > 0 ? pc.sigma_s[i] / sigma_t[i] : 0.0;
        }
    } catch (const std::exception& e) {
        diag.error(m.primPath, "volphoton:preset", e.what() + keep);
    }
    return c;
}

MediumCoefficients mediumCoefficients(const MediumParams& m, Diagnostics& diag) {
    EffectiveCoefficients c = effectiveCoefficients(m, diag);
    return MediumCoefficients::fromAlbedo(c.density, c.extinctionColor, c.albedo, m.emission * m.emissionScale,
                                          buildPhase(m.phase));
}

namespace {
Bounds3 worldBox(const std::pair<Vec3, Vec3>& b, const Affine& xf) {
    Bounds3 out;
    for (int c = 0; c < 8; ++c)
        out.extend(xf.point(Vec3(c & 1 ? b.second.x : b.first.x, c & 2 ? b.second.y : b.first.y,
                                 c & 4 ? b.second.z : b.first.z)));
    return out;
}
}  // namespace

MediumPtr buildProceduralMedium(const MediumParams& m, const Affine& world, bool useBounds, Diagnostics& diag,
                                std::string* kind) {
    try {
        MediumCoefficients c = mediumCoefficients(m, diag);
        Bounds3 bounds = useBounds && m.bounds ? worldBox(*m.bounds, world) : infiniteBounds();
        if (m.densityMode == "exponential") {
            Vec3 origin = world.point(m.expOrigin);
            Vec3 up = world.vector(m.expUp);
            double len = length(up);
            if (!(len > 0) || !isFinite(up)) {
                diag.error(m.primPath, "volphoton:exponential:up",
                           "up direction degenerates under the prim's transform; medium skipped");
                return nullptr;
            }
            if (kind) *kind = "exponential";
            return std::make_shared<ExponentialMedium>(c, m.expA, m.expB / len, origin, up / len, bounds);
        }
        if (kind) *kind = "homogeneous";
        return std::make_shared<HomogeneousMedium>(c, bounds);
    } catch (const std::exception& e) {
        diag.error(m.primPath, "", std::string("cannot build the medium: ") + e.what() + "; skipped");
        return nullptr;
    }
}

GridMediumDesc gridMediumDesc(const MediumParams& m, const Affine& world, Diagnostics& diag) {
    EffectiveCoefficients c = effectiveCoefficients(m, diag);
    GridMediumDesc g;
    g.densityScale = c.density;
    g.extinctionColor = c.extinctionColor;
    g.albedo = c.albedo;
    g.emission = m.emission;
    g.emissionScale = m.emissionScale;
    g.temperatureScale = m.temperatureScale;
    g.phase = buildPhase(m.phase);
    g.objectToWorld = world;
    return g;
}

namespace {
void writePhase(std::ostringstream& o, const PhaseParams& p) {
    o << p.kind << '(' << p.g << ',' << p.k << ',' << p.x << ",[";
    for (double v : p.table) o << v << ',';
    o << "],{";
    for (const auto& [w, lobe] : p.lobes) {
        o << w << ':';
        writePhase(o, lobe);
        o << ';';
    }
    o << "})";
}
void writeSpectrum(std::ostringstream& o, const Spectrum& s) { o << s[0] << ',' << s[1] << ',' << s[2] << '|'; }
void writeVec(std::ostringstream& o, const Vec3& s) { o << s.x << ',' << s.y << ',' << s.z << '|'; }
}  // namespace

std::string mediumKey(const MediumParams& m) {
    std::ostringstream o;
    o.precision(17);
    o << m.primPath << '|' << m.density << '|';
    writeSpectrum(o, m.albedo);
    writeSpectrum(o, m.extinctionColor);
    writeSpectrum(o, m.emission);
    o << m.emissionScale << '|' << m.temperatureScale << '|';
    writePhase(o, m.phase);
    o << '|' << m.densityMode << '|' << m.expA << '|' << m.expB << '|';
    writeVec(o, m.expUp);
    writeVec(o, m.expOrigin);
    o << m.ior << '|' << m.preset << '|' << m.sceneUnitsPerMm << '|';
    if (m.bounds) {
        writeVec(o, m.bounds->first);
        writeVec(o, m.bounds->second);
    }
    return o.str();
}

}  // namespace volphoton::translate
