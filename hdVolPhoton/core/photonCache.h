// Photon maps kept across renders that differ only in what photons do not see: the camera, the image
// size, the AOVs, the number of passes (issue 15, "reuse what does not change").
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>

namespace volphoton {

class PhotonMap;
class PhotonBeamMap;

/// \class PhotonCache
/// Front ends keep one per scene content and hand it to every Renderer of that content: the Hydra
/// delegate until a prim other than the camera changes, the CLI across a --frames range whose
/// lights, media and geometry do not vary. The photon-map integrator then takes pass i's photon map
/// from the cache when pass i was traced before under the same key, and stores the maps it traces
/// while their total size stays within RenderSettings::photonMapBudgetBytes (later passes are traced
/// each time). A pass's photons depend only on the scene, the seed, the pass index and the count, so
/// a reused pass is bit-identical to a traced one: a render with a cache is the render without one,
/// faster. (An automatic count follows the cache's: its start and the later count its first render
/// measured, which depends on that render's view and image size.)
///
/// The key (set by the integrator at the start of each render, PhotonMapper::photonKey) hashes the
/// photon settings and the records of the deterministic pilot photons (positions, directions,
/// powers), so a change the pilot's photons meet (a light, a medium, a surface, the photon count,
/// the bounds that aim distant light) empties the cache by itself. It is a safety net, not the
/// contract: the front end still drops the cache when the scene's content changes.
///
/// Photons and beams hold no pointer into their scene (Photon, PhotonBeam), so cached maps outlive it.
/// Thread-safe; one render at a time is the intended use.
class PhotonCache {
public:
    struct Pass {
        std::shared_ptr<const PhotonMap> map;        ///< points, or
        std::shared_ptr<const PhotonBeamMap> beams;  ///< beams (RenderSettings::photonBeams)
        uint64_t traced = 0;         ///< photons traced for it
        uint64_t thinned = 0;        ///< photons the memory budget dropped
        uint64_t radiusCapped = 0;   ///< stored photons whose kernel the mean-free-path cap narrowed
        size_t size() const;  ///< photons or beams stored
        size_t bytes() const;
    };

    /// Makes `key` current: a different key than the one the cached maps were traced under empties
    /// the cache. Returns true when the maps already cached were traced under `key`.
    bool use(uint64_t key);
    /// The map of pass `pass`, or null when it was not cached under the current key.
    std::shared_ptr<const Pass> find(int pass) const;
    /// Keeps pass `pass`'s map if the cache then stays within budgetBytes; returns whether it did.
    bool store(int pass, Pass entry, size_t budgetBytes);
    /// Photon count per pass the cached maps were traced with (0 while empty). An automatic count
    /// (RenderSettings::photonsPerPass = 0) follows it, so a resized image keeps its photons.
    int photonsPerPass() const;
    void setPhotonsPerPass(int n);
    /// An automatic count's size from its measurement on (PhotonMapper, "how many photons"; 0 while
    /// not measured): a render that follows the cached count follows this too.
    int resizedPhotonsPerPass() const;
    void setResizedPhotonsPerPass(int n);
    /// combined's measured choice (Renderer, "the measured choice") over the cached maps: a later
    /// render of the same content (a camera move) follows it instead of measuring again.
    enum class Choice { Unmeasured, Photons, PathTracer };
    Choice measuredChoice() const;
    void setMeasuredChoice(Choice c);
    size_t passes() const;
    size_t bytes() const;
    void clear();

private:
    mutable std::mutex mutex_;
    uint64_t key_ = 0;
    bool hasKey_ = false;
    int photonsPerPass_ = 0, resizedPhotonsPerPass_ = 0;
    Choice measuredChoice_ = Choice::Unmeasured;
    size_t bytes_ = 0;
    std::map<int, std::shared_ptr<const Pass>> passes_;
};

}  // namespace volphoton
