"""Tests of the held-out log-likelihood behind ConditionalRBM.score.

Tiny models have exact answers: the exact path is checked against a
brute-force sum of ``exp(-E(v, h))`` written from the energy alone (over
all visible and hidden states for binary visibles; over the hidden states
and a fine grid of visible values for Gaussian ones), and annealed
importance sampling against the exact path.
"""

import itertools

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.special import logsumexp

from sklearn_crbm import ConditionalRBM
from sklearn_crbm._engines._likelihood import (
    annealing_schedule,
    exact_is_cheaper,
    log_partition_ais,
    log_partition_exact,
)
from sklearn_crbm.layers._base import GaussianUnits
from sklearn_crbm.layers._crbm import CRBMFrames


def random_model(
    n_features=3,
    n_components=4,
    order=2,
    visible_type="gaussian",
    variance=None,
    scale=0.5,
    seed=0,
):
    """A ConditionalRBM with random parameters set by hand (no training).

    With ``variance`` the model learns its variances (a unit-variance model
    keeps ``s = 1`` whatever is assigned to ``visible_variance_``).
    """
    rng = np.random.default_rng(seed)
    model = ConditionalRBM(
        n_components,
        order=order,
        visible_type=visible_type,
        visible_variance="unit" if variance is None else "learned",
        n_iter=1,
        random_state=0,
    )
    model.fit(rng.random((order + 5, n_features)))
    model.components_ = scale * rng.standard_normal((n_components, n_features))
    model.intercept_hidden_ = scale * rng.standard_normal(n_components)
    model.intercept_visible_ = scale * rng.standard_normal(n_features)
    model.autoregressive_ = 0.3 * rng.standard_normal((order, n_features, n_features))
    model.past_to_hidden_ = scale * rng.standard_normal(
        (order, n_components, n_features)
    )
    if variance is not None:
        model.visible_variance_ = np.asarray(variance, dtype=float)
    return model


def frames(n_frames, n_features, binary=False, seed=1):
    rng = np.random.default_rng(seed)
    if binary:
        return (rng.random((n_frames, n_features)) < 0.5).astype(float)
    t = np.arange(n_frames)[:, None] * 0.4 + np.arange(n_features)
    return np.sin(t) + 0.3 * rng.standard_normal((n_frames, n_features))


def dynamic_biases(model, past):
    """c_hat and b_hat from the past frames (``past[q - 1] = x[t - q]``)."""
    c_hat = model.intercept_visible_.copy()
    b_hat = model.intercept_hidden_.copy()
    for q in range(len(model.autoregressive_)):
        c_hat = c_hat + model.autoregressive_[q] @ past[q]
        b_hat = b_hat + model.past_to_hidden_[q] @ past[q]
    return c_hat, b_hat


def all_states(n):
    return np.array(list(itertools.product([0.0, 1.0], repeat=n)))


def negative_energy(model, v, h, c_hat, b_hat):
    """-E(v, h) from the documented energy; v (..., D), h (..., H)."""
    W = model.components_
    if model.visible_type == "binary":
        return v @ c_hat + h @ b_hat + np.einsum("...i,...i->...", v, h @ W)
    s = np.sqrt(getattr(model, "visible_variance_", np.ones(W.shape[1])))
    return (
        -np.sum((v - c_hat) ** 2 / (2 * s**2), axis=-1)
        + h @ b_hat
        + np.einsum("...i,...i->...", v / s, h @ W)
    )


def brute_force_log_likelihood(model, X, t):
    """log p(x_t | x_{t-1}, ..., x_{t-order}) by summing exp(-E) directly."""
    c_hat, b_hat = dynamic_biases(model, X[t - model.order : t][::-1])
    H = all_states(model.n_components)
    log_joint_x = logsumexp(negative_energy(model, X[t], H, c_hat, b_hat))
    if model.visible_type == "binary":
        V = all_states(len(c_hat))
        log_z = logsumexp(
            negative_energy(model, V[:, None, :], H[None, :, :], c_hat, b_hat)
        )
        return log_joint_x - log_z
    # Gaussian, two visibles: a fine grid around the frame's means
    s = np.sqrt(getattr(model, "visible_variance_", np.ones(2)))
    means = c_hat + s * (H @ model.components_)
    lo, hi = means.min(axis=0) - 8 * s, means.max(axis=0) + 8 * s
    axes = [np.linspace(lo[i], hi[i], 301) for i in range(2)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 2)
    log_density = logsumexp(
        negative_energy(model, grid[:, None, :], H[None, :, :], c_hat, b_hat), axis=1
    )
    cell = (axes[0][1] - axes[0][0]) * (axes[1][1] - axes[1][0])
    return log_joint_x - (logsumexp(log_density) + np.log(cell))


@pytest.mark.parametrize(
    "visible_type, n_features, variance",
    [
        ("gaussian", 2, None),
        ("gaussian", 2, [0.3, 2.5]),
        ("binary", 4, None),
    ],
)
def test_exact_path_equals_brute_force_enumeration(visible_type, n_features, variance):
    model = random_model(
        n_features, 5, order=2, visible_type=visible_type, variance=variance, scale=0.8
    )
    X = frames(6, n_features, binary=visible_type == "binary")
    result = model.estimate_log_likelihood(X, method="exact")
    assert result.method == "exact"
    for t in range(2, len(X)):
        assert result.log_likelihood[t] == pytest.approx(
            brute_force_log_likelihood(model, X, t), abs=1e-6
        )


def test_gaussian_exact_density_integrates_to_one_with_learned_variances():
    """exp(score_samples) over a grid of frames, one history, sums to 1."""
    model = random_model(2, 4, order=1, variance=[0.5, 1.7], scale=1.0)
    axes = np.linspace(-12, 12, 481)
    grid = np.stack(np.meshgrid(axes, axes, indexing="ij"), axis=-1).reshape(-1, 2)
    past = np.array([[0.4, -0.3]])
    X = np.concatenate([np.repeat(past, len(grid), axis=0)[:, None], grid[:, None]], 1)
    ids = np.repeat(np.arange(len(grid)), 2)
    log_p = model.score_samples(X.reshape(-1, 2), sequence_ids=ids)[1::2]
    cell = (axes[1] - axes[0]) ** 2
    assert np.exp(logsumexp(log_p)) * cell == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize(
    "visible_type, variance, order",
    [
        ("gaussian", None, 2),
        ("gaussian", [0.4, 1.0, 2.0, 0.7, 1.3], 2),
        ("binary", None, 2),
        ("gaussian", [0.4, 1.0, 2.0, 0.7, 1.3], 0),
        ("binary", None, 0),
    ],
)
def test_ais_agrees_with_exact_within_005_nats_per_frame(visible_type, variance, order):
    model = random_model(
        5, 10, order=order, visible_type=visible_type, variance=variance, seed=2
    )
    X = frames(60, 5, binary=visible_type == "binary")
    exact = model.estimate_log_likelihood(X, method="exact", reverse=False)
    ais = model.estimate_log_likelihood(X, method="ais", reverse=False)
    assert ais.method == "ais"
    assert abs(ais.log_likelihood.mean() - exact.log_likelihood.mean()) < 0.05
    # with more chains the standard error says how far each frame can be off
    model.set_params(ais_chains=16)
    ais = model.estimate_log_likelihood(X, method="ais", reverse=False)
    errors = np.abs(ais.log_likelihood - exact.log_likelihood)
    assert np.mean(errors <= 3 * ais.standard_error + 0.01) > 0.85


@pytest.mark.parametrize(
    "visible_type, scale, n_steps, n_chains",
    [("gaussian", 0.8, 10, 2), ("binary", 1.5, 5, 1)],
)
def test_reverse_and_forward_estimates_bracket_the_exact_value(
    visible_type, scale, n_steps, n_chains
):
    # short annealing: both estimates are visibly biased, in opposite directions
    model = random_model(5, 10, order=2, visible_type=visible_type, scale=scale, seed=3)
    model.set_params(ais_steps=n_steps, ais_chains=n_chains)
    X = frames(200, 5, binary=visible_type == "binary")
    exact = model.estimate_log_likelihood(X, method="exact").log_likelihood.mean()
    for seed in range(3):
        result = model.estimate_log_likelihood(X, method="ais", random_state=seed)
        assert result.lower.mean() < exact < result.log_likelihood.mean()


def test_ais_is_unbiased_for_the_partition_function():
    """Many chains: log of the mean weight converges on the exact log Z."""
    rng = np.random.default_rng(0)
    weights = rng.standard_normal((8, 4))
    visible_bias, hidden_bias = rng.standard_normal((3, 4)), rng.standard_normal((3, 8))
    std = np.array([0.5, 1, 1, 2])
    rbms = CRBMFrames(visible_bias, hidden_bias, std, GaussianUnits(), weights)
    log_z, error = log_partition_ais(rbms, 200, 2000, np.random.default_rng(1))
    assert_allclose(log_z, log_partition_exact(rbms), atol=max(0.01, 4 * error.max()))


def test_score_is_mean_of_score_samples_on_frames_with_history():
    model = random_model(3, 4, order=2)
    X = frames(24, 3)
    ids = np.repeat([0, 1], 12)
    per_frame = model.score_samples(X, sequence_ids=ids)
    valid = np.r_[2:12, 14:24]
    assert model.score(X, sequence_ids=ids) == pytest.approx(per_frame[valid].mean())
    weights = np.arange(24.0)
    assert model.score(X, sequence_ids=ids, sample_weight=weights) == pytest.approx(
        np.average(per_frame[valid], weights=weights[valid])
    )


def test_ais_score_is_reproducible_for_a_random_state():
    model = random_model(4, 30, order=1)
    X = frames(30, 4)
    assert model.score(X) == model.score(X)
    other = model.estimate_log_likelihood(X, random_state=7, reverse=False)
    assert other.method == "ais"
    assert not np.array_equal(other.log_likelihood, model.score_samples(X))


def test_auto_enumerates_only_when_cheaper():
    assert exact_is_cheaper(8, 62, 100, 4)
    assert not exact_is_cheaper(30, 62, 100, 4)
    assert not exact_is_cheaper(200, 62, 100, 4)
    assert random_model(3, 6).estimate_log_likelihood(frames(5, 3)).method == "exact"


def test_annealing_schedule_runs_from_zero_to_one_upwards():
    for n_steps in (1, 2, 7, 100):
        betas = annealing_schedule(n_steps)
        assert len(betas) == n_steps + 1
        assert betas[0] == 0 and betas[-1] == 1
        assert np.all(np.diff(betas) > 0)


def test_estimate_log_likelihood_rejects_unknown_method():
    with pytest.raises(ValueError, match="method must be"):
        random_model().estimate_log_likelihood(frames(5, 3), method="bogus")


def test_held_out_score_ranks_orders_and_sizes():
    """On held-out oscillations history helps, by far more than AIS noise."""
    X = frames(400, 5)
    ids = np.repeat(np.arange(8), 50)
    train, test = ids < 6, ids >= 6
    scores = {}
    for order in (0, 2):
        model = ConditionalRBM(
            30, order=order, n_iter=60, learning_rate=0.01, random_state=0
        ).fit(X[train], sequence_ids=ids[train])
        scores[order] = model.score(X[test], sequence_ids=ids[test])
    assert scores[2] > scores[0] + 1.0


# ------------------------------------------------------------ early stopping
def test_early_stopping_keeps_the_parameters_that_score_best():
    X = frames(400, 5)
    ids = np.repeat(np.arange(10), 40)
    params = dict(
        n_components=12,
        order=2,
        learning_rate=0.01,
        n_iter=400,
        early_stopping=True,
        validation_fraction=0.2,
        validation_interval=5,
        n_iter_no_change=20,
        random_state=0,
    )
    model = ConditionalRBM(**params).fit(X, sequence_ids=ids)
    scores = model.validation_scores_
    assert model.n_iter_ < 400  # it stopped
    assert len(scores) == int(np.ceil(model.n_iter_ / 5))
    assert model.best_validation_score_ >= max(scores) - model.tol
    assert model.best_validation_score_ in scores
    # the kept parameters are those of the best check, not the last
    again = ConditionalRBM(**params).fit(X, sequence_ids=ids)
    assert_allclose(again.components_, model.components_)
    assert again.validation_scores_ == scores


def test_early_stopping_needs_several_sequences():
    model = ConditionalRBM(4, order=1, early_stopping=True, n_iter=5)
    with pytest.raises(ValueError, match="single sequence"):
        model.fit(frames(50, 3))


def test_learned_visible_variances_enter_the_likelihood():
    X = frames(240, 2)
    ids = np.repeat(np.arange(6), 40)
    model = ConditionalRBM(
        5,
        order=1,
        visible_variance="learned",
        n_iter=30,
        learning_rate=0.01,
        random_state=0,
    ).fit(X, sequence_ids=ids)
    variance = model.visible_variance_
    assert not np.allclose(variance, 1)
    exact = model.estimate_log_likelihood(X[:40], method="exact").log_likelihood
    for t in (1, 10, 39):
        assert exact[t] == pytest.approx(
            brute_force_log_likelihood(model, X[:40], t), abs=1e-6
        )
    ais = model.estimate_log_likelihood(X[:40], method="ais", reverse=False)
    assert abs(ais.log_likelihood.mean() - exact.mean()) < 0.05
