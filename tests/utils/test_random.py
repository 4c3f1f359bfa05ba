"""The fast random draws of Gibbs sampling and training, against numpy's own."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy import stats

from sklearn_crbm.utils._random import (
    add_history_noise,
    add_normal_noise,
    standard_normal,
    uniform,
)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("symmetric", [False, True])
def test_uniform_draws_are_uniform_reproducible_and_in_range(dtype, symmetric):
    draws = uniform(np.random.default_rng(0), (400, 250), dtype, symmetric=symmetric)
    low = -1.0 if symmetric else 0.0
    assert draws.dtype == dtype and draws.shape == (400, 250)
    assert draws.min() >= low and draws.max() < 1
    # 10^5 draws: mean and variance of U(low, 1) to within 5 standard errors
    width = 1 - low
    assert abs(draws.mean() - (low + 1) / 2) < 5 * width / np.sqrt(12 * draws.size)
    assert draws.var() == pytest.approx(width**2 / 12, rel=0.02)
    counts, _ = np.histogram(draws, bins=10, range=(low, 1))
    assert counts.min() > 0.95 * draws.size / 10
    again = uniform(np.random.default_rng(0), (400, 250), dtype, symmetric=symmetric)
    assert_array_equal(again, draws)
    out = np.empty((400, 250), dtype)
    result = uniform(
        np.random.default_rng(0), (400, 250), dtype, out, symmetric=symmetric
    )
    assert result is out
    assert_array_equal(out, draws)


def test_float64_uniform_draws_are_the_generators_own():
    expected = np.random.default_rng(4).random((3, 5))
    assert_array_equal(uniform(np.random.default_rng(4), (3, 5), np.float64), expected)


def test_float32_uniform_draws_are_the_bit_generators_mantissas():
    shape = (50, 99)  # an odd number of draws, enough for the bit route
    size = 50 * 99
    raw = np.random.default_rng(4).bit_generator.random_raw((size + 1) // 2)
    expected = (raw.view(np.uint32)[:size] >> 9).astype(np.float64) / 2**23
    draws = uniform(np.random.default_rng(4), shape, np.float32)
    assert_array_equal(draws.ravel(), expected.astype(np.float32))
    small = uniform(np.random.default_rng(4), (3, 5), np.float32)
    assert_array_equal(small, np.random.default_rng(4).random((3, 5), np.float32))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_few_normal_draws_are_the_generators_own(dtype):
    draws = standard_normal(np.random.default_rng(4), (3, 5), dtype)
    expected = np.random.default_rng(4).standard_normal((3, 5), dtype)
    assert draws.dtype == dtype
    assert_array_equal(draws, expected)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_normal_draws_are_box_muller_of_the_uniforms(dtype):
    shape = (400, 251)  # an odd number of draws, enough for the bit route
    size, half = 400 * 251, (400 * 251 + 1) // 2
    u, v = uniform(np.random.default_rng(4), (2, half), np.float32).astype(float)
    radius = np.sqrt(-2 * np.log1p(-u))
    expected = np.concatenate(
        [radius * np.cos(2 * np.pi * v), radius * np.sin(2 * np.pi * v)]
    )
    draws = standard_normal(np.random.default_rng(4), shape, dtype)
    assert draws.dtype == dtype and draws.shape == shape
    assert_allclose(draws.ravel(), expected[:size], rtol=1e-5, atol=1e-5)
    # float64 draws are the float32 ones, converted
    single = standard_normal(np.random.default_rng(4), shape, np.float32)
    assert_array_equal(draws, single.astype(dtype))
    # standard normal: 10^5 draws pass Kolmogorov-Smirnov, pairs uncorrelated
    assert stats.kstest(draws.ravel().astype(float), "norm").pvalue > 1e-3
    assert abs(draws.mean()) < 5 / np.sqrt(size)
    assert draws.var() == pytest.approx(1, abs=5 * np.sqrt(2 / size))
    assert (
        abs(np.corrcoef(draws.ravel()[: half - 1], draws.ravel()[half:-1])[0, 1]) < 0.02
    )
    for out in (np.empty(shape, dtype), np.empty((400, 502), dtype)[:, ::2]):
        assert standard_normal(np.random.default_rng(4), shape, dtype, out) is out
        assert_array_equal(out, draws)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("shape", [(3, 5), (100, 93)])
def test_add_normal_noise_adds_scaled_standard_normals(dtype, shape):
    base = np.linspace(-1, 1, shape[0] * shape[1]).reshape(shape).astype(dtype)
    noisy = base.copy()
    work = np.empty(shape, dtype)
    assert add_normal_noise(np.random.default_rng(2), noisy, 0.3, work) is noisy
    draw_dtype = dtype if shape == (3, 5) else np.float32  # >= 4096: float32
    draws = standard_normal(np.random.default_rng(2), shape, draw_dtype)
    assert noisy.dtype == dtype
    assert_allclose(noisy, base + (0.3 * draws).astype(dtype), rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("n", [4, 100])
def test_history_noise_on_a_fraction_of_the_channels(dtype, n):
    """Each frame's channel is noised at every lag or at none, drawn first."""
    n_features, n_lags, fraction = 31, 3, 0.4
    base = np.linspace(-1, 1, n * n_lags * n_features).reshape(n, -1).astype(dtype)
    noisy = add_history_noise(
        np.random.default_rng(5), base.copy(), 0.3, n_features, fraction
    )
    rng = np.random.default_rng(5)
    noised = uniform(rng, (n, n_features), dtype) < fraction
    added = noisy - base
    expected = add_normal_noise(rng, np.zeros_like(base), 0.3) * np.tile(noised, n_lags)
    assert_allclose(added, expected, rtol=1e-5, atol=1e-6)
    blocks = added.reshape(n, n_lags, n_features) != 0
    assert_array_equal(blocks, np.broadcast_to(noised[:, None], blocks.shape))
    assert_array_equal(
        add_history_noise(np.random.default_rng(5), base.copy(), 0.3, n_features, 1.0),
        add_normal_noise(np.random.default_rng(5), base.copy(), 0.3),
    )


def test_history_noise_fraction_is_the_share_of_noised_channels():
    history = np.zeros((2000, 3 * 10))
    add_history_noise(np.random.default_rng(0), history, 1.0, 10, 0.3)
    share = np.mean(history[:, :10] != 0)
    assert abs(share - 0.3) < 0.01  # 20,000 Bernoulli(0.3): sd 0.0032
