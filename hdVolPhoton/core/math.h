// Small value types shared by the whole core: vectors, RGB spectra, frames, affine transforms.
// Double precision throughout: scenes span 1e-4..1e5 scene units and sigma_t up to 1e7, and the
// closed forms (optical depth, free flight) lose too much in single precision at those ranges.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

namespace volphoton {

constexpr double Pi = 3.14159265358979323846;
constexpr double InvPi = 1.0 / Pi;
constexpr double Inv4Pi = 1.0 / (4.0 * Pi);
constexpr double Infinity = std::numeric_limits<double>::infinity();

struct Vec3 {
    double x = 0, y = 0, z = 0;
    constexpr Vec3() = default;
    constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
    double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    Vec3 operator-() const { return {-x, -y, -z}; }
    Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
    Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
    Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    Vec3& operator*=(double s) { x *= s; y *= s; z *= s; return *this; }
    bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
};
inline Vec3 operator*(double s, const Vec3& v) { return v * s; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double lengthSquared(const Vec3& v) { return dot(v, v); }
inline double length(const Vec3& v) { return std::sqrt(dot(v, v)); }
inline Vec3 normalize(const Vec3& v) { return v / length(v); }
inline Vec3 vmin(const Vec3& a, const Vec3& b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3 vmax(const Vec3& a, const Vec3& b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline bool isFinite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

inline double lerp(double a, double b, double t) { return a + (b - a) * t; }
/// Trilinear blend of the eight corner values of a unit cell, c[(dx << 2) | (dy << 1) | dz] at corner
/// (dx, dy, dz), at the fractions (u, v, w) across the cell.
template <typename T>
inline double trilinear(const T (&c)[8], double u, double v, double w) {
    double x00 = lerp(c[0], c[4], u), x01 = lerp(c[1], c[5], u), x10 = lerp(c[2], c[6], u), x11 = lerp(c[3], c[7], u);
    return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

/// RGB radiometric quantity (radiance, coefficients, throughput). Component-wise arithmetic.
struct Spectrum {
    double c[3] = {0, 0, 0};
    constexpr Spectrum() = default;
    constexpr explicit Spectrum(double v) : c{v, v, v} {}
    constexpr Spectrum(double r, double g, double b) : c{r, g, b} {}
    double operator[](int i) const { return c[i]; }
    double& operator[](int i) { return c[i]; }
#define VP_SPECTRUM_OP(op)                                                                        \
    Spectrum operator op(const Spectrum& o) const { return {c[0] op o.c[0], c[1] op o.c[1], c[2] op o.c[2]}; } \
    Spectrum& operator op##=(const Spectrum& o) { c[0] op## = o.c[0]; c[1] op## = o.c[1]; c[2] op## = o.c[2]; return *this; } \
    Spectrum operator op(double s) const { return {c[0] op s, c[1] op s, c[2] op s}; }           \
    Spectrum& operator op##=(double s) { c[0] op## = s; c[1] op## = s; c[2] op## = s; return *this; }
    VP_SPECTRUM_OP(+)
    VP_SPECTRUM_OP(-)
    VP_SPECTRUM_OP(*)
    VP_SPECTRUM_OP(/)
#undef VP_SPECTRUM_OP
    Spectrum operator-() const { return {-c[0], -c[1], -c[2]}; }
    bool operator==(const Spectrum& o) const { return c[0] == o.c[0] && c[1] == o.c[1] && c[2] == o.c[2]; }
    double maxValue() const { return std::max(c[0], std::max(c[1], c[2])); }
    double minValue() const { return std::min(c[0], std::min(c[1], c[2])); }
    double average() const { return (c[0] + c[1] + c[2]) / 3.0; }
    bool isBlack() const { return c[0] == 0 && c[1] == 0 && c[2] == 0; }
    bool isFinite() const { return std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]); }
};
inline Spectrum operator*(double s, const Spectrum& v) { return v * s; }
inline Spectrum exp(const Spectrum& s) { return {std::exp(s[0]), std::exp(s[1]), std::exp(s[2])}; }
/// Division that returns 0 where the denominator is 0 (pbrt's SafeDiv).
inline Spectrum safeDiv(const Spectrum& a, const Spectrum& b) {
    Spectrum r;
    for (int i = 0; i < 3; ++i) r[i] = b[i] != 0 ? a[i] / b[i] : 0.0;
    return r;
}
inline double luminance(const Spectrum& s) { return 0.2126 * s[0] + 0.7152 * s[1] + 0.0722 * s[2]; }

struct Ray {
    Vec3 o;
    Vec3 d;  ///< unit length
    Vec3 at(double t) const { return o + d * t; }
};

/// Axis-aligned box; empty when lo > hi.
struct Bounds3 {
    Vec3 lo{Infinity, Infinity, Infinity};
    Vec3 hi{-Infinity, -Infinity, -Infinity};
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    void extend(const Vec3& p) { lo = vmin(lo, p); hi = vmax(hi, p); }
    void extend(const Bounds3& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
    bool contains(const Vec3& p) const {
        return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
    }
    /// Slab test; returns the parametric overlap of [tMin, tMax] with the box.
    bool intersect(const Ray& r, double tMin, double tMax, double* t0, double* t1) const {
        for (int a = 0; a < 3; ++a) {
            double inv = 1.0 / r.d[a];
            double tn = (lo[a] - r.o[a]) * inv, tf = (hi[a] - r.o[a]) * inv;
            if (tn > tf) std::swap(tn, tf);
            // NaN (0 * inf when the origin lies on a slab and d[a] == 0) keeps the old bound.
            if (tn > tMin) tMin = tn;
            if (tf < tMax) tMax = tf;
            if (tMin > tMax) return false;
        }
        *t0 = tMin;
        *t1 = tMax;
        return true;
    }
};

/// Orthonormal basis around a unit vector n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
struct Frame {
    Vec3 s, t, n;
    static Frame fromZ(const Vec3& n) {
        double sign = std::copysign(1.0, n.z);
        double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
        return {Vec3(1 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3(b, sign + n.y * n.y * a, -n.y), n};
    }
    Vec3 toWorld(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
    Vec3 toLocal(const Vec3& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
};

/// Direction with cosine cosTheta to `axis` and azimuth phi around it.
inline Vec3 sphericalDirection(const Vec3& axis, double cosTheta, double phi) {
    cosTheta = std::clamp(cosTheta, -1.0, 1.0);
    double sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
    return Frame::fromZ(axis).toWorld({sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta});
}

/// Row-major 3x4 affine transform (the last row is implicitly 0 0 0 1).
struct Affine {
    double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
    Vec3 point(const Vec3& p) const {
        return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
    }
    Vec3 vector(const Vec3& v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    /// Transforms a normal: the inverse-transpose of the linear part, which callers pass as `inverse`.
    static Vec3 normal(const Affine& inverse, const Vec3& n) {
        return {inverse.m[0][0] * n.x + inverse.m[1][0] * n.y + inverse.m[2][0] * n.z,
                inverse.m[0][1] * n.x + inverse.m[1][1] * n.y + inverse.m[2][1] * n.z,
                inverse.m[0][2] * n.x + inverse.m[1][2] * n.y + inverse.m[2][2] * n.z};
    }
    double determinant() const {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    }
    bool isFinite() const {
        for (auto& row : m)
            for (double v : row)
                if (!std::isfinite(v)) return false;
        return true;
    }
    Affine operator*(const Affine& b) const {
        Affine r;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j)
                r.m[i][j] = m[i][0] * b.m[0][j] + m[i][1] * b.m[1][j] + m[i][2] * b.m[2][j] + (j == 3 ? m[i][3] : 0.0);
        return r;
    }
    /// Inverse, or nullopt when the transform is singular or not finite (the caller reports it).
    std::optional<Affine> inverse() const {
        double det = determinant();
        double scale = 0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) scale = std::max(scale, std::abs(m[i][j]));
        if (!isFinite() || scale == 0 || !(std::abs(det) > 1e-12 * scale * scale * scale)) return std::nullopt;
        Affine r;
        double inv = 1.0 / det;
        r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * inv;
        r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv;
        r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv;
        r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * inv;
        r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv;
        r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv;
        r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * inv;
        r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv;
        r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv;
        for (int i = 0; i < 3; ++i)
            r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
        return r;
    }
    static Affine translate(const Vec3& t) {
        Affine a;
        a.m[0][3] = t.x; a.m[1][3] = t.y; a.m[2][3] = t.z;
        return a;
    }
    static Affine scale(const Vec3& s) {
        Affine a;
        a.m[0][0] = s.x; a.m[1][1] = s.y; a.m[2][2] = s.z;
        return a;
    }
};

}  // namespace volphoton
