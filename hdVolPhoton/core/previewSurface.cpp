#include "core/previewSurface.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace volphoton {

namespace {
std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}
std::string str(const Spectrum& s) { return "(" + num(s[0]) + ", " + num(s[1]) + ", " + num(s[2]) + ")"; }
}  // namespace

std::optional<SurfaceMaterial> previewSurfaceMaterial(const PreviewSurfaceInputs& in,
                                                      std::vector<PreviewSurfaceNote>* notes) {
    auto note = [&](bool error, const char* input, const std::string& s) {
        if (notes) notes->push_back({error, input, s});
    };
    Spectrum diffuse = in.diffuseColor, emissive = in.emissiveColor;
    if (!diffuse.isFinite()) {
        note(true, "diffuseColor", "diffuseColor is not finite; using the default");
        diffuse = Spectrum(0.18);
    }
    if (!emissive.isFinite()) {
        note(true, "emissiveColor", "emissiveColor is not finite; using the default");
        emissive = Spectrum(0.0);
    }
    Spectrum clamped;
    for (int c = 0; c < 3; ++c) clamped[c] = std::min(std::max(diffuse[c], 0.0), 1.0);
    if (!(clamped == diffuse)) note(false, "diffuseColor", "diffuseColor " + str(diffuse) + " outside [0, 1]; clamped to " + str(clamped));
    if (emissive.minValue() < 0) {
        note(false, "emissiveColor", "negative emissiveColor clamped to 0");
        for (int c = 0; c < 3; ++c) emissive[c] = std::max(emissive[c], 0.0);
    }
    if (in.metallic > 0) note(false, "metallic", "metallic = " + num(in.metallic) + " is not supported; rendered as diffuse");
    if (in.opacityThreshold > 0 && in.opacity < in.opacityThreshold) return std::nullopt;  // cutout
    if (in.opacity <= 1e-3) {
        if (in.iorAuthored && in.ior > 1.0 + 1e-6) {
            SurfaceMaterial glass;
            glass.kind = SurfaceMaterial::Kind::Dielectric;
            glass.ior = in.ior;
            return glass;
        }
        return std::nullopt;  // fully transparent
    }
    if (in.opacity < 1.0)
        note(false, "opacity", "opacity = " + num(in.opacity) +
             ": partial transparency is not supported; rendered opaque (use opacity 0 with an ior for glass)");
    SurfaceMaterial m;
    m.albedo = clamped;
    m.emission = emissive;
    return m;
}

}  // namespace volphoton
