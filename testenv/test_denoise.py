"""Denoising as an option (issue 17, item 2): ``volphoton render --denoise`` adds a ``denoised`` layer
from Intel Open Image Denoise with the albedo/normal guides, makes the PNG from it and never
replaces the beauty; without the library it stops with a message saying what to install.

The denoiser test runs where the optional library loads (tools/setup.sh installs the ``oidn`` wheel)
and is SKIPPED otherwise, naming why.

Tolerances: the denoised image must be closer to a 16x-more-samples reference than the noisy beauty
(RMSE ratio < 0.7: a denoiser that did nothing gives 1.0) and keep the image mean within 3% (the
reference's own standard error of the mean is ~0.1%).
"""

import numpy as np
import pytest

import slab_scene
from conftest import run_cli
from volphoton import denoise, output


def _stage(tmp_path):
    stage = tmp_path / "slab.usda"
    stage.write_text(slab_scene.stage_text(
        slab_scene.camera("above") + slab_scene.SLAB + slab_scene.ground(10) + slab_scene.DOME,
        settings=dict(size=48, spp=4, seed=1, integrator="pathTracer")))
    return stage


def _beauty(path, layer=None):
    ch, _ = output.read_exr(str(path))
    names = ["%s.%s" % (layer, c) if layer else c for c in "RGB"]
    return np.stack([ch[n] for n in names], axis=-1).astype(np.float64), ch


def test_denoise_adds_a_layer_that_is_closer_to_the_reference(tmp_path):
    reason = denoise.available()
    if reason:
        pytest.skip("optional denoiser absent: " + reason)
    stage = _stage(tmp_path)
    noisy, ref, plain = tmp_path / "noisy.exr", tmp_path / "ref.exr", tmp_path / "plain.exr"
    r = run_cli("render", stage, "-o", noisy, "--camera", "/World/cam", "--denoise")
    assert r.returncode == 0, r.stderr
    assert "denoised (the PNG's image)" in r.stderr
    r = run_cli("render", stage, "-o", plain, "--camera", "/World/cam", "--no-png", "-q")
    assert r.returncode == 0, r.stderr
    r = run_cli("render", stage, "-o", ref, "--camera", "/World/cam", "--no-png", "-q", "--spp", "64", "--seed", "99")
    assert r.returncode == 0, r.stderr
    beauty, ch = _beauty(noisy)
    denoised, _ = _beauty(noisy, "denoised")
    reference, _ = _beauty(ref)
    # The beauty is the render's, not the denoiser's: the same as without --denoise.
    np.testing.assert_array_equal(beauty, _beauty(plain)[0])
    for layer in ("albedo", "normal"):
        assert all("%s.%s" % (layer, c) in ch for c in "RGB")
    # Guides: the slab's single-scattering albedo is 0.8 where the camera's ray collides in it, the
    # ground's is 0; the normals are unit vectors facing the camera (+y, the camera looks down).
    assert 0.3 < ch["albedo.R"].mean() < 0.8 + 1e-6
    assert ch["normal.G"].mean() > 0.95
    assert np.isfinite(denoised).all()
    rmse = lambda a: float(np.sqrt(((a - reference) ** 2).mean()))
    print("RMSE noisy %.5f denoised %.5f" % (rmse(beauty), rmse(denoised)))
    assert rmse(denoised) < 0.7 * rmse(beauty)
    assert abs(denoised.mean() / reference.mean() - 1) < 0.03


def test_denoise_without_the_library_says_what_to_install(tmp_path):
    r = run_cli("render", _stage(tmp_path), "-o", tmp_path / "x.exr", "--denoise",
                env_updates={"VOLPHOTON_OIDN": str(tmp_path / "no" / "libOpenImageDenoise.so")})
    assert r.returncode == 2, r.stderr
    assert "--denoise: Open Image Denoise could not be loaded" in r.stderr and "pip install oidn" in r.stderr, r.stderr
    assert not (tmp_path / "x.exr").exists()
