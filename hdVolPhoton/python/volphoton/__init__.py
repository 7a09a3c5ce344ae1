"""hdVolPhoton Python tools: USD schema reader/validator (volphoton.schema) and helpers.

Modules
    volphoton.schema    reader/validator of the VolPhotonMediumAPI / VolPhotonPhaseLobeAPI schemas
    volphoton._core     the C++ renderer core (pybind11; built by ``pip install .``)
    volphoton.usdscene  usd-core stage -> core SceneDesc (geometry, materials, lights, media, camera)
    volphoton.output    multi-layer OpenEXR + OCIO display PNG/JPEG
    volphoton.cli       the ``volphoton`` command (``volphoton render SCENE.usd -o OUT.exr``)

The USD schema plug-in
    USD reads plug-ins once, when ``pxr`` is first used, so the schema's plugInfo directory must be on
    ``PXR_PLUGINPATH_NAME`` before that.  An installed wheel ships a copy in ``volphoton/usd/`` and this
    module adds it when ``volphoton`` is imported (import volphoton before pxr, as ``volphoton.cli``
    does); ``register_usd_plugin()`` also finds the repository's ``plugInfo/`` for a source checkout.
    Nothing is added when a directory on the variable already registers the ``volPhoton`` plug-in.
"""

import json
import os

__version__ = "0.1.0"

_PLUGIN_NAME = "volPhoton"
_HERE = os.path.dirname(os.path.abspath(__file__))


def _declares_plugin(directory):
    """True when directory/plugInfo.json registers the volPhoton plug-in."""
    # PXR_PLUGINPATH_NAME entries are directories, or plugInfo.json files themselves.
    path = directory if directory.endswith(".json") else os.path.join(directory, "plugInfo.json")
    try:
        with open(path) as f:
            text = "\n".join(line for line in f if not line.lstrip().startswith("#"))
        info = json.loads(text)
    except (OSError, ValueError):
        return False
    return any(p.get("Name") == _PLUGIN_NAME for p in info.get("Plugins", []))


def plugin_dirs_on_path():
    """Directories on PXR_PLUGINPATH_NAME that register the volPhoton schema plug-in."""
    return [d for d in os.environ.get("PXR_PLUGINPATH_NAME", "").split(os.pathsep) if d and _declares_plugin(d)]


def find_usd_plugin_dir(include_source_tree=False):
    """The packaged plugInfo directory (volphoton/usd/plugInfo), or with include_source_tree the
    repository's plugInfo/ when running from a checkout; None when neither exists."""
    candidates = [os.path.join(_HERE, "usd", "plugInfo")]
    if include_source_tree:
        # <repo>/hdVolPhoton/python/volphoton -> <repo>/plugInfo
        candidates.append(os.path.normpath(os.path.join(_HERE, "..", "..", "..", "plugInfo")))
    for c in candidates:
        if _declares_plugin(c):
            return c
    return None


def register_usd_plugin(include_source_tree=True):
    """Puts the schema plug-in on PXR_PLUGINPATH_NAME unless it is already there.  Returns the
    directory registered (or already present), or None when no copy was found.  Must run before the
    first ``import pxr`` to have an effect."""
    present = plugin_dirs_on_path()
    if present:
        return present[0]
    d = find_usd_plugin_dir(include_source_tree)
    if d is None:
        return None
    old = os.environ.get("PXR_PLUGINPATH_NAME", "")
    os.environ["PXR_PLUGINPATH_NAME"] = d + (os.pathsep + old if old else "")
    return d


# An installed wheel registers its own copy at import.  A source checkout does not (the schema tests
# check the reader's behaviour without the plug-in); volphoton.cli calls register_usd_plugin().
register_usd_plugin(include_source_tree=False)
