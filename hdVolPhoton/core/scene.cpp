#include "core/scene.h"

#include "core/embreeRay.h"
#include "core/workCount.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "core/diagnostics.h"
#include "core/mediumAggregate.h"

namespace volphoton {

namespace {
void embreeError(void*, RTCError code, const char* str) {
    warn(std::string("embree error ") + std::to_string(static_cast<int>(code)) + ": " + (str ? str : ""));
}
}  // namespace

namespace {
/// Every undirected edge shared by exactly two triangles (a closed surface, whatever the winding).
bool isClosedMesh(const std::vector<uint32_t>& indices) {
    if (indices.empty()) return false;
    std::vector<std::pair<uint32_t, uint32_t>> edges;
    edges.reserve(indices.size());
    for (size_t t = 0; t + 2 < indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            uint32_t a = indices[t + e], b = indices[t + (e + 1) % 3];
            edges.emplace_back(std::min(a, b), std::max(a, b));
        }
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && edges[j] == edges[i]) ++j;
        if (j - i != 2) return false;
        i = j;
    }
    return true;
}
}  // namespace

void Scene::addMeshLights() {
    // Every instance of an emissive lambertian mesh is a light (uniform over its area): next-event
    // estimation and photon emission find it like any other light, chosen by power with them.
    instanceLight_.assign(desc_.instances.size(), -1);
    if (!desc_.emissiveMeshLights) return;
    for (size_t ii = 0; ii < desc_.instances.size(); ++ii) {
        const InstanceDesc& inst = desc_.instances[ii];
        const MeshDesc& m = desc_.meshes[inst.mesh];
        if (m.material.kind != SurfaceMaterial::Kind::Lambertian || m.material.emission.isBlack()) continue;
        if (!inst.transform.inverse()) continue;  // skipped above, with a warning
        std::vector<Vec3> world;
        world.reserve(m.points.size());
        for (const Vec3& p : m.points) world.push_back(inst.transform.point(p));
        // The emitting side is the one SurfaceHit::ng points to (the object-space winding's normal
        // carried by the inverse transpose): a mirroring transform reverses the world winding.
        std::vector<uint32_t> indices = m.indices;
        if (inst.transform.determinant() < 0)
            for (size_t t = 0; t + 2 < indices.size(); t += 3) std::swap(indices[t + 1], indices[t + 2]);
        LightPtr light;
        try {
            light = makeMeshLight(m.name, std::move(world), indices, m.material.emission);
        } catch (const std::exception& e) {
            warn("mesh '" + m.name + "': " + e.what() + "; its emission is not sampled as a light");
            continue;
        }
        if (!light) continue;  // no triangle with area: it cannot be hit either
        instanceLight_[ii] = static_cast<int>(desc_.lights.size());
        desc_.lights.push_back(std::move(light));
    }
}

Scene::Scene(SceneDesc desc) : desc_(std::move(desc)) {
    device_ = rtcNewDevice("verbose=0");
    if (!device_) throw std::runtime_error("cannot create an Embree device");
    rtcSetDeviceErrorFunction(device_, embreeError, nullptr);
    top_ = rtcNewScene(device_);
    rtcSetSceneFlags(top_, RTC_SCENE_FLAG_ROBUST);

    for (auto& m : desc_.media)
        if (!m) throw std::invalid_argument("scene: null medium");
    Bounds3 bounds;
    for (size_t mi = 0; mi < desc_.meshes.size(); ++mi) {
        MeshDesc& m = desc_.meshes[mi];
        if (m.indices.size() % 3) throw std::invalid_argument("mesh '" + m.name + "': index count is not a multiple of 3");
        if (!m.triangleElements.empty() && m.triangleElements.size() != m.indices.size() / 3)
            throw std::invalid_argument("mesh '" + m.name + "': triangleElements must be empty or one per triangle");
        for (uint32_t i : m.indices)
            if (i >= m.points.size()) throw std::invalid_argument("mesh '" + m.name + "': index out of range");
        for (const Vec3& p : m.points)
            if (!isFinite(p)) throw std::invalid_argument("mesh '" + m.name + "': non-finite point");
        if (!m.normals.empty() && m.normals.size() != m.points.size()) {
            warn("mesh '" + m.name + "': normals count does not match points; using face normals");
            m.normals.clear();
        }
        if (m.interiorMedium >= static_cast<int>(desc_.media.size()))
            throw std::invalid_argument("mesh '" + m.name + "': interior medium index out of range");
        meshClosed_.push_back(isClosedMesh(m.indices));
    }
    // A mesh with one instance goes into the top-level scene as world-space triangles (no instance
    // level: Embree's two-level traversal cost 84 ns a ray against 66 flat on benchmark scene 1,
    // tools/bench_core); meshes instanced more than once keep one shared scene. Precision is the
    // same either way: Embree transforms the float ray into an instance's space in float, and hits
    // are rebuilt in double from the object-space triangle and the barycentrics (intersect()).
    std::vector<int> instanceCount(desc_.meshes.size(), 0);
    std::vector<std::optional<Affine>> inverses;
    for (const InstanceDesc& inst : desc_.instances) {
        if (inst.mesh < 0 || inst.mesh >= static_cast<int>(desc_.meshes.size()))
            throw std::invalid_argument("instance " + std::to_string(inverses.size()) + ": mesh index out of range");
        inverses.push_back(inst.transform.inverse());
        if (inverses.back()) ++instanceCount[inst.mesh];
    }
    // The mesh's points as floats, in world space when toWorld is given; false if one is not finite.
    auto floatPoints = [](const MeshDesc& m, const Affine* toWorld, std::vector<float>* out) {
        out->resize(3 * m.points.size());
        for (size_t i = 0; i < m.points.size(); ++i) {
            Vec3 p = toWorld ? toWorld->point(m.points[i]) : m.points[i];
            for (int k = 0; k < 3; ++k) (*out)[3 * i + k] = static_cast<float>(p[k]);
        }
        return std::all_of(out->begin(), out->end(), [](float f) { return std::isfinite(f); });
    };
    std::vector<float> points;
    meshScenes_.assign(desc_.meshes.size(), nullptr);
    auto meshScene = [&](int mi) {
        if (!meshScenes_[mi]) {
            RTCScene s = rtcNewScene(device_);
            // Watertight ray/triangle tests: without ROBUST, a ray through a shared edge can miss both
            // triangles, and a path inside a closed medium mesh walks out through the "hole".
            rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
            floatPoints(desc_.meshes[mi], nullptr, &points);
            RTCGeometry g = embreeTriangles(device_, points, desc_.meshes[mi].indices);
            rtcAttachGeometry(s, g);
            rtcReleaseGeometry(g);
            rtcCommitScene(s);
            meshScenes_[mi] = s;
        }
        return meshScenes_[mi];
    };
    meshBounds_.resize(desc_.meshes.size());
    for (size_t ii = 0; ii < desc_.instances.size(); ++ii) {
        const InstanceDesc& inst = desc_.instances[ii];
        const std::optional<Affine>& inv = inverses[ii];
        if (!inv) {
            warn("instance " + std::to_string(ii) + " of mesh '" + desc_.meshes[inst.mesh].name +
                 "': transform is not invertible or not finite; the instance is skipped");
            instanceInverse_.push_back(Affine());
            continue;
        }
        instanceInverse_.push_back(*inv);
        RTCGeometry g;
        if (instanceCount[inst.mesh] == 1 && floatPoints(desc_.meshes[inst.mesh], &inst.transform, &points)) {
            g = embreeTriangles(device_, points, desc_.meshes[inst.mesh].indices);
        } else {
            g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, meshScene(inst.mesh));
            float xfm[12];  // column-major 3x4
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 3; ++r) xfm[c * 3 + r] = static_cast<float>(inst.transform.m[r][c]);
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
            rtcCommitGeometry(g);
        }
        rtcAttachGeometryByID(top_, g, static_cast<unsigned>(ii));
        rtcReleaseGeometry(g);
        for (const Vec3& p : desc_.meshes[inst.mesh].points) {
            bounds.extend(inst.transform.point(p));
            meshBounds_[inst.mesh].extend(inst.transform.point(p));
        }
    }
    rtcCommitScene(top_);
    addMeshLights();
    // Closed dielectric meshes with no light inside their bounds: a shadow ray from inside one must
    // cross its surface, where shadow rays stop (a refracting surface passes no straight line).
    sealed_.assign(desc_.meshes.size(), 0);
    for (size_t mi = 0; mi < desc_.meshes.size(); ++mi) {
        if (!meshClosed_[mi] || desc_.meshes[mi].material.kind != SurfaceMaterial::Kind::Dielectric) continue;
        const Bounds3& mb = meshBounds_[mi];
        if (mb.empty()) continue;
        bool lightInside = false;
        for (const LightPtr& l : desc_.lights) {
            std::optional<Bounds3> e = l->extent();
            if (!e) continue;  // at infinity
            bool apart = e->hi.x < mb.lo.x || e->lo.x > mb.hi.x || e->hi.y < mb.lo.y || e->lo.y > mb.hi.y ||
                         e->hi.z < mb.lo.z || e->lo.z > mb.hi.z;
            lightInside |= !apart;
        }
        sealed_[mi] = !lightInside;
    }

    // The media's own box too (volumes with bounds, media inside meshes): none when one is unbounded.
    Bounds3 media;
    bool unboundedMedium = false;
    for (int i : desc_.unboundedMedia) {
        if (i < 0 || i >= static_cast<int>(desc_.media.size())) throw std::invalid_argument("scene: unbounded medium index out of range");
        Bounds3 b = desc_.media[i]->bounds();
        if (isFinite(b.lo) && isFinite(b.hi)) {
            bounds.extend(b);
            media.extend(b);
        } else {
            unboundedMedium = true;
        }
    }
    for (size_t mi = 0; mi < desc_.meshes.size(); ++mi)
        if (desc_.meshes[mi].interiorMedium >= 0 && !meshBounds_[mi].empty()) media.extend(meshBounds_[mi]);
    for (const auto& m : desc_.media) emissiveMedia_ |= m->isEmissive();
    hasMedia_ = !desc_.unboundedMedia.empty();
    for (const auto& m : desc_.meshes) hasMedia_ |= m.interiorMedium >= 0;
    {
        // A point is in at most MediumAggregate::MaxMedia media (all unbounded media plus the
        // innermost closed mesh's): say so rather than drop the rest silently.
        size_t unbounded = desc_.unboundedMedia.size();
        bool meshMedia = false;
        for (const MeshDesc& m : desc_.meshes) meshMedia |= m.interiorMedium >= 0;
        if (unbounded > size_t(MediumAggregate::MaxMedia) || (meshMedia && unbounded >= size_t(MediumAggregate::MaxMedia))) {
            std::ostringstream msg;
            msg << "the scene has " << unbounded << " volumes/unbounded media" << (meshMedia ? " and media inside meshes" : "")
                << ", but at most " << MediumAggregate::MaxMedia
                << " media are rendered at any point (all volumes plus the innermost mesh's medium); the media after the "
                << (meshMedia ? MediumAggregate::MaxMedia - 1 : MediumAggregate::MaxMedia) << "th are ignored";
            warn(msg.str());
        }
    }
#ifdef VOLPHOTON_NO_VOLUMES
    if (hasMedia_) warn("this core is built with VOLPHOTON_NO_VOLUMES: the scene's media are ignored");
    hasMedia_ = emissiveMedia_ = false;
#endif
    if (bounds.empty()) {  // only unbounded media (or nothing): a unit box around the camera
        Vec3 eye = desc_.camera.cameraToWorld.point(Vec3());
        if (!isFinite(eye)) eye = Vec3();
        bounds.extend(eye - Vec3(1, 1, 1));
        bounds.extend(eye + Vec3(1, 1, 1));
    }
    center_ = (bounds.lo + bounds.hi) * 0.5;
    radius_ = std::max(1e-6, length(bounds.hi - bounds.lo) * 0.5);
    bounds_ = bounds;
    if (!unboundedMedium && !media.empty()) {
        mediaCenter_ = (media.lo + media.hi) * 0.5;
        mediaRadius_ = std::max(1e-300, length(media.hi - media.lo) * 0.5);
    }
}

Scene::~Scene() {
    for (RTCScene s : meshScenes_)
        if (s) rtcReleaseScene(s);
    if (top_) rtcReleaseScene(top_);
    if (device_) rtcReleaseDevice(device_);
}

bool Scene::intersect(const Ray& ray, double tMin, double tMax, SurfaceHit* hit) const {
    if (desc_.instances.empty()) return false;
    ++work::rays;
    // Embree asserts on rays outside its range (|org| <= FLT_LARGE = 1.844e18 in rtcore_ray.h);
    // nothing real lies out there (FloatSafe).
    if (!isFinite(ray.o) || !isFinite(ray.d) || std::abs(ray.o.x) > FloatSafe || std::abs(ray.o.y) > FloatSafe ||
        std::abs(ray.o.z) > FloatSafe || !(tMin <= tMax) || !(tMin < FloatSafe))
        return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = embreeRayHit(ray.o, ray.d, tMin, tMax);
    rtcIntersect1(top_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    // An instance's hit names it in instID; a single-instance mesh's triangles are geometry `instance`.
    int inst = static_cast<int>(rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID);
    const InstanceDesc& id = desc_.instances[inst];
    const MeshDesc& m = desc_.meshes[id.mesh];
    hit->t = rh.ray.tfar;
    hit->mesh = id.mesh;
    hit->instance = inst;
    hit->triangle = static_cast<int>(rh.hit.primID);
    uint32_t i0 = m.indices[3 * rh.hit.primID], i1 = m.indices[3 * rh.hit.primID + 1], i2 = m.indices[3 * rh.hit.primID + 2];
    const Vec3 &a = m.points[i0], &b = m.points[i1], &c = m.points[i2];
    Vec3 nObj = cross(b - a, c - a);
    Vec3 ng = Affine::normal(instanceInverse_[inst], nObj);
    double len = length(ng);
    hit->ng = len > 0 ? ng / len : Vec3(0, 0, 1);
    // The point from the barycentrics, in double: on the triangle's plane whatever the error of the
    // float t (which grows with the distance travelled), so a ray spawned from it needs an offset
    // for the triangle's own precision only. Its bound (pbrt-v4's idea): the rounding of each
    // coordinate scales with sum_i b_i |v_i| in object space, carried to world space by |M|, plus
    // the rounding of the translation; projected on |ng|.
    double bu = std::clamp<double>(rh.hit.u, 0.0, 1.0), bv = std::clamp<double>(rh.hit.v, 0.0, 1.0 - bu), bw = 1 - bu - bv;
    Vec3 pObj = a * bw + b * bu + c * bv;
    Vec3 aObj(std::abs(a.x) * bw + std::abs(b.x) * bu + std::abs(c.x) * bv, std::abs(a.y) * bw + std::abs(b.y) * bu + std::abs(c.y) * bv,
              std::abs(a.z) * bw + std::abs(b.z) * bu + std::abs(c.z) * bv);
    const Affine& M = id.transform;
    hit->p = M.point(pObj);
    double err[3];
    for (int r = 0; r < 3; ++r)
        err[r] = FloatError * (std::abs(M.m[r][0]) * aObj.x + std::abs(M.m[r][1]) * aObj.y + std::abs(M.m[r][2]) * aObj.z +
                               std::abs(M.m[r][3]));
    hit->pError = std::abs(hit->ng.x) * err[0] + std::abs(hit->ng.y) * err[1] + std::abs(hit->ng.z) * err[2];
    // Exactly representable planes (z = 0 with identity transforms) have no error at all, and Embree
    // accepts t = tnear: a floor far below any other offset keeps spawned rays strictly off them.
    hit->pError = std::max(hit->pError, 1e-3 * floatError(hit->p)) + std::numeric_limits<float>::min();
    if (!isFinite(hit->p) || !std::isfinite(hit->pError)) {  // degenerate instance: fall back on the ray
        hit->p = ray.at(hit->t);
        hit->pError = floatError(hit->p);
    }
    hit->ns = hit->ng;
    if (!m.normals.empty()) {
        double u = rh.hit.u, v = rh.hit.v;
        Vec3 n = m.normals[i0] * (1 - u - v) + m.normals[i1] * u + m.normals[i2] * v;
        Vec3 ns = Affine::normal(instanceInverse_[inst], n);
        double l = length(ns);
        if (l > 0 && std::isfinite(l)) {
            ns = ns / l;
            hit->ns = dot(ns, hit->ng) < 0 ? -ns : ns;
        }
    }
    return true;
}

namespace {

/// The point of triangle abc nearest to p, by the Voronoi region of p among the triangle's vertices,
/// edges and face (Ericson, "Real-Time Collision Detection", 2005, section 5.1.5).
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    Vec3 ab = b - a, ac = c - a, ap = p - a;
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    Vec3 bp = p - b;
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    Vec3 cp = p - c;
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    double denom = va + vb + vc;
    if (!(std::abs(denom) > 0)) return a;  // degenerate triangle: its vertices and edges were tried
    return a + ab * (vb / denom) + ac * (vc / denom);
}

struct NearestQuery {
    const SceneDesc* desc;
    Vec3 p;
    double best;
    std::optional<Scene::NearestSurface> found;
};

bool nearestTriangle(RTCPointQueryFunctionArguments* args) {
    auto* q = static_cast<NearestQuery*>(args->userPtr);
    // An instanced mesh's triangle names its instance on the context's stack; a flattened one is
    // geometry `instance` of the top-level scene (as in Scene::intersect).
    unsigned inst = args->context->instStackSize > 0 ? args->context->instID[0] : args->geomID;
    const InstanceDesc& id = q->desc->instances[inst];
    const MeshDesc& m = q->desc->meshes[id.mesh];
    const uint32_t* tri = &m.indices[3 * size_t(args->primID)];
    Vec3 a = id.transform.point(m.points[tri[0]]), b = id.transform.point(m.points[tri[1]]),
         c = id.transform.point(m.points[tri[2]]);
    Vec3 x = closestPointOnTriangle(q->p, a, b, c);
    double d = length(q->p - x);
    if (!(d < q->best)) return false;
    q->best = d;
    Vec3 towards = q->p - x;
    if (d > 0) {
        towards = towards / d;
    } else {
        towards = cross(b - a, c - a);
        double l = length(towards);
        towards = l > 0 ? towards / l : Vec3(0, 0, 1);
    }
    q->found = Scene::NearestSurface{x, towards, d};
    // Shrink the search to what was found (rounded up: the float radius must not cut it off).
    args->query->radius = std::nextafter(static_cast<float>(d), std::numeric_limits<float>::infinity());
    return true;
}

}  // namespace

std::optional<Scene::NearestSurface> Scene::nearestSurface(const Vec3& p, double maxDistance) const {
    // As for rays (intersect): nothing real lies beyond Embree's range.
    if (desc_.instances.empty() || !isFinite(p) || !(maxDistance > 0) || std::abs(p.x) > FloatSafe ||
        std::abs(p.y) > FloatSafe || std::abs(p.z) > FloatSafe)
        return std::nullopt;
    RTCPointQuery query;
    query.x = static_cast<float>(p.x);
    query.y = static_cast<float>(p.y);
    query.z = static_cast<float>(p.z);
    query.time = 0;
    query.radius = static_cast<float>(std::min(maxDistance, 1e30));
    RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    NearestQuery q{&desc_, p, maxDistance, std::nullopt};
    rtcPointQuery(top_, &query, &ctx, nearestTriangle, &q);
    return q.found;
}

MediumAggregate Scene::mediaFor(const MediumStack& stack) const {
    MediumAggregate agg;
#ifdef VOLPHOTON_NO_VOLUMES
    (void)stack;
    return agg;
#endif
    for (int i : desc_.unboundedMedia) agg.add(desc_.media[i].get());
    int inner = stack.innermost();
    if (inner >= 0 && desc_.meshes[inner].interiorMedium >= 0) agg.add(desc_.media[desc_.meshes[inner].interiorMedium].get());
    return agg;
}

double Scene::exitDistance(int mesh, const Ray& ray) const {
    double t0, t1;
    const Bounds3& b = meshBounds_[mesh];
    double pad = std::max(floatError(b.lo), floatError(b.hi));  // the float precision of the bounds
    Bounds3 padded{b.lo - Vec3(1, 1, 1) * pad, b.hi + Vec3(1, 1, 1) * pad};
    if (b.empty() || !padded.intersect(ray, 0.0, Infinity, &t0, &t1)) return Infinity;
    return t1;
}

MediumStack Scene::stackAt(const Vec3& p) const {
    MediumStack stack;
    // Parity along a fixed, non-axis-aligned probe direction; the nearest first crossing of a
    // containing mesh belongs to the innermost one, so containing meshes are pushed far to near.
    // The probe restarts at each crossing with that crossing's own offset (spawnTMin).
    Ray probe{p, normalize(Vec3(0.5773, 0.5774, 0.5775))};
    std::vector<std::pair<int, double>> crossings;  // mesh, first distance along the probe
    std::vector<int> parity(desc_.meshes.size(), 0);
    double tMin = 0, travelled = 0;
    SurfaceHit hit;
    for (int n = 0; n < 1024 && intersect(probe, tMin, Infinity, &hit); ++n) {
        travelled += hit.t;
        if (desc_.meshes[hit.mesh].material.kind != SurfaceMaterial::Kind::Lambertian) {
            if (parity[hit.mesh]++ == 0) crossings.push_back({hit.mesh, travelled});
        }
        probe.o = hit.p;
        tMin = spawnTMin(hit, probe.d);
    }
    std::sort(crossings.begin(), crossings.end(), [](auto& a, auto& b) { return a.second > b.second; });
    for (auto& [mesh, first] : crossings)
        if (parity[mesh] % 2 == 1) stack.toggle(mesh);
    return stack;
}

}  // namespace volphoton
