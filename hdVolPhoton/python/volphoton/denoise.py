"""Optional denoising with Intel Open Image Denoise (OIDN), for ``volphoton render --denoise``.

The denoiser is never applied to the EXR's beauty: ``--denoise`` adds a ``denoised`` layer (and the
``albedo`` / ``normal`` guide layers it used) and makes the PNG from it.

Where the library comes from: the ``oidn`` package on PyPI (``pip install oidn``; tools/setup.sh
installs it when the package registry has it) ships ``libOpenImageDenoise.so``; this module loads it
with ctypes and calls OIDN's C API (oidn.h: oidnNewDevice, oidnNewFilter "RT",
oidnSetSharedFilterImage, oidnSetFilter1b "hdr", oidnCommitFilter, oidnExecuteFilter,
oidnGetDeviceError). ``VOLPHOTON_OIDN=/path/to/libOpenImageDenoise.so`` names another build of the
library (OIDN 1.x or 2.x: the calls used are in both). Without a library, ``library()`` raises
DenoiserUnavailable with what to install.

Guides: the albedo and the camera-facing normal at the first non-specular vertex of each camera path
(RenderSettings.guideAovs, core/integrator.h "AOVs": glass is looked through), averaged over the pixel's samples as OIDN's
"RT" filter expects (noisy guides are allowed). Media report their single-scattering albedo and the
normal -ray direction, a documented stand-in: OIDN has no volume-specific guide.
"""

from __future__ import annotations

import ctypes
import glob
import importlib.util
import os
from typing import Optional

import numpy as np

_FORMAT_FLOAT3 = 3
_DEVICE_DEFAULT = 0
_lib = None


class DenoiserUnavailable(RuntimeError):
    """Open Image Denoise cannot be loaded; the message says what to install."""


def _candidates():
    env = os.environ.get("VOLPHOTON_OIDN")
    if env:
        return [env]
    spec = importlib.util.find_spec("oidn")
    if spec is None or not spec.submodule_search_locations:
        return []
    found = []
    for root in spec.submodule_search_locations:
        found += sorted(glob.glob(os.path.join(root, "lib*", "libOpenImageDenoise.so*")))
    return found


def library():
    """The loaded OIDN library (ctypes), loaded once; DenoiserUnavailable when there is none."""
    global _lib
    if _lib is not None:
        return _lib
    paths = _candidates()
    if not paths:
        raise DenoiserUnavailable("Open Image Denoise is not installed: 'pip install oidn' (its wheel ships "
                                  "libOpenImageDenoise), or set VOLPHOTON_OIDN to a libOpenImageDenoise.so")
    errors = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            errors.append("%s: %s" % (path, e))
            continue
        p, s, z, i = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t, ctypes.c_int
        for name, args, res in (("oidnNewDevice", [i], p), ("oidnCommitDevice", [p], None),
                                ("oidnNewFilter", [p, s], p),
                                ("oidnSetSharedFilterImage", [p, s, p, i, z, z, z, z, z], None),
                                ("oidnCommitFilter", [p], None), ("oidnExecuteFilter", [p], None),
                                ("oidnGetDeviceError", [p, ctypes.POINTER(ctypes.c_char_p)], i),
                                ("oidnReleaseFilter", [p], None), ("oidnReleaseDevice", [p], None)):
            f = getattr(lib, name)
            f.argtypes, f.restype = args, res
        # A bool parameter: oidnSetFilter1b in OIDN 1.x, oidnSetFilterBool in 2.x.
        setter = getattr(lib, "oidnSetFilterBool", None) or getattr(lib, "oidnSetFilter1b")
        setter.argtypes, setter.restype = [p, s, ctypes.c_bool], None
        lib.volphoton_set_bool = setter
        _lib = lib
        return lib
    raise DenoiserUnavailable("Open Image Denoise could not be loaded (%s); install it with 'pip install oidn' or "
                              "point VOLPHOTON_OIDN at a libOpenImageDenoise.so" % "; ".join(errors))


def available() -> Optional[str]:
    """None when the denoiser can run, else the reason it cannot."""
    try:
        library()
        return None
    except DenoiserUnavailable as e:
        return str(e)


def denoise(beauty: np.ndarray, albedo: Optional[np.ndarray] = None, normal: Optional[np.ndarray] = None) -> np.ndarray:
    """(H, W, 3) HDR beauty -> denoised (H, W, 3) float32 through OIDN's "RT" filter, with the albedo
    and normal guides when given (normal only together with albedo, as OIDN requires)."""
    lib = library()
    height, width = beauty.shape[:2]
    images = {"color": np.ascontiguousarray(beauty, np.float32)}
    if albedo is not None:
        images["albedo"] = np.ascontiguousarray(np.clip(albedo, 0.0, 1.0), np.float32)
        if normal is not None:
            images["normal"] = np.ascontiguousarray(normal, np.float32)
    out = np.zeros((height, width, 3), np.float32)
    images["output"] = out
    device = lib.oidnNewDevice(_DEVICE_DEFAULT)
    if not device:
        raise RuntimeError("Open Image Denoise: no device")
    try:
        lib.oidnCommitDevice(device)
        flt = lib.oidnNewFilter(device, b"RT")
        try:
            for name, img in images.items():
                lib.oidnSetSharedFilterImage(flt, name.encode(), img.ctypes.data, _FORMAT_FLOAT3, width, height, 0, 0, 0)
            lib.volphoton_set_bool(flt, b"hdr", True)
            lib.oidnCommitFilter(flt)
            lib.oidnExecuteFilter(flt)
            message = ctypes.c_char_p()
            if lib.oidnGetDeviceError(device, ctypes.byref(message)) != 0:
                raise RuntimeError("Open Image Denoise: %s" % (message.value or b"error").decode(errors="replace"))
        finally:
            lib.oidnReleaseFilter(flt)
    finally:
        lib.oidnReleaseDevice(device)
    return np.where(np.isfinite(out), out, 0.0).astype(np.float32)
