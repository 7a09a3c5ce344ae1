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
// | Mesh + MeshLightAPI | light:materialSyncMode (materialGlowTintsLight,   | no light of its own: the mesh's surface      |
// | (mesh)              | independent, noMaterialResponse); the mesh's      | emits radiance s (/ world area with          |
// |                     | world area (context)                              | normalize), see meshLightSurface(); the      |
// |                     |                                                   | Scene makes it a light (core/lights.h)       |
// Unusable values: non-finite intensity/exposure/color -> the light is skipped (error); negative
// intensity or colour channels -> clamped to 0 (warning); inputs:diffuse/specular != 1, shaping focus
// and IES, rect textures, filters -> ignored (warning); other light types -> not supported (warning).
// Units: radiance, irradiance and intensity in the renderer's linear RGB.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/lights.h"
#include "core/scene.h"
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
    /// mesh: the world-space area of the mesh's triangles (inputs:normalize divides by it).
    double meshArea = 0;
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
    std::string materialSyncMode;  ///< mesh: light:materialSyncMode as used
};

LightResult translateLight(const AttributeRecord& record, const LightContext& context, Diagnostics& diagnostics);

/// The world-space area of triangles (indices in threes) under toWorld: LightContext::meshArea.
double meshWorldArea(const std::vector<Vec3>& points, const std::vector<uint32_t>& indices, const Affine& toWorld);

/// The surface of a mesh with MeshLightAPI (`light` from translateLight with kind "mesh"), given the
/// surface its bound material makes (UsdLux materialSyncMode):
/// | materialSyncMode                 | emission                                    | reflection        |
/// |----------------------------------|---------------------------------------------|-------------------|
/// | materialGlowTintsLight (default) | light x the material's emissiveColor, or    | the material's    |
/// |                                  | the light's alone when that is black        |                   |
/// | independent                      | the light's (the material's glow ignored)   | the material's    |
/// | noMaterialResponse               | the light's                                 | none (albedo 0)   |
/// Emission is lambertian: a dielectric or boundary material becomes a black lambertian emitter.
SurfaceMaterial meshLightSurface(const LightResult& light, SurfaceMaterial material);

}  // namespace volphoton::translate
