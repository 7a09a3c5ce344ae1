"""glTF 2.0 -> USD: ``volphoton gltf2usd IN.gltf|IN.glb OUT.usd[a|c]``.

The translation itself is C++ (``hdVolPhoton/gltf/gltfToUsda.cpp``, tinygltf): it writes the layer as
usda text, which usd-core parses here and exports in the format OUT's extension names.  The Sdf
file-format plug-in of a Hydra build (``references = @asset.glb@``) uses the same C++ translator, so
both give the same prims.  The mapping table (nodes, meshes, primitives, materials, scenes) is at the
top of ``gltfToUsda.h``; in short:

* the default prim is an Xform named after the file (``--root-name`` overrides), with layer metadata
  ``upAxis = "Y"`` and ``metersPerUnit = 1`` (glTF is +Y up, in metres), so a stage in centimetres
  or Z-up that references it can correct the difference with a transform on the referencing prim;
* each node is an Xform (matrix -> ``xformOp:transform``, TRS -> translate/orient/scale), each mesh
  a Mesh prim under its node (``class`` prototype + reference when several nodes share it);
* several glTF scenes become the variant set ``scene`` on the default prim.

To give a converted asset a medium, apply the API on the Mesh prim from the referencing layer::

    def Xform "Statue" (references = @statue.usdc@) {
        over "node_0" { over "mesh" (prepend apiSchemas = ["VolPhotonMediumAPI"]) {
            float volphoton:ior = 1.5
            token volphoton:preset = "marble"
        } }
    }

Exit status of the command: 0 converted (warnings possible), 1 converted with errors (the elements
named in the errors are left out), 2 nothing written (unreadable input, bad arguments).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

OUTPUT_EXTENSIONS = (".usd", ".usda", ".usdc")


class GltfError(Exception):
    """The input could not be read at all, or the output not written."""


@dataclass
class Conversion:
    output: str
    diagnostics: List[Tuple[str, str, str]] = field(default_factory=list)  # (severity, element, message)
    stats: Dict[str, int] = field(default_factory=dict)

    @property
    def errors(self) -> List[Tuple[str, str, str]]:
        return [d for d in self.diagnostics if d[0] == "error"]


def format_diagnostic(path: str, diagnostic: Tuple[str, str, str]) -> str:
    severity, element, message = diagnostic
    return "%s: %s: %s%s" % (path, severity, element + ": " if element else "", message)


def translate(path: str, root_name: str = "") -> Tuple[str, List[Tuple[str, str, str]], Dict[str, int]]:
    """(usda text, diagnostics, stats) of a glTF file; GltfError when it cannot be read at all."""
    from . import _core
    if not os.path.isfile(path):
        raise GltfError("%s: no such file" % path)
    ok, text, diagnostics, stats = _core.gltf_to_usda(path, root_name)
    if not ok:
        raise GltfError("\n".join(format_diagnostic(path, d) for d in diagnostics) or "%s: unreadable" % path)
    return text.decode("utf-8"), diagnostics, stats


def convert(path: str, output: str, root_name: str = "") -> Conversion:
    """Translates `path` and writes `output` (.usda text, .usdc crate, .usd = crate)."""
    from pxr import Sdf, Tf
    from .output import ensure_directory
    if os.path.splitext(output)[1].lower() not in OUTPUT_EXTENSIONS:
        raise GltfError("%s: the output must end in %s" % (output, ", ".join(OUTPUT_EXTENSIONS)))
    text, diagnostics, stats = translate(path, root_name)
    layer = Sdf.Layer.CreateAnonymous(".usda")
    try:
        parsed = layer.ImportFromString(text)
    except Tf.ErrorException as e:
        parsed, detail = False, str(e).strip()
    else:
        detail = ""
    if not parsed:
        # The translator writes only what it validated; a parse failure is a bug, not bad input.
        raise GltfError("%s: internal error: the translated layer does not parse %s" % (path, detail))
    ensure_directory(output)
    if not layer.Export(output):
        raise GltfError("%s: cannot write" % output)
    return Conversion(output, list(diagnostics), dict(stats))
