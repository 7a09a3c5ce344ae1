// Deterministic counts of the operations that dominate render time, for sizing the photon pass
// against the camera pass without a clock (PhotonMapper, "photon counts that fit the job"): a clock
// would make the photon count, and so the image, depend on the machine and its load.
#pragma once

#include <cstdint>

namespace volphoton::work {

/// Per-thread running counts. A task reads them before and after its own work on its own thread
/// (snapshot()), so the difference is its work whatever else the thread did.
inline thread_local uint64_t rays = 0;     ///< Scene::intersect calls (BVH traversals)
inline thread_local uint64_t lookups = 0;  ///< MediumAggregate::properties calls (medium evaluations)

/// Costs in units of one camera-path medium lookup (a march step or a shadow-ray step): a ray, and a
/// photon's medium lookup (free flight: majorant traversal, null collisions, event sampling around
/// it). Fitted to the six benchmark scenes' measured photon and camera costs at 80 x 60 (2-core VM):
/// the modelled balance is 0.68x-1.29x the measured one (rms log error 0.19; RayCost alone, 27.5,
/// left 0.68x-2.28x). `python tools/bench_photon_cost.py` prints both and refits.
constexpr double RayCost = 28.0, PhotonLookupCost = 2.0;

/// Rays and lookups counted, or their difference between two snapshots.
struct Count {
    double rays = 0, lookups = 0;
    /// Work units, a lookup costing lookupCost (PhotonLookupCost for photons).
    double units(double lookupCost = 1.0) const { return rays * RayCost + lookups * lookupCost; }
    Count& operator+=(const Count& o) {
        rays += o.rays;
        lookups += o.lookups;
        return *this;
    }
    Count operator*(double f) const { return {rays * f, lookups * f}; }
};
using Snapshot = Count;
inline Count snapshot() { return {double(rays), double(lookups)}; }
/// What this thread counted since `from`.
inline Count since(const Count& from) { return {double(rays) - from.rays, double(lookups) - from.lookups}; }

}  // namespace volphoton::work
