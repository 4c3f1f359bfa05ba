"""The CRBM layer's fast paths compute the same numbers as the plain formulas.

Buffers, in-place activations, the velocity accumulation folded into the CD
statistics and the memory layout of the parameters are optimisations only:
these tests pin them to the straightforward expressions.
"""

import pickle
import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import expit

from sklearn_crbm._engines._gibbs import HiddenSampler, gibbs_frames
from sklearn_crbm.layers._base import logistic
from sklearn_crbm.layers._crbm import CRBMFrames, CRBMLayer
from sklearn_crbm.layers._parameters import MomentumUpdate
from sklearn_crbm.utils._random import uniform


def make_params(dtype=np.float64, order=2, hidden_order=2, seed=0, scale=0.5):
    rng = np.random.default_rng(seed)
    params = CRBMLayer(5, 7, order, hidden_order, "gaussian", dtype).initialize(rng)
    params.flat[...] = scale * rng.standard_normal(params.flat.shape)
    params.dynamic *= params.dynamic_mask()
    return params


def batch(params, n=30, seed=1):
    rng = np.random.default_rng(seed)
    dtype = params.dtype
    visible = rng.standard_normal((n, params.n_features)).astype(dtype)
    history = rng.standard_normal((n, params.n_lags * params.n_features)).astype(dtype)
    return visible, history


def frames_of(params, hidden_bias, visible_bias=None):
    """The frame RBMs of ``params`` with the given dynamic biases."""
    if visible_bias is None:
        visible_bias = np.zeros((len(hidden_bias), params.n_features), params.dtype)
    return CRBMFrames(
        visible_bias, hidden_bias, None, params.visible_units, params.weights
    )


def cd(params, visible, history, cd_steps, rng, *, out=None, scale=1.0, workspace=None):
    """The layer's CD statistics, in new buffers unless given."""
    out = params.zeros_like() if out is None else out
    workspace = params.new_workspace(len(visible)) if workspace is None else workspace
    return params.cd_statistics(
        visible, history, None, cd_steps, rng, out=out, scale=scale, workspace=workspace
    )


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
    _, hidden_bias = params.dynamic_biases(history)
    shape = hidden_bias.shape
    out, work = np.empty(shape, dtype), np.empty(shape, dtype)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        sampler = HiddenSampler(frames_of(params, hidden_bias))
        states = sampler(visible, np.random.default_rng(3), out, work)
    assert states is out and states.dtype == dtype
    test_dtype = np.float32 if symmetric else np.float64
    draws = uniform(np.random.default_rng(3), shape, test_dtype, symmetric=symmetric)
    u = (draws.astype(float) + 1) / 2 if symmetric else draws
    p = frames_of(make_params(), hidden_bias.astype(float)).hidden_probabilities(
        visible.astype(float)
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
        states = HiddenSampler(frames_of(params, hidden_bias))(
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
    _, hidden_bias = params.dynamic_biases(history)
    shape = hidden_bias.shape
    out, work, noise = (np.empty(shape, dtype) for _ in range(3))
    noisy = HiddenSampler(frames_of(params, hidden_bias))(
        visible, np.random.default_rng(6), out, work, hidden_noise=1.5, noise=noise
    ).copy()
    rng = np.random.default_rng(6)
    shifted = hidden_bias + 1.5 * rng.standard_normal(shape, dtype=dtype)
    expected = HiddenSampler(frames_of(params, shifted))(visible, rng, out, work)
    assert (noisy != expected).mean() < 1e-3


@pytest.mark.parametrize("cd_steps", [1, 3])
@pytest.mark.parametrize("orders", [(2, 2), (1, 3), (3, 0), (0, 0)])
def test_cd_statistics_scale_into_reused_buffers(cd_steps, orders):
    params = make_params(order=orders[0], hidden_order=orders[1])
    visible, history = batch(params)
    plain, error = cd(params, visible, history, cd_steps, np.random.default_rng(0))
    out = params.zeros_like()
    out.flat[...] = np.nan
    workspace = params.new_workspace(50)  # larger than the batch: reused slices
    result, error2 = cd(
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
    params = make_params().copy("F")
    loaded = pickle.loads(pickle.dumps(params))
    assert_array_equal(loaded.flat, params.flat)
    assert loaded.layout == "F"
    loaded.flat[0] += 1  # the views follow the loaded buffer
    assert loaded.weights.flags.f_contiguous
    assert np.shares_memory(loaded.weights, loaded.flat)


def test_cd_statistics_do_not_depend_on_memory_layout():
    params = make_params()
    visible, history = batch(params)
    c_order, _ = cd(params, visible, history, 1, np.random.default_rng(0))
    f_order, _ = cd(params.copy("F"), visible, history, 1, np.random.default_rng(0))
    for name in ("weights", "hidden_bias", "visible_bias", "dynamic"):
        assert_allclose(
            getattr(c_order, name), getattr(f_order, name), rtol=1e-12, atol=1e-14
        )


def test_gibbs_frames_keep_observed_values_and_draw_as_before():
    params = make_params()
    visible, history = batch(params, n=8)
    visible_bias, hidden_bias = params.dynamic_biases(history)
    rbms = frames_of(params, hidden_bias, visible_bias)
    mask = np.zeros(visible.shape, dtype=bool)
    mask[:, :2] = True
    frames = gibbs_frames(
        rbms,
        visible,
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
        hidden = rng.random(hidden_bias.shape) < frames_of(
            params, bias
        ).hidden_probabilities(current)
        current = hidden @ params.weights + visible_bias
        current[mask] = visible[mask]
    current = rbms.hidden_probabilities(current) @ params.weights
    current += visible_bias
    current[mask] = visible[mask]
    assert_allclose(frames, current, rtol=1e-12, atol=1e-12)


def test_gibbs_frames_end_with_n_mean_field_steps():
    params = make_params()
    visible, history = batch(params, n=8)
    visible_bias, hidden_bias = params.dynamic_biases(history)
    rbms = frames_of(params, hidden_bias, visible_bias)
    frames = gibbs_frames(rbms, visible, 5, np.random.default_rng(0), n_mean_field=4)

    # the same chain written plainly: sampled hidden states, then mean field
    rng = np.random.default_rng(0)
    current = visible.copy()
    for _ in range(5):
        hidden = rng.random(hidden_bias.shape) < rbms.hidden_probabilities(current)
        current = hidden @ params.weights + visible_bias
    for _ in range(4):
        current = rbms.hidden_probabilities(current) @ params.weights + visible_bias
    assert_allclose(frames, current, rtol=1e-12, atol=1e-12)
