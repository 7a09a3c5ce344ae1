#include "core/gridMedium.h"

#include <atomic>
#include <chrono>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/blackbody.h"
#include "core/diagnostics.h"
#include "core/majorantGrid.h"
#include "core/vdbFile.h"

namespace volphoton {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::FloatTree;

namespace {

/// Unregistered accessor: the trees never change after construction, so the registration of the
/// default (safe) accessor, a concurrent hash map insertion per construction, buys nothing.
using ConstAccessor = openvdb::tree::ValueAccessor<const FloatTree, /*IsSafe=*/false>;
using LeafT = FloatTree::LeafNodeType;

// ---- transforms --------------------------------------------------------------------------------

/// Index -> grid world (object) space of a linear OpenVDB transform. OpenVDB multiplies row vectors
/// (p' = p M, translation in row 3); Affine multiplies column vectors.
Affine indexToObject(const openvdb::math::Transform& xf) {
    openvdb::math::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
    Affine a;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) a.m[i][j] = m(j, i);
        a.m[i][3] = m(3, i);
    }
    return a;
}

// ---- trilinear sampling ------------------------------------------------------------------------

/// Trilinear interpolation of the values at integer index coordinates (voxel centres).
double sampleTrilinear(ConstAccessor& acc, const Vec3& p) {
    // Outside +-2^30 the integer coordinates would overflow; no grid reaches that far.
    constexpr double Far = 1073741824.0;
    if (!(std::abs(p.x) < Far && std::abs(p.y) < Far && std::abs(p.z) < Far)) return acc.tree().background();
    double fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
    int ix = static_cast<int>(fx), iy = static_cast<int>(fy), iz = static_cast<int>(fz);
    double u = p.x - fx, v = p.y - fy, w = p.z - fz;
    const Coord c(ix, iy, iz);
    float s[8];  // s[(dx << 2) | (dy << 1) | dz]
    constexpr int Mask = LeafT::DIM - 1;
    const LeafT* leaf = ((ix & Mask) != Mask && (iy & Mask) != Mask && (iz & Mask) != Mask) ? acc.probeConstLeaf(c) : nullptr;
    if (leaf) {  // the whole 2x2x2 stencil lies in one leaf: read its buffer directly
        const float* d = leaf->buffer().data();
        const openvdb::Index o = LeafT::coordToOffset(c);
        constexpr openvdb::Index DX = LeafT::DIM * LeafT::DIM, DY = LeafT::DIM;
        s[0] = d[o];
        s[1] = d[o + 1];
        s[2] = d[o + DY];
        s[3] = d[o + DY + 1];
        s[4] = d[o + DX];
        s[5] = d[o + DX + 1];
        s[6] = d[o + DX + DY];
        s[7] = d[o + DX + DY + 1];
    } else {
        for (int k = 0; k < 8; ++k) s[k] = acc.getValue(Coord(ix + (k >> 2), iy + ((k >> 1) & 1), iz + (k & 1)));
    }
    return trilinear(s, u, v, w);
}

// ---- sanitising --------------------------------------------------------------------------------

struct BadValues {
    size_t nan = 0, inf = 0, negative = 0;
    size_t total() const { return nan + inf + negative; }
    void count(float v) {
        if (std::isnan(v)) ++nan;
        else if (std::isinf(v)) ++inf;  // both signs: -Inf counts as infinite, not negative
        else if (v < 0) ++negative;
    }
};
inline bool isBad(float v) { return !(v >= 0) || std::isinf(v); }

/// Counts the invalid values of every leaf voxel (active or not: trilinear lookups read both), every
/// tile and the background. On a non-const tree it also clamps them to 0.
template <typename TreeT>
BadValues scanValues(TreeT& tree) {
    constexpr bool Fix = !std::is_const_v<TreeT>;
    using LeafPtr = std::conditional_t<Fix, float*, const float*>;
    openvdb::tree::LeafManager<TreeT> leaves(tree);
    std::atomic<size_t> nan{0}, inf{0}, neg{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.leafCount()), [&](const tbb::blocked_range<size_t>& r) {
        BadValues local;
        for (size_t i = r.begin(); i != r.end(); ++i) {
            LeafPtr d = leaves.leaf(i).buffer().data();
            for (openvdb::Index k = 0; k < LeafT::SIZE; ++k) {
                if (!isBad(d[k])) continue;
                local.count(d[k]);
                if constexpr (Fix) d[k] = 0.0f;
            }
        }
        nan += local.nan;
        inf += local.inf;
        neg += local.negative;
    });
    BadValues bad;
    bad.nan = nan;
    bad.inf = inf;
    bad.negative = neg;
    auto tile = tree.beginValueAll();
    tile.setMaxDepth(decltype(tile)::LEAF_DEPTH - 1);
    for (; tile; ++tile) {
        float v = *tile;
        if (!isBad(v)) continue;
        bad.count(v);
        if constexpr (Fix) tile.setValue(0.0f);
    }
    float bg = tree.background();
    if (isBad(bg)) {
        bad.count(bg);
        if constexpr (Fix) tree.root().setBackground(0.0f, /*updateChildNodes=*/false);
    }
    return bad;
}

// ---- majorant grid -----------------------------------------------------------------------------

/// Inset, in voxels, of each value's reach (-1, +1 around its voxel centre). The closed reach would
/// also touch the cells that only share its boundary, where the value's trilinear weight is 0: at a
/// dense grid's edge those cells (a full cell layer on every side) then carried the edge's majorant
/// over empty space, ~1e4 null collisions per crossing at the density clamp. A point the DDA
/// attributes to such a cell by rounding (~1e-12 voxels from the boundary) gives the value a weight
/// of that order, far below the collision tests' resolution.
constexpr double ReachInset = 1e-9;

/// Densities are clamped where one voxel's optical depth would exceed this (see the constructor).
constexpr double MaxVoxelOpticalDepth = 1e4;
/// Target optical depth of one majorant cell at the grid's largest density (finer cells below it).
constexpr double MaxCellOpticalDepth = 64;

/// Fills `grid` with, per cell, the maximum of every stored value whose trilinear reach (the open
/// cube of half-width 1 voxel around the voxel centre) overlaps the cell, plus the background.
/// Leaves are processed in parallel, tiles serially; no dense copy is made.
void fillMajorants(const FloatTree& tree, MajorantGrid& grid) {
    const float bg = tree.background();
    if (bg > 0) grid.raiseAll(bg);  // any cell may touch inactive space

    auto tile = tree.cbeginValueAll();
    tile.setMaxDepth(FloatTree::ValueAllCIter::LEAF_DEPTH - 1);
    for (; tile; ++tile) {
        float v = *tile;
        if (!(v > bg)) continue;
        openvdb::CoordBBox b;
        tile.getBoundingBox(b);
        Bounds3 reach{{b.min().x() - 1 + ReachInset, b.min().y() - 1 + ReachInset, b.min().z() - 1 + ReachInset},
                      {b.max().x() + 1 - ReachInset, b.max().y() + 1 - ReachInset, b.max().z() + 1 - ReachInset}};
        grid.raiseBox(reach, v);
    }

    openvdb::tree::LeafManager<const FloatTree> leaves(tree);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.leafCount(), 16), [&](const tbb::blocked_range<size_t>& r) {
        constexpr int D = LeafT::DIM;
        constexpr int MaxSpan = 8;  // cells per axis a dilated leaf may overlap before the slow path
        for (size_t li = r.begin(); li != r.end(); ++li) {
            const LeafT& leaf = leaves.leaf(li);
            const float* data = leaf.buffer().data();
            float leafMax = 0;
            for (openvdb::Index k = 0; k < LeafT::SIZE; ++k) leafMax = std::max(leafMax, data[k]);
            if (!(leafMax > bg)) continue;
            const Coord origin = leaf.origin();
            // Per axis and local coordinate: the cells the voxel's reach overlaps.
            int c0[3][D], c1[3][D];
            bool inside[3][D];
            int lo[3] = {1 << 30, 1 << 30, 1 << 30}, hi[3] = {-1, -1, -1};
            for (int a = 0; a < 3; ++a)
                for (int l = 0; l < D; ++l) {
                    double i = origin[a] + l;
                    inside[a][l] = grid.cellRange(a, i - 1 + ReachInset, i + 1 - ReachInset, &c0[a][l], &c1[a][l]);
                    if (inside[a][l]) {
                        lo[a] = std::min(lo[a], c0[a][l]);
                        hi[a] = std::max(hi[a], c1[a][l]);
                    }
                }
            if (hi[0] < 0 || hi[1] < 0 || hi[2] < 0) continue;  // leaf entirely out of reach
            if (lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2]) {
                grid.raiseAtomic(lo[0], lo[1], lo[2], leafMax);
                continue;
            }
            const int span[3] = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
            const bool local = span[0] <= MaxSpan && span[1] <= MaxSpan && span[2] <= MaxSpan;
            float acc[MaxSpan * MaxSpan * MaxSpan];
            if (local) std::fill(acc, acc + span[0] * span[1] * span[2], 0.0f);
            for (int x = 0; x < D; ++x) {
                if (!inside[0][x]) continue;
                for (int y = 0; y < D; ++y) {
                    if (!inside[1][y]) continue;
                    for (int z = 0; z < D; ++z) {
                        if (!inside[2][z]) continue;
                        float v = data[(x * D + y) * D + z];
                        if (!(v > bg)) continue;
                        for (int cx = c0[0][x]; cx <= c1[0][x]; ++cx)
                            for (int cy = c0[1][y]; cy <= c1[1][y]; ++cy)
                                for (int cz = c0[2][z]; cz <= c1[2][z]; ++cz) {
                                    if (local) {
                                        float& m = acc[((cx - lo[0]) * span[1] + (cy - lo[1])) * span[2] + (cz - lo[2])];
                                        m = std::max(m, v);
                                    } else {
                                        grid.raiseAtomic(cx, cy, cz, v);
                                    }
                                }
                    }
                }
            }
            if (local)
                for (int cx = 0; cx < span[0]; ++cx)
                    for (int cy = 0; cy < span[1]; ++cy)
                        for (int cz = 0; cz < span[2]; ++cz) {
                            float m = acc[(cx * span[1] + cy) * span[2] + cz];
                            if (m > 0) grid.raiseAtomic(lo[0] + cx, lo[1] + cy, lo[2] + cz, m);
                        }
        }
    });
}

// ---- per-thread accessors ----------------------------------------------------------------------

enum FieldIndex { DensityField = 0, TemperatureField, EmissionField, AlbedoField, FieldCount };

std::atomic<uint64_t> nextMediumId{1};

}  // namespace

// ---- GridMedium --------------------------------------------------------------------------------

struct GridMedium::Impl {
    struct Field {
        std::string name;  // grid name, for messages
        FloatGrid::ConstPtr grid;
        Affine worldToIndex, indexToWorld;
        bool bound() const { return grid != nullptr; }
    };

    uint64_t id = 0;
    std::string source;  // file path or "<in-memory>"
    GridMediumDesc desc;
    Field fields[FieldCount];
    Bounds3 support;  // density index space
    MajorantGrid majorant;
    double majorantSeconds = 0;
    size_t activeVoxels = 0;
    double maxDensity = 0;
    double densityCap = Infinity;  // densities are clamped here (MaxVoxelOpticalDepth per voxel)
    double maxAlbedoGrid = 1;    // max of the albedo grid, clamped to [0, 1]
    double maxEmissionGrid = 1;  // max of the emission grid
    double maxTemperature = 0;   // max of the temperature grid (grid units)
    Spectrum sigmaTPerDensity;   // densityScale * extinctionColor
    double sigmaMajPerDensity = 0;
    Spectrum albedo;             // clamped to [0, 1]
    Spectrum emission;           // emission * emissionScale

    /// One accessor per field per thread, rebuilt when the thread moves to another medium. Keyed by
    /// a never-reused id, not the address, so a stale accessor is never dereferenced.
    struct AccessorCache {
        uint64_t owner = 0;
        std::optional<ConstAccessor> acc[FieldCount];
    };
    AccessorCache& accessors() const {
        thread_local AccessorCache cache;
        if (cache.owner != id) {
            for (int f = 0; f < FieldCount; ++f) {
                if (fields[f].bound()) cache.acc[f].emplace(fields[f].grid->constTree());
                else cache.acc[f].reset();
            }
            cache.owner = id;
        }
        return cache;
    }
};

namespace {

double gridMaxValue(const FloatTree& tree) {
    float m = tree.background();
    openvdb::tree::LeafManager<const FloatTree> leaves(tree);
    for (size_t i = 0; i < leaves.leafCount(); ++i) {
        const float* d = leaves.leaf(i).buffer().data();
        for (openvdb::Index k = 0; k < LeafT::SIZE; ++k) m = std::max(m, d[k]);
    }
    auto tile = tree.cbeginValueAll();
    tile.setMaxDepth(FloatTree::ValueAllCIter::LEAF_DEPTH - 1);
    for (; tile; ++tile) m = std::max(m, *tile);
    return m;
}

void checkScalar(double v, const char* name) {
    if (!std::isfinite(v) || v < 0)
        throw std::invalid_argument(std::string("grid medium: ") + name + " must be finite and >= 0");
}
void checkSpectrum(const Spectrum& s, const char* name) {
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(s[i]) || s[i] < 0)
            throw std::invalid_argument(std::string("grid medium: ") + name + " must be finite and >= 0 per channel");
}

}  // namespace

GridMedium::GridMedium(const GridMediumDesc& desc, const GridMediumGrids& grids)
    : GridMedium(desc, grids, /*gridsOwned=*/false) {}

GridMedium::GridMedium(const GridMediumDesc& desc, const GridMediumGrids& grids, bool gridsOwned)
    : impl_(std::make_unique<Impl>()) {
    initOpenVdb();
    Impl& m = *impl_;
    m.id = nextMediumId.fetch_add(1);
    m.desc = desc;
    m.source = desc.filePath.empty() ? std::string("<in-memory>") : desc.filePath;
    if (!m.desc.phase) m.desc.phase = makeIsotropicPhase();

    checkScalar(desc.densityScale, "densityScale");
    checkScalar(desc.emissionScale, "emissionScale");
    checkScalar(desc.temperatureScale, "temperatureScale");
    checkSpectrum(desc.extinctionColor, "extinctionColor");
    checkSpectrum(desc.emission, "emission");
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(desc.albedo[i])) throw std::invalid_argument("grid medium: albedo must be finite");
    m.albedo = desc.albedo;
    bool albedoClamped = false;
    for (int i = 0; i < 3; ++i) {
        double a = std::clamp(desc.albedo[i], 0.0, 1.0);
        albedoClamped |= a != desc.albedo[i];
        m.albedo[i] = a;
    }
    if (albedoClamped)
        warn("grid medium " + quote(m.source) + ": albedo (" + std::to_string(desc.albedo[0]) + ", " +
             std::to_string(desc.albedo[1]) + ", " + std::to_string(desc.albedo[2]) + ") clamped to [0, 1]");

    if (!desc.objectToWorld.isFinite())
        throw std::runtime_error("grid medium " + quote(m.source) + ": objectToWorld has non-finite entries");
    if (!desc.objectToWorld.inverse())
        throw std::runtime_error("grid medium " + quote(m.source) + ": objectToWorld is not invertible");

    const std::shared_ptr<const openvdb::GridBase>* in[FieldCount] = {&grids.density, &grids.temperature,
                                                                        &grids.emission, &grids.albedo};
    const std::string* names[FieldCount] = {&desc.densityGrid, &desc.temperatureGrid, &desc.emissionGrid,
                                            &desc.albedoGrid};
    const char* roles[FieldCount] = {"density", "temperature", "emission", "albedo"};
    if (!grids.density)
        throw std::runtime_error("grid medium " + quote(m.source) + ": no density grid given");

    for (int f = 0; f < FieldCount; ++f) {
        const auto& base = *in[f];
        if (!base) continue;
        Impl::Field& field = m.fields[f];
        field.name = !base->getName().empty() ? base->getName() : (!names[f]->empty() ? *names[f] : roles[f]);
        const std::string where = "grid " + quote(field.name) + " (" + roles[f] + ") of " + quote(m.source);
        auto grid = openvdb::GridBase::constGrid<FloatGrid>(base);
        if (!grid)
            throw std::runtime_error(where + " has value type " + base->valueType() + " (grid type " + base->type() +
                                "), but a float grid (FloatGrid) is required");
        const openvdb::math::Transform& xf = grid->transform();
        if (!xf.isLinear())
            throw std::runtime_error(where + " has a non-linear (" + xf.mapType() +
                                ") transform; only linear (affine) grid transforms are supported");
        Affine toWorld = desc.objectToWorld * indexToObject(xf);
        std::optional<Affine> toIndex = toWorld.inverse();
        if (!toIndex) throw std::runtime_error(where + ": index-to-world transform is not invertible");
        field.indexToWorld = toWorld;
        field.worldToIndex = *toIndex;

        // Sanitise. A caller's grid is copied before it is changed; a grid we read ourselves is not.
        BadValues bad = scanValues(grid->constTree());
        if (bad.total() > 0) {
            FloatGrid::Ptr fixedGrid = gridsOwned ? std::const_pointer_cast<FloatGrid>(grid) : grid->deepCopy();
            scanValues(fixedGrid->tree());
            grid = fixedGrid;
            std::ostringstream msg;
            msg << where << ": clamped " << bad.total() << " invalid value(s) to 0 (" << bad.nan << " NaN, " << bad.inf
                << " infinite, " << bad.negative << " negative)";
            if (grid->getGridClass() == openvdb::GRID_LEVEL_SET)
                msg << "; the grid is a level set (signed distance), not a fog volume";
            warn(msg.str());
        }
        field.grid = grid;
    }

    const FloatTree& tree = m.fields[DensityField].grid->constTree();
    if (tree.background() != 0.0f)
        warn("grid " + quote(m.fields[DensityField].name) + " of " + quote(m.source) + " has background value " +
             std::to_string(tree.background()) + "; it applies only inside the active voxels' bounding box");
    m.activeVoxels = static_cast<size_t>(tree.activeVoxelCount());
    openvdb::CoordBBox bbox;
    if (tree.evalActiveVoxelBoundingBox(bbox)) {
        m.support.lo = Vec3(bbox.min().x() - 1.0, bbox.min().y() - 1.0, bbox.min().z() - 1.0);
        m.support.hi = Vec3(bbox.max().x() + 1.0, bbox.max().y() + 1.0, bbox.max().z() + 1.0);
        auto start = std::chrono::steady_clock::now();
        // Optical depth across one voxel at the grid's largest density. Beyond MaxVoxelOpticalDepth a
        // voxel is opaque at any precision that matters (T = e^-1e4), so the density is clamped
        // there: delta tracking through the trilinear ramp at a dense edge then costs ~sqrt(2 x 1e4)
        // null collisions instead of a number that grows with the density (a VDB of 3e38 never
        // finished). Dense grids also get finer majorant cells, so that crossing a cell costs at most
        // ~MaxCellOpticalDepth tentative collisions even where its stencil is mostly empty.
        const Impl::Field& dens = m.fields[DensityField];
        const double voxel = std::min({length(dens.indexToWorld.vector(Vec3(1, 0, 0))),
                                       length(dens.indexToWorld.vector(Vec3(0, 1, 0))),
                                       length(dens.indexToWorld.vector(Vec3(0, 0, 1)))});
        const double sigmaPerDensity = desc.densityScale * desc.extinctionColor.maxValue();
        const double maxValue = gridMaxValue(tree);
        double voxelDepth = maxValue * sigmaPerDensity * voxel;
        if (voxelDepth > MaxVoxelOpticalDepth) {
            m.densityCap = MaxVoxelOpticalDepth / (sigmaPerDensity * voxel);
            std::ostringstream msg;
            msg << "grid " << quote(dens.name) << " of " << quote(m.source) << ": density " << maxValue << " x scale "
                << desc.densityScale << " reaches an optical depth of " << voxelDepth << " across one voxel; clamped to "
                << MaxVoxelOpticalDepth << " per voxel (density " << m.densityCap << "), which is opaque either way";
            warn(msg.str());
            voxelDepth = MaxVoxelOpticalDepth;
        }
        const double voxelsPerCell = std::clamp(MaxCellOpticalDepth / std::max(voxelDepth, 1e-300), 1.0, 8.0);
        std::array<int, 3> res = MajorantGrid::resolutionFor(m.support, voxelsPerCell, voxelsPerCell < 8 ? 256 : 128);
        m.majorant = MajorantGrid(m.support, res[0], res[1], res[2]);
        fillMajorants(tree, m.majorant);
        if (m.densityCap < Infinity) m.majorant.capAll(static_cast<float>(m.densityCap));
        m.majorantSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        m.maxDensity = m.majorant.maxValue();
    }

    m.sigmaTPerDensity = desc.extinctionColor * desc.densityScale;
    // The factor 1 + 1e-9 absorbs the rounding of the interpolation (a few ulps), so that sigma_t
    // never exceeds sigmaMaj even by one ulp.
    m.sigmaMajPerDensity = desc.densityScale * desc.extinctionColor.maxValue() * (1.0 + 1e-9);
    m.emission = desc.emission * desc.emissionScale;
    if (m.fields[AlbedoField].bound())
        m.maxAlbedoGrid = std::clamp(gridMaxValue(m.fields[AlbedoField].grid->constTree()), 0.0, 1.0);
    if (m.fields[EmissionField].bound()) m.maxEmissionGrid = gridMaxValue(m.fields[EmissionField].grid->constTree());
    if (m.fields[TemperatureField].bound())
        m.maxTemperature = gridMaxValue(m.fields[TemperatureField].grid->constTree());
}

GridMedium::~GridMedium() = default;

double GridMedium::density(const Vec3& p) const {
    const Impl& m = *impl_;
    if (m.support.empty()) return 0;
    Vec3 pi = m.fields[DensityField].worldToIndex.point(p);
    if (!m.support.contains(pi)) return 0;
    return std::min(sampleTrilinear(*m.accessors().acc[DensityField], pi), m.densityCap);
}

Spectrum GridMedium::extinction(const Vec3& p) const {
    double d = density(p);
    return d > 0 ? impl_->sigmaTPerDensity * d : Spectrum(0.0);  // as properties(): 0 where !(d > 0)
}

MediumProperties GridMedium::properties(const Vec3& p) const {
    MediumProperties mp;
    const Impl& m = *impl_;
    if (m.support.empty()) return mp;
    const Vec3 pi = m.fields[DensityField].worldToIndex.point(p);
    if (!m.support.contains(pi)) return mp;
    Impl::AccessorCache& cache = m.accessors();
    const double density = sampleTrilinear(*cache.acc[DensityField], pi);
    const double d = std::min(density, m.densityCap);
    if (!(d > 0)) return mp;
    // Another field's value at p; a field that is the density grid itself is not looked up again.
    auto field = [&](int f) {
        return m.fields[f].grid == m.fields[DensityField].grid ? density
                                                                : sampleTrilinear(*cache.acc[f], m.fields[f].worldToIndex.point(p));
    };

    const Spectrum sigma_t = m.sigmaTPerDensity * d;
    Spectrum albedo = m.albedo;
    if (m.fields[AlbedoField].bound()) albedo *= std::clamp(field(AlbedoField), 0.0, 1.0);
    const Spectrum sigma_s = sigma_t * albedo;
    mp.sigma_a = sigma_t - sigma_s;
    mp.addLobe(m.desc.phase.get(), sigma_s);

    Spectrum e = m.emission;
    if (m.fields[EmissionField].bound() && !e.isBlack()) e *= field(EmissionField);
    if (m.fields[TemperatureField].bound() && m.desc.emissionScale > 0 && !mp.sigma_a.isBlack()) {
        double T = m.desc.temperatureScale * field(TemperatureField);
        if (T > 0) e += mp.sigma_a * blackbodyRadiance(T) * m.desc.emissionScale;
    }
    mp.emission = e;
    return mp;
}

void GridMedium::majorants(const Ray& ray, double tMin, double tMax, MajorantCallback segment) const {
    const Impl& m = *impl_;
    if (m.majorant.empty() || m.sigmaMajPerDensity == 0) return;
    const Affine& w2i = m.fields[DensityField].worldToIndex;
    const double scale = m.sigmaMajPerDensity;
    // The direction is not normalised, so t along the index-space ray is the world ray's t.
    m.majorant.walk(w2i.point(ray.o), w2i.vector(ray.d), tMin, tMax, [&](double t0, double t1, double v) {
        return segment(MajorantSegment{t0, t1, v * scale, 0.0});
    });
}

Bounds3 GridMedium::bounds() const {
    const Impl& m = *impl_;
    Bounds3 b;
    if (m.support.empty()) return b;
    for (int k = 0; k < 8; ++k) {
        Vec3 c((k & 1) ? m.support.hi.x : m.support.lo.x, (k & 2) ? m.support.hi.y : m.support.lo.y,
               (k & 4) ? m.support.hi.z : m.support.lo.z);
        b.extend(m.fields[DensityField].indexToWorld.point(c));
    }
    return b;
}

bool GridMedium::isEmissive() const {
    const Impl& m = *impl_;
    if (!(m.maxDensity * m.desc.densityScale > 0) || m.desc.extinctionColor.isBlack()) return false;
    bool fromColour = !m.emission.isBlack() && m.maxEmissionGrid > 0;
    // Blackbody emission needs absorption: an albedo below 1 somewhere (an albedo grid may lower it).
    bool absorbs = m.albedo.minValue() < 1 || m.fields[AlbedoField].bound();
    bool fromTemperature = m.fields[TemperatureField].bound() && m.maxTemperature * m.desc.temperatureScale > 0 &&
                           m.desc.emissionScale > 0 && absorbs;
    return fromColour || fromTemperature;
}

double GridMedium::maxAlbedo() const {
    const Impl& m = *impl_;
    double a = 0;
    for (int i = 0; i < 3; ++i)
        if (m.desc.extinctionColor[i] > 0) a = std::max(a, m.albedo[i] * m.maxAlbedoGrid);
    return (m.maxDensity * m.desc.densityScale > 0) ? a : 0.0;
}

double GridMedium::phasePeak() const { return volphoton::phasePeak(impl_->desc.phase.get()); }

std::string GridMedium::describe() const {
    const Impl& m = *impl_;
    std::ostringstream s;
    s << "grid(file=" << quote(m.source) << " density=" << quote(m.fields[DensityField].name) << " "
      << m.activeVoxels << " active voxels";
    if (m.fields[TemperatureField].bound()) s << " temperature=" << quote(m.fields[TemperatureField].name);
    if (m.fields[EmissionField].bound()) s << " emission=" << quote(m.fields[EmissionField].name);
    if (m.fields[AlbedoField].bound()) s << " albedo=" << quote(m.fields[AlbedoField].name);
    s << " densityScale=" << m.desc.densityScale << " phase=" << m.desc.phase->describe() << ")";
    return s.str();
}

double GridMedium::maxDensity() const { return impl_->maxDensity; }
Bounds3 GridMedium::indexBounds() const { return impl_->support; }
size_t GridMedium::activeVoxelCount() const { return impl_->activeVoxels; }
const MajorantGrid& GridMedium::majorantGrid() const { return impl_->majorant; }
double GridMedium::majorantBuildSeconds() const { return impl_->majorantSeconds; }
const Affine& GridMedium::worldToIndex() const { return impl_->fields[DensityField].worldToIndex; }
const Affine& GridMedium::indexToWorld() const { return impl_->fields[DensityField].indexToWorld; }

std::shared_ptr<GridMedium> loadGridMedium(const GridMediumDesc& desc) {
    const std::string& path = desc.filePath;
    if (path.empty()) throw std::runtime_error("grid medium: no VDB file path given");
    if (desc.densityGrid.empty())
        throw std::runtime_error("grid medium " + quote(path) + ": no density grid name given");
    checkVdbPath(path);
    if (!desc.objectToWorld.isFinite())
        throw std::runtime_error("grid medium " + quote(path) + ": objectToWorld has non-finite entries");
    if (!desc.objectToWorld.inverse())
        throw std::runtime_error("grid medium " + quote(path) + ": objectToWorld is not invertible");
    auto read = readVdbFloatGrids(path,
                                  {{desc.densityGrid, "density"},
                                   {desc.temperatureGrid, "temperature"},
                                   {desc.emissionGrid, "emission"},
                                   {desc.albedoGrid, "albedo"}},
                                  desc.maxActiveVoxels);
    GridMediumGrids grids(read[0], read[1], read[2], read[3]);
    return std::shared_ptr<GridMedium>(new GridMedium(desc, grids, /*gridsOwned=*/true));
}

}  // namespace volphoton
