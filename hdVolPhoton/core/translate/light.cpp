#include "core/translate/light.h"

#include <algorithm>
#include <cmath>

namespace volphoton::translate {

namespace {

// UsdLux's blackbody knots, 1000 K to 10000 K in 500 K steps, the first and last repeated so that the
// Catmull-Rom spline has end segments (John Walker, "Colour Rendering of Spectra"; the values
// UsdLux's blackbody.cpp tabulates).
constexpr double BlackbodyKnots[][3] = {
    {1.000000, 0.027490, 0.000000}, {1.000000, 0.027490, 0.000000}, {1.000000, 0.149664, 0.000000},
    {1.000000, 0.256644, 0.008095}, {1.000000, 0.372033, 0.067450}, {1.000000, 0.476725, 0.153601},
    {1.000000, 0.570376, 0.259196}, {1.000000, 0.653480, 0.377155}, {1.000000, 0.726878, 0.501606},
    {1.000000, 0.791543, 0.628050}, {1.000000, 0.848462, 0.753228}, {1.000000, 0.898581, 0.874905},
    {1.000000, 0.942771, 0.991642}, {0.906947, 0.890456, 1.000000}, {0.828247, 0.841838, 1.000000},
    {0.765791, 0.801896, 1.000000}, {0.715255, 0.768579, 1.000000}, {0.673683, 0.740423, 1.000000},
    {0.638992, 0.716359, 1.000000}, {0.609681, 0.695588, 1.000000}, {0.609681, 0.695588, 1.000000},
    {0.609681, 0.695588, 1.000000}};

bool asNumber(const AttrValue* v, double* out) {
    if (!v) return false;
    if (auto b = std::get_if<bool>(v)) return *out = *b, true;
    if (auto i = std::get_if<int64_t>(v)) return *out = double(*i), true;
    if (auto d = std::get_if<double>(v)) return *out = *d, true;
    return false;
}

/// Reads typed values with UsdLux's fallbacks; a value of the wrong type is an error and the fallback.
class LightReader {
public:
    LightReader(const AttributeRecord& r, Diagnostics& d) : rec_(r), diag_(d) {}
    double number(const std::string& name, double fallback) {
        const AttrValue* v = rec_.find(name);
        double x;
        if (!v) return fallback;
        if (!asNumber(v, &x)) {
            diag_.error(rec_.primPath, name, "expected a number, got " + formatValue(*v) + "; using " + formatNumber(fallback));
            return fallback;
        }
        return x;
    }
    bool flag(const std::string& name, bool fallback) { return number(name, fallback ? 1.0 : 0.0) != 0.0; }
    Spectrum color(const std::string& name, const Spectrum& fallback) {
        const AttrValue* v = rec_.find(name);
        if (!v) return fallback;
        if (auto p = std::get_if<Vec3>(v)) return {p->x, p->y, p->z};
        if (auto a = std::get_if<std::vector<double>>(v); a && a->size() == 3) return {(*a)[0], (*a)[1], (*a)[2]};
        diag_.error(rec_.primPath, name, "expected a color3f, got " + formatValue(*v) + "; using the default");
        return fallback;
    }
    std::string text(const std::string& name) {
        const AttrValue* v = rec_.find(name);
        auto s = v ? std::get_if<std::string>(v) : nullptr;
        return s ? *s : std::string();
    }
    bool has(const std::string& name) const { return rec_.find(name) != nullptr; }

private:
    const AttributeRecord& rec_;
    Diagnostics& diag_;
};

}  // namespace

Spectrum usdLuxBlackbody(double kelvin) {
    constexpr int knots = sizeof(BlackbodyKnots) / sizeof(BlackbodyKnots[0]);
    constexpr int segments = knots - 3;  // segment i runs from knot i + 1 to knot i + 2
    double u = std::clamp((kelvin - 1000.0) / 9000.0, 0.0, 1.0) * (segments - 1);
    int seg = std::min(int(std::floor(u)), segments - 1);
    double t = u - seg;
    Spectrum rgb;
    for (int c = 0; c < 3; ++c) {
        double p0 = BlackbodyKnots[seg][c], p1 = BlackbodyKnots[seg + 1][c], p2 = BlackbodyKnots[seg + 2][c],
               p3 = BlackbodyKnots[seg + 3][c];
        // Catmull-Rom: p1 at t = 0, p2 at t = 1, tangents (p2 - p0)/2 and (p3 - p1)/2.
        rgb[c] = 0.5 * (2 * p1 + (p2 - p0) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t +
                        (3 * p1 - p0 - 3 * p2 + p3) * t * t * t);
    }
    rgb = rgb / luminance(rgb);
    for (int c = 0; c < 3; ++c) rgb[c] = std::max(rgb[c], 0.0);
    return rgb;
}

const std::vector<std::string>& lightAttributeNames() {
    static const std::vector<std::string> n = {
        "inputs:intensity",          "inputs:exposure",       "inputs:color",          "inputs:normalize",
        "inputs:enableColorTemperature", "inputs:colorTemperature", "inputs:diffuse",  "inputs:specular",
        "inputs:angle",              "inputs:radius",         "treatAsPoint",          "inputs:width",
        "inputs:height",             "inputs:texture:file",   "inputs:texture:format", "inputs:shaping:cone:angle",
        "inputs:shaping:cone:softness", "inputs:shaping:focus", "inputs:shaping:ies:file", "light:materialSyncMode"};
    return n;
}

namespace {

/// (cone angle in radians, softness) of an applied ShapingAPI, or nullopt (no cone).
std::optional<std::pair<double, double>> shaping(LightReader& r, const std::string& path, Diagnostics& d) {
    if (!r.has("inputs:shaping:cone:angle")) return std::nullopt;
    double angle = r.number("inputs:shaping:cone:angle", 90.0);
    double softness = r.number("inputs:shaping:cone:softness", 0.0);
    if (r.number("inputs:shaping:focus", 0.0) != 0.0)
        d.warn(path, "inputs:shaping:focus", "shaping focus is not supported; ignored");
    if (!r.text("inputs:shaping:ies:file").empty())
        d.warn(path, "inputs:shaping:ies:file", "IES profiles are not supported; ignored");
    if (!std::isfinite(angle) || !std::isfinite(softness)) {
        d.error(path, "inputs:shaping:cone:angle", "cone angle/softness not finite; no cone");
        return std::nullopt;
    }
    if (angle >= 180.0) return std::nullopt;
    if (angle <= 0.0) {
        d.warn(path, "inputs:shaping:cone:angle", "cone angle " + formatNumber(angle) + " <= 0; using 0.01 degrees");
        angle = 0.01;
    }
    return std::make_pair(angle * Pi / 180.0, std::clamp(softness, 0.0, 1.0));
}

}  // namespace

LightResult translateLight(const AttributeRecord& rec, const LightContext& ctx, Diagnostics& d) {
    const std::string& path = rec.primPath;
    LightReader r(rec, d);
    LightResult out;
    double intensity = r.number("inputs:intensity", 1.0);
    double exposure = r.number("inputs:exposure", 0.0);
    Spectrum color = r.color("inputs:color", Spectrum(1.0));
    bool normalize = r.flag("inputs:normalize", false);
    if (!std::isfinite(intensity) || !std::isfinite(exposure) || !color.isFinite()) {
        const char* name = !std::isfinite(intensity) ? "inputs:intensity" : !std::isfinite(exposure) ? "inputs:exposure" : "inputs:color";
        d.error(path, name, std::string(name + 7) + " is not finite; light skipped");
        return out;
    }
    if (intensity < 0 || color.minValue() < 0) {
        d.warn(path, intensity < 0 ? "inputs:intensity" : "inputs:color", "negative emission clamped to 0");
        intensity = std::max(intensity, 0.0);
        for (int c = 0; c < 3; ++c) color[c] = std::max(color[c], 0.0);
    }
    Spectrum s = color * (intensity * std::exp2(exposure));
    if (r.flag("inputs:enableColorTemperature", false)) {
        double kelvin = r.number("inputs:colorTemperature", 6500.0);
        if (std::isfinite(kelvin)) s = s * usdLuxBlackbody(kelvin);
        else d.error(path, "inputs:colorTemperature", "colorTemperature is not finite; ignored");
    }
    if (!s.isFinite()) {  // e.g. 2^exposure overflowed
        d.error(path, "inputs:exposure", "intensity * 2^exposure is not finite; light skipped");
        return out;
    }
    for (const char* name : {"inputs:diffuse", "inputs:specular"}) {
        double v = r.number(name, 1.0);
        if (v != 1.0)
            d.warn(path, name, std::string(name + 7) + " = " + formatNumber(v) + " is a non-physical control and is ignored");
    }
    if (ctx.hasFilters) d.warn(path, "light:filters", "light filters are not supported; ignored");

    const Affine& world = ctx.lightToWorld;
    if (!world.isFinite()) {
        d.error(path, "xformOpOrder", "transform is not finite (NaN or infinite); light skipped");
        return out;
    }
    Vec3 pos = world.point(Vec3());
    Vec3 axis = world.vector(Vec3(0, 0, -1));
    axis = length(axis) > 0 ? volphoton::normalize(axis) : Vec3(0, 0, -1);
    double linScale = std::cbrt(std::abs(world.determinant()));
    out.scalars["normalize"] = normalize;
    try {
        if (ctx.kind == "distant") {
            double half = std::clamp(r.number("inputs:angle", 0.53), 0.0, 180.0) * Pi / 180.0 / 2.0;
            Spectrum E = (normalize || half == 0.0) ? s : s * (Pi * std::sin(half) * std::sin(half));
            out.kind = "distant";
            out.emission = E;
            out.quantity = "irradiance";
            out.vectors["direction"] = axis;
            out.scalars["half_angle"] = half;
            out.light = makeDistantLight(axis, half, E);
        } else if (ctx.kind == "sphere") {
            double rad = r.number("inputs:radius", 0.5) * linScale;
            bool point = r.flag("treatAsPoint", false) || !(rad > 0);
            Spectrum L = normalize && rad > 0 ? s / (4 * Pi * rad * rad) : s;
            double radius = point ? 0.0 : rad;
            out.emission = point ? (rad > 0 ? L * (Pi * rad * rad) : L) : L;
            out.quantity = point ? "intensity" : "radiance";
            out.vectors["position"] = pos;
            out.scalars["radius"] = radius;
            out.scalars["authored_radius"] = rad;
            if (auto cone = shaping(r, path, d)) {
                out.kind = "spot";
                out.vectors["axis"] = axis;
                out.scalars["cone_angle"] = cone->first;
                out.scalars["cone_softness"] = cone->second;
                out.light = makeSpotLight(pos, radius, out.emission, axis, cone->first, cone->second);
            } else {
                out.kind = radius == 0 ? "point" : "sphere";
                out.light = makeSphereLight(pos, radius, out.emission);
            }
        } else if (ctx.kind == "rect" || ctx.kind == "disk") {
            bool rect = ctx.kind == "rect";
            double stretch = length(cross(world.vector(Vec3(1, 0, 0)), world.vector(Vec3(0, 1, 0))));
            double w = r.number("inputs:width", 1.0), h = r.number("inputs:height", 1.0), rad = r.number("inputs:radius", 0.5);
            double area = (rect ? w * h : Pi * rad * rad) * stretch;
            if (rect && !r.text("inputs:texture:file").empty())
                d.warn(path, "inputs:texture:file", "rect light textures are not supported; ignored");
            Spectrum L = normalize && area > 0 ? s / area : s;
            out.kind = ctx.kind;
            out.emission = L;
            out.quantity = "radiance";
            out.vectors["position"] = pos;
            out.vectors["normal"] = axis;
            out.scalars["area"] = area;
            if (rect) {
                out.scalars["width"] = w;
                out.scalars["height"] = h;
                out.light = makeRectLight(world, w, h, L);
            } else {
                out.scalars["radius"] = rad;
                out.light = makeDiskLight(world, rad, L);
            }
        } else if (ctx.kind == "dome") {
            LatLongImage image;
            std::string file = r.text("inputs:texture:file");
            std::string format = r.text("inputs:texture:format");
            if (!ctx.textureAssetPath.empty() || !file.empty()) {
                if (!format.empty() && format != "automatic" && format != "latlong")
                    d.warn(path, "inputs:texture:format", "format '" + format + "' is not supported; the texture is read as lat-long");
                if (file.empty()) {
                    d.error(path, "inputs:texture:file", "cannot resolve @" + ctx.textureAssetPath + "@; using a constant dome");
                } else {
                    try {
                        image = loadLatLongExr(file);
                        out.texture = file;
                    } catch (const std::exception& e) {
                        d.error(path, "inputs:texture:file", std::string(e.what()) + "; using a constant dome");
                    }
                }
            }
            out.kind = "dome";
            out.emission = s;
            out.quantity = "radiance";
            out.light = makeDomeLight(s, std::move(image), world);
        } else if (ctx.kind == "mesh") {
            std::string sync = r.text("light:materialSyncMode");
            if (sync.empty()) sync = "materialGlowTintsLight";  // MeshLightAPI's fallback
            if (sync != "materialGlowTintsLight" && sync != "independent" && sync != "noMaterialResponse") {
                d.warn(path, "light:materialSyncMode", "'" + sync + "' is not a materialSyncMode; using materialGlowTintsLight");
                sync = "materialGlowTintsLight";
            }
            out.kind = "mesh";
            out.emission = normalize && ctx.meshArea > 0 ? s / ctx.meshArea : s;
            out.quantity = "radiance";
            out.scalars["area"] = ctx.meshArea;
            out.materialSyncMode = sync;
        } else {
            d.warn(path, "", (ctx.typeName.empty() ? std::string("this kind of") : ctx.typeName) + " lights are not supported; ignored");
        }
    } catch (const std::exception& e) {
        d.error(path, "", std::string("cannot create the light: ") + e.what() + "; skipped");
        out.light = nullptr;
    }
    return out;
}

double meshWorldArea(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices, const Affine& toWorld) {
    double area = 0;
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        Vec3 a = toWorld.point(points[indices[t]]), b = toWorld.point(points[indices[t + 1]]),
             c = toWorld.point(points[indices[t + 2]]);
        area += 0.5 * length(cross(b - a, c - a));
    }
    return area;
}

SurfaceMaterial meshLightSurface(const LightResult& light, SurfaceMaterial m) {
    if (m.kind != SurfaceMaterial::Kind::Lambertian) {
        m.kind = SurfaceMaterial::Kind::Lambertian;
        m.albedo = Spectrum(0.0);
        m.emission = Spectrum(0.0);
    }
    bool tint = light.materialSyncMode == "materialGlowTintsLight" && !m.emission.isBlack();
    m.emission = tint ? light.emission * m.emission : light.emission;
    if (light.materialSyncMode == "noMaterialResponse") m.albedo = Spectrum(0.0);
    return m;
}

}  // namespace volphoton::translate
