"""The fast paths of ``_crbm_math`` compute the same numbers as the plain formulas.

Buffers, in-place activations, the velocity accumulation folded into
``cd_gradients`` and the memory layout of the parameters are optimisations
only: these tests pin them to the straightforward expressions.
"""

import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy import stats
from scipy.special import expit

from sklearn_crbm._crbm_math import (
    CDWorkspace,
    CRBMParameters,
    HiddenSampler,
    MomentumUpdate,
    add_history_noise,
    add_normal_noise,
    cd_gradients,
    dynamic_biases,
    gibbs_frames,
    hidden_probabilities,
    logistic,
    standard_normal,
    uniform,
)


def make_params(dtype=np.float64, order=2, hidden_order=2, seed=0, scale=0.5):
    rng = np.random.default_rng(seed)
    params = CRBMParameters.initialize(
        5, 7, order, hidden_order, "gaussian", dtype, rng
    )
    params.flat[...] = scale * rng.standard_normal(params.flat.shape)
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


@pytest.mark.parametrize(
    "dtype, n, symmetric",
    [
        (np.float32, 2000, True),  # 2u - 1 < tanh(a / 2), 23-bit uniforms
        (np.float32, 10, True),  # numpy's float32 uniforms
        (np.float64, 2000, True),  # >= 4096 draws: the float32 test
        (np.float64, 10, False),  # u (1 + exp(-a)) < 1, numpy's float64 uniforms
    ],
)
def test_hidden_sampler_is_uniform_below_probability(dtype, n, symmetric):
    params = make_params(dtype)
    visible, history = batch(params, n=n)
    _, hidden_bias = dynamic_biases(params, history)
    shape = hidden_bias.shape
    out, work = np.empty(shape, dtype), np.empty(shape, dtype)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        sampler = HiddenSampler(params, hidden_bias)
        states = sampler(visible, np.random.default_rng(3), out, work)
    assert states is out and states.dtype == dtype
    test_dtype = np.float32 if symmetric else np.float64
    draws = uniform(np.random.default_rng(3), shape, test_dtype, symmetric=symmetric)
    u = (draws.astype(float) + 1) / 2 if symmetric else draws
    p = hidden_probabilities(
        make_params(), visible.astype(float), hidden_bias.astype(float)
    )
    expected = u < p
    # the forms agree with u < p except within rounding of the boundary
    differ = states != expected
    assert np.all(np.abs(u - p)[differ] < 10 * np.finfo(test_dtype).eps)
    assert differ.mean() < 1e-3
    assert set(np.unique(states)) <= {0.0, 1.0}


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_hidden_states_have_their_probabilities_as_frequencies(dtype):
    # one activation per column, 2000 draws of each: Bernoulli frequencies
    params = make_params(dtype)
    params.weights[...] = 0
    levels = np.array([-6.0, -2.0, -0.5, 0.0, 0.3, 1.0, 4.0])
    hidden_bias = np.tile(levels, (2000, 1)).astype(dtype)
    visible = np.zeros((2000, params.n_features), dtype)
    out, work = np.empty_like(hidden_bias), np.empty_like(hidden_bias)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        states = HiddenSampler(params, hidden_bias)(
            visible, np.random.default_rng(8), out, work
        )
    p = expit(levels)
    frequency = states.mean(axis=0)
    assert np.all(np.abs(frequency - p) < 5 * np.sqrt(p * (1 - p) / 2000) + 1e-3)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("n", [500, 700])  # 3500 and 4900 states: both float64 tests
def test_hidden_noise_is_added_to_the_hidden_biases(dtype, n):
    params = make_params(dtype)
    visible, history = batch(params, n=n)
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
    out = params.zeros_like()
    out.flat[...] = np.nan
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
    assert result is out
    assert_allclose(out.flat, 0.01 * plain.flat, rtol=1e-10, atol=1e-14)
    assert_array_equal(plain.dynamic * (1 - params.dynamic_mask()), 0)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("orders", [(2, 2), (1, 3), (0, 0)])
def test_momentum_update_is_the_original_update_rule(dtype, orders):
    params = make_params(dtype, order=orders[0], hidden_order=orders[1]).copy("F")
    assert params.weights.flags.f_contiguous and params.dynamic.flags.f_contiguous
    rng = np.random.default_rng(5)
    velocity = params.zeros_like()
    velocity.flat[...] = rng.standard_normal(velocity.flat.shape)
    velocity.dynamic *= params.dynamic_mask()
    before, old_velocity = params.copy(), velocity.copy()
    update = MomentumUpdate(params, velocity)
    statistics = update.statistics
    statistics.flat[...] = rng.standard_normal(statistics.flat.shape)
    statistics.dynamic *= params.dynamic_mask()
    expected_statistics = statistics.copy()
    update.apply(0.9, 0.1, 0.02)
    decays = {"weights": 0.02, "dynamic": 0.02}  # W and the directed weights only
    tol = dict(rtol=1e-5, atol=1e-6) if dtype == np.float32 else dict(rtol=1e-12)
    for name in ("weights", "hidden_bias", "visible_bias", "dynamic"):
        expected = (
            0.9 * getattr(old_velocity, name)
            + getattr(expected_statistics, name)
            - 0.1 * decays.get(name, 0.0) * getattr(before, name)
        )
        assert_allclose(getattr(update.velocity, name), expected, **tol)
        assert_allclose(getattr(params, name), getattr(before, name) + expected, **tol)
    assert_array_equal(params.dynamic * (1 - params.dynamic_mask()), 0)


def test_parameters_are_views_of_one_buffer_in_either_layout():
    params = make_params(order=3, hidden_order=1)
    for layout in ("C", "F"):
        copy = params.copy(layout)
        views = [
            copy.weights,
            copy.hidden_bias,
            copy.visible_bias,
            copy.dynamic,
            copy.autoregressive,
            copy.past_to_hidden,
        ]
        for view in views:
            assert np.shares_memory(view, copy.flat)
        assert copy.weights.flags[f"{layout}_CONTIGUOUS"]
        assert_array_equal(copy.weights, params.weights)
        assert_array_equal(copy.dynamic, params.dynamic)
        # the lag blocks of the public layout, read from the packed matrix
        n = params.n_features
        for q in range(3):
            assert_array_equal(
                copy.autoregressive[q], params.dynamic[:n, q * n : (q + 1) * n]
            )
        assert_array_equal(copy.past_to_hidden[0], params.dynamic[n:, :n])
    # weight decay covers exactly the directed and symmetric weights
    decayed = np.zeros(params.flat.shape, bool)
    decayed[params.decayed] = True
    for name, expected in [
        ("weights", True),
        ("dynamic", True),
        ("hidden_bias", False),
    ]:
        view = params.views(decayed)[name]
        assert view.all() == expected and view.any() == expected


def test_parameters_pickle_as_one_buffer():
    import pickle

    params = make_params().copy("F")
    loaded = pickle.loads(pickle.dumps(params))
    assert_array_equal(loaded.flat, params.flat)
    assert loaded.layout == "F"
    loaded.flat[0] += 1  # the views follow the loaded buffer
    assert loaded.weights.flags.f_contiguous
    assert np.shares_memory(loaded.weights, loaded.flat)


def test_cd_gradients_do_not_depend_on_memory_layout():
    params = make_params()
    visible, history = batch(params)
    c_order, _ = cd_gradients(params, visible, history, 1, np.random.default_rng(0))
    f_order, _ = cd_gradients(
        params.copy("F"), visible, history, 1, np.random.default_rng(0)
    )
    for name in ("weights", "hidden_bias", "visible_bias", "dynamic"):
        assert_allclose(
            getattr(c_order, name), getattr(f_order, name), rtol=1e-12, atol=1e-14
        )


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
