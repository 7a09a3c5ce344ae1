"""Image output of the front end: multi-layer OpenEXR and the OCIO display image (PNG/JPEG).

EXR layout (32-bit float, ZIP compression, written by the core's OpenEXR writer):

    R, G, B, A                 beauty (= single + multiple + emission + surface), alpha
    single.R/G/B               light scattered once in a medium (see integrator.h for the split)
    multiple.R/G/B             light scattered more than once / scattered emission
    emission.R/G/B             volume emission seen directly
    surface.R/G/B              surfaces, lights and environment seen through the media
    depth.Z                    camera distance to the first surface (+inf where none)
    error.Y                    estimated relative error of the beauty's luminance per pixel
                               (core Film::resolveRelativeError; -1 where a pixel has < 2 samples)
    samples.Y                  camera samples the pixel got (adaptive sampling varies it)
    denoised.R/G/B             only with ``--denoise``: the beauty through Open Image Denoise
    albedo.R/G/B, normal.R/G/B only with ``--denoise``: the denoiser's guides (volphoton/denoise.py)

String header attributes: ``software``, ``volphoton:scene``, ``volphoton:camera``,
``volphoton:frame``, ``volphoton:settings`` (JSON of the render settings).

Display image: the beauty through an OpenColorIO display/view transform (``_core.DisplayTransform``):
the built-in config (linear Rec.709 ``scene_linear`` -> sRGB display, standard piecewise sRGB curve)
unless ``$OCIO`` names a config, in which case ``--display``/``--view`` pick among its displays and
views (defaults: the config's).  Values are clamped to [0, 1], quantised to 8 bits and encoded with
Pillow (PNG; JPEG quality 95 for .jpg/.jpeg; anything Pillow writes by extension).  Alpha is not
written to the display image.

Files are written to a temporary name next to the target and renamed, so a farm never sees a
half-written frame.
"""

from __future__ import annotations

import os
import tempfile
from typing import Dict, Optional

import numpy as np

from . import _core

LAYERS = ("single", "multiple", "emission", "surface")



def ensure_directory(path: str) -> None:
    """Creates the directory an output file goes to (a farm task's first frame often meets a new
    folder); raises OSError naming it when that is impossible."""
    directory = os.path.dirname(os.path.abspath(path))
    try:
        os.makedirs(directory, exist_ok=True)
    except OSError as e:
        raise OSError("cannot create output directory %s: %s" % (directory, e.strerror or e)) from None

def film_planes(film) -> Dict[str, np.ndarray]:
    """{channel name: (H, W) float32} of a core Film in the layout above."""
    planes: Dict[str, np.ndarray] = {}
    beauty = film.beauty
    for i, c in enumerate("RGB"):
        planes[c] = np.ascontiguousarray(beauty[:, :, i])
    planes["A"] = film.alpha()
    for layer in LAYERS:
        rgb = getattr(film, layer)
        for i, c in enumerate("RGB"):
            planes["%s.%s" % (layer, c)] = np.ascontiguousarray(rgb[:, :, i])
    planes["depth.Z"] = film.depth()
    error = film.relative_error()
    planes["error.Y"] = np.where(np.isfinite(error), error, -1.0).astype(np.float32)
    planes["samples.Y"] = film.samples().astype(np.float32)
    return planes


def _temp_path(path: str, suffix: str) -> str:
    """A unique hidden name next to path (not created: the writer creates it with the umask's
    permissions)."""
    directory = os.path.dirname(os.path.abspath(path)) or "."
    return os.path.join(directory, ".%s.%d.%s%s" % (os.path.basename(path), os.getpid(),
                                                   next(tempfile._get_candidate_names()), suffix))


def write_exr(path: str, planes: Dict[str, np.ndarray], attributes: Optional[Dict[str, str]] = None) -> None:
    """Writes the planes atomically (temporary file + rename)."""
    ensure_directory(path)
    tmp = _temp_path(path, ".exr")
    try:
        _core.write_exr(tmp, planes, attributes or {})
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read_exr(path: str):
    """(channels {name: (H, W) float32}, string attributes) of an OpenEXR file."""
    return _core.read_exr(path)


def display_transform(display: str = "", view: str = "", config: Optional[str] = None):
    """The OCIO display transform: ``config`` (default: ``$OCIO`` when set, else the built-in)."""
    if config is None:
        config = os.environ.get("OCIO", "")
    return _core.DisplayTransform(config, display or "", view or "")


def write_display_image(path: str, rgb: np.ndarray, transform, quality: int = 95) -> None:
    """Encodes the scene-linear (H, W, 3) image through the display transform with Pillow."""
    from PIL import Image  # imported here: the EXR path does not need Pillow

    pixels = transform.to_uint8(np.ascontiguousarray(rgb, dtype=np.float32))
    ext = os.path.splitext(path)[1].lower()
    ensure_directory(path)
    fmt = Image.registered_extensions().get(ext)
    if fmt is None:
        raise ValueError("cannot write '%s': unknown image extension '%s' (use .png or .jpg)" % (path, ext))
    tmp = _temp_path(path, ext)
    try:
        img = Image.fromarray(pixels)  # uint8 (H, W, 3) -> RGB
        kwargs = {"quality": quality} if fmt == "JPEG" else {}
        img.save(tmp, format=fmt, **kwargs)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
