// The renderer's scene: plain description structs that any front end fills (the usd-core front end
// through the Python bindings, the Hydra delegate in Sync), and the Scene built from them once:
// Embree BVH over instanced triangle meshes, lights, media.
//
// Surface materials:
// | kind        | fields            | meaning                                                         |
// |-------------|-------------------|-----------------------------------------------------------------|
// | lambertian  | albedo, emission  | diffuse reflector; emission is radiance leaving the front side   |
// | dielectric  | ior               | smooth Fresnel interface (glass, a translucent object's surface) |
// | boundary    |                   | index-matched (ior = 1) medium container: invisible to light     |
// A mesh with an interior medium (index into SceneDesc::media) bounds it; it must be closed. Media
// listed in unboundedMedia (volumes, atmospheres, camera fog) are bounded by their own bounds.
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/lights.h"
#include "core/medium.h"
#include "core/mediumAggregate.h"

namespace volphoton {

struct SurfaceMaterial {
    enum class Kind { Lambertian, Dielectric, Boundary };
    Kind kind = Kind::Lambertian;
    Spectrum albedo{0.5};
    Spectrum emission{0.0};
    double ior = 1.5;
};

struct MeshDesc {
    std::string name;
    std::vector<Vec3> points;
    std::vector<uint32_t> indices;  ///< triangles
    std::vector<Vec3> normals;      ///< optional, per vertex
    SurfaceMaterial material;
    int interiorMedium = -1;  ///< index into SceneDesc::media, or -1
    /// Optional, one per triangle: the front end's element (authored face) index of the triangle,
    /// reported by the element-id image. Empty: the triangle index.
    std::vector<int> triangleElements;
};

struct InstanceDesc {
    int mesh = 0;
    Affine transform;
    /// Opaque identities the front end gives this instance, reported per pixel by the id images of
    /// the Film (the Hydra delegate: the rprim's prim id and the instance index). -1: none.
    int objectId = -1;
    int instanceId = -1;
};

struct SceneDesc {
    std::vector<MeshDesc> meshes;
    std::vector<InstanceDesc> instances;  ///< a mesh with no instance is not rendered
    std::vector<MediumPtr> media;
    std::vector<int> unboundedMedia;
    std::vector<LightPtr> lights;
    CameraDesc camera;
    /// Every instance of an emissive lambertian mesh becomes a light (Scene::instanceLight). false:
    /// emissive meshes are found by hits only, as before they were lights: a baseline for
    /// tools/bench_emissive.py (the path tracer is unbiased either way; the photon map then has no
    /// photons from them).
    bool emissiveMeshLights = true;
};

struct SurfaceHit {
    double t = Infinity;
    Vec3 p;
    Vec3 ng;  ///< geometric normal, unit, facing as authored
    Vec3 ns;  ///< shading normal, unit, same side as ng
    int mesh = -1;
    int instance = -1;
    int triangle = -1;  ///< index of the triangle within the mesh
    /// Bound on how far, along ng, the surface Embree intersects (single precision: rounded
    /// vertices, transform and ray origin) may lie from p. It follows the magnitude of the
    /// triangle's own coordinates, never the scene's size (Scene::spawnTMin).
    double pError = 0;
};

/// The closed dielectric and boundary meshes the path is inside, innermost last. Crossing one toggles
/// it (robust to either winding). The innermost mesh's interior medium replaces enclosing ones
/// (nesting, not overlap); a dielectric with no medium is a clear interior.
struct MediumStack {
    static constexpr int MaxDepth = 8;
    int mesh[MaxDepth];
    int size = 0;
    void toggle(int meshIndex) {
        for (int i = 0; i < size; ++i)
            if (mesh[i] == meshIndex) {
                for (int j = i; j + 1 < size; ++j) mesh[j] = mesh[j + 1];
                --size;
                return;
            }
        if (size < MaxDepth) mesh[size++] = meshIndex;
    }
    int innermost() const { return size ? mesh[size - 1] : -1; }
    bool contains(int meshIndex) const {
        for (int i = 0; i < size; ++i)
            if (mesh[i] == meshIndex) return true;
        return false;
    }
};

/// \class Scene
/// Built once from a SceneDesc (validating it) and then immutable; shared by render threads.
class Scene {
public:
    explicit Scene(SceneDesc desc);
    ~Scene();
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    bool intersect(const Ray& ray, double tMin, double tMax, SurfaceHit* hit) const;
    /// Media along a segment: the unbounded ones plus the innermost interior medium of the stack.
    MediumAggregate mediaFor(const MediumStack& stack) const;
    /// Where `ray` leaves the world bounds of mesh `mesh` (infinity when it does not meet them). A
    /// path inside a mesh that finds no surface ahead has escaped through a hole in it (an open or
    /// broken mesh): its medium ends here rather than extending to infinity.
    double exitDistance(int mesh, const Ray& ray) const;
    /// Stack of closed dielectric/boundary meshes containing p, found by parity along a probe ray.
    MediumStack stackAt(const Vec3& p) const;
    /// The surface point nearest to a point, and the unit vector from it towards the point (the
    /// geometric normal, turned towards the point, when the point lies on the surface).
    struct NearestSurface {
        Vec3 p, towards;
        double distance = 0;
    };
    /// The nearest point of any surface within `maxDistance` of p (Embree's closest-point query over
    /// the instanced triangles, distances in double in world space), or nothing.
    std::optional<NearestSurface> nearestSurface(const Vec3& p, double maxDistance) const;

    const SceneDesc& desc() const { return desc_; }
    const MeshDesc& mesh(int i) const { return desc_.meshes[i]; }
    /// Whether mesh i is topologically closed (every edge shared by exactly two triangles).
    bool meshClosed(int i) const { return meshClosed_[i] != 0; }
    /// Whether mesh i is a translucent object: a closed dielectric with a medium inside.
    bool meshTranslucent(int i) const {
        const MeshDesc& m = desc_.meshes[i];
        return meshClosed(i) && m.material.kind == SurfaceMaterial::Kind::Dielectric && m.interiorMedium >= 0;
    }
    /// Whether no light can be reached by a straight shadow ray from a point inside the meshes of
    /// `stack`: one of them is a closed dielectric (shadow rays stop at it) with no light's extent
    /// overlapping its bounds. Next-event estimation there always returns zero and is skipped.
    bool sealedFromLights(const MediumStack& stack) const {
        for (int i = 0; i < stack.size; ++i)
            if (sealed_[stack.mesh[i]]) return true;
        return false;
    }
    /// Whether some light is a delta light (point, spot of radius 0, sharp distant light).
    bool hasDeltaLight() const {
        return std::any_of(desc_.lights.begin(), desc_.lights.end(), [](const LightPtr& l) { return l->isDelta(); });
    }
    /// Whether some mesh is sealed from the lights (sealedFromLights for a stack holding it).
    bool hasSealedMeshes() const { return std::find(sealed_.begin(), sealed_.end(), 1) != sealed_.end(); }
    /// The SceneDesc's lights, then one mesh light per instance of an emissive lambertian mesh.
    const std::vector<LightPtr>& lights() const { return desc_.lights; }
    /// Index in lights() of instance i's mesh light, or -1 when the instance does not emit.
    int instanceLight(int instance) const { return instance >= 0 ? instanceLight_[instance] : -1; }
#ifdef VOLPHOTON_NO_VOLUMES
    // Benchmark baseline (CMake option VOLPHOTON_NO_VOLUMES): media are ignored and every
    // `if (scene.hasMedia())` branch of the integrators is dead code the compiler removes.
    constexpr bool hasMedia() const { return false; }
    constexpr bool hasEmissiveMedia() const { return false; }
#else
    bool hasMedia() const { return hasMedia_; }
    bool hasEmissiveMedia() const { return emissiveMedia_; }
#endif
    bool hasSurfaces() const { return !desc_.instances.empty(); }
    /// Bounding sphere of geometry and bounded media (for distant and dome light photons).
    Vec3 center() const { return center_; }
    double radius() const { return radius_; }
    /// The box of geometry and bounded media that center() and radius() bound.
    const Bounds3& bounds() const { return bounds_; }
    /// World bounds of mesh `mesh` over its instances (empty when it has none).
    const Bounds3& meshBounds(int mesh) const { return meshBounds_[mesh]; }
    /// Bounding sphere of the media (volumes with bounds and media inside meshes); radius 0 when
    /// there are none or one is unbounded. The photon map aims photons and sizes its defaults by it.
    Vec3 mediaCenter() const { return mediaCenter_; }
    double mediaRadius() const { return mediaRadius_; }
    /// Bound on the single-precision rounding error of a point p: FloatError x max_i |p_i|.
    /// Offsets that have no surface to go by (shadow-ray ends, mesh bounds) use it.
    static double floatError(const Vec3& p) {
        return FloatError * std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    }
    /// Ray parameter from which a ray leaving `hit` along w may meet surfaces again: past the slab of
    /// half-width hit.pError around the surface, measured along w (a grazing direction is taken at
    /// no less than MinSpawnCos). The offset follows the local float precision of the hit (pbrt-v4's
    /// error bounds), not the scene's extent: a thin layer or a close surface far from any large
    /// object keeps its own scale. Rays start exactly at the hit point, so the medium behind a
    /// surface is tracked from the surface itself; offsetting the origin instead skipped a layer
    /// of medium, which matters when the mean free path is below the offset.
    double spawnTMin(const SurfaceHit& hit, const Vec3& w) const {
        return hit.pError / std::max(std::abs(dot(w, hit.ng)), MinSpawnCos);
    }
    /// Relative error bound for single-precision intersection (vertices, instance transform and
    /// ray origin rounded to float, then Embree's watertight test): 16 float epsilons, about four
    /// times pbrt-v4's gamma(7) + gamma(3) for the same steps.
    static constexpr double FloatError = 16 * 1.1920928955078125e-07;
    static constexpr double MinSpawnCos = 0.02;

private:
    /// Coordinates beyond this are outside Embree's range (FLT_LARGE = 1.844e18 in rtcore_ray.h):
    /// queries there find nothing.
    static constexpr double FloatSafe = 1e18;
    SceneDesc desc_;
    RTCDevice device_ = nullptr;
    RTCScene top_ = nullptr;
    std::vector<RTCScene> meshScenes_;
    std::vector<Affine> instanceInverse_;
    std::vector<Bounds3> meshBounds_;  ///< world bounds of each mesh over its instances
    bool hasMedia_ = false, emissiveMedia_ = false;
    Vec3 center_;
    double radius_ = 1;
    Bounds3 bounds_;
    Vec3 mediaCenter_;
    double mediaRadius_ = 0;
    std::vector<char> meshClosed_;
    std::vector<char> sealed_;  ///< closed dielectric meshes with no light inside (sealedFromLights)
    std::vector<int> instanceLight_;  ///< per instance: index of its mesh light in lights(), or -1

    void addMeshLights();
};

}  // namespace volphoton
