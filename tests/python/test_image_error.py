"""The study's error metrics on synthetic images whose noise and bias are known."""
import math

import numpy as np

from eyerender.image_error import error_noise_bias, rel_rmse, relative_errors


def _renders(bias, noise, shape=(128, 128, 3), seed=3):
    """A reference in [0.5, 1.5] and two renders of it with relative `bias` and relative Gaussian `noise`."""
    rng = np.random.default_rng(seed)
    ref = rng.uniform(0.5, 1.5, shape)
    a = ref * (1 + bias + noise * rng.standard_normal(shape))
    b = ref * (1 + bias + noise * rng.standard_normal(shape))
    return a, b, ref


def test_known_noise_and_bias_are_recovered_within_three_percent():
    a, b, ref = _renders(bias=0.05, noise=0.1)
    rmse, noise, bias = error_noise_bias(a, b, ref)
    # eps = 0.01 mean^2 shrinks the errors of pixels near the mean by ~0.5 %: well inside the tolerance.
    assert abs(noise - 0.1) < 0.003, noise
    assert abs(bias - 0.05) < 0.0015, bias
    assert abs(rmse - math.hypot(0.1, 0.05)) < 0.004, rmse
    assert math.isclose(rmse**2, noise**2 + bias**2, rel_tol=1e-12), (rmse, noise, bias)


def test_unbiased_renders_have_a_bias_near_zero_and_all_their_error_is_noise():
    a, b, ref = _renders(bias=0.0, noise=0.2)
    rmse, noise, bias = error_noise_bias(a, b, ref)
    # mean(e_a e_b) of independent noise has a standard deviation noise^2 / sqrt(n): bias reads ~noise / n^(1/4).
    assert bias < 2 * noise / a.size**0.25, (bias, noise)
    assert abs(rmse - noise) < 0.005, (rmse, noise)


def test_a_black_reference_region_with_a_small_error_gives_a_small_error_not_a_division_by_zero():
    ref = np.ones((64, 64, 3))
    ref[:, 32:] = 0.0  # a black background
    img = ref.copy()
    img[:, 32:] = 1e-3  # a thousandth of the lit pixels, where the reference is exactly 0
    e = relative_errors(img, ref)
    assert np.isfinite(e).all()
    # eps = 0.01 * 0.5^2: the black pixels' error is 1e-3 / 0.05 = 0.02, the lit pixels' is 0.
    assert abs(rel_rmse(img, ref) - 0.02 / math.sqrt(2)) < 1e-9, rel_rmse(img, ref)


def test_one_reference_firefly_the_render_misses_costs_at_most_one_pixel_of_relative_error():
    a, b, ref = _renders(bias=0.0, noise=0.05, shape=(64, 64, 3))
    ref[10, 20] = 1e4  # a corneal highlight one sample in many hits, present only in the reference
    rmse, _, bias = error_noise_bias(a, b, ref)
    n = ref.size
    # Its relative error is ~ -1 in each of 3 channels: at most 3 / n more MSE.
    assert rmse < math.sqrt(0.05**2 + 3.0 / n) + 0.003, rmse
    assert bias < 0.04, bias


def test_the_errors_do_not_depend_on_the_images_unit():
    a, b, ref = _renders(bias=0.02, noise=0.1, shape=(32, 32, 3))
    ref[:8] = 0.0
    got = error_noise_bias(a, b, ref)
    scaled = error_noise_bias(a * 1000, b * 1000, ref * 1000)
    assert np.allclose(got, scaled, rtol=1e-12), (got, scaled)


def test_the_mask_selects_the_pixels_and_an_empty_mask_or_black_reference_gives_nan():
    a, b, ref = _renders(bias=0.0, noise=0.1, shape=(32, 32, 3))
    mask = np.zeros((32, 32), bool)
    mask[:16] = True
    a[16:] = 1e6  # outside the mask: must not count
    assert rel_rmse(a, ref, mask) < 0.12, rel_rmse(a, ref, mask)
    assert all(math.isnan(x) for x in error_noise_bias(a, b, ref, np.zeros((32, 32), bool)))
    assert math.isnan(rel_rmse(a, np.zeros_like(ref)))
