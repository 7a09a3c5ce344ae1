// Coarse grid of maxima over a box in a local (index) space, walked along a ray with a 3D DDA
// (Amanatides and Woo 1987, "A Fast Voxel Traversal Algorithm for Ray Tracing"). GridMedium builds
// one over the density grid and turns each reported run of cells into a constant majorant segment.
//
// | parameter      | type   | default | meaning                                                      |
// |----------------|--------|---------|--------------------------------------------------------------|
// | box            | Bounds3|         | local-space box covered by the grid (outside it: empty)       |
// | resolution     | int[3] |         | cells per axis (>= 1 each)                                     |
// | voxelsPerCell  | double | 8       | resolutionFor(): target cell width in local units (voxels)     |
// | maxCells       | int    | 128     | resolutionFor(): cap on cells per axis                         |
//
// Cells start at 0; raise()/raiseBox() only ever increase them (capAll() lowers them after a build), so a build may raise cells
// concurrently through raiseAtomic(). Cell values must be >= 0 (maxima of non-negative fields).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/functionRef.h"
#include "core/math.h"

namespace volphoton {

/// \class MajorantGrid
class MajorantGrid {
public:
    /// Callback of walk(): one run [t0, t1) of consecutive cells sharing the maximum maxValue (> 0).
    /// Returning false stops the walk.
    using WalkCallback = FunctionRef<bool(double t0, double t1, double maxValue)>;

    /// An empty grid: walk() reports nothing.
    MajorantGrid() = default;
    /// A grid of nx * ny * nz cells over `box`, all 0. Throws std::invalid_argument on an empty or
    /// non-finite box or a resolution < 1.
    MajorantGrid(const Bounds3& box, int nx, int ny, int nz);

    /// Cells per axis for a box measured in voxels: ceil(extent / voxelsPerCell), clamped to
    /// [1, maxCells].
    static std::array<int, 3> resolutionFor(const Bounds3& box, double voxelsPerCell = 8.0, int maxCells = 128);

    bool empty() const { return cells_.empty(); }
    const Bounds3& box() const { return box_; }
    int resolution(int axis) const { return res_[axis]; }
    size_t cellCount() const { return cells_.size(); }
    /// Local-space box of cell (x, y, z).
    Bounds3 cellBounds(int x, int y, int z) const;
    double at(int x, int y, int z) const { return cells_[index(x, y, z)]; }
    /// Largest cell value (0 for an empty grid).
    double maxValue() const;

    /// Index range [*c0, *c1] of the cells along `axis` that overlap the closed interval [lo, hi];
    /// false when none does.
    bool cellRange(int axis, double lo, double hi, int* c0, int* c1) const;
    /// cell = max(cell, v).
    void raise(int x, int y, int z, float v) {
        float& c = cells_[index(x, y, z)];
        if (v > c) c = v;
    }
    /// Thread-safe raise(): several threads may call it at once (and nothing else meanwhile).
    /// Implemented with the GCC/Clang __atomic builtins on the float cell.
    void raiseAtomic(int x, int y, int z, float v);
    /// Raises every cell overlapping the closed local-space box b (clipped to the grid) to >= v.
    void raiseBox(const Bounds3& b, float v);
    /// Raises every cell to >= v.
    void raiseAll(float v);
    /// Lowers every cell to <= v, after the build: for a field clamped at v where it is sampled.
    void capAll(float v);

    /// Walks the ray o + t d (local space; d need not be unit length, so t stays the parameter of
    /// the caller's ray through an affine map) over [tMin, tMax] clipped to the box, calling `cb` in
    /// increasing t for each run of consecutive crossed cells with equal maximum. Cells whose
    /// maximum is 0 are not reported (gaps), so empty space costs only the DDA steps.
    void walk(const Vec3& o, const Vec3& d, double tMin, double tMax, WalkCallback cb) const;

private:
    size_t index(int x, int y, int z) const {
        return (static_cast<size_t>(z) * static_cast<size_t>(res_[1]) + static_cast<size_t>(y)) *
                   static_cast<size_t>(res_[0]) + static_cast<size_t>(x);
    }

    Bounds3 box_;
    int res_[3] = {0, 0, 0};
    Vec3 cellSize_, invCellSize_;
    std::vector<float> cells_;
};

}  // namespace volphoton
