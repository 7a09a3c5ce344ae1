// Embree plumbing shared by the scene, the photon points and the photon beams: the one conversion of
// a core ray to Embree's single-ray record, and a device with one scene owned together.
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/math.h"

namespace volphoton {

/// An RTCRayHit for origin o, direction d over [tNear, tFar] (an infinite tFar stays infinite), with
/// no hit recorded yet.
inline RTCRayHit embreeRayHit(const Vec3& o, const Vec3& d, double tNear, double tFar) {
    RTCRayHit rh;
    rh.ray.org_x = static_cast<float>(o.x);
    rh.ray.org_y = static_cast<float>(o.y);
    rh.ray.org_z = static_cast<float>(o.z);
    rh.ray.dir_x = static_cast<float>(d.x);
    rh.ray.dir_y = static_cast<float>(d.y);
    rh.ray.dir_z = static_cast<float>(d.z);
    rh.ray.tnear = static_cast<float>(tNear);
    rh.ray.tfar = std::isinf(tFar) ? std::numeric_limits<float>::infinity() : static_cast<float>(tFar);
    rh.ray.mask = ~0u;
    rh.ray.flags = 0;
    rh.ray.time = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

/// A committed triangle geometry: float3 vertices (x, y, z after one another), three `indices` a
/// triangle. The caller attaches it to a scene and releases it (Scene, tools/bench_core's raw scene).
inline RTCGeometry embreeTriangles(RTCDevice device, const std::vector<float>& points, const std::vector<uint32_t>& indices) {
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), points.size() / 3));
    std::copy(points.begin(), points.end(), v);
    unsigned* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), indices.size() / 3));
    std::copy(indices.begin(), indices.end(), idx);
    rtcCommitGeometry(g);
    return g;
}

/// \class EmbreeScene
/// An Embree device with one scene, created together and released together (PhotonMap, PhotonBeamMap).
class EmbreeScene {
public:
    /// `what` names the owner in the error thrown when Embree cannot make a device.
    explicit EmbreeScene(const char* what) {
        device_ = rtcNewDevice("verbose=0");
        if (!device_) throw std::runtime_error(std::string("cannot create an Embree device for ") + what);
        scene_ = rtcNewScene(device_);
    }
    ~EmbreeScene() {
        if (scene_) rtcReleaseScene(scene_);
        if (device_) rtcReleaseDevice(device_);
    }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;
    RTCDevice device() const { return device_; }
    RTCScene scene() const { return scene_; }
    /// Commits g, attaches it to the scene and drops this reference to it.
    void attach(RTCGeometry g) {
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene_, g);
        rtcReleaseGeometry(g);
    }

private:
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
};

}  // namespace volphoton
