#include "core/gridMedium.h"

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/diagnostics.h"
#include "core/majorantGrid.h"
#include "core/rng.h"

namespace volphoton {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::FloatTree;

namespace {

/// Unregistered accessor: the trees never change after construction, so the registration of the
/// default (safe) accessor, a concurrent hash map insertion per construction, buys nothing.
using ConstAccessor = openvdb::tree::ValueAccessor<const FloatTree, /*IsSafe=*/false>;
using LeafT = FloatTree::LeafNodeType;

void initOpenVdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

/// Thrown by this file with a complete message; the loader rethrows it unchanged and wraps any other
/// exception (OpenVDB's, std::bad_alloc, stream failures) with the file and grid it was reading.
struct GridLoadError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

std::string quote(const std::string& s) { return "'" + s + "'"; }

// ---- blackbody ---------------------------------------------------------------------------------

/// Wyman, Sloan and Shirley 2013, multi-lobe fit: g(x; mu, s1, s2) with s1 left of mu, s2 right.
double piecewiseGaussian(double x, double mu, double s1, double s2) {
    double t = (x - mu) / (x < mu ? s1 : s2);
    return std::exp(-0.5 * t * t);
}

Spectrum blackbodyColorExact(double T) {
    // Planck: B(l, T) ~ l^-5 / (exp(c2 / (l T)) - 1), c2 = hc/k in nm K. Only the chromaticity is
    // kept, so constant factors drop out; exp(-(x - x0)) keeps the numbers in range at low T.
    const double c2 = 1.4387769e7;
    const double x0 = c2 / (830.0 * T);
    double X = 0, Y = 0, Z = 0;
    for (double l = 360.0; l <= 830.0; l += 1.0) {
        double x = c2 / (l * T);
        double b = std::pow(l / 560.0, -5.0) * std::exp(-(x - x0)) / -std::expm1(-x);
        double xb = 1.056 * piecewiseGaussian(l, 599.8, 37.9, 31.0) + 0.362 * piecewiseGaussian(l, 442.0, 16.0, 26.7) -
                    0.065 * piecewiseGaussian(l, 501.1, 20.4, 26.2);
        double yb = 0.821 * piecewiseGaussian(l, 568.8, 46.9, 40.5) + 0.286 * piecewiseGaussian(l, 530.9, 16.3, 31.1);
        double zb = 1.217 * piecewiseGaussian(l, 437.0, 11.8, 36.0) + 0.681 * piecewiseGaussian(l, 459.0, 26.0, 13.8);
        X += b * xb;
        Y += b * yb;
        Z += b * zb;
    }
    // XYZ -> linear sRGB (Rec.709 primaries, D65 white).
    Spectrum rgb(3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z, -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
                 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z);
    for (int i = 0; i < 3; ++i) rgb[i] = std::max(0.0, rgb[i]);
    double lum = luminance(rgb);
    return lum > 0 ? rgb / lum : Spectrum(0.0);
}

struct BlackbodyTable {
    static constexpr int N = 512;
    static constexpr double TMin = 300.0, TMax = 50000.0;
    Spectrum c[N];
    BlackbodyTable() {
        for (int i = 0; i < N; ++i) c[i] = blackbodyColorExact(TMin * std::pow(TMax / TMin, double(i) / (N - 1)));
    }
    Spectrum lookup(double T) const {
        double u = std::log(std::clamp(T, TMin, TMax) / TMin) / std::log(TMax / TMin) * (N - 1);
        int i = std::min(static_cast<int>(u), N - 2);
        double f = u - i;
        return c[i] * (1 - f) + c[i + 1] * f;
    }
};

const BlackbodyTable& blackbodyTable() {
    static const BlackbodyTable table;
    return table;
}

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

inline double lerp(double a, double b, double t) { return a + (b - a) * t; }

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
    double x00 = lerp(s[0], s[4], u), x01 = lerp(s[1], s[5], u), x10 = lerp(s[2], s[6], u), x11 = lerp(s[3], s[7], u);
    return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
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

// ---- public blackbody helpers ------------------------------------------------------------------

Spectrum blackbodyColor(double kelvin) {
    if (!(kelvin > 0)) return Spectrum(0.0);
    return blackbodyTable().lookup(kelvin);
}

Spectrum blackbodyRadiance(double kelvin) {
    if (!(kelvin > 0) || !std::isfinite(kelvin)) return Spectrum(0.0);
    double t = kelvin / 1000.0;
    return blackbodyColor(kelvin) * (t * t * t * t);
}

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
        throw GridLoadError("grid medium " + quote(m.source) + ": objectToWorld has non-finite entries");
    if (!desc.objectToWorld.inverse())
        throw GridLoadError("grid medium " + quote(m.source) + ": objectToWorld is not invertible");

    const std::shared_ptr<const openvdb::GridBase>* in[FieldCount] = {&grids.density, &grids.temperature,
                                                                        &grids.emission, &grids.albedo};
    const std::string* names[FieldCount] = {&desc.densityGrid, &desc.temperatureGrid, &desc.emissionGrid,
                                            &desc.albedoGrid};
    const char* roles[FieldCount] = {"density", "temperature", "emission", "albedo"};
    if (!grids.density)
        throw GridLoadError("grid medium " + quote(m.source) + ": no density grid given");

    for (int f = 0; f < FieldCount; ++f) {
        const auto& base = *in[f];
        if (!base) continue;
        Impl::Field& field = m.fields[f];
        field.name = !base->getName().empty() ? base->getName() : (!names[f]->empty() ? *names[f] : roles[f]);
        const std::string where = "grid " + quote(field.name) + " (" + roles[f] + ") of " + quote(m.source);
        auto grid = openvdb::GridBase::constGrid<FloatGrid>(base);
        if (!grid)
            throw GridLoadError(where + " has value type " + base->valueType() + " (grid type " + base->type() +
                                "), but a float grid (FloatGrid) is required");
        const openvdb::math::Transform& xf = grid->transform();
        if (!xf.isLinear())
            throw GridLoadError(where + " has a non-linear (" + xf.mapType() +
                                ") transform; only linear (affine) grid transforms are supported");
        Affine toWorld = desc.objectToWorld * indexToObject(xf);
        std::optional<Affine> toIndex = toWorld.inverse();
        if (!toIndex) throw GridLoadError(where + ": index-to-world transform is not invertible");
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

MediumProperties GridMedium::properties(const Vec3& p) const {
    MediumProperties mp;
    const Impl& m = *impl_;
    if (m.support.empty()) return mp;
    const Vec3 pi = m.fields[DensityField].worldToIndex.point(p);
    if (!m.support.contains(pi)) return mp;
    Impl::AccessorCache& cache = m.accessors();
    const double d = std::min(sampleTrilinear(*cache.acc[DensityField], pi), m.densityCap);
    if (!(d > 0)) return mp;

    const Spectrum sigma_t = m.sigmaTPerDensity * d;
    Spectrum albedo = m.albedo;
    if (m.fields[AlbedoField].bound()) {
        double a = sampleTrilinear(*cache.acc[AlbedoField], m.fields[AlbedoField].worldToIndex.point(p));
        albedo *= std::clamp(a, 0.0, 1.0);
    }
    const Spectrum sigma_s = sigma_t * albedo;
    mp.sigma_a = sigma_t - sigma_s;
    mp.addLobe(m.desc.phase.get(), sigma_s);

    Spectrum e = m.emission;
    if (m.fields[EmissionField].bound() && !e.isBlack())
        e *= sampleTrilinear(*cache.acc[EmissionField], m.fields[EmissionField].worldToIndex.point(p));
    if (m.fields[TemperatureField].bound() && m.desc.emissionScale > 0 && !mp.sigma_a.isBlack()) {
        double T = m.desc.temperatureScale *
                   sampleTrilinear(*cache.acc[TemperatureField], m.fields[TemperatureField].worldToIndex.point(p));
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

// ---- loading -----------------------------------------------------------------------------------

namespace {

/// Bounded little-endian reader over a file: every read is checked against the file size first.
class CheckedReader {
public:
    CheckedReader(const std::string& path, uint64_t size) : in_(path, std::ios::binary), size_(size) {}
    bool ok() const { return static_cast<bool>(in_); }
    uint64_t pos() const { return pos_; }
    uint64_t remaining() const { return size_ - pos_; }
    template <typename T>
    T read(const char* what) {
        T v{};
        need(sizeof(T), what);
        in_.read(reinterpret_cast<char*>(&v), sizeof(T));
        advance(sizeof(T), what);
        return v;
    }
    void skip(uint64_t n, const char* what) {
        need(n, what);
        in_.seekg(static_cast<std::streamoff>(pos_ + n));
        advance(n, what);
    }
    std::string readString(const char* what) {
        uint32_t n = read<uint32_t>(what);
        need(n, what);
        std::string s(n, '\0');
        if (n) in_.read(&s[0], n);
        advance(n, what);
        return s;
    }
    void seek(uint64_t p, const char* what) {
        if (p > size_) fail(std::string(what) + " points past the end of the file");
        in_.seekg(static_cast<std::streamoff>(p));
        pos_ = p;
        if (!in_) fail(std::string("cannot seek to ") + what);
    }
    [[noreturn]] static void fail(const std::string& why) { throw GridLoadError(why); }

private:
    void need(uint64_t n, const char* what) {
        if (n > remaining()) fail(std::string("the file ends inside the ") + what);
    }
    void advance(uint64_t n, const char* what) {
        if (!in_) fail(std::string("cannot read the ") + what);
        pos_ += n;
    }
    std::ifstream in_;
    uint64_t size_, pos_ = 0;
};

/// Walks the VDB header, file metadata and grid descriptors (the same way io::File::open does) with
/// every length and offset checked against the file size. OpenVDB itself reads lengths from a failed
/// stream as uninitialised values, so a truncated file can make it allocate gigabytes or load garbage
/// without complaint; this catches truncation and damaged headers before OpenVDB sees the file.
/// Throws GridLoadError with a description (the caller adds the path).
void checkVdbStructure(const std::string& path, uint64_t size) {
    CheckedReader r(path, size);
    if (!r.ok()) CheckedReader::fail("cannot open the file for reading");
    if (r.read<int64_t>("header") != openvdb::OPENVDB_MAGIC) CheckedReader::fail("not a VDB file (bad magic number)");
    uint32_t version = r.read<uint32_t>("header");
    if (version > openvdb::OPENVDB_FILE_VERSION)
        CheckedReader::fail("unsupported VDB file format version " + std::to_string(version) + " (this OpenVDB reads up to " +
                            std::to_string(openvdb::OPENVDB_FILE_VERSION) + ")");
    if (version < 211) {  // separate major, minor and patch numbers
        uint32_t minor = r.read<uint32_t>("header"), patch = r.read<uint32_t>("header");
        version = 100 * version + 10 * minor + patch;
    } else {
        r.skip(8, "header");  // library major and minor version
    }
    bool hasGridOffsets = true;
    if (version >= 212) hasGridOffsets = r.read<char>("header") != 0;
    if (version >= openvdb::OPENVDB_FILE_VERSION_SELECTIVE_COMPRESSION &&
        version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
        r.skip(1, "header");
    r.skip(version >= openvdb::OPENVDB_FILE_VERSION_BOOST_UUID ? 36 : 16, "header (UUID)");
    // A metadata map: count, then (name, type name, size-prefixed value) triples.
    auto skipMetaMap = [&r](const char* what) {
        uint32_t count = r.read<uint32_t>(what);
        if (count > r.remaining()) CheckedReader::fail(std::string("the ") + what + " count is implausible");
        for (uint32_t i = 0; i < count; ++i) {
            r.readString(what);
            r.readString(what);
            r.skip(r.read<uint32_t>(what), what);
        }
    };
    skipMetaMap("file metadata");
    if (!hasGridOffsets) return;  // very old files: nothing more can be checked without reading grids
    int32_t gridCount = r.read<int32_t>("grid count");
    if (gridCount < 0 || static_cast<uint64_t>(gridCount) > r.remaining())
        CheckedReader::fail("the grid count " + std::to_string(gridCount) + " is implausible");
    for (int32_t g = 0; g < gridCount; ++g) {
        std::string name = r.readString("grid descriptor");
        r.readString("grid descriptor");  // type
        if (version >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
            r.readString("grid descriptor");  // instance parent
        int64_t gridPos = r.read<int64_t>("grid descriptor");
        int64_t blockPos = r.read<int64_t>("grid descriptor");
        int64_t endPos = r.read<int64_t>("grid descriptor");
        const uint64_t here = r.pos();
        if (gridPos < 0 || blockPos < gridPos || endPos < blockPos || static_cast<uint64_t>(gridPos) < here)
            CheckedReader::fail("the descriptor of grid " + quote(name) + " has inconsistent offsets");
        if (static_cast<uint64_t>(endPos) > size)
            CheckedReader::fail("grid " + quote(name) + " ends at byte " + std::to_string(endPos) + " but the file has only " +
                                std::to_string(size) + " bytes (truncated?)");
        // The start of the grid itself: compression flags, grid metadata and the transform's type.
        r.seek(static_cast<uint64_t>(gridPos), "grid start");
        if (version >= openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) r.skip(4, "grid compression flags");
        skipMetaMap("grid metadata");
        if (r.pos() > static_cast<uint64_t>(endPos)) CheckedReader::fail("grid " + quote(name) + "'s metadata overruns the grid");
        if (version >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING) {
            std::string map = r.readString("grid transform");
            if (!openvdb::math::MapRegistry::isRegistered(map))
                CheckedReader::fail("grid " + quote(name) + " has an unknown transform type " + quote(map));
        }
        r.seek(static_cast<uint64_t>(endPos), "grid end");
    }
}

}  // namespace


std::shared_ptr<GridMedium> loadGridMedium(const GridMediumDesc& desc) {
    initOpenVdb();
    const std::string& path = desc.filePath;
    if (path.empty()) throw std::runtime_error("grid medium: no VDB file path given");
    if (desc.densityGrid.empty())
        throw std::runtime_error("grid medium " + quote(path) + ": no density grid name given");
    {
        std::error_code ec;
        auto status = std::filesystem::status(path, ec);
        if (ec || !std::filesystem::exists(status))
            throw std::runtime_error("cannot open VDB file " + quote(path) + ": file does not exist");
        if (std::filesystem::is_directory(status))
            throw std::runtime_error("cannot open VDB file " + quote(path) + ": it is a directory");
    }
    if (!desc.objectToWorld.isFinite())
        throw std::runtime_error("grid medium " + quote(path) + ": objectToWorld has non-finite entries");
    if (!desc.objectToWorld.inverse())
        throw std::runtime_error("grid medium " + quote(path) + ": objectToWorld is not invertible");

    GridMediumGrids grids;
    std::string reading = "header";
    try {
        uint64_t size = std::filesystem::file_size(path);
        try {
            checkVdbStructure(path, size);
        } catch (const GridLoadError& e) {
            throw GridLoadError("cannot read VDB file " + quote(path) + ": the file is corrupt or truncated: " + e.what());
        }
        openvdb::io::File file(path);
        // No delayed loading: the medium owns all of its data and never touches the file again.
        file.open(/*delayLoad=*/false);
        auto readFloatGrid = [&](const std::string& name, const char* role) -> std::shared_ptr<const openvdb::GridBase> {
            if (name.empty()) return nullptr;
            reading = std::string(role) + " grid " + quote(name);
            if (!file.hasGrid(name)) {
                std::ostringstream msg;
                msg << "VDB file " << quote(path) << " has no grid named " << quote(name) << " (" << role
                    << "); grids in the file:";
                bool any = false;
                for (auto it = file.beginName(); it != file.endName(); ++it) {
                    msg << (any ? ", " : " ") << quote(*it);
                    try {
                        msg << " (" << file.readGridMetadata(*it)->type() << ")";
                    } catch (...) {
                    }
                    any = true;
                }
                if (!any) msg << " none";
                throw GridLoadError(msg.str());
            }
            auto overCap = [&](std::uint64_t voxels, const char* how) {
                return GridLoadError("grid " + quote(name) + " (" + role + ") in VDB file " + quote(path) + " has " +
                                     std::to_string(voxels) + " active voxels (" + how + "), more than the grid-size cap of " +
                                     std::to_string(desc.maxActiveVoxels) +
                                     " (volphoton:maxGridVoxels on the RenderSettings prim, or --max-grid-voxels)");
            };
            if (desc.maxActiveVoxels > 0) {
                openvdb::MetaMap::Ptr meta = file.readGridMetadata(name);
                if (auto count = meta ? meta->getMetadata<openvdb::Int64Metadata>("file_voxel_count") : nullptr;
                    count && count->value() > 0 && std::uint64_t(count->value()) > desc.maxActiveVoxels)
                    throw overCap(std::uint64_t(count->value()), "recorded in the file");
            }
            openvdb::GridBase::Ptr g = file.readGrid(name);
            if (!g) throw GridLoadError("VDB file " + quote(path) + ": could not read " + reading);
            if (desc.maxActiveVoxels > 0 && g->activeVoxelCount() > desc.maxActiveVoxels)
                throw overCap(g->activeVoxelCount(), "counted after reading");
            if (!g->isType<FloatGrid>())
                throw GridLoadError("grid " + quote(name) + " (" + role + ") in VDB file " + quote(path) +
                                    " has value type " + g->valueType() + " (grid type " + g->type() +
                                    "), but a float grid (FloatGrid) is required");
            return g;
        };
        grids.density = readFloatGrid(desc.densityGrid, "density");
        grids.temperature = readFloatGrid(desc.temperatureGrid, "temperature");
        grids.emission = readFloatGrid(desc.emissionGrid, "emission");
        grids.albedo = readFloatGrid(desc.albedoGrid, "albedo");
        file.close();
    } catch (const GridLoadError&) {
        throw;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read VDB file " + quote(path) + " (" + reading +
                                 "): the file is unreadable or corrupt: " + e.what());
    } catch (...) {
        throw std::runtime_error("cannot read VDB file " + quote(path) + " (" + reading +
                                 "): the file is unreadable or corrupt");
    }
    return std::shared_ptr<GridMedium>(new GridMedium(desc, grids, /*gridsOwned=*/true));
}

// ---- procedural cloud --------------------------------------------------------------------------

namespace {

/// Lattice value in [-1, 1] from one 64-bit mix of the seed and the integer coordinates.
inline double latticeValue(uint64_t seed, int64_t i, int64_t j, int64_t k) {
    uint64_t h = mix64(seed ^ (static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ULL) ^
                       (static_cast<uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL) ^ (static_cast<uint64_t>(k) * 0x165667B19E3779F9ULL));
    return static_cast<double>(h >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

inline double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }  // quintic, C2

/// Value noise with quintic interpolation (smooth, deterministic, only +, *, floor).
double valueNoise(uint64_t seed, double x, double y, double z) {
    double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    int64_t i = static_cast<int64_t>(fx), j = static_cast<int64_t>(fy), k = static_cast<int64_t>(fz);
    double u = fade(x - fx), v = fade(y - fy), w = fade(z - fz);
    double c[8];
    for (int n = 0; n < 8; ++n) c[n] = latticeValue(seed, i + (n >> 2), j + ((n >> 1) & 1), k + (n & 1));
    double x00 = lerp(c[0], c[4], u), x01 = lerp(c[1], c[5], u), x10 = lerp(c[2], c[6], u), x11 = lerp(c[3], c[7], u);
    return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

/// Five octaves of value noise, normalised to about [-1, 1].
double fractalNoise(uint64_t seed, double x, double y, double z) {
    double sum = 0, amp = 1, norm = 0, f = 1;
    for (int o = 0; o < 5; ++o) {
        sum += amp * valueNoise(mix64(seed + static_cast<uint64_t>(o)), x * f, y * f, z * f);
        norm += amp;
        amp *= 0.5;
        f *= 2.03;
    }
    return sum / norm;
}

}  // namespace

void writeProceduralCloudVdb(const std::string& path, int resolution, double voxelSize, uint64_t seed) {
    if (resolution < 1) throw std::invalid_argument("writeProceduralCloudVdb: resolution must be >= 1");
    if (!(voxelSize > 0) || !std::isfinite(voxelSize))
        throw std::invalid_argument("writeProceduralCloudVdb: voxelSize must be finite and > 0");
    initOpenVdb();
    const double centre = 0.5 * (resolution - 1);
    const double radius = 0.45 * resolution;
    const uint64_t noiseSeed = mix64(seed ^ 0x636c6f7564ULL);  // "cloud"
    const int D = static_cast<int>(LeafT::DIM);
    const int blocks = (resolution + D - 1) / D;

    // Slabs of one leaf depth in z go to different trees (disjoint leaves), merged afterwards: the
    // result does not depend on the thread schedule.
    tbb::enumerable_thread_specific<FloatTree> trees(0.0f);
    tbb::parallel_for(tbb::blocked_range<int>(0, blocks), [&](const tbb::blocked_range<int>& r) {
        FloatTree& tree = trees.local();
        openvdb::tree::ValueAccessor<FloatTree> acc(tree);
        for (int b = r.begin(); b != r.end(); ++b)
            for (int k = b * D; k < std::min(resolution, (b + 1) * D); ++k)
                for (int j = 0; j < resolution; ++j)
                    for (int i = 0; i < resolution; ++i) {
                        double ux = (i - centre) / radius, uy = (j - centre) / radius, uz = (k - centre) / radius;
                        double r2 = ux * ux + uy * uy + uz * uz;
                        if (r2 >= 1) continue;
                        double n = fractalNoise(noiseSeed, 2.5 * ux + 17.0, 2.5 * uy + 31.0, 2.5 * uz + 47.0);
                        double d = (1.0 - r2) * (0.45 + 1.2 * n) * 1.4 - 0.08;
                        if (d <= 0) continue;
                        acc.setValue(Coord(i, j, k), static_cast<float>(std::min(d, 1.0)));
                    }
    });
    FloatGrid::Ptr grid = FloatGrid::create(0.0f);
    for (FloatTree& t : trees) grid->tree().merge(t, openvdb::MERGE_ACTIVE_STATES);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
    try {
        openvdb::io::File file(path);
        file.write({grid});
        file.close();
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write VDB file " + quote(path) + ": " + e.what());
    }
}

}  // namespace volphoton
