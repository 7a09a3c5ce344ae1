// Light sources. Quantities are physical (the USD front ends convert UsdLux intensity, exposure,
// colour and normalize into them):
//
// | kind     | parameters                                   | emitted quantity                          |
// |----------|----------------------------------------------|-------------------------------------------|
// | distant  | direction (propagation), halfAngle (rad)     | irradiance E (W/m^2) normal to direction  |
// | sphere   | position, radius (0: point light)            | radiance L; intensity I (W/sr) if point   |
// |          | spot: axis, coneAngle (rad), coneSoftness    | spot falloff, see spotFalloff()           |
// | rect     | lightToWorld, width, height                  | radiance L, emitted towards local -Z      |
// | disk     | lightToWorld, radius                         | radiance L, emitted towards local -Z      |
// | dome     | constant radiance or lat-long RGB texture    | radiance L(direction)                     |
// | mesh     | world-space triangles (an emissive mesh)     | radiance L from the front side (+normal)  |
//
// Mesh lights are the scene's emissive geometry (SurfaceMaterial::emission), made by the Scene for
// every emissive mesh instance: sampled uniformly by area for next-event estimation and photon
// emission. They are surfaces in the BVH, so paths find them by surface hits (intersect() is false)
// and weight those with pdfAt().
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/math.h"

namespace volphoton {

/// Light sampled from a reference point: direction towards the light, distance to it, radiance
/// arriving (intensity / d^2 for point lights) and solid-angle density (1 for delta lights).
struct LightSample {
    Vec3 wi;
    double dist = Infinity;
    Spectrum Li;
    double pdf = 0;
    bool isDelta = false;
};

/// A photon leaving a light: origin, propagation direction and flux weight (power / pdf).
struct PhotonEmission {
    Ray ray;
    Spectrum flux;
};

/// Where photons from distant and dome lights (which have no position) enter the scene. Each photon
/// of direction d starts on a plane upstream of the scene's bounding sphere (center, radius), at a
/// point of the disk that sphere projects to; with focusRadius > 0 half of the photons take a point
/// of the disk the media's bounding sphere (focusCenter, focusRadius) projects to instead. The flux
/// is divided by the mixture's density over that plane, so the estimate is unbiased either way, and
/// a small medium in a large scene (a fog layer over kilometres of terrain) still gets half of the
/// photons (the volume photon map stores photons in media only). With a non-empty `box` (the scene's
/// bounds, where nothing lies outside it) the photon then starts just before its line enters the box,
/// not on the far plane: a photon from a million units away cannot tell apart surfaces 0.02 apart
/// (single-precision intersection), one from the box's edge can. Other lights ignore it.
struct PhotonAim {
    Vec3 center;
    double radius = 1;
    Vec3 focusCenter;
    double focusRadius = 0;  ///< 0: no focus
    Bounds3 box;             ///< empty: photons start on the upstream plane
};

/// \class Light
/// Immutable; all methods thread-safe.
class Light {
public:
    virtual ~Light() = default;
    virtual LightSample sample(const Vec3& ref, double u1, double u2) const = 0;
    /// Ray-hit query for lights with area or extent (escaping rays for distant and dome lights):
    /// radiance seen along the ray if it hits the light before tMax, the hit distance and the
    /// solid-angle density sample() would have produced the direction with.
    virtual bool intersect(const Ray& ray, double tMax, double* t, Spectrum* Le, double* pdf) const = 0;
    virtual bool isDelta() const = 0;
    /// Lights that are scene geometry (mesh lights) are met by surface hits, never by intersect().
    virtual bool isGeometry() const { return false; }
    /// The environment (dome) light: RenderSettings::domeVisibleToCamera may hide it from camera rays.
    virtual bool isDome() const { return false; }
    /// A dome of one radiance in every direction (no texture).
    virtual bool isConstantDome() const { return false; }
    /// Position of a point (or point spot) light, for equiangular sampling; nullopt for others.
    virtual std::optional<Vec3> pointPosition() const { return std::nullopt; }
    /// Centre towards which equiangular sampling aims (point, spot and sphere lights); nullopt for others.
    virtual std::optional<Vec3> equiangularCenter() const { return std::nullopt; }
    /// The interval [*t0, *t1] of the line ray.o + t ray.d outside which this light sends no light
    /// to any point (a spot's cone, widened to contain its sphere), so that distance sampling towards
    /// the light may keep to it. Conservative (a superset); default: the whole line.
    virtual void litInterval(const Ray& ray, double* t0, double* t1) const {
        (void)ray;
        *t0 = -Infinity;
        *t1 = Infinity;
    }
    /// Total emitted power (W); sceneRadius bounds the scene for distant and dome lights.
    virtual Spectrum power(double sceneRadius) const = 0;
    virtual PhotonEmission emitPhoton(const PhotonAim& aim, double u[4]) const = 0;
    /// Lights that are scene geometry (mesh lights): the solid-angle density with which sample(ref)
    /// produces the point p on the light, whose geometric normal is n (for MIS at surface hits).
    /// 0 for every other light (their hits come from intersect()).
    virtual double pdfAt(const Vec3& ref, const Vec3& p, const Vec3& n) const {
        (void)ref, (void)p, (void)n;
        return 0;
    }
    /// Box holding every point that emits (a sphere light's ball, a rect's corners, a mesh light's
    /// points); nullopt for lights at infinity (distant, dome). Scene::sealedFromLights reads it.
    virtual std::optional<Bounds3> extent() const = 0;
    virtual std::string describe() const = 0;
};

using LightPtr = std::shared_ptr<const Light>;

struct LatLongImage {
    int width = 0, height = 0;
    std::vector<float> rgb;  ///< linear RGB, row-major, top row = +Y (up)
};

/// Reads a lat-long environment from an OpenEXR file; throws std::runtime_error naming the file.
LatLongImage loadLatLongExr(const std::string& path);

LightPtr makeDistantLight(const Vec3& direction, double halfAngle, const Spectrum& irradiance);
LightPtr makeSphereLight(const Vec3& position, double radius, const Spectrum& radianceOrIntensity);
/// Spot: a sphere/point light with its emission shaped by a cone around `axis`.
LightPtr makeSpotLight(const Vec3& position, double radius, const Spectrum& radianceOrIntensity, const Vec3& axis,
                       double coneAngle, double coneSoftness);
LightPtr makeRectLight(const Affine& lightToWorld, double width, double height, const Spectrum& radiance);
LightPtr makeDiskLight(const Affine& lightToWorld, double radius, const Spectrum& radiance);
/// Dome: constant radiance, or radiance * texture when the image is non-empty. worldToLight orients it.
LightPtr makeDomeLight(const Spectrum& radiance, LatLongImage image = {}, const Affine& lightToWorld = {});

/// Emissive triangles (world space; indices in threes) of radiance L leaving the front side (the
/// side the counter-clockwise winding's normal points to). Degenerate triangles are ignored; nullptr
/// when no triangle has area. Throws std::invalid_argument for negative or non-finite L.
LightPtr makeMeshLight(const std::string& name, std::vector<Vec3> points, const std::vector<uint32_t>& indices,
                       const Spectrum& radiance);

/// UsdLux ShapingAPI cone falloff: 1 inside coneAngle*(1-softness), smoothstep to 0 at coneAngle.
double spotFalloff(double cosAngle, double coneAngle, double coneSoftness);

/// The t interval [*t0, *t1] (possibly half-infinite) where the line ray.o + t ray.d (ray.d unit) lies
/// inside the single cone {x : angle(x - apex, axis) <= halfAngle}, axis unit, halfAngle in (0, pi/2);
/// false when the line misses it. A line through the apex or along the cone's surface gets the whole
/// line (true, conservative).
bool coneInterval(const Ray& ray, const Vec3& apex, const Vec3& axis, double halfAngle, double* t0, double* t1);

}  // namespace volphoton
