"""Measured subsurface-scattering materials (``volphoton:preset``): the one table the front end uses.

Source
    Jensen, Marschner, Levoy and Hanrahan 2001, "A Practical Model for Subsurface Light
    Transport" (SIGGRAPH 2001), table 2: reduced scattering coefficient sigma_s' and absorption
    coefficient sigma_a per RGB channel in 1/mm, measured with a relative index of refraction
    eta = 1.3.  The numbers below were checked digit by digit against pbrt-v4's copy of that table
    (``SubsurfaceParameterTable`` in ``src/pbrt/media.cpp``, mmp/pbrt-v4 commit 0205b861, the
    entries "From 'A Practical Model for Subsurface Light Transport'"); pbrt-v3's
    ``src/core/media.cpp`` has the same entries.

    ==========  ======================  =========================  ==================
    name        sigma_s' (1/mm) R G B   sigma_a (1/mm) R G B       albedo' R G B
    ==========  ======================  =========================  ==================
    apple       2.29   2.39   1.97      0.0030  0.0034  0.046      0.999 0.999 0.977
    chicken1    0.15   0.21   0.38      0.015   0.077   0.19       0.909 0.732 0.667
    chicken2    0.19   0.25   0.32      0.018   0.088   0.20       0.913 0.740 0.615
    cream       7.38   5.47   3.15      0.0002  0.0028  0.0163     1.000 0.999 0.995
    ketchup     0.18   0.07   0.03      0.061   0.97    1.45       0.747 0.067 0.020
    marble      2.19   2.62   3.00      0.0021  0.0041  0.0071     0.999 0.998 0.998
    potato      0.68   0.70   0.55      0.0024  0.0090  0.12       0.996 0.987 0.821
    skimmilk    0.70   1.22   1.90      0.0014  0.0025  0.0142     0.998 0.998 0.993
    skin1       0.74   0.88   1.01      0.032   0.17    0.48       0.959 0.838 0.678
    skin2       1.09   1.59   1.79      0.013   0.070   0.145      0.988 0.958 0.925
    spectralon  11.6   20.4   14.9      0       0       0          1     1     1
    wholemilk   2.55   3.21   3.77      0.0011  0.0024  0.014      1.000 0.999 0.996
    ==========  ======================  =========================  ==================

    (albedo' = sigma_s' / (sigma_s' + sigma_a), the reduced albedo, for orientation only.)

Mapping to the renderer's coefficients (``preset_coefficients``)
    With g the mean cosine of the prim's phase function (``volphoton:phase:g`` for the default
    Henyey-Greenstein phase; 0 when nothing is authored) and u = ``volphoton:sceneUnitsPerMm``::

        sigma_s = sigma_s' / (1 - g) / u        (similarity relation: same reduced scattering)
        sigma_a = sigma_a / u
        sigma_t = sigma_s + sigma_a             (1/scene unit)

    and these replace ``volphoton:density``, ``volphoton:albedo`` and ``volphoton:extinctionColor``
    (density = max_c sigma_t, extinctionColor = sigma_t / density, albedo = sigma_s / sigma_t).  A
    scene modelled in centimetres authors ``sceneUnitsPerMm = 0.1``.  The measured materials had
    eta = 1.3 (``MEASURED_IOR``): author ``volphoton:ior = 1.3`` for the measured look (the preset
    does not set the ior).  An unknown name is an error naming the prim and the attribute and
    listing the valid names; the authored density/albedo/extinctionColor are used instead.

How translucent objects are rendered (single scattering included)
    A medium inside a dielectric (``volphoton:ior > 1``) is a translucent object.  No renderer path
    connects to a light *through* the refracting surface: shadow rays stop at dielectrics.
      * photonMap: the single-scattering pass (ray march + shadow rays) therefore sees nothing inside
        a translucent object; every photon event after a refraction is stored in the photon map, so
        *all* light inside -- single scattering included -- comes from the beam radiance estimate.
        Consequences: the inside of a translucent object has the photon map's kernel blur and bias
        (shrinking with the radius over passes), strongly absorbing presets (ketchup, skin in blue)
        whose look is mostly single scattering are noisier than a march would make them, and light
        from point, spot and zero-angle distant lights does reach the inside (photons refract in).
      * pathTracer: inside a dielectric, next-event estimation finds nothing; light is found only when
        a path leaves through the surface and hits a light with extent (rect, disk, sphere with a
        radius, dome, distant light with an angle).  Delta lights (point, spot with radius 0,
        distant with angle 0) cannot light the inside of a translucent object in the path tracer --
        only the photon map renders that -- and small bright lights are noisy.  Light translucent
        objects with area or dome lights when the two integrators must agree.
      * combined (and auto, which picks it when a translucent object is in view): inside translucent
        objects as photonMap (the photons' estimate, delta lights included), everywhere else the path
        tracer's paths.
    Dense presets at real scale take hundreds to thousands of scattering events per path (a 2 cm
    marble object has an optical size of about 50): the default ``maxDepth`` (a safety cap) does not
    truncate them (a lower one does, darkening the object); lower ``photonsPerPass`` (each photon is
    stored at every event).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, List, Tuple

__all__ = ["PRESETS", "MEASURED_IOR", "SOURCE", "PresetCoefficients", "UnknownPresetError", "names",
           "preset_coefficients", "reduced_albedo"]

Vec3 = Tuple[float, float, float]

SOURCE = ("Jensen, Marschner, Levoy, Hanrahan 2001, 'A Practical Model for Subsurface Light Transport', "
          "table 2 (as in pbrt-v4 src/pbrt/media.cpp SubsurfaceParameterTable)")
MEASURED_IOR = 1.3  # = volphoton::MeasuredPresetIor

# name -> (reduced scattering sigma_s', absorption sigma_a), RGB, 1/mm.  Keep the docstring table
# and schemas/README.md in step (testenv/test_subsurface.py checks both).
def _table() -> Dict[str, Tuple[Vec3, Vec3]]:
    """The table lives in the C++ core (hdVolPhoton/core/presets.cpp), shared with the Hydra delegate."""
    from . import _core
    return {name: (tuple(ssp), tuple(sa)) for name, ssp, sa in _core.subsurface_presets()}  # type: ignore[misc]


PRESETS: Dict[str, Tuple[Vec3, Vec3]] = _table()


class UnknownPresetError(KeyError):
    """A preset name that is not in PRESETS; the message lists the valid names."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


@dataclass(frozen=True)
class PresetCoefficients:
    """Coefficients in 1/scene unit, and the same as the schema's (density, extinctionColor, albedo)."""

    sigma_s: Vec3
    sigma_a: Vec3

    @property
    def sigma_t(self) -> Vec3:
        return tuple(s + a for s, a in zip(self.sigma_s, self.sigma_a))  # type: ignore[return-value]

    @property
    def density(self) -> float:
        return max(self.sigma_t)

    @property
    def extinction_color(self) -> Vec3:
        d = self.density
        return tuple(t / d for t in self.sigma_t)  # type: ignore[return-value]

    @property
    def albedo(self) -> Vec3:
        return tuple(s / t if t > 0 else 0.0 for s, t in zip(self.sigma_s, self.sigma_t))  # type: ignore[return-value]


def names() -> List[str]:
    return sorted(PRESETS)


def reduced_albedo(name: str) -> Vec3:
    """sigma_s' / (sigma_s' + sigma_a) per channel (independent of g and units)."""
    ssp, sa = _lookup(name)
    return tuple(s / (s + a) for s, a in zip(ssp, sa))  # type: ignore[return-value]


def _lookup(name: str) -> Tuple[Vec3, Vec3]:
    try:
        return PRESETS[name]
    except KeyError:
        raise UnknownPresetError("unknown preset '%s' (valid: %s)" % (name, ", ".join(names()))) from None


def preset_coefficients(name: str, scene_units_per_mm: float = 1.0, g: float = 0.0) -> PresetCoefficients:
    """The preset's sigma_s = sigma_s' / (1 - g) and sigma_a, in 1/scene unit (see the module doc; the
    mapping is the C++ core's, core/presets.h, which both front ends use).

    Raises UnknownPresetError for a name not in PRESETS and ValueError for scene_units_per_mm <= 0
    or g outside (-1, 1)."""
    from . import _core

    _lookup(name)
    sigma_s, sigma_a = _core.preset_coefficients(name, float(scene_units_per_mm), float(g))
    return PresetCoefficients(tuple(sigma_s), tuple(sigma_a))  # type: ignore[arg-type]
