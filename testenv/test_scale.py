"""Right at any scale (issue 14, part 1): ray offsets follow the local float precision of each hit,
not the scene's extent.

A 1-unit slab of fog (x, z in [-2, 2], y in [0, 1]) under a dome of radiance 1, with a black ground
plane 0.02 below it whose half-width W is the only thing that changes (1e2, 1e4, 1e5, 1e6: the
scene's extent follows W).  Two cameras 1e-3 from the medium's boundary: one below the slab looking
up through it at the sky (the ground behind it), one above looking down into it (the ground 0.02
past its far side).  Nothing near the slab changes with W, so every W must give the same picture.

With offsets of 1e-5 x the scene's extent (the old Scene::epsilon) a W = 1e5 ground made the ray
entering the slab from below skip its far side (0.1 .. 10 units of offset against 1 unit of
slab), and the ray leaving its bottom skip the ground 0.02 below (the sky came through): both
views changed by far more than the noise.

Through the standalone front end: the .usda files are translated by volphoton.usdscene (as
`volphoton render` does) and rendered by the core, one image per pass.  The photon map runs its
single-scattering march and camera paths only (multipleScattering off, march step and radius set):
its dome photons are emitted over the scene's bounding disk, so with W = 1e6 almost none of them
reach a 4-unit slab, a separate matter from ray offsets (the multiple part would be pure noise).

Tolerance: the image mean of each (W, seed, pass) is one sample; sigma is the standard error of
the mean over 2 seeds x 16 passes.  The difference to W = 1e2 must stay within 5 sigma of the
combined standard errors (k = 5: 3 W values x 2 views x 2 integrators = 12 comparisons, a Gaussian
exceeds 5 sigma with probability 6e-7 each).  The old code misses by tens to hundreds of sigma.
"""

import pytest

import slab_scene

HALF_WIDTHS = (1e2, 1e4, 1e5, 1e6)
INTEGRATORS = ("pathTracer", "photonMap")
SEEDS = (1, 2)
PASSES = 16
RES = 8
K = 5.0


def single_scattering_march(s):
    """The photon map without its photon pass, its march step and radius set (see the docstring)."""
    if s.integrator == s.Integrator.PhotonMap:
        s.multiple_scattering = False
        s.march_step = 0.01
        s.initial_radius = 0.05


def pass_means(tmp_path, view, w, integrator):
    """Image mean of every pass, over SEEDS: (len(SEEDS) * PASSES,) float64."""
    path = tmp_path / ("%s_%g.usda" % (view, w))
    path.write_text(slab_scene.stage_text(slab_scene.camera(view) + slab_scene.SLAB + slab_scene.ground(w) +
                                          slab_scene.DOME))
    return slab_scene.pass_means(path, integrator, RES, SEEDS, PASSES, configure=single_scattering_march)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("view", sorted(slab_scene.VIEWS))
def test_thin_slab_is_the_same_whatever_the_ground_plane_size(tmp_path, view, integrator):
    stats = {}
    for w in HALF_WIDTHS:
        stats[w] = slab_scene.mean_and_error(pass_means(tmp_path, view, w, integrator))
    ref, ref_se = stats[HALF_WIDTHS[0]]
    # The layer is there at all (not black, not the bare sky): 1 unit of optical depth, albedo 0.8.
    if view == "below":
        assert 0.3 < ref < 0.95, ref  # e^-1 of the sky plus the light it scatters forward
    else:
        assert 0.05 < ref < 0.45, ref  # only the light the slab scatters back (ground black)
    for w in HALF_WIDTHS[1:]:
        m, se = stats[w]
        tol = K * (se ** 2 + ref_se ** 2) ** 0.5
        print("%s %s W=%g: %.5f +- %.5f (W=1e2: %.5f +- %.5f)" % (integrator, view, w, m, se, ref, ref_se))
        assert abs(m - ref) <= tol, (integrator, view, w, m, se, ref, ref_se)
