"""The benchmark's statistics (tools/bench/run.py) on synthetic images whose answer is known."""

import importlib.util
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def _run_module():
    spec = importlib.util.spec_from_file_location("bench_run", os.path.join(HERE, "..", "tools", "bench", "run.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_mean_check_sigma_counts_pixels_not_channels():
    # A grey image: each pixel's three channels carry the same noise (one path per sample), as in
    # benchmark scenes lit and coloured grey. Over 400 noisy images of an exact reference, z must
    # spread with standard deviation 1 (its standard error over 400 trials is 0.035; tolerance 0.15,
    # 4 of them). Counting channels as independent gave sqrt(3) = 1.73.
    run = _run_module()
    rng = np.random.default_rng(5)
    ref = np.full((30, 40, 3), 0.5)
    zs = []
    for _ in range(400):
        noise = rng.normal(0.0, 0.1, (30, 40, 1))
        img = ref + noise
        err = float(np.sqrt(np.mean((img - ref) ** 2)))
        zs.append(run.mean_check(img, ref, err)["z"])
    assert abs(np.std(zs) - 1.0) < 0.15, np.std(zs)


def test_mean_check_sigma_sees_noise_that_pixels_share():
    # A photon map's noise is shared by every pixel of its pass. Renders of 16 passes whose pixels
    # carry each pass's common offset (sigma 0.05) beside independent noise (sigma 0.1): over 400
    # renders of an exact reference z must spread with standard deviation 1 (tolerance 0.15, 4
    # standard errors of the spread as above) when the passes' image means are given; from the pixels
    # alone it spreads far wider (the common offset's sigma / sqrt(16) against 0.1 / sqrt(16 x 1200)).
    run = _run_module()
    rng = np.random.default_rng(7)
    ref = np.full((30, 40, 3), 0.5)
    with_passes, pixels_only = [], []
    for _ in range(400):
        passes = ref + rng.normal(0.0, 0.05, (16, 1, 1, 1)) + rng.normal(0.0, 0.1, (16, 30, 40, 1))
        img = passes.mean(axis=0)
        err = float(np.sqrt(np.mean((img - ref) ** 2)))
        pass_means = passes.mean(axis=(1, 2, 3))
        with_passes.append(run.mean_check(img, ref, err, pass_means)["z"])
        pixels_only.append(run.mean_check(img, ref, err)["z"])
    assert abs(np.std(with_passes) - 1.0) < 0.15, np.std(with_passes)
    assert np.std(pixels_only) > 5, np.std(pixels_only)
