// Warping functions and discrete/piecewise-constant distributions (pbrt-v4 ch. A.5, Shirley 1997).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/math.h"

namespace volphoton {

inline Vec3 uniformSphere(double u1, double u2) {
    double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * Pi * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}
constexpr double UniformSpherePdf = Inv4Pi;

/// Uniform direction in the cone of half-angle acos(cosMax) around +Z.
inline Vec3 uniformCone(double u1, double u2, double cosMax) {
    double cosTheta = 1 - u1 * (1 - cosMax);
    double sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta)), phi = 2 * Pi * u2;
    return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}
inline double uniformConePdf(double cosMax) { return 1 / (2 * Pi * (1 - cosMax)); }

/// Shirley-Chiu concentric map of the unit square to the unit disk.
inline void concentricDisk(double u1, double u2, double* x, double* y) {
    double a = 2 * u1 - 1, b = 2 * u2 - 1;
    if (a == 0 && b == 0) { *x = *y = 0; return; }
    double r, theta;
    if (std::abs(a) > std::abs(b)) { r = a; theta = Pi / 4 * (b / a); }
    else { r = b; theta = Pi / 2 - Pi / 4 * (a / b); }
    *x = r * std::cos(theta);
    *y = r * std::sin(theta);
}

inline Vec3 cosineHemisphere(double u1, double u2) {
    double x, y;
    concentricDisk(u1, u2, &x, &y);
    return {x, y, std::sqrt(std::max(0.0, 1 - x * x - y * y))};
}

/// A position in pixel [x, x+1) x [y, y+1) (image coordinates) and its weight, for a pixel whose
/// footprint holds the image (cx, cy) of a point light in a medium (Renderer::lightPixels_).
/// Light scattered towards the camera by a medium around a point light falls off as 1/h with the
/// distance h of the camera ray from the light, so a uniform pixel position gives that pixel an
/// estimate whose variance diverges (logarithmically): its rare samples very close to the light
/// dominate the whole image's error (fog + spot benchmark scene: 44-94% of the squared error of the
/// photon map's image at 4 s in the light's pixel). Here one-sample MIS (Veach 1997, sec. 9.2.4, balance
/// heuristic) of the uniform density 1 and a polar density q = 1 / (2 pi R h) around (cx, cy) on the
/// disc of radius R (the farthest pixel corner), half the samples each: weight = 1 / (1/2 + q/2) where
/// the position is inside the pixel, 0 for a polar position outside it (the returned position is then
/// the uniform one, for the guides). E[weight f] is the pixel's integral of f, and weight x 1/h is
/// bounded. u0, u1: the camera sample's pixel pair (the first half of u0 picks the strategy, so the
/// pair keeps its stratification).
struct PixelPosition {
    double x, y, weight;
};
/// A point of the image plane in pixel coordinates (Camera::generateRay's).
struct ImagePoint {
    double x, y;
};
inline PixelPosition samplePixelAroundPoint(int x, int y, const ImagePoint& c, double u0, double u1) {
    const double cx = c.x, cy = c.y;
    const double R = std::max(std::hypot(std::max(cx - x, x + 1 - cx), std::max(cy - y, y + 1 - cy)), 1e-12);
    const bool uniform = u0 < 0.5;
    const double u = uniform ? 2 * u0 : 2 * u0 - 1;
    double px = x + u, py = y + u1;
    if (!uniform) {
        double r = R * u, phi = 2 * Pi * u1;
        double qx = cx + r * std::cos(phi), qy = cy + r * std::sin(phi);
        if (!(qx >= x && qx < x + 1 && qy >= y && qy < y + 1)) return {px, py, 0.0};
        px = qx;
        py = qy;
    }
    double h = std::hypot(px - cx, py - cy);
    double q = h > 0 ? 1 / (2 * Pi * R * h) : Infinity;
    return {px, py, 1 / (0.5 + 0.5 * q)};
}

/// Power heuristic with beta = 2 (Veach 1997).
inline double powerHeuristic(double fPdf, double gPdf) {
    if (std::isinf(fPdf)) return 1;
    double f = fPdf * fPdf, g = gPdf * gPdf;
    return f + g > 0 ? f / (f + g) : 0.0;
}

/// Piecewise-constant distribution over [0, 1) (pbrt's PiecewiseConstant1D).
class Distribution1D {
public:
    Distribution1D() = default;
    explicit Distribution1D(std::vector<double> f) : func_(std::move(f)), cdf_(func_.size() + 1, 0.0) {
        size_t n = func_.size();
        for (size_t i = 0; i < n; ++i) cdf_[i + 1] = cdf_[i] + std::max(0.0, func_[i]) / n;
        integral_ = cdf_[n];
        if (integral_ == 0)
            for (size_t i = 1; i <= n; ++i) cdf_[i] = static_cast<double>(i) / n;
        else
            for (size_t i = 1; i <= n; ++i) cdf_[i] /= integral_;
    }
    size_t size() const { return func_.size(); }
    double integral() const { return integral_; }
    /// Continuous sample in [0,1); *pdf is its density, *index the bin.
    double sample(double u, double* pdf, size_t* index) const {
        size_t i = std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin();
        i = std::clamp<size_t>(i, 1, func_.size()) - 1;
        *index = i;
        double width = cdf_[i + 1] - cdf_[i];
        double du = width > 0 ? (u - cdf_[i]) / width : 0.5;
        *pdf = integral_ > 0 ? std::max(0.0, func_[i]) / integral_ : 1.0;
        return std::min((i + du) / func_.size(), std::nextafter(1.0, 0.0));
    }
    /// Discrete sample: bin index with probability func_i / sum.
    size_t sampleDiscrete(double u, double* prob) const {
        double pdf;
        size_t i;
        sample(u, &pdf, &i);
        *prob = discretePdf(i);
        return i;
    }
    double discretePdf(size_t i) const { return cdf_[i + 1] - cdf_[i]; }
    double pdf(double x) const {
        size_t i = std::min(func_.size() - 1, static_cast<size_t>(x * func_.size()));
        return integral_ > 0 ? std::max(0.0, func_[i]) / integral_ : 1.0;
    }

private:
    std::vector<double> func_, cdf_;
    double integral_ = 0;
};

/// Piecewise-constant 2D distribution over [0,1)^2: marginal over v (rows), conditionals over u.
class Distribution2D {
public:
    Distribution2D() = default;
    Distribution2D(const std::vector<double>& f, int nu, int nv) {
        std::vector<double> marginal;
        for (int v = 0; v < nv; ++v) {
            conditional_.emplace_back(std::vector<double>(f.begin() + v * nu, f.begin() + (v + 1) * nu));
            marginal.push_back(conditional_.back().integral());
        }
        marginal_ = Distribution1D(marginal);
    }
    void sample(double u1, double u2, double* u, double* v, double* pdf) const {
        double pdfV, pdfU;
        size_t row, col;
        *v = marginal_.sample(u2, &pdfV, &row);
        *u = conditional_[row].sample(u1, &pdfU, &col);
        *pdf = pdfU * pdfV;
    }
    double pdf(double u, double v) const {
        size_t row = std::min(conditional_.size() - 1, static_cast<size_t>(v * conditional_.size()));
        return marginal_.integral() > 0 ? conditional_[row].pdf(u) * conditional_[row].integral() / marginal_.integral() : 1.0;
    }

private:
    std::vector<Distribution1D> conditional_;
    Distribution1D marginal_;
};

}  // namespace volphoton
