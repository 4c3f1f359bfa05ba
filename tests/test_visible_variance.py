"""Learned visible variances: the math pinned exactly on tiny models.

Energy (Hinton's practical guide form), for a frame given its history:

    E(v, h) = sum_i (v_i - c_i)^2 / (2 s_i^2) - b . h - (v / s) . (W.T h)

with ``c``, ``b`` the dynamic biases.  Every quantity below is computed by
enumerating the hidden configurations of a model with 3 hidden units and
compared with what the package computes.
"""

import itertools
import pickle

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import expit, logsumexp

from sklearn_crbm import ConditionalRBM
from sklearn_crbm._engines._gibbs import HiddenSampler
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.layers._crbm import CRBMFrames, CRBMLayer

N_FEATURES, N_COMPONENTS, ORDER = 2, 3, 1
HIDDEN = np.array(list(itertools.product([0, 1], repeat=N_COMPONENTS)), dtype=float)


def tiny_params(seed=0, zero_weights=False):
    rng = np.random.default_rng(seed)
    params = CRBMLayer(
        N_FEATURES,
        N_COMPONENTS,
        ORDER,
        ORDER,
        "gaussian",
        np.float64,
        learned_variance=True,
    )
    params.weights[...] = 0 if zero_weights else rng.normal(size=params.weights.shape)
    params.hidden_bias[...] = rng.normal(size=N_COMPONENTS)
    params.visible_bias[...] = rng.normal(size=N_FEATURES)
    params.dynamic[...] = 0.5 * rng.normal(size=params.dynamic.shape)
    params.log_visible_variance[...] = rng.uniform(-2.0, 0.5, size=N_FEATURES)
    return params


def energy(v, h, c, b, params):
    """E(v, h) written out, for one frame and one hidden configuration."""
    s = np.sqrt(params.visible_variance)
    return np.sum((v - c) ** 2 / (2 * s**2)) - b @ h - (v / s) @ (params.weights.T @ h)


def frame(params, seed=1):
    rng = np.random.default_rng(seed)
    history = rng.normal(size=(1, ORDER * N_FEATURES))
    c, b = params.dynamic_biases(history)
    return rng.normal(size=N_FEATURES), c[0], b[0]


def frame_rbms(params, visible_bias, hidden_bias):
    """The RBMs of frames with the dynamic biases given (one row each)."""
    return CRBMFrames(
        visible_bias,
        hidden_bias,
        params.visible_std,
        params.visible_units,
        params.weights,
    )


def cd_statistics(params, visible, history, cd_steps, rng, *, scale=1.0):
    """The layer's CD statistics of one minibatch, in new buffers."""
    return params.cd_statistics(
        visible,
        history,
        None,
        cd_steps,
        rng,
        out=params.zeros_like(),
        scale=scale,
        workspace=params.new_workspace(len(visible)),
    )


def test_visible_variance_is_a_view_of_the_log_variance():
    params = tiny_params()
    assert_allclose(params.visible_variance, np.exp(params.log_visible_variance))
    assert_allclose(params.visible_std, np.exp(params.log_visible_variance / 2))
    params.visible_variance = np.array([0.25, 4.0])
    assert_allclose(params.log_visible_variance, np.log([0.25, 4.0]))
    unit = CRBMLayer(2, 3, 1, 1, "gaussian", np.float64)
    assert unit.visible_std is None
    assert_array_equal(unit.visible_variance, np.ones(2))


def test_hidden_conditional_by_enumeration():
    params = tiny_params()
    v, c, b = frame(params)
    log_joint = np.array([-energy(v, h, c, b, params) for h in HIDDEN])
    posterior = np.exp(log_joint - logsumexp(log_joint))
    expected = posterior @ HIDDEN  # p(h_j = 1 | v)
    got = frame_rbms(params, c[None], b[None]).hidden_probabilities(v[None])[0]
    assert_allclose(got, expected, rtol=1e-12)
    s = np.sqrt(params.visible_variance)
    assert_allclose(got, expit(b + params.weights @ (v / s)), rtol=1e-12)


def test_visible_conditional_is_the_gaussian_of_the_energy():
    params = tiny_params()
    _, c, b = frame(params)
    rng = np.random.default_rng(2)
    variance = params.visible_variance
    for h in HIDDEN:
        mean = frame_rbms(params, c[None], b[None]).visible_mean(h[None])[0]
        assert_allclose(
            mean, c + np.sqrt(variance) * (params.weights.T @ h), rtol=1e-12
        )
        # E(v, h) - E(mean, h) is the Gaussian's quadratic form: the
        # conditional is N(mean, diag(variance)), whatever v
        for v in rng.normal(size=(4, N_FEATURES)):
            difference = energy(v, h, c, b, params) - energy(mean, h, c, b, params)
            assert difference == pytest.approx(
                np.sum((v - mean) ** 2 / (2 * variance)), rel=1e-10
            )


def test_samplers_follow_the_conditionals():
    params = tiny_params()
    v, c, b = frame(params)
    # hidden states: u < p(h = 1 | v), with the sampler's own uniform draws
    # (numpy's float64 uniforms: fewer than _MIN_BIT_DRAWS at once)
    n = 1000
    visible = np.repeat(v[None], n, axis=0)
    means = np.repeat(c[None], n, axis=0)
    rbms = frame_rbms(params, means, np.repeat(b[None], n, axis=0))
    states = np.empty((n, N_COMPONENTS))
    HiddenSampler(rbms)(
        visible, np.random.default_rng(3), states, np.empty_like(states)
    )
    uniforms = np.random.default_rng(3).random((n, N_COMPONENTS))
    probabilities = rbms.hidden_probabilities(visible)
    assert_array_equal(states, uniforms < probabilities)
    # visible draws: mean + s * standard normal
    draws = rbms.sample_visibles(means, np.random.default_rng(4))
    noise = np.random.default_rng(4).standard_normal((n, N_FEATURES))
    assert_allclose(draws, means + np.sqrt(params.visible_variance) * noise)


def free_energy(params, visible, visible_bias, hidden_bias):
    """F(v | history) as the package computes it for its likelihood."""
    return -frame_rbms(params, visible_bias, hidden_bias).negative_free_energy(visible)


def test_free_energy_by_enumeration():
    params = tiny_params()
    for seed in range(3):
        v, c, b = frame(params, seed)
        expected = -logsumexp([-energy(v, h, c, b, params) for h in HIDDEN])
        got = free_energy(params, v[None], c[None], b[None])[0]
        assert got == pytest.approx(expected, rel=1e-12)


def log_partition(params, c, b):
    """log Z = log sum_h int exp(-E(v, h)) dv, the visibles integrated exactly."""
    s = np.sqrt(params.visible_variance)
    u = HIDDEN @ params.weights  # W.T h for every configuration
    terms = HIDDEN @ b + u @ (c / s) + 0.5 * np.sum(u**2, axis=1)
    return logsumexp(terms) + np.sum(np.log(np.sqrt(2 * np.pi) * s))


def test_exact_log_likelihood_integrates_to_one():
    params = tiny_params()
    _, c, b = frame(params)
    s = np.sqrt(params.visible_variance)
    # exp(-F(v) - log Z) on a grid wide enough for every mixture component
    centre = c + s * (HIDDEN @ params.weights).mean(axis=0)
    width = 8 * s + np.abs(s * (HIDDEN @ params.weights)).max(axis=0)
    axes = [np.linspace(m - w, m + w, 801) for m, w in zip(centre, width, strict=True)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    n = len(grid)
    log_density = -free_energy(
        params, grid, np.repeat(c[None], n, axis=0), np.repeat(b[None], n, axis=0)
    ) - log_partition(params, c, b)
    cell = np.prod([a[1] - a[0] for a in axes])
    assert np.exp(log_density).sum() * cell == pytest.approx(1.0, abs=1e-6)


def test_exact_log_likelihood_of_a_fitted_model_by_enumeration():
    """log p(v | history) of frames of a fitted model, enumerated by hand."""
    X, ids = make_oscillations(n_sequences=3, n_frames=30, n_features=2, random_state=0)
    model = ConditionalRBM(
        N_COMPONENTS,
        order=ORDER,
        visible_variance="learned",
        n_iter=30,
        cd_steps=2,
        learning_rate=0.01,
        random_state=0,
    ).fit(X, sequence_ids=ids)
    assert not np.allclose(model.visible_variance_, 1.0)
    params = model._layer
    history = X[:-1]
    c, b = params.dynamic_biases(history)
    negative_free = -free_energy(params, X[1:], c, b)
    # score_samples: log p(x_t | past), frame 0 edge padded (one sequence here)
    scores = model.score_samples(X[ids == 0])
    for t in range(0, len(history), 7):
        expected = logsumexp(
            [-energy(X[t + 1], h, c[t], b[t], params) for h in HIDDEN]
        ) - log_partition(params, c[t], b[t])
        got = negative_free[t] - log_partition(params, c[t], b[t])
        assert got == pytest.approx(expected, rel=1e-10)
        if ids[t + 1] == 0 and ids[t] == 0:
            assert scores[t + 1] == pytest.approx(expected, rel=1e-9)


def test_without_hidden_units_the_variance_statistic_is_the_exact_gradient():
    """W = 0: p(v) = N(c, s^2), and the statistic of z = log s^2 is d log p / dz."""
    params = tiny_params(zero_weights=True)
    rng = np.random.default_rng(5)
    visible = rng.normal(size=(7, N_FEATURES))
    history = rng.normal(size=(7, ORDER * N_FEATURES))
    gradients, _ = cd_statistics(params, visible, history, 1, rng)
    c, _ = params.dynamic_biases(history)
    variance = params.visible_variance
    exact = ((visible - c) ** 2 / (2 * variance) - 0.5).sum(axis=0)
    assert_allclose(gradients.log_visible_variance, exact, rtol=1e-12)


@pytest.mark.parametrize("cd_steps", [1, 2])
def test_one_update_against_the_equations(cd_steps):
    params = tiny_params()
    rng = np.random.default_rng(6)
    n = 5
    visible = rng.normal(size=(n, N_FEATURES))
    history = rng.normal(size=(n, ORDER * N_FEATURES))
    scale = 0.1
    gradients, squared_error = cd_statistics(
        params, visible.copy(), history, cd_steps, np.random.default_rng(7), scale=scale
    )

    # written out: the sampler draws one uniform per hidden unit and step
    draws = np.random.default_rng(7)
    W, s = params.weights, np.sqrt(params.visible_variance)
    c = params.visible_bias + history @ params.dynamic[:N_FEATURES].T
    b = params.hidden_bias + history @ params.dynamic[N_FEATURES:].T
    h0 = (draws.random((n, N_COMPONENTS)) < expit(b + (visible / s) @ W.T)) * 1.0
    v1 = c + s * (h0 @ W)
    reconstruction, hidden = v1, h0
    for _ in range(cd_steps - 1):
        p = expit(b + (reconstruction / s) @ W.T)
        hidden = (draws.random((n, N_COMPONENTS)) < p) * 1.0
        reconstruction = c + s * (hidden @ W)
    p_last = expit(b + (reconstruction / s) @ W.T)
    residual = visible - reconstruction
    expected = {
        "weights": h0.T @ (visible / s) - p_last.T @ (reconstruction / s),
        "hidden_bias": (h0 - p_last).sum(axis=0),
        "visible_bias": residual.sum(axis=0),
        "dynamic": np.hstack([residual, h0 - p_last]).T @ history,
        "log_visible_variance": (
            ((visible - c) ** 2 + c * (reconstruction - c) - visible * (v1 - c)).sum(
                axis=0
            )
            / (2 * s**2)
            - n / 2
        ),
    }
    for name, value in expected.items():
        assert_allclose(getattr(gradients, name), scale * value, rtol=1e-10)
    assert squared_error == pytest.approx(np.sum(residual**2), rel=1e-12)


def test_unit_variance_has_no_variance_statistic_and_ones():
    X, ids = make_oscillations(n_sequences=3, n_frames=30, random_state=1)
    model = ConditionalRBM(8, order=2, n_iter=5, random_state=0)
    model.fit(X, sequence_ids=ids)
    assert_array_equal(model.visible_variance_, np.ones(X.shape[1]))
    assert model.visible_variance_.shape == (X.shape[1],)


def test_learned_variances_shrink_to_the_residual_and_stop_at_the_floor():
    X, ids = make_oscillations(n_sequences=4, n_frames=50, noise=0.05, random_state=2)
    X[:, 0] = 0.0  # a channel its past predicts exactly
    model = ConditionalRBM(
        8,
        order=2,
        visible_variance="learned",
        cd_steps=2,
        n_iter=100,
        history_noise=0.0,
        learning_rate=0.02,
        random_state=0,
    ).fit(X, sequence_ids=ids)
    variance = model.visible_variance_
    assert variance[0] == pytest.approx(1e-4, rel=1e-6)
    # the others near the noise's variance (0.05^2) plus what W leaves
    assert np.all((variance[1:] > 1e-3) & (variance[1:] < 0.01))


def test_variances_are_computed_from_the_packed_log_variances():
    X, ids = make_oscillations(n_sequences=3, n_frames=30, random_state=4)
    model = ConditionalRBM(8, order=2, visible_variance="learned", n_iter=3)
    model.fit(X, sequence_ids=ids)
    packed = model._layer
    assert np.shares_memory(packed.log_visible_variance, packed.flat)
    assert_allclose(model.visible_variance_, np.exp(packed.log_visible_variance))
    loaded = pickle.loads(pickle.dumps(model))
    assert_array_equal(loaded.visible_variance_, model.visible_variance_)


def test_setting_the_variances_changes_the_model():
    X, ids = make_oscillations(n_sequences=3, n_frames=30, random_state=3)
    model = ConditionalRBM(8, order=2, visible_variance="learned", n_iter=5)
    model.fit(X, sequence_ids=ids)
    before = model.score_samples(X, sequence_ids=ids)
    model.visible_variance_ = np.full(X.shape[1], 0.5)
    assert_allclose(model.visible_variance_, 0.5)
    assert not np.allclose(model.score_samples(X, sequence_ids=ids), before)


def test_binary_visibles_cannot_learn_variances():
    X = (np.random.default_rng(0).random((40, 3)) > 0.5).astype(float)
    with pytest.raises(ValueError, match="needs Gaussian visibles"):
        ConditionalRBM(
            4, visible_type="binary", visible_variance="learned", n_iter=2
        ).fit(X)


def test_setting_the_variances_of_a_unit_variance_model_is_an_error():
    X, ids = make_oscillations(n_sequences=3, n_frames=30, random_state=3)
    model = ConditionalRBM(8, order=2, n_iter=2).fit(X, sequence_ids=ids)
    with pytest.raises(ValueError, match="unit variance"):
        model.visible_variance_ = np.full(X.shape[1], 0.5)
    assert_array_equal(model.visible_variance_, 1.0)
