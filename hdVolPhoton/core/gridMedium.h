// Heterogeneous medium over OpenVDB float grids (density, and optionally temperature, emission and
// albedo fields), sampled with trilinear interpolation, with a coarse majorant grid for free flights.
//
// | parameter        | type     | default   | units            | meaning                                        |
// |------------------|----------|-----------|------------------|------------------------------------------------|
// | filePath         | string   |           |                  | .vdb file (loadGridMedium only)                |
// | densityGrid      | string   | "density" |                  | FloatGrid of relative density (>= 0)           |
// | temperatureGrid  | string   | ""        |                  | FloatGrid of temperature units; "" = none      |
// | emissionGrid     | string   | ""        |                  | FloatGrid scaling `emission`; "" = none        |
// | albedoGrid       | string   | ""        |                  | FloatGrid scaling `albedo` (clamped to [0,1])  |
// | densityScale     | double   | 1         | 1/scene unit     | sigma_t = densityScale*density(x)*extinctionColor |
// | extinctionColor  | Spectrum | (1,1,1)   |                  | per-channel extinction multiplier (>= 0)       |
// | albedo           | Spectrum | (0.8,...) |                  | sigma_s / sigma_t, each in [0, 1]              |
// | emission         | Spectrum | 0         | radiance/unit    | emitted radiance per unit length               |
// | emissionScale    | double   | 1         |                  | multiplies `emission` and blackbody emission   |
// | temperatureScale | double   | 1         | K per grid unit  | T = temperatureScale * temperature(x)          |
// | phase            | PhasePtr | isotropic |                  | phase function                                 |
// | objectToWorld    | Affine   | identity  |                  | grid world (object) space -> render world space|
//
// Coefficients at a world point x (all grids sampled trilinearly in their own index space):
//   sigma_t(x)  = densityScale * density(x) * extinctionColor
//   sigma_s(x)  = sigma_t(x) * clamp(albedo * albedoGrid(x), 0, 1)          (albedoGrid = 1 if unbound)
//   sigma_a(x)  = sigma_t(x) - sigma_s(x)
//   emission(x) = emissionScale * emission * emissionGrid(x)                 (emissionGrid = 1 if unbound)
//               + emissionScale * sigma_a(x) * blackbodyRadiance(temperatureScale * temperature(x))
// Every coefficient, emission included, is 0 where the interpolated density is 0: the free-flight
// sampler only visits points inside majorant segments, which cover exactly where density may be
// non-zero, so emission elsewhere could never be gathered. The blackbody term follows Kirchhoff's
// law (emission coefficient = absorption coefficient * blackbody radiance, blackbody.h), as in pbrt-v4.
//
// The medium's support is the density grid's active voxel bounding box dilated by one voxel (the
// reach of trilinear interpolation); a non-zero background value applies inside it only.
// NaN, infinite and negative values of every grid are clamped to 0 at load, with one warning per grid.
// Files are read by vdbFile.h; the test scenes' cloud is written by proceduralCloud.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include "core/medium.h"
#include "core/workCount.h"
#include "core/vdbFile.h"  // light: declares openvdb::GridBase only

namespace volphoton {

class MajorantGrid;

/// Parameters of a grid medium (the schema's VolPhotonMediumAPI plus the bound field names).
struct GridMediumDesc {
    std::string filePath;
    std::string densityGrid = "density";
    std::string temperatureGrid;  ///< "" = no temperature field (no blackbody emission)
    std::string emissionGrid;     ///< "" = no emission field
    std::string albedoGrid;       ///< "" = no albedo field
    double densityScale = 1.0;
    Spectrum extinctionColor{1.0, 1.0, 1.0};
    Spectrum albedo{0.8, 0.8, 0.8};
    Spectrum emission{0.0, 0.0, 0.0};
    double emissionScale = 1.0;
    double temperatureScale = 1.0;
    PhasePtr phase;  ///< null = isotropic
    Affine objectToWorld;
    /// Grid-size cap: a grid with more active voxels is refused before its tree is read when the
    /// file records its voxel count (OpenVDB's "file_voxel_count" metadata), else right after.
    /// 2^30 float voxels are about 4 GiB plus the tree; 0 = no cap.
    std::uint64_t maxActiveVoxels = kDefaultMaxGridVoxels;
    static constexpr std::uint64_t kDefaultMaxGridVoxels = std::uint64_t(1) << 30;
};

/// In-memory grids for the GridMedium constructor; each must be an openvdb::FloatGrid with a linear
/// transform. Only `density` is required. (A FloatGrid::Ptr converts to these implicitly.)
struct GridMediumGrids {
    using GridPtr = std::shared_ptr<const openvdb::GridBase>;
    GridMediumGrids() = default;
    GridMediumGrids(GridPtr density_, GridPtr temperature_ = nullptr, GridPtr emission_ = nullptr,
                    GridPtr albedo_ = nullptr)
        : density(std::move(density_)), temperature(std::move(temperature_)), emission(std::move(emission_)),
          albedo(std::move(albedo_)) {}
    std::shared_ptr<const openvdb::GridBase> density;
    std::shared_ptr<const openvdb::GridBase> temperature;
    std::shared_ptr<const openvdb::GridBase> emission;
    std::shared_ptr<const openvdb::GridBase> albedo;
};

/// \class GridMedium
/// Immutable after construction; properties() and majorants() are thread-safe.
class GridMedium final : public Medium {
public:
    /// From in-memory grids. The caller's grids are never modified: if a grid needs sanitising
    /// (NaN/Inf/negative values) the medium keeps a cleaned deep copy. desc.filePath only names the
    /// source in messages. Throws std::runtime_error on a missing/non-float/non-linear grid or a
    /// non-invertible transform, std::invalid_argument on invalid scalar parameters.
    GridMedium(const GridMediumDesc& desc, const GridMediumGrids& grids);
    ~GridMedium() override;
    GridMedium(const GridMedium&) = delete;
    GridMedium& operator=(const GridMedium&) = delete;

    MediumProperties properties(const Vec3& p) const override;
    Spectrum extinction(const Vec3& p) const override;
    /// Walks the majorant grid in index space: one segment per run of crossed cells with equal
    /// maximum, sigmaMaj = cellMax * densityScale * extinctionColor.maxValue() * (1 + 1e-9) (the
    /// factor absorbs interpolation rounding), decay 0. Empty cells give gaps.
    void majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const override;
    Bounds3 bounds() const override;
    bool isEmissive() const override;
    double maxAlbedo() const override;
    double phasePeak() const override;
    double lookupCost() const override { return work::GridLookupCost; }
    std::string describe() const override;

    /// Largest density grid value within reach of the support, background included (after
    /// sanitising; before densityScale): majorantGrid().maxValue().
    double maxDensity() const;
    /// Support in the density grid's index space: active voxel bbox dilated by one voxel
    /// (voxel centres at integer coordinates). Empty when the grid has no active values.
    Bounds3 indexBounds() const;
    /// Active voxels of the density grid, active tiles counted by the voxels they cover.
    size_t activeVoxelCount() const;
    /// Interpolated density grid value at a world point (before densityScale); 0 outside the support.
    double density(const Vec3& p) const;
    /// The majorant grid over indexBounds() (cell values are density grid maxima, unscaled).
    const MajorantGrid& majorantGrid() const;
    /// Wall-clock seconds spent building the majorant grid (statistics).
    double majorantBuildSeconds() const;
    /// Render world <-> density index space (density grid transform composed with objectToWorld).
    const Affine& worldToIndex() const;
    const Affine& indexToWorld() const;

private:
    struct Impl;
    GridMedium(const GridMediumDesc& desc, const GridMediumGrids& grids, bool gridsOwned);
    friend std::shared_ptr<GridMedium> loadGridMedium(const GridMediumDesc& desc);
    std::unique_ptr<Impl> impl_;
};

/// Opens desc.filePath, reads the named grids (readVdbFloatGrids) and builds the medium. Throws
/// std::runtime_error naming the file and grid on a missing, unreadable or corrupt file, a grid name
/// not in the file (the message lists the grids that are there), a grid that is not a FloatGrid
/// (naming its type), a frustum (non-linear) grid transform, or a non-finite / non-invertible
/// objectToWorld.
std::shared_ptr<GridMedium> loadGridMedium(const GridMediumDesc& desc);

}  // namespace volphoton
