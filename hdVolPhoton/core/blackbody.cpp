#include "core/blackbody.h"

#include <algorithm>
#include <cmath>

namespace volphoton {
namespace {

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

}  // namespace

Spectrum blackbodyColor(double kelvin) {
    if (!(kelvin > 0)) return Spectrum(0.0);
    return blackbodyTable().lookup(kelvin);
}

Spectrum blackbodyRadiance(double kelvin) {
    if (!(kelvin > 0) || !std::isfinite(kelvin)) return Spectrum(0.0);
    double t = kelvin / 1000.0;
    return blackbodyColor(kelvin) * (t * t * t * t);
}

}  // namespace volphoton
