// The one conversion of a core ray to Embree's single-ray record (scene intersection, photon points,
// photon beams).
#pragma once

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>

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

}  // namespace volphoton
