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
`volphoton render` does) and rendered by the core, one image per pass, at default settings, the
photon map's multiple scattering included.  Its defaults follow the media, not the scene (kernel
radius and march step from the media's diameter; half of the dome's photons aimed at the media,
starting where their line enters the scene's box: core/lights.h PhotonAim).  Before that, with
W = 1e6 the dome's photons were spread over the scene's disk (almost none reached the slab), and
those that did started 1.4e6 units away, where single-precision intersection cannot tell the ground
from the slab 0.02 above it: the multiple-scattering image was 24% too bright (0.108 against 0.087
over 6 seeds of 16 passes, 3 sigma).

Tolerance: the image mean of each (W, seed, pass) is one sample; sigma is the standard error of
the mean over 2 seeds x 16 passes.  The difference to W = 1e2 must stay within 5 sigma of the
combined standard errors (and, paired, the differences at 1e5 and 1e6 to 1e4: see the test) (k = 5: 3 W values x 2 views x 2 integrators = 12 comparisons, a Gaussian
exceeds 5 sigma with probability 6e-7 each).  The old offsets miss by tens to hundreds of sigma.
"""

import pytest

import slab_scene

HALF_WIDTHS = (1e2, 1e4, 1e5, 1e6)
INTEGRATORS = ("pathTracer", "photonMap")
SEEDS = (1, 2)
PASSES = 16
RES = 8
K = 5.0


def pass_means(tmp_path, view, w, integrator):
    """Image mean of every pass, over SEEDS: (len(SEEDS) * PASSES,) float64."""
    path = tmp_path / ("%s_%g.usda" % (view, w))
    path.write_text(slab_scene.stage_text(slab_scene.camera(view) + slab_scene.SLAB + slab_scene.ground(w) +
                                          slab_scene.DOME))
    return slab_scene.pass_means(path, integrator, RES, SEEDS, PASSES)


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("view", sorted(slab_scene.VIEWS))
def test_thin_slab_is_the_same_whatever_the_ground_plane_size(tmp_path, view, integrator):
    values = {w: pass_means(tmp_path, view, w, integrator) for w in HALF_WIDTHS}
    stats = {w: slab_scene.mean_and_error(v) for w, v in values.items()}
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
    # Paired: the same seeds and passes at W = 1e5 and 1e6 against 1e4, where the ground hides the
    # same directions to within 1e-4 radians, so the noise cancels and a shift of a fraction of a
    # sigma above shows (the photon map's photons from 1.4e6 units away made the W = 1e6 view from
    # below 0.029 brighter, under 3 of the unpaired sigma above). Allowance 1e-4 of the mean for the
    # horizon the ground still moves.
    for w in HALF_WIDTHS[2:]:
        diff = values[w] - values[1e4]
        m, se = slab_scene.mean_and_error(diff)
        print("%s %s W=%g - W=1e4 (paired): %.6f +- %.6f" % (integrator, view, w, m, se))
        assert abs(m) <= K * se + 1e-4 * stats[1e4][0], (integrator, view, w, m, se)
