#include "core/photonBeams.h"

#include "core/photonMap.h"
#include "core/workCount.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volphoton {

namespace {

struct BeamQuery {
    RTCIntersectContext embree;  // first member: Embree hands this pointer back to the callbacks
    const std::vector<PhotonBeam>* beams;
    const Ray* ray;
    double tMin, tMax;
    FunctionRef<void(const BeamHit&)>* visit;
};

void beamBounds(const RTCBoundsFunctionArguments* args) {
    const auto* beams = static_cast<const std::vector<PhotonBeam>*>(args->geometryUserPtr);
    const PhotonBeam& b = (*beams)[args->primID];
    float r = b.radius * 1.001f;  // float slack; the exact test is in beamIntersect
    RTCBounds* out = args->bounds_o;
    float lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
        float e = b.origin[c] + b.dir[c] * b.length;
        lo[c] = std::min(b.origin[c], e) - r;
        hi[c] = std::max(b.origin[c], e) + r;
    }
    out->lower_x = lo[0], out->lower_y = lo[1], out->lower_z = lo[2];
    out->upper_x = hi[0], out->upper_y = hi[1], out->upper_z = hi[2];
}

/// Closest approach of the query line and the beam line; reports, never accepts (traversal goes on).
void beamIntersect(const RTCIntersectFunctionNArguments* args) {
    if (!args->valid[0]) return;
    ++work::gathers;
    auto* q = reinterpret_cast<BeamQuery*>(args->context);
    const PhotonBeam& b = (*q->beams)[args->primID];
    const Ray& ray = *q->ray;
    Vec3 a(b.origin[0], b.origin[1], b.origin[2]), w(b.dir[0], b.dir[1], b.dir[2]);
    double dw = dot(ray.d, w), denom = 1 - dw * dw;
    if (!(denom > 1e-8)) return;  // parallel: sin theta < 1e-4
    Vec3 r0 = ray.o - a;
    double wr = dot(w, r0), dr = dot(ray.d, r0);
    double t = (dw * wr - dr) / denom;  // minimises |r0 + t d - s w|^2
    double s = wr + t * dw;
    if (t < q->tMin || t > q->tMax || s < 0 || s > b.length) return;
    Vec3 gap = r0 + ray.d * t - w * s;
    if (lengthSquared(gap) > double(b.radius) * b.radius) return;
    (*q->visit)(BeamHit{&b, t, s, std::sqrt(denom), -dw});
}

}  // namespace

PhotonBeamMap::PhotonBeamMap(std::vector<PhotonBeam> beams, double radius) : beams_(std::move(beams)), radius_(radius) {
    for (PhotonBeam& b : beams_) b.radius = kernelRadius(b.radius, radius);
    if (!beams_.empty()) {
        RTCGeometry g = rtcNewGeometry(embree_.device(), RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(beams_.size()));
        rtcSetGeometryUserData(g, &beams_);
        rtcSetGeometryBoundsFunction(g, beamBounds, nullptr);
        rtcSetGeometryIntersectFunction(g, beamIntersect);
        embree_.attach(g);
    }
    rtcCommitScene(embree_.scene());
}

void PhotonBeamMap::query(const Ray& ray, double tMin, double tMax, FunctionRef<void(const BeamHit&)> visit) const {
    if (beams_.empty() || !(tMax > tMin)) return;
    BeamQuery q;
    rtcInitIntersectContext(&q.embree);
    q.beams = &beams_;
    q.ray = &ray;
    q.tMin = tMin;
    q.tMax = tMax;
    q.visit = &visit;
    // Boxes are entered at most a radius before the closest point (float slack aside).
    RTCRayHit rh = embreeRayHit(ray.o, ray.d, std::max(0.0, tMin - 2 * radius_), tMax + 2 * radius_);
    rtcIntersect1(embree_.scene(), &q.embree, &rh);
}

}  // namespace volphoton
