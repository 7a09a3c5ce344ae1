"""Reader and validator for the volPhoton USD schemas (VolPhotonMediumAPI, VolPhotonPhaseLobeAPI).

``read_medium(prim, time)`` turns a prim's medium attributes into a plain ``MediumDesc`` and a list
of ``Diagnostic``s that name the prim and the attribute.  Pure Python on ``pxr`` (usd-core); the
schema definitions are in ``schemas/schema.usda`` and documented in ``schemas/README.md``.

Which prims are media
    A prim with VolPhotonMediumAPI applied (a UsdVolVolume or a closed UsdGeomGprim), and every
    UsdVolVolume: a Volume without the API is rendered as a medium with the schema defaults (and
    any ``volphoton:*`` values authored on it), never as a surface.  Anything else gives ``None``.

Values
    This module only reads values off the stage: every ``volphoton:*`` attribute with a value at
    ``time`` (``UsdAttribute.Get``, so the schema's registered fallbacks apply when the API is
    applied), the applied lobe instances, the stage's up axis and the ``field:*`` relationships.
    Defaults, ranges, rules and messages are the C++ translation layer's
    (``hdVolPhoton/core/translate/medium.h``), which the Hydra delegate calls too; ``DEFAULTS`` and
    ``LOBE_DEFAULTS`` below come from it, and the tests keep them identical to the registered
    fallbacks.

Diagnostics
    Numbers outside their valid range are clamped into it with a ``warning``.  Values that cannot
    be used at all -- NaN/inf, wrong value types, unknown tokens, a mixture without usable lobes, a
    tabulated phase with fewer than 2 values, sceneUnitsPerMm <= 0, a zero exponential:up,
    inverted bounds, densityMode field without a density field, field relationships that do not
    target an OpenVDBAsset, a missing or unresolvable ``filePath`` -- are ``error``s and fall back
    to the default.  The description returned is always usable.  VDB contents (grid present, grid type)
    are checked by the C++ core when it loads the file.

The schema plug-in is found through ``PXR_PLUGINPATH_NAME`` (``<repo>/plugInfo``), which must be set
before ``pxr`` is first imported.
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

from pxr import Gf, Sdf, Usd, UsdGeom, UsdVol

from . import _core

__all__ = [
    "MEDIUM_API",
    "LOBE_API",
    "PHASE_KINDS",
    "LOBE_PHASE_KINDS",
    "DENSITY_MODES",
    "FIELD_NAMES",
    "G_LIMIT",
    "DEFAULTS",
    "LOBE_DEFAULTS",
    "Diagnostic",
    "PhaseDesc",
    "FieldDesc",
    "MediumDesc",
    "lobe_attr",
    "schlick_k_from_g",
    "is_schema_registered",
    "read_medium",
    "read_stage",
]

Vec3 = Tuple[float, float, float]

MEDIUM_API = "VolPhotonMediumAPI"
LOBE_API = "VolPhotonPhaseLobeAPI"

PHASE_KINDS = tuple(_core.phase_kinds())
LOBE_PHASE_KINDS = tuple(k for k in PHASE_KINDS if k != "mixture")
DENSITY_MODES = tuple(_core.density_modes())
# UsdVolVolume field relationships (``field:<name>``) that the renderer uses.
FIELD_NAMES = ("density", "emission", "temperature", "albedo")
# |g| and |k| are clamped to this (the C++ core clamps the same way).
G_LIMIT = _core.translate_g_limit()


def _python_value(v):
    return tuple(v) if isinstance(v, tuple) else v


# The single table of defaults, from the C++ translation layer: identical to the fallbacks in
# schemas/generatedSchema.usda.  None means "no fallback" (not authored -> derived: k from g,
# densityMode from the fields, exponential:up from the stage's up axis; bounds absent).
DEFAULTS = {name: _python_value(v) for name, v in _core.medium_attributes()}

# Defaults of the VolPhotonPhaseLobeAPI properties, by base name (see lobe_attr()).
LOBE_DEFAULTS = {name: _python_value(v) for name, v in _core.lobe_properties()}


def lobe_attr(lobe: str, prop: str) -> str:
    """Attribute name of property ``prop`` (weight, phase, g, k, x, table) of lobe ``lobe``."""
    return "volphoton:lobe:%s:%s" % (lobe, prop)


def schlick_k_from_g(g: float) -> float:
    """Schlick's k matching a Henyey-Greenstein g (the core's schlickKFromG)."""
    return _core.schlick_k_from_g(g)


_registered: Optional[bool] = None


def is_schema_registered() -> bool:
    """True when USD knows VolPhotonMediumAPI (PXR_PLUGINPATH_NAME included ``plugInfo``)."""
    global _registered
    if _registered is None:
        reg = Usd.SchemaRegistry()
        _registered = (reg.FindAppliedAPIPrimDefinition(MEDIUM_API) is not None
                       and reg.FindAppliedAPIPrimDefinition(LOBE_API) is not None)
    return _registered


# --------------------------------------------------------------------------------------------
# Result types
# --------------------------------------------------------------------------------------------


@dataclass
class Diagnostic:
    """A problem found on a prim; ``str()`` gives ``severity: /prim.attribute: message``."""

    severity: str  # 'error' | 'warning'
    prim_path: str
    attribute: str  # property name, '' for the prim itself
    message: str

    def __str__(self) -> str:
        where = self.prim_path + ("." + self.attribute if self.attribute else "")
        return "%s: %s: %s" % (self.severity, where, self.message)


@dataclass
class PhaseDesc:
    """A phase function; ``lobes`` (weight, PhaseDesc) is only non-empty for ``mixture``.

    ``k`` is always set: authored, or derived from ``g``.  ``table`` is only meaningful for
    ``tabulated`` (it holds the authored values otherwise, possibly empty).
    """

    kind: str = "henyeyGreenstein"
    g: float = 0.0
    k: float = 0.0
    x: float = 0.0
    table: List[float] = field(default_factory=list)
    lobes: List[Tuple[float, "PhaseDesc"]] = field(default_factory=list)


@dataclass
class FieldDesc:
    """An OpenVDBAsset bound to a ``field:<name>`` relationship of a Volume, at one time.

    ``file_path`` is the resolved absolute path, or '' when it cannot be resolved (an error is
    reported).  ``field_index`` is -1 when not authored; ``field_name`` '' when not authored.
    """

    file_path: str
    field_name: str
    field_index: int
    prim_path: str


@dataclass
class MediumDesc:
    """Plain description of a medium; all values validated (see the module docstring)."""

    prim_path: str
    density: float = 1.0
    albedo: Vec3 = (0.8, 0.8, 0.8)
    extinction_color: Vec3 = (1.0, 1.0, 1.0)
    emission: Vec3 = (0.0, 0.0, 0.0)
    emission_scale: float = 1.0
    temperature_scale: float = 1.0
    phase: PhaseDesc = field(default_factory=PhaseDesc)
    density_mode: str = "constant"
    exp_a: float = 1.0
    exp_b: float = 1.0
    exp_up: Vec3 = (0.0, 1.0, 0.0)
    exp_origin: Vec3 = (0.0, 0.0, 0.0)
    ior: float = 1.0
    preset: str = ""
    scene_units_per_mm: float = 1.0
    bounds: Optional[Tuple[Vec3, Vec3]] = None
    fields: Dict[str, FieldDesc] = field(default_factory=dict)
    core: object = field(default=None, compare=False, repr=False)  # the _core.MediumParams read


# --------------------------------------------------------------------------------------------
# Reader
# --------------------------------------------------------------------------------------------


def plain_value(v):
    """A USD attribute value as the translation layer takes it: bool, int, float, str, a 3-tuple for
    any 3-vector, a list for arrays and other numeric tuples; anything else is passed as is (the C++
    side reports it as unusable, naming its type)."""
    if isinstance(v, (bool, int, float, str)):
        return v
    if isinstance(v, Sdf.AssetPath):
        return v.resolvedPath or v.path
    if isinstance(v, (Gf.Vec3f, Gf.Vec3d, Gf.Vec3h, Gf.Vec3i)):
        return (float(v[0]), float(v[1]), float(v[2]))
    if hasattr(v, "__len__") and hasattr(v, "__getitem__"):
        try:
            return [float(c) for c in v]
        except (TypeError, ValueError):
            return v
    return v


def diagnostics_from_core(diags) -> List["Diagnostic"]:
    """(severity, prim, attribute, message) tuples from the C++ translation layer -> Diagnostics."""
    return [Diagnostic(s, p, a, m) for s, p, a, m in diags]


def _applied_schemas(prim: Usd.Prim) -> List[str]:
    """Applied API schema names, also when the volPhoton plug-in is not registered (USD then drops
    unknown names from GetAppliedSchemas(), so the composed apiSchemas list op is read)."""
    names = list(prim.GetAppliedSchemas())
    if not is_schema_registered():
        listop = prim.GetMetadata("apiSchemas")
        if listop is not None:
            for n in listop.ApplyOperations([]):
                if n not in names:
                    names.append(n)
    return names


def stage_up(stage: Usd.Stage) -> Vec3:
    return (0.0, 0.0, 1.0) if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z else (0.0, 1.0, 0.0)


def read_attributes(prim: Usd.Prim, time, prefix: str = "volphoton:", names=None):
    """({name: plain value}, [authored names]) of the prim's attributes under ``prefix`` (or, with
    ``names``, of those attributes only) that have a value at ``time`` (authored or a registered
    fallback)."""
    values, authored = {}, []
    attrs = prim.GetAttributes() if names is None else (prim.GetAttribute(n) for n in names)
    for attr in attrs:
        if not attr:
            continue
        name = attr.GetName()
        if not name.startswith(prefix):
            continue
        v = attr.Get(time)
        if v is None:
            continue
        values[name] = plain_value(v)
        if attr.HasAuthoredValue():
            authored.append(name)
    return values, authored


class _FieldReader:
    """The ``field:*`` relationships of a Volume (USD structure, not attribute values)."""

    def __init__(self, prim: Usd.Prim, time: Usd.TimeCode):
        self.prim = prim
        self.time = time
        self.path = str(prim.GetPath())
        self.diags: List[Diagnostic] = []

    def error(self, attr: str, msg: str, prim_path: Optional[str] = None) -> None:
        self.diags.append(Diagnostic("error", prim_path or self.path, attr, msg))

    def warn(self, attr: str, msg: str, prim_path: Optional[str] = None) -> None:
        self.diags.append(Diagnostic("warning", prim_path or self.path, attr, msg))

    def fields(self) -> Dict[str, FieldDesc]:
        out: Dict[str, FieldDesc] = {}
        stage = self.prim.GetStage()
        for fname in FIELD_NAMES:
            rel_name = "field:" + fname
            rel = self.prim.GetRelationship(rel_name)
            if not rel:
                continue
            targets = rel.GetForwardedTargets()
            if not targets:
                continue
            if len(targets) > 1:
                self.warn(rel_name, "has %d targets; using the first, %s" % (len(targets), targets[0]))
            target = targets[0]
            if not target.IsPrimPath():
                self.error(rel_name, "targets %s, which is not a prim; field ignored" % target)
                continue
            tprim = stage.GetPrimAtPath(target)
            if not tprim:
                self.error(rel_name, "targets %s, which does not exist; field ignored" % target)
                continue
            if not tprim.IsA(UsdVol.OpenVDBAsset):
                self.error(rel_name, "targets %s of type '%s', which is not an OpenVDBAsset; field ignored"
                           % (target, tprim.GetTypeName()))
                continue
            out[fname] = self.field_desc(fname, UsdVol.OpenVDBAsset(tprim))
        return out

    def field_desc(self, fname: str, asset: UsdVol.OpenVDBAsset) -> FieldDesc:
        apath = str(asset.GetPath())
        attr = asset.GetFilePathAttr()
        time = self.time
        value = attr.Get(time)
        if value is None and time.IsDefault() and attr.GetNumTimeSamples() > 0:
            time = Usd.TimeCode(attr.GetTimeSamples()[0])
            value = attr.Get(time)
            self.warn("filePath", "filePath is only time-sampled and no time was given; using the "
                      "sample at time %s" % "%g" % time.GetValue(), prim_path=apath)
        field_name = asset.GetFieldNameAttr().Get(time)
        field_index = asset.GetFieldIndexAttr().Get(time)
        desc = FieldDesc(file_path="", field_name=str(field_name) if field_name else "",
                         field_index=int(field_index) if field_index is not None else -1,
                         prim_path=apath)
        when = "" if time.IsDefault() else " at time %s" % "%g" % time.GetValue()
        if value is None or not isinstance(value, Sdf.AssetPath) or not value.path:
            self.error("filePath", "no filePath authored%s (field:%s of %s)" % (when, fname, self.path),
                       prim_path=apath)
            return desc
        if not value.resolvedPath:
            self.error("filePath", "cannot resolve filePath @%s@%s (field:%s of %s); the file does "
                       "not exist or the path is not resolvable" % (value.path, when, fname, self.path),
                       prim_path=apath)
            return desc
        resolved = value.resolvedPath
        # Package-relative paths (usdz[inner.vdb]) are left as the resolver returns them.
        desc.file_path = resolved if "[" in resolved else os.path.abspath(resolved)
        return desc



def _phase_from_core(p) -> PhaseDesc:
    return PhaseDesc(kind=p.kind, g=p.g, k=p.k, x=p.x, table=list(p.table),
                     lobes=[(w, _phase_from_core(l)) for w, l in p.lobes])


def read_medium(prim: Usd.Prim, time=Usd.TimeCode.Default()
                ) -> Tuple[Optional[MediumDesc], List[Diagnostic]]:
    """Reads the medium of ``prim`` at ``time`` (a Usd.TimeCode or a number).

    Returns ``(None, diags)`` when the prim is neither a UsdVolVolume nor has VolPhotonMediumAPI
    (``diags`` then only warns when ``volphoton:*`` attributes are authored on it anyway).  A
    Volume without the API gives a MediumDesc with the schema defaults.
    """
    if not isinstance(time, Usd.TimeCode):
        time = Usd.TimeCode(time)
    if not prim or not prim.IsValid():
        return None, []
    is_volume = prim.IsA(UsdVol.Volume)
    applied = _applied_schemas(prim)
    has_api = MEDIUM_API in applied
    lobes = [s[len(LOBE_API) + 1:] for s in applied if s.startswith(LOBE_API + ":")]
    values, authored = read_attributes(prim, time)
    fields: Dict[str, FieldDesc] = {}
    diags: List[Diagnostic] = []
    if is_volume:
        fr = _FieldReader(prim, time)
        fields = fr.fields()
        diags = fr.diags
    params, core_diags = _core.read_medium(
        str(prim.GetPath()), values, authored, is_volume=is_volume, is_gprim=prim.IsA(UsdGeom.Gprim),
        has_api=has_api, schema_registered=is_schema_registered(), type_name=str(prim.GetTypeName()),
        has_density_field="density" in fields, stage_up=stage_up(prim.GetStage()), lobe_names=lobes)
    diags = diags + diagnostics_from_core(core_diags)
    if params is None:
        return None, diags
    b = params.bounds
    desc = MediumDesc(prim_path=params.prim_path, density=params.density, albedo=tuple(params.albedo),
                      extinction_color=tuple(params.extinction_color), emission=tuple(params.emission),
                      emission_scale=params.emission_scale, temperature_scale=params.temperature_scale,
                      phase=_phase_from_core(params.phase), density_mode=params.density_mode, exp_a=params.exp_a,
                      exp_b=params.exp_b, exp_up=tuple(params.exp_up), exp_origin=tuple(params.exp_origin),
                      ior=params.ior, preset=params.preset, scene_units_per_mm=params.scene_units_per_mm,
                      bounds=None if b is None else (tuple(b[0]), tuple(b[1])), fields=fields, core=params)
    return desc, diags


def read_stage(stage: Usd.Stage, time=Usd.TimeCode.Default()
               ) -> List[Tuple[Usd.Prim, Optional[MediumDesc], List[Diagnostic]]]:
    """``read_medium`` on every prim of the stage (default predicate) that is a medium or has
    diagnostics."""
    out = []
    for prim in stage.Traverse():
        desc, diags = read_medium(prim, time)
        if desc is not None or diags:
            out.append((prim, desc, diags))
    return out


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python -m volphoton.schema stage.usda [--time T]``: prints every medium's diagnostics;
    exit status 1 when there are errors."""
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("stage")
    ap.add_argument("--time", type=float, default=None, help="time code (default: the default time)")
    ap.add_argument("-v", "--verbose", action="store_true", help="also print each medium description")
    args = ap.parse_args(argv)
    stage = Usd.Stage.Open(args.stage)
    if not stage:
        print("error: cannot open %s" % args.stage, file=sys.stderr)
        return 2
    time = Usd.TimeCode.Default() if args.time is None else Usd.TimeCode(args.time)
    errors = 0
    for prim, desc, diags in read_stage(stage, time):
        if args.verbose and desc is not None:
            print(desc)
        for d in diags:
            print(d)
            errors += d.severity == "error"
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
