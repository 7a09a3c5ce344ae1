#include "core/majorantGrid.h"

#include <stdexcept>

namespace volphoton {

MajorantGrid::MajorantGrid(const Bounds3& box, int nx, int ny, int nz) : box_(box), res_{nx, ny, nz} {
    if (box.empty() || !isFinite(box.lo) || !isFinite(box.hi))
        throw std::invalid_argument("MajorantGrid: the box must be finite and non-empty");
    if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("MajorantGrid: resolution must be >= 1 per axis");
    for (int a = 0; a < 3; ++a) {
        double extent = box.hi[a] - box.lo[a];
        // A flat box (one voxel thick after dilation never is, but callers may pass one) gets a
        // nominal width so that the cell arithmetic stays finite.
        cellSize_[a] = extent > 0 ? extent / res_[a] : 1.0;
        invCellSize_[a] = 1.0 / cellSize_[a];
    }
    cells_.assign(static_cast<size_t>(nx) * static_cast<size_t>(ny) * static_cast<size_t>(nz), 0.0f);
}

std::array<int, 3> MajorantGrid::resolutionFor(const Bounds3& box, double voxelsPerCell, int maxCells) {
    std::array<int, 3> r{1, 1, 1};
    if (box.empty() || !(voxelsPerCell > 0)) return r;
    for (int a = 0; a < 3; ++a) {
        double n = std::ceil((box.hi[a] - box.lo[a]) / voxelsPerCell);
        r[a] = std::isfinite(n) ? static_cast<int>(std::clamp(n, 1.0, static_cast<double>(std::max(1, maxCells)))) : 1;
    }
    return r;
}

Bounds3 MajorantGrid::cellBounds(int x, int y, int z) const {
    const int c[3] = {x, y, z};
    Bounds3 b;
    for (int a = 0; a < 3; ++a) {
        b.lo[a] = box_.lo[a] + c[a] * cellSize_[a];
        b.hi[a] = c[a] + 1 == res_[a] ? box_.hi[a] : box_.lo[a] + (c[a] + 1) * cellSize_[a];
    }
    return b;
}

double MajorantGrid::maxValue() const {
    float m = 0;
    for (float v : cells_) m = std::max(m, v);
    return m;
}

bool MajorantGrid::cellRange(int axis, double lo, double hi, int* c0, int* c1) const {
    if (cells_.empty() || !(lo <= hi) || hi < box_.lo[axis] || lo > box_.hi[axis]) return false;
    double f0 = std::floor((lo - box_.lo[axis]) * invCellSize_[axis]);
    double f1 = std::floor((hi - box_.lo[axis]) * invCellSize_[axis]);
    double top = res_[axis] - 1;
    *c0 = static_cast<int>(std::clamp(f0, 0.0, top));
    *c1 = static_cast<int>(std::clamp(f1, 0.0, top));
    return true;
}

void MajorantGrid::raiseAtomic(int x, int y, int z, float v) {
    float* c = &cells_[index(x, y, z)];
    float cur;
    __atomic_load(c, &cur, __ATOMIC_RELAXED);
    while (v > cur && !__atomic_compare_exchange(c, &cur, &v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
    }
}

void MajorantGrid::raiseBox(const Bounds3& b, float v) {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
        if (!cellRange(a, b.lo[a], b.hi[a], &lo[a], &hi[a])) return;
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) raise(x, y, z, v);
}

void MajorantGrid::raiseAll(float v) {
    for (float& c : cells_) c = std::max(c, v);
}

void MajorantGrid::capAll(float v) {
    for (float& c : cells_) c = std::min(c, v);
}

void MajorantGrid::walk(const Vec3& o, const Vec3& d, double tMin, double tMax, WalkCallback cb) const {
    if (cells_.empty() || !(tMin < tMax)) return;
    // Clip [tMin, tMax] to the box (slab test). An axis with d = 0 leaves t alone when the origin
    // lies inside its slab and rejects the ray otherwise.
    double t0 = tMin, t1 = tMax;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) {
            if (o[a] < box_.lo[a] || o[a] > box_.hi[a]) return;
            continue;
        }
        double inv = 1.0 / d[a];
        double tn = (box_.lo[a] - o[a]) * inv, tf = (box_.hi[a] - o[a]) * inv;
        if (tn > tf) std::swap(tn, tf);
        t0 = std::max(t0, tn);
        t1 = std::min(t1, tf);
    }
    if (!(t0 < t1)) return;  // also rejects NaN (non-finite o or d)

    // Amanatides-Woo set-up. The crossing parameters are recomputed from o at each step rather than
    // accumulated, so no drift builds up over long walks.
    int cell[3], step[3], stop[3];
    double next[3], invD[3];  // invD: a multiplication per step instead of a division
    const Vec3 p = o + d * t0;
    for (int a = 0; a < 3; ++a) {
        double f = std::floor((p[a] - box_.lo[a]) * invCellSize_[a]);
        cell[a] = static_cast<int>(std::clamp(f, 0.0, static_cast<double>(res_[a] - 1)));
        invD[a] = d[a] != 0 ? 1.0 / d[a] : 0.0;
        if (d[a] > 0) {
            step[a] = 1;
            stop[a] = res_[a];
            next[a] = (box_.lo[a] + (cell[a] + 1) * cellSize_[a] - o[a]) * invD[a];
        } else if (d[a] < 0) {
            step[a] = -1;
            stop[a] = -1;
            next[a] = (box_.lo[a] + cell[a] * cellSize_[a] - o[a]) * invD[a];
        } else {
            step[a] = 0;
            stop[a] = -2;
            next[a] = Infinity;
        }
    }

    double runStart = t0, runValue = 0;
    double t = t0;
    for (;;) {
        int axis = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        // max(t, .) keeps the runs monotone where rounding puts a crossing before the current t.
        double tExit = std::max(t, std::min(next[axis], t1));
        double v = cells_[index(cell[0], cell[1], cell[2])];
        if (v != runValue) {
            if (runValue > 0 && t > runStart && !cb(runStart, t, runValue)) return;
            runStart = t;
            runValue = v;
        }
        t = tExit;
        if (t >= t1) break;
        cell[axis] += step[axis];
        if (cell[axis] == stop[axis]) {
            t = t1;  // left the box: in exact arithmetic exactly at t1, so cover any rounding sliver
            break;
        }
        next[axis] = (box_.lo[axis] + (cell[axis] + (step[axis] > 0 ? 1 : 0)) * cellSize_[axis] - o[axis]) * invD[axis];
    }
    if (runValue > 0 && t > runStart) cb(runStart, t, runValue);
}

}  // namespace volphoton
