"""The fast paths of ``_crbm_math`` compute the same numbers as the plain formulas.

Buffers, in-place activations, the velocity accumulation folded into
``cd_gradients`` and the memory layout of the parameters are optimisations
only: these tests pin them to the straightforward expressions.
"""

import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import expit

from sklearn_crbm._crbm_math import (
    CDWorkspace,
    CRBMParameters,
    HiddenSampler,
    MomentumUpdate,
    cd_gradients,
    dynamic_biases,
    gibbs_frames,
    hidden_probabilities,
    logistic,
    uniform,
)


def make_params(dtype=np.float64, order=2, hidden_order=2, seed=0, scale=0.5):
    rng = np.random.default_rng(seed)
    params = CRBMParameters.initialize(
        5, 7, order, hidden_order, "gaussian", dtype, rng
    )
    for array in params.arrays():
        array[...] = scale * rng.standard_normal(array.shape)
    params.dynamic *= params.dynamic_mask()
    return params


def batch(params, n=30, seed=1):
    rng = np.random.default_rng(seed)
    dtype = params.dtype
    visible = rng.standard_normal((n, params.n_features)).astype(dtype)
    history = rng.standard_normal((n, params.n_lags * params.n_features)).astype(dtype)
    return visible, history


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_logistic_is_expit_without_warnings(dtype):
    x = np.concatenate([np.linspace(-50, 50, 1001), [-1e4, -800, 0, 800, 1e4]])
    x = x.astype(dtype)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = logistic(x)
    assert result.dtype == dtype
    assert_allclose(result, expit(x), rtol=4 * np.finfo(dtype).eps, atol=0)
    out = x.copy()
    assert logistic(out, out=out) is out
    assert_array_equal(out, result)


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
def test_hidden_sampler_is_uniform_below_probability(dtype):
    params = make_params(dtype)
    visible, history = batch(params, n=2000)
    _, hidden_bias = dynamic_biases(params, history)
    shape = hidden_bias.shape
    out, work = np.empty(shape, dtype), np.empty(shape, dtype)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        sampler = HiddenSampler(params, hidden_bias)
        states = sampler(visible, np.random.default_rng(3), out, work)
    assert states.dtype == dtype
    # float32 compares 2u - 1 < tanh(a / 2), float64 u (1 + exp(-a)) < 1
    symmetric = dtype == np.float32
    draws = uniform(np.random.default_rng(3), states.shape, dtype, symmetric=symmetric)
    u = (draws.astype(float) + 1) / 2 if symmetric else draws
    p = hidden_probabilities(
        make_params(), visible.astype(float), hidden_bias.astype(float)
    )
    expected = u < p
    # the forms agree with u < p except within rounding of the boundary
    differ = states != expected
    assert np.all(np.abs(u - p)[differ] < 10 * np.finfo(dtype).eps)
    assert differ.mean() < 1e-3
    assert set(np.unique(states)) <= {0.0, 1.0}


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_hidden_noise_is_added_to_the_hidden_biases(dtype):
    params = make_params(dtype)
    visible, history = batch(params, n=500)
    _, hidden_bias = dynamic_biases(params, history)
    shape = hidden_bias.shape
    out, work, noise = (np.empty(shape, dtype) for _ in range(3))
    noisy = HiddenSampler(params, hidden_bias)(
        visible, np.random.default_rng(6), out, work, hidden_noise=1.5, noise=noise
    ).copy()
    rng = np.random.default_rng(6)
    shifted = hidden_bias + 1.5 * rng.standard_normal(shape, dtype=dtype)
    expected = HiddenSampler(params, shifted)(visible, rng, out, work)
    assert (noisy != expected).mean() < 1e-3


@pytest.mark.parametrize("cd_steps", [1, 3])
@pytest.mark.parametrize("orders", [(2, 2), (1, 3), (3, 0), (0, 0)])
def test_cd_gradients_scale_into_reused_buffers(cd_steps, orders):
    params = make_params(order=orders[0], hidden_order=orders[1])
    visible, history = batch(params)
    plain, error = cd_gradients(
        params, visible, history, cd_steps, np.random.default_rng(0)
    )
    out = [np.full_like(a, np.nan) for a in params.arrays()]
    workspace = CDWorkspace(params, 50)  # larger than the batch: reused slices
    result, error2 = cd_gradients(
        params,
        visible,
        history,
        cd_steps,
        np.random.default_rng(0),
        out=out,
        scale=0.01,
        workspace=workspace,
    )
    assert error2 == pytest.approx(error, rel=1e-12)
    for got, array, gradient in zip(result, out, plain, strict=True):
        assert got is array
        assert_allclose(array, 0.01 * gradient, rtol=1e-10, atol=1e-14)
    assert_array_equal(plain[3] * (1 - params.dynamic_mask()), 0)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("orders", [(2, 2), (1, 3), (0, 0)])
def test_momentum_update_is_the_original_update_rule(dtype, orders):
    params = make_params(dtype, order=orders[0], hidden_order=orders[1])
    rng = np.random.default_rng(5)
    velocities = [rng.standard_normal(a.shape).astype(dtype) for a in params.arrays()]
    velocities[3] *= params.dynamic_mask()
    before = [a.copy() for a in params.arrays()]
    old_velocities = [v.copy() for v in velocities]
    update = MomentumUpdate(params, velocities)
    # params now view one buffer, in Fortran order, with the same values
    for array, value in zip(params.arrays(), before, strict=True):
        assert array.size == 0 or np.shares_memory(array, update.parameters)
        assert_array_equal(array, value)
    assert params.weights.flags.f_contiguous and params.dynamic.flags.f_contiguous
    statistics = [rng.standard_normal(a.shape).astype(dtype) for a in before]
    statistics[3] *= params.dynamic_mask()
    for buffer, statistic in zip(update.statistics, statistics, strict=True):
        buffer[...] = statistic
    update.apply(0.9, 0.1, 0.02)
    decays = (0.02, 0.0, 0.0, 0.02)  # W and the directed weights only
    tol = dict(rtol=1e-5, atol=1e-6) if dtype == np.float32 else dict(rtol=1e-12)
    for k, (param, velocity) in enumerate(
        zip(params.arrays(), update.velocities, strict=True)
    ):
        expected = 0.9 * old_velocities[k] + statistics[k] - 0.1 * decays[k] * before[k]
        assert_allclose(velocity, expected, **tol)
        assert_allclose(param, before[k] + expected, **tol)
    assert_array_equal(params.dynamic * (1 - params.dynamic_mask()), 0)


def test_cd_gradients_do_not_depend_on_memory_layout():
    params = make_params()
    visible, history = batch(params)
    c_order, _ = cd_gradients(params, visible, history, 1, np.random.default_rng(0))
    params.weights = np.asfortranarray(params.weights)
    params.dynamic = np.asfortranarray(params.dynamic)
    f_order, _ = cd_gradients(params, visible, history, 1, np.random.default_rng(0))
    for a, b in zip(c_order, f_order, strict=True):
        assert_allclose(a, b, rtol=1e-12, atol=1e-14)


def test_gibbs_frames_keep_observed_values_and_draw_as_before():
    params = make_params()
    visible, history = batch(params, n=8)
    visible_bias, hidden_bias = dynamic_biases(params, history)
    mask = np.zeros(visible.shape, dtype=bool)
    mask[:, :2] = True
    frames = gibbs_frames(
        params,
        visible,
        visible_bias,
        hidden_bias,
        5,
        np.random.default_rng(0),
        hidden_noise=0.5,
        observed_mask=mask,
    )
    assert_array_equal(frames[mask], visible[mask])

    # the same chain written plainly: noise draws, then uniforms, each step
    rng = np.random.default_rng(0)
    current = visible.copy()
    for _ in range(5):
        bias = hidden_bias + 0.5 * rng.standard_normal(hidden_bias.shape)
        hidden = rng.random(hidden_bias.shape) < hidden_probabilities(
            params, current, bias
        )
        current = hidden @ params.weights + visible_bias
        current[mask] = visible[mask]
    current = hidden_probabilities(params, current, hidden_bias) @ params.weights
    current += visible_bias
    current[mask] = visible[mask]
    assert_allclose(frames, current, rtol=1e-12, atol=1e-12)
