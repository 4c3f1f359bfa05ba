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
    cd_gradients,
    dynamic_biases,
    gibbs_frames,
    hidden_probabilities,
    logistic,
    sample_hidden_states,
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


def test_sample_hidden_states_is_uniform_below_probability():
    params = make_params()
    visible, history = batch(params, n=2000)
    _, hidden_bias = dynamic_biases(params, history)
    states = sample_hidden_states(
        params, visible, hidden_bias, np.random.default_rng(3)
    )
    uniform = np.random.default_rng(3).random(states.shape)
    expected = uniform < hidden_probabilities(params, visible, hidden_bias)
    assert_array_equal(states, expected.astype(float))
    negated = sample_hidden_states(
        params, visible, -hidden_bias, np.random.default_rng(3), negated=True
    )
    assert_array_equal(negated, states)


@pytest.mark.parametrize("cd_steps", [1, 3])
@pytest.mark.parametrize("orders", [(2, 2), (1, 3), (3, 0), (0, 0)])
def test_cd_gradients_accumulate_like_a_momentum_update(cd_steps, orders):
    params = make_params(order=orders[0], hidden_order=orders[1])
    visible, history = batch(params)
    plain, error = cd_gradients(
        params, visible, history, cd_steps, np.random.default_rng(0)
    )
    rng = np.random.default_rng(5)
    velocities = [rng.standard_normal(a.shape) for a in params.arrays()]
    velocities[3] *= params.dynamic_mask()
    before = [v.copy() for v in velocities]
    workspace = CDWorkspace(params, 50)  # larger than the batch: reused slices
    out, error2 = cd_gradients(
        params,
        visible,
        history,
        cd_steps,
        np.random.default_rng(0),
        out=velocities,
        scale=0.01,
        momentum=0.9,
        workspace=workspace,
    )
    assert error2 == pytest.approx(error, rel=1e-12)
    for result, velocity, old, gradient in zip(
        out, velocities, before, plain, strict=True
    ):
        assert result is velocity
        assert_allclose(velocity, 0.9 * old + 0.01 * gradient, rtol=1e-10, atol=1e-14)


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
