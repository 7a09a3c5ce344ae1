// Deterministic counts of the operations that dominate render time, for sizing the photon pass
// against the camera pass without a clock (PhotonMapper, "photon counts that fit the job"): a clock
// would make the photon count, and so the image, depend on the machine and its load.
#pragma once

#include <cstdint>

namespace volphoton::work {

/// Per-thread running counts. A task reads them before and after its own work on its own thread
/// (snapshot()), so the difference is its work whatever else the thread did.
inline thread_local uint64_t rays = 0;  ///< Scene::intersect calls (BVH traversals)
/// MediumAggregate::properties calls (medium evaluations), each weighted by its media's
/// Medium::lookupCost (a grid's trilinear lookup costs several homogeneous ones).
inline thread_local double lookups = 0;
/// Photon-map gather candidates: photons (PhotonMap) and beams (PhotonBeamMap) a camera query tested.
/// Their number grows with the photons a pass stores, so the automatic photon count weighs them
/// (PhotonMapper: a camera pilot with the pilot photons' maps).
inline thread_local uint64_t gathers = 0;

/// Costs in work units: a ray, a medium's lookup by kind (Medium::lookupCost), and per photon traced
/// its fixed cost (emission sampling, its random stream, its record) and the factor on its lookups
/// (free flight: majorant traversal, null collisions and event sampling around each). The units are
/// relative: the three lookup costs are in proportion to the measured time of a camera lookup in each
/// kind of medium (2-core VM, 80 x 60, 2026-12-05: the cube gives the homogeneous one, the atmosphere
/// the exponential one, the VDB cloud, dense cloud and emissive smoke the grid's). RayCost,
/// PhotonLookupCost and PhotonBaseCost are then the least-squares fit of
/// `python tools/bench_photon_cost.py` to the measured balances of the six open-media benchmark
/// scenes: modelled 0.85x-1.06x the measured (rms log error 0.08), where a ray at 28 unweighted
/// lookups and no per-photon cost gave 0.62x-3.98x (0.54; fog + spot the 3.98x: its photons' fixed
/// cost was not counted).
constexpr double RayCost = 30.0, PhotonLookupCost = 2.0, PhotonBaseCost = 10.0;
/// A gather candidate (gathers: a photon disc Embree found on the ray, or a beam whose box it
/// entered, tested exactly), besides the lookups of the candidates that count. Fitted alone, the other
/// constants as they stand, by `python tools/bench_photon_cost.py --resolution 160 120 --passes 8`
/// (2-core VM, 2026-12-06) to the measured balances with each photon's gathers measured as the
/// camera pass's growth from 4096 photons to the automatic count: modelled 0.53x-1.36x the measured
/// (rms log error 0.30; without candidates counted 0.41, fog + spot's beams 2.1x).
constexpr double GatherCost = 5.0;
constexpr double HomogeneousLookupCost = 20.0, ExponentialLookupCost = 45.0, GridLookupCost = 130.0;

/// Rays and lookups counted, or their difference between two snapshots.
struct Count {
    double rays = 0, lookups = 0, gathers = 0;
    /// Work units, lookups weighted by lookupFactor (PhotonLookupCost for photons).
    double units(double lookupFactor = 1.0) const { return rays * RayCost + lookups * lookupFactor + gathers * GatherCost; }
    Count& operator+=(const Count& o) {
        rays += o.rays;
        lookups += o.lookups;
        gathers += o.gathers;
        return *this;
    }
    Count operator-(const Count& o) const { return {rays - o.rays, lookups - o.lookups, gathers - o.gathers}; }
    Count operator*(double f) const { return {rays * f, lookups * f, gathers * f}; }
};
using Snapshot = Count;
/// The work of one photon (the automatic photon count, the measured choice): its fixed cost, its
/// tracing's rays and lookups, and the gathers it adds to a camera pass.
inline double photonUnits(const Count& tracing, const Count& gathers) {
    return PhotonBaseCost + tracing.units(PhotonLookupCost) + gathers.units();
}
inline Count snapshot() { return {double(rays), lookups, double(gathers)}; }
/// What this thread counted since `from`.
inline Count since(const Count& from) { return snapshot() - from; }

}  // namespace volphoton::work
