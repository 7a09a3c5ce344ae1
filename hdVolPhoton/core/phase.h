// Phase functions. All are azimuthally symmetric, so each is a function of the cosine of the
// scattering angle, cosTheta = dot(dirIn, dirOut), where both are *propagation* directions: the
// direction light travelled before the event and the one it travels after. cosTheta = 1 is forward.
// A camera path that arrived along ray direction d and continues along w sees the same angle
// (cosTheta = dot(d, w)) by reciprocity, so path tracing and photon tracing call the same routines.
//
// Parameters (also the schema's `volphoton:phase*` attributes):
// | kind              | parameter | range        | meaning                                             |
// |-------------------|-----------|--------------|-----------------------------------------------------|
// | isotropic         |           |              | p = 1/(4 pi)                                         |
// | linear            | x         | [-1, 1]      | p = (1 + x cosTheta)/(4 pi)                          |
// | rayleigh          |           |              | p = 3/(16 pi) (1 + cos^2 Theta)                      |
// | lambertianSphere  |           |              | large diffuse sphere; mean cosine -4/9               |
// | henyeyGreenstein  | g         | (-1, 1)      | mean cosine g; |g| clamped to 0.99999              |
// | schlick           | k         | (-1, 1)      | k = 1.55g - 0.55g^3 when only g is given             |
// | tabulated         | values    | >= 0         | p over a uniform grid in cosTheta, normalised on load|
// | mixture           | lobes     | weights >= 0 | weighted sum of any of these, weights normalised     |
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/math.h"

namespace volphoton {

/// Result of sampling a phase function: the new propagation direction, the phase function's
/// value and the density (solid angle) with which the direction was chosen.
struct PhaseSample {
    Vec3 dirOut;
    double p = 0;
    double pdf = 0;
};

/// \class PhaseFunction
/// Immutable and shared between threads; every method is const and allocation free.
class PhaseFunction {
public:
    virtual ~PhaseFunction() = default;
    /// Value in 1/sr; integrates to 1 over the sphere.
    virtual double eval(double cosTheta) const = 0;
    /// Density (1/sr) with which sampleCosTheta() produces cosTheta; equals eval() for the exact
    /// samplers.
    virtual double pdf(double cosTheta) const { return eval(cosTheta); }
    /// Draws cosTheta from u in [0, 1).
    virtual double sampleCosTheta(double u) const = 0;
    /// Analytic mean cosine <cos Theta>.
    virtual double meanCosine() const = 0;
    virtual std::string describe() const = 0;

    /// Samples a propagation direction after scattering of light travelling along dirIn.
    PhaseSample sample(const Vec3& dirIn, double u1, double u2) const {
        double cosTheta = sampleCosTheta(u1);
        PhaseSample s;
        s.dirOut = sphericalDirection(dirIn, cosTheta, 2 * Pi * u2);
        s.p = eval(cosTheta);
        s.pdf = pdf(cosTheta);
        return s;
    }
    double eval(const Vec3& dirIn, const Vec3& dirOut) const { return eval(std::clamp(dot(dirIn, dirOut), -1.0, 1.0)); }
    double pdf(const Vec3& dirIn, const Vec3& dirOut) const { return pdf(std::clamp(dot(dirIn, dirOut), -1.0, 1.0)); }
};

using PhasePtr = std::shared_ptr<const PhaseFunction>;

/// How peaked a phase function is: 4 pi max(p(1), p(-1)), 1 for isotropic scattering (and for null,
/// which media read as isotropic); Henyey-Greenstein's is (1 + |g|) / (1 - |g|)^2 (g = 0.6: 10).
inline double phasePeak(const PhaseFunction* phase) {
    return phase ? 4 * Pi * std::max(phase->eval(1.0), phase->eval(-1.0)) : 1.0;
}

/// Factories. They validate and clamp parameters; invalid input throws std::invalid_argument with a
/// message naming the parameter (the USD layer prefixes the prim and attribute).
PhasePtr makeIsotropicPhase();
PhasePtr makeLinearPhase(double x);
PhasePtr makeRayleighPhase();
PhasePtr makeLambertianSpherePhase();
PhasePtr makeHenyeyGreensteinPhase(double g);
/// Schlick's approximation with parameter k; schlickKFromG() gives k = 1.55g - 0.55g^3
/// (Blasi, Le Saec and Schlick 1993).
PhasePtr makeSchlickPhase(double k);
double schlickKFromG(double g);
/// Tabulated p(cosTheta) at cosTheta_i = -1 + 2 i/(n-1), piecewise linear between; normalised on load.
PhasePtr makeTabulatedPhase(const std::vector<double>& values);
/// Weighted mixture; weights are normalised to sum to 1.
PhasePtr makeMixturePhase(const std::vector<std::pair<double, PhasePtr>>& lobes);

}  // namespace volphoton
