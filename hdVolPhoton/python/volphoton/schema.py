"""Reader and validator for the volPhoton USD schemas (VolPhotonMediumAPI, VolPhotonPhaseLobeAPI).

``read_medium(prim, time)`` turns a prim's medium attributes into a plain ``MediumDesc`` and a list
of ``Diagnostic``s that name the prim and the attribute.  Pure Python on ``pxr`` (usd-core); the
schema definitions are in ``schemas/schema.usda`` and documented in ``schemas/README.md``.

Which prims are media
    A prim with VolPhotonMediumAPI applied (a UsdVolVolume or a closed UsdGeomGprim), and every
    UsdVolVolume: a Volume without the API is rendered as a medium with the schema defaults (and
    any ``volphoton:*`` values authored on it), never as a surface.  Anything else gives ``None``.

Values
    Attributes are read with ``UsdAttribute.Get(time)``, so the schema's registered fallbacks apply
    when the API is applied; for a Volume without the API (or when the schema plug-in is not
    registered) the same defaults come from ``DEFAULTS`` / ``LOBE_DEFAULTS`` below, which the tests
    keep identical to the registered fallbacks.

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

from pxr import Sdf, Usd, UsdGeom, UsdVol

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

PHASE_KINDS = (
    "isotropic",
    "linear",
    "rayleigh",
    "lambertianSphere",
    "henyeyGreenstein",
    "schlick",
    "tabulated",
    "mixture",
)
LOBE_PHASE_KINDS = tuple(k for k in PHASE_KINDS if k != "mixture")
DENSITY_MODES = ("field", "constant", "exponential")
# UsdVolVolume field relationships (``field:<name>``) that the renderer uses.
FIELD_NAMES = ("density", "emission", "temperature", "albedo")
# |g| and |k| are clamped to this (the C++ core clamps the same way).
G_LIMIT = 0.99999

# The single table of defaults: identical to the fallbacks in schemas/generatedSchema.usda.
# None means "no fallback" (not authored -> derived: k from g, densityMode from the fields,
# exponential:up from the stage's up axis; bounds absent).
DEFAULTS = {
    "volphoton:density": 1.0,
    "volphoton:albedo": (0.8, 0.8, 0.8),
    "volphoton:extinctionColor": (1.0, 1.0, 1.0),
    "volphoton:emission": (0.0, 0.0, 0.0),
    "volphoton:emissionScale": 1.0,
    "volphoton:temperatureScale": 1.0,
    "volphoton:phase": "henyeyGreenstein",
    "volphoton:phase:g": 0.0,
    "volphoton:phase:k": None,
    "volphoton:phase:x": 0.0,
    "volphoton:phase:table": None,
    "volphoton:densityMode": None,
    "volphoton:exponential:a": 1.0,
    "volphoton:exponential:b": 1.0,
    "volphoton:exponential:up": None,
    "volphoton:exponential:origin": (0.0, 0.0, 0.0),
    "volphoton:ior": 1.0,
    "volphoton:preset": "",
    "volphoton:sceneUnitsPerMm": 1.0,
    "volphoton:bounds:min": None,
    "volphoton:bounds:max": None,
}

# Defaults of the VolPhotonPhaseLobeAPI properties, by base name (see lobe_attr()).
LOBE_DEFAULTS = {
    "weight": 1.0,
    "phase": "henyeyGreenstein",
    "g": 0.0,
    "k": None,
    "x": 0.0,
    "table": None,
}


def lobe_attr(lobe: str, prop: str) -> str:
    """Attribute name of property ``prop`` (weight, phase, g, k, x, table) of lobe ``lobe``."""
    return "volphoton:lobe:%s:%s" % (lobe, prop)


def schlick_k_from_g(g: float) -> float:
    """Schlick's k matching a Henyey-Greenstein g: k = 1.55 g - 0.55 g^3."""
    return 1.55 * g - 0.55 * g * g * g


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


# --------------------------------------------------------------------------------------------
# Reader
# --------------------------------------------------------------------------------------------


def _fmt(v) -> str:
    if isinstance(v, (tuple, list)):
        return "(" + ", ".join(_fmt(c) for c in v) + ")"
    if isinstance(v, float):
        return "%.6g" % v
    return repr(v) if isinstance(v, str) else str(v)


def _short(attr_name: str) -> str:
    """'volphoton:phase:g' -> 'g', 'volphoton:albedo' -> 'albedo' (for messages)."""
    return attr_name.rsplit(":", 1)[-1]


def _finite(v: float) -> bool:
    return not (math.isnan(v) or math.isinf(v))


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


class _Reader:
    def __init__(self, prim: Usd.Prim, time: Usd.TimeCode):
        self.prim = prim
        self.time = time
        self.path = str(prim.GetPath())
        self.diags: List[Diagnostic] = []

    # -- diagnostics -------------------------------------------------------------------------
    def error(self, attr: str, msg: str, prim_path: Optional[str] = None) -> None:
        self.diags.append(Diagnostic("error", prim_path or self.path, attr, msg))

    def warn(self, attr: str, msg: str, prim_path: Optional[str] = None) -> None:
        self.diags.append(Diagnostic("warning", prim_path or self.path, attr, msg))

    # -- raw values --------------------------------------------------------------------------
    def raw(self, name: str):
        """Value at self.time (schema fallback included), or None when neither authored nor
        provided by a registered fallback."""
        attr = self.prim.GetAttribute(name)
        if not attr:
            return None
        return attr.Get(self.time)

    def authored(self, name: str) -> bool:
        attr = self.prim.GetAttribute(name)
        return bool(attr) and attr.HasAuthoredValue()

    # -- typed readers with validation -------------------------------------------------------
    def scalar(self, name: str, default: float, lo: Optional[float] = None,
               hi: Optional[float] = None, lo_open: bool = False, hi_open: bool = False,
               clamp_lo: Optional[float] = None, clamp_hi: Optional[float] = None) -> float:
        """Float attribute; malformed or non-finite -> error + default; outside [lo, hi] (or the
        open interval) -> clamped to clamp_lo/clamp_hi (default lo/hi) with a warning."""
        v = self.raw(name)
        if v is None:
            return default
        try:
            if isinstance(v, str):
                raise ValueError(v)
            v = float(v)
        except (TypeError, ValueError):
            self.error(name, "expected a float, got %s; using the default %s" % (_fmt(v), _fmt(default)))
            return default
        short = _short(name)
        if not _finite(v):
            self.error(name, "%s = %s is not a finite number; using the default %s"
                       % (short, _fmt(v), _fmt(default)))
            return default
        below = lo is not None and (v <= lo if lo_open else v < lo)
        above = hi is not None and (v >= hi if hi_open else v > hi)
        if below or above:
            if below:
                target = clamp_lo if clamp_lo is not None else lo
            else:
                target = clamp_hi if clamp_hi is not None else hi
            if hi is not None:
                what = "is outside %s%s, %s%s" % ("(" if lo_open else "[", _fmt(float(lo)),
                                                 _fmt(float(hi)), ")" if hi_open else "]")
            elif lo == 0.0 and not lo_open:
                what = "is negative"
            else:
                what = "is %s %s" % ("not above" if lo_open else "below", _fmt(float(lo)))
            msg = "%s = %s %s; clamped to %s" % (short, _fmt(v), what, _fmt(float(target)))
            self.warn(name, msg)
            v = float(target)
        return v

    def positive(self, name: str, default: float) -> float:
        """Float that must be > 0 (a scale); anything else -> error + default."""
        v = self.scalar(name, default)
        if v <= 0.0:
            self.error(name, "%s = %s is not > 0; using the default %s" % (_short(name), _fmt(v), _fmt(default)))
            return default
        return v

    def vec3(self, name: str, default: Optional[Vec3]) -> Optional[Vec3]:
        """3-vector attribute (no range check); non-finite or malformed -> error + default."""
        v = self.raw(name)
        if v is None:
            return default
        fallback = "ignored" if default is None else "using the default %s" % _fmt(default)
        try:
            if isinstance(v, str):
                raise ValueError(v)
            t = tuple(float(c) for c in v)
            if len(t) != 3:
                raise ValueError
        except (TypeError, ValueError):
            self.error(name, "expected 3 floats, got %s; %s" % (_fmt(v), fallback))
            return default
        if not all(_finite(c) for c in t):
            self.error(name, "%s = %s is not finite; %s" % (_short(name), _fmt(t), fallback))
            return default
        return t

    def color(self, name: str, default: Vec3, hi: Optional[float]) -> Vec3:
        """color3f with each component in [0, hi] (hi None: [0, inf)); non-finite components ->
        error + default component, out-of-range components clamped with a warning."""
        v = self.raw(name)
        if v is None:
            return default
        try:
            if isinstance(v, str):
                raise ValueError(v)
            t = [float(c) for c in v]
            if len(t) != 3:
                raise ValueError
        except (TypeError, ValueError):
            self.error(name, "expected a color3f, got %s; using the default %s" % (_fmt(v), _fmt(default)))
            return default
        short = _short(name)
        if not all(_finite(c) for c in t):
            fixed = [c if _finite(c) else d for c, d in zip(t, default)]
            self.error(name, "%s = %s has non-finite components; replaced by the default: %s"
                       % (short, _fmt(tuple(t)), _fmt(tuple(fixed))))
            t = fixed
        clamped = [min(max(c, 0.0), hi) if hi is not None else max(c, 0.0) for c in t]
        if clamped != t:
            rng = "[0, %s]" % _fmt(float(hi)) if hi is not None else ">= 0"
            self.warn(name, "%s = %s has components outside %s; clamped to %s"
                      % (short, _fmt(tuple(t)), rng, _fmt(tuple(clamped))))
        return tuple(clamped)

    def token(self, name: str, default: Optional[str]) -> Optional[str]:
        v = self.raw(name)
        if v is None:
            return default
        return str(v)

    def float_array(self, name: str) -> Optional[List[float]]:
        v = self.raw(name)
        if v is None:
            return None
        try:
            if isinstance(v, str):
                raise ValueError(v)
            return [float(c) for c in v]
        except (TypeError, ValueError):
            self.error(name, "expected a float[], got %s; ignored" % _fmt(v))
            return None

    # -- phase -------------------------------------------------------------------------------
    def phase(self, names: Dict[str, str], defaults: Dict[str, object],
              allowed: Sequence[str], what: str) -> PhaseDesc:
        """Reads kind/g/k/x/table (not lobes).  ``names`` maps phase/g/k/x/table to attribute
        names; an invalid kind falls back to the default kind with an error."""
        kind_attr = names["phase"]
        kind = self.token(kind_attr, defaults["phase"])
        if kind not in allowed:
            if kind in PHASE_KINDS:  # 'mixture' on a lobe
                self.error(kind_attr, "%s cannot be '%s'; using %s" % (what, kind, defaults["phase"]))
            else:
                self.error(kind_attr, "unknown phase '%s' (expected one of %s); using %s"
                           % (kind, ", ".join(allowed), defaults["phase"]))
            kind = defaults["phase"]
        g = self.scalar(names["g"], defaults["g"], -1.0, 1.0, lo_open=True, hi_open=True,
                        clamp_lo=-G_LIMIT, clamp_hi=G_LIMIT)
        # Derived k is clamped silently: k(g) slightly exceeds 1 just below g = 1.
        k_from_g = min(max(schlick_k_from_g(g), -G_LIMIT), G_LIMIT)
        if self.raw(names["k"]) is None:
            k = k_from_g
        else:
            k = self.scalar(names["k"], k_from_g, -1.0, 1.0, lo_open=True, hi_open=True,
                            clamp_lo=-G_LIMIT, clamp_hi=G_LIMIT)
        x = self.scalar(names["x"], defaults["x"], -1.0, 1.0)
        table = self.float_array(names["table"]) or []
        desc = PhaseDesc(kind=kind, g=g, k=k, x=x, table=table)
        if kind == "tabulated":
            tattr = names["table"]
            if len(table) < 2:
                self.error(tattr, "tabulated phase needs at least 2 values, got %d; using isotropic"
                           % len(table))
                desc.kind = "isotropic"
                return desc
            bad = [i for i, v in enumerate(table) if not _finite(v)]
            if bad:
                self.error(tattr, "table has non-finite values at indices %s; set to 0"
                           % ", ".join(map(str, bad[:8])))
                table = [v if _finite(v) else 0.0 for v in table]
            neg = [i for i, v in enumerate(table) if v < 0]
            if neg:
                self.warn(tattr, "table has negative values at indices %s; clamped to 0"
                          % ", ".join(map(str, neg[:8])))
                table = [max(v, 0.0) for v in table]
            desc.table = table
            if not any(v > 0 for v in table):
                self.error(tattr, "table is all zero and cannot be normalised; using isotropic")
                desc.kind = "isotropic"
        return desc

    def medium_phase(self) -> PhaseDesc:
        names = {"phase": "volphoton:phase", "g": "volphoton:phase:g", "k": "volphoton:phase:k",
                 "x": "volphoton:phase:x", "table": "volphoton:phase:table"}
        defaults = {"phase": DEFAULTS["volphoton:phase"], "g": DEFAULTS["volphoton:phase:g"],
                    "x": DEFAULTS["volphoton:phase:x"]}
        desc = self.phase(names, defaults, PHASE_KINDS, "volphoton:phase")
        prefix = LOBE_API + ":"
        lobe_names = [s[len(prefix):] for s in _applied_schemas(self.prim) if s.startswith(prefix)]
        if desc.kind != "mixture":
            if lobe_names:
                self.warn("volphoton:phase", "phase is '%s', so the applied %s lobes %s are ignored "
                          "(set phase to mixture to use them)" % (desc.kind, LOBE_API, ", ".join(lobe_names)))
            return desc
        if not lobe_names:
            self.error("volphoton:phase", "phase is mixture but no %s lobe is applied; using isotropic"
                       % LOBE_API)
            desc.kind = "isotropic"
            return desc
        lobes = []
        for name in lobe_names:
            lnames = {p: lobe_attr(name, p) for p in ("phase", "g", "k", "x", "table")}
            weight = self.scalar(lobe_attr(name, "weight"), LOBE_DEFAULTS["weight"], 0.0, None)
            lobe = self.phase(lnames, LOBE_DEFAULTS, LOBE_PHASE_KINDS, "a mixture lobe")
            lobes.append((weight, lobe))
        if not any(w > 0 for w, _ in lobes):
            self.error("volphoton:phase", "phase is mixture but all lobe weights (%s) are 0; using isotropic"
                       % ", ".join(lobe_names))
            desc.kind = "isotropic"
            return desc
        desc.lobes = lobes
        return desc

    # -- fields ------------------------------------------------------------------------------
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
                      "sample at time %s" % _fmt(time.GetValue()), prim_path=apath)
        field_name = asset.GetFieldNameAttr().Get(time)
        field_index = asset.GetFieldIndexAttr().Get(time)
        desc = FieldDesc(file_path="", field_name=str(field_name) if field_name else "",
                         field_index=int(field_index) if field_index is not None else -1,
                         prim_path=apath)
        when = "" if time.IsDefault() else " at time %s" % _fmt(time.GetValue())
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

    # -- everything --------------------------------------------------------------------------
    def read(self, is_volume: bool, has_api: bool) -> MediumDesc:
        p = self.path
        if has_api and not is_schema_registered():
            self.warn("", "%s is applied but the volPhoton schema plug-in is not registered "
                      "(set PXR_PLUGINPATH_NAME to hdVolPhoton's plugInfo directory); using the "
                      "built-in defaults" % MEDIUM_API)
        d = DEFAULTS
        m = MediumDesc(prim_path=p)
        m.density = self.scalar("volphoton:density", d["volphoton:density"], 0.0, None)
        m.albedo = self.color("volphoton:albedo", d["volphoton:albedo"], 1.0)
        m.extinction_color = self.color("volphoton:extinctionColor", d["volphoton:extinctionColor"], None)
        m.emission = self.color("volphoton:emission", d["volphoton:emission"], None)
        m.emission_scale = self.scalar("volphoton:emissionScale", d["volphoton:emissionScale"], 0.0, None)
        m.temperature_scale = self.scalar("volphoton:temperatureScale", d["volphoton:temperatureScale"],
                                          0.0, None)
        m.phase = self.medium_phase()

        m.fields = self.fields() if is_volume else {}
        derived_mode = "field" if "density" in m.fields else "constant"
        mode = self.token("volphoton:densityMode", None)
        if mode is None:
            mode = derived_mode
        elif mode not in DENSITY_MODES:
            self.error("volphoton:densityMode", "unknown densityMode '%s' (expected one of %s); using %s"
                       % (mode, ", ".join(DENSITY_MODES), derived_mode))
            mode = derived_mode
        elif mode == "field" and "density" not in m.fields:
            if is_volume:
                why = "no usable field:density relationship (targeting an OpenVDBAsset) is bound"
            else:
                why = "the prim is a %s, not a UsdVolVolume with a density field" % (
                    self.prim.GetTypeName() or "typeless prim")
            self.error("volphoton:densityMode", "densityMode is field but %s; using constant" % why)
            mode = "constant"
        m.density_mode = mode

        m.exp_a = self.scalar("volphoton:exponential:a", d["volphoton:exponential:a"], 0.0, None)
        m.exp_b = self.scalar("volphoton:exponential:b", d["volphoton:exponential:b"], 0.0, None)
        stage_up = (0.0, 0.0, 1.0) if UsdGeom.GetStageUpAxis(self.prim.GetStage()) == UsdGeom.Tokens.z \
            else (0.0, 1.0, 0.0)
        up = self.vec3("volphoton:exponential:up", None)
        if up is None:
            m.exp_up = stage_up
        else:
            n = math.sqrt(sum(c * c for c in up))
            if n == 0.0:
                self.error("volphoton:exponential:up", "up = (0, 0, 0) has no direction; using the "
                           "stage's up axis %s" % _fmt(stage_up))
                m.exp_up = stage_up
            else:
                m.exp_up = tuple(c / n for c in up)
        m.exp_origin = self.vec3("volphoton:exponential:origin", d["volphoton:exponential:origin"])

        m.ior = self.scalar("volphoton:ior", d["volphoton:ior"], 1.0, None)
        if is_volume and self.authored("volphoton:ior") and m.ior != 1.0:
            self.warn("volphoton:ior", "ior is ignored on a Volume (only a Gprim's surface refracts)")
        m.preset = self.token("volphoton:preset", d["volphoton:preset"]) or ""
        m.scene_units_per_mm = self.positive("volphoton:sceneUnitsPerMm", d["volphoton:sceneUnitsPerMm"])
        m.bounds = self.bounds(is_volume)
        return m

    def bounds(self, is_volume: bool):
        lo = self.vec3("volphoton:bounds:min", None)
        hi = self.vec3("volphoton:bounds:max", None)
        if lo is None and hi is None:
            return None
        if lo is None or hi is None:
            given = "volphoton:bounds:max" if lo is None else "volphoton:bounds:min"
            missing = "volphoton:bounds:min" if lo is None else "volphoton:bounds:max"
            self.warn(given, "%s is not authored (or not usable), so the bounds are ignored" % missing)
            return None
        if any(a > b for a, b in zip(lo, hi)):
            self.error("volphoton:bounds:min", "bounds:min %s is not <= bounds:max %s on every axis; "
                       "bounds ignored" % (_fmt(lo), _fmt(hi)))
            return None
        if not is_volume:
            self.warn("volphoton:bounds:min", "bounds are ignored on a %s (its surface bounds the medium)"
                      % (self.prim.GetTypeName() or "typeless prim"))
            return None
        return (lo, hi)


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
    has_api = MEDIUM_API in _applied_schemas(prim)
    reader = _Reader(prim, time)
    if not is_volume and not has_api:
        stray = [a.GetName() for a in prim.GetAuthoredAttributes()
                 if a.GetName().startswith("volphoton:")]
        if stray:
            reader.warn("", "has %s authored but %s is not applied, so it is not a medium (apply the API)"
                        % (", ".join(sorted(stray)[:4]) + (", ..." if len(stray) > 4 else ""), MEDIUM_API))
        return None, reader.diags
    if has_api and not is_volume and not prim.IsA(UsdGeom.Gprim):
        reader.warn("", "%s is applied to a %s; it only applies to Volume and Gprim prims"
                    % (MEDIUM_API, prim.GetTypeName() or "typeless prim"))
    desc = reader.read(is_volume, has_api)
    return desc, reader.diags


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
