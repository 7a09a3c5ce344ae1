// Blackbody emission for temperature fields: the colour of a blackbody at a given temperature and
// the radiance a grid medium emits per unit of absorption (Kirchhoff's law, as in pbrt-v4). The
// colour is Planck's law against the CIE 1931 colour matching functions in the fit of Wyman, Sloan
// and Shirley 2013 (see blackbodyColor). Used by GridMedium; no OpenVDB types.
#pragma once

#include "core/math.h"

namespace volphoton {

/// Chromaticity of a blackbody at `kelvin` as linear Rec.709/sRGB primaries, normalised to luminance
/// 1: Planck's law integrated against the CIE 1931 2-degree colour matching functions in the
/// multi-lobe Gaussian fit of Wyman, Sloan and Shirley 2013 ("Simple Analytic Approximations to the
/// CIE XYZ Color Matching Functions", JCGT 2(2)), then XYZ -> linear sRGB, negative components
/// clamped to 0. Tabulated at start-up; 0 for kelvin <= 0.
Spectrum blackbodyColor(double kelvin);

/// Blackbody radiance used for temperature emission (radiance units of the scene):
///   blackbodyRadiance(T) = blackbodyColor(T) * (T / 1000 K)^4
/// i.e. luminance follows the Stefan-Boltzmann T^4 law, normalised to 1 at 1000 K:
/// | T (K)  | luminance |
/// |--------|-----------|
/// | 500    | 0.0625    |
/// | 1000   | 1         |
/// | 1500   | 5.06      |
/// | 3000   | 81        |
/// | 6500   | 1785      |
/// Multiply by emissionScale (and, in the medium, by sigma_a) to tune brightness.
Spectrum blackbodyRadiance(double kelvin);

}  // namespace volphoton
