#include "core/photonMap.h"

#include "core/workCount.h"

#include <algorithm>

namespace volphoton {

namespace {
struct QueryContext {
    RTCIntersectContext embree;  // first member: Embree hands this pointer back to the filter
    const PhotonMap* map;
    const std::vector<Photon>* photons;
    const Ray* ray;
    double tMin, tMax;
    FunctionRef<void(const Photon&, double, double)>* visit;
};

void gatherFilter(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        args->valid[i] = 0;  // never accept: keep traversing to find every disc along the ray
        ++work::gathers;
        unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        const Photon& ph = (*ctx->photons)[prim];
        Vec3 c(ph.p[0], ph.p[1], ph.p[2]);
        Vec3 oc = c - ctx->ray->o;
        double t = dot(oc, ctx->ray->d);
        if (t < ctx->tMin || t > ctx->tMax) continue;
        double d2 = std::max(0.0, lengthSquared(oc) - t * t);
        if (d2 > double(ph.radius) * ph.radius) continue;
        (*ctx->visit)(ph, t, d2);
    }
}
}  // namespace

PhotonMap::PhotonMap(std::vector<Photon> photons, double radius) : photons_(std::move(photons)), radius_(radius) {
    for (Photon& ph : photons_) ph.radius = kernelRadius(ph.radius, radius);
    if (!photons_.empty()) {
        RTCGeometry g = rtcNewGeometry(embree_.device(), RTC_GEOMETRY_TYPE_DISC_POINT);
        float* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), photons_.size()));
        for (size_t i = 0; i < photons_.size(); ++i) {
            v[4 * i] = photons_[i].p[0];
            v[4 * i + 1] = photons_[i].p[1];
            v[4 * i + 2] = photons_[i].p[2];
            v[4 * i + 3] = photons_[i].radius * 1.001f;  // float slack; the exact test is in the filter
        }
        rtcSetGeometryIntersectFilterFunction(g, gatherFilter);
        embree_.attach(g);
    }
    rtcCommitScene(embree_.scene());
}

void PhotonMap::query(const Ray& ray, double tMin, double tMax, FunctionRef<void(const Photon&, double, double)> visit) const {
    if (photons_.empty() || !(tMax > tMin)) return;
    QueryContext ctx;
    rtcInitIntersectContext(&ctx.embree);
    ctx.map = this;
    ctx.photons = &photons_;
    ctx.ray = &ray;
    ctx.tMin = tMin;
    ctx.tMax = tMax;
    ctx.visit = &visit;
    // Embree skips discs closer to the ray origin than a multiple of their radius (its curve
    // self-intersection avoidance, EMBREE_CURVE_SELF_INTERSECTION_AVOIDANCE_FACTOR), so the query ray
    // starts `back` behind the segment; the filter measures t from the real origin.
    const double back = 4 * radius_;
    Vec3 o = ray.o - ray.d * back;
    RTCRayHit rh = embreeRayHit(o, ray.d, back + std::max(0.0, tMin - radius_), back + tMax + radius_);
    rtcIntersect1(embree_.scene(), &ctx.embree, &rh);
}

}  // namespace volphoton
