// UsdLux light attributes -> core lights: the one set of rules both front ends apply.
//
// With s = intensity * 2^exposure * color (* usdLuxBlackbody(colorTemperature) when
// enableColorTemperature is on):
// | light (kind)        | attributes read                                   | core light                                   |
// |---------------------|---------------------------------------------------|----------------------------------------------|
// | DistantLight        | inputs:angle (degrees, clamped to [0, 180])       | irradiance E = s with normalize or angle 0,  |
// | (distant)           |                                                   | else s pi sin^2(angle/2) (s = disk radiance) |
// | SphereLight         | inputs:radius (x cube root of |det| of the        | radiance s (/ 4 pi r^2 with normalize);      |
// | (sphere)            | transform), treatAsPoint                          | treatAsPoint or r = 0: point light of        |
// |                     |                                                   | intensity L pi r^2 (s when r = 0)            |
// | + shaping           | inputs:shaping:cone:angle (degrees; >= 180: none),| spot light around world -Z                   |
// |                     | inputs:shaping:cone:softness ([0, 1])             |                                              |
// | RectLight (rect)    | inputs:width, inputs:height                       | radiance s (/ world area with normalize)     |
// | DiskLight (disk)    | inputs:radius                                     | radiance s (/ world area with normalize)     |
// | DomeLight (dome)    | inputs:texture:file (lat-long OpenEXR, resolved), | radiance s x texture                         |
// |                     | inputs:texture:format (automatic, latlong)        |                                              |
// Unusable values: non-finite intensity/exposure/color -> the light is skipped (error); negative
// intensity or colour channels -> clamped to 0 (warning); inputs:diffuse/specular != 1, shaping focus
// and IES, rect textures, filters -> ignored (warning); other light types -> not supported (warning).
// Units: radiance, irradiance and intensity in the renderer's linear RGB.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/lights.h"
#include "core/translate/record.h"

namespace volphoton::translate {

/// UsdLuxBlackbodyTemperatureAsRgb: RGB of a blackbody at `kelvin` (clamped to [1000, 10000]),
/// normalised to Rec.709 luminance 1 (6500 K is white). Catmull-Rom interpolation of the table of
/// John Walker, "Colour Rendering of Spectra" (as UsdLux tabulates it, 500 K steps).
Spectrum usdLuxBlackbody(double kelvin);

/// The attribute names the rules above read, by their UsdLux names ("inputs:intensity", ...).
const std::vector<std::string>& lightAttributeNames();

/// What the front end knows beyond the attributes.
struct LightContext {
    std::string kind;  ///< distant, sphere, rect, disk, dome; anything else is not supported
    std::string typeName;  ///< for messages (e.g. "CylinderLight")
    Affine lightToWorld;
    bool hasFilters = false;  ///< light:filters has targets
    /// inputs:texture:file as authored (the record holds the resolved path, or nothing when it
    /// cannot be resolved).
    std::string textureAssetPath;
};

/// A translated light and what a front end reports about it.
struct LightResult {
    LightPtr light;          ///< null: skipped (diagnostics say why)
    std::string kind;        ///< distant, sphere, point, spot, rect, disk, dome
    Spectrum emission;       ///< the value given to the core
    std::string quantity;    ///< radiance, irradiance or intensity
    std::map<std::string, double> scalars;  ///< half_angle, radius, authored_radius, area, width, ...
    std::map<std::string, Vec3> vectors;    ///< position, direction, axis, normal
    std::string texture;     ///< the dome texture actually used ("" = constant)
};

LightResult translateLight(const AttributeRecord& record, const LightContext& context, Diagnostics& diagnostics);

}  // namespace volphoton::translate
