"""Tests of StackedCRBM: greedy training, the passes up and down, generation."""

import itertools

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import expit, logsumexp
from sklearn.exceptions import NotFittedError
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from sklearn_crbm import ConditionalRBM, FactoredCRBM, LabelledCRBM
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.model_selection import make_prediction_scorer
from sklearn_crbm.models import _base as base_module
from sklearn_crbm.models._stacked import StackedCRBM


def small_stack(**params):
    defaults = dict(n_components=(6, 4), order=2, n_iter=5, random_state=0)
    defaults.update(params)
    return StackedCRBM(**defaults)


@pytest.mark.parametrize("bad", [(), (4, 0), (4, 2.5), "abc", (True, 3)])
def test_bad_layer_sizes_are_rejected(bad):
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    with pytest.raises((ValueError, TypeError), match="n_components"):
        small_stack(n_components=bad).fit(X, sequence_ids=ids)


# ---------------------------------------------------------- greedy training
def test_layers_are_trained_greedily_on_valid_hidden_probabilities():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack(n_components=(6, 4), order=2, hidden_order=3).fit(
        X, sequence_ids=ids
    )
    bottom, top = stack.layers_
    assert [bottom.visible_type, top.visible_type] == ["gaussian", "binary"]
    assert bottom.components_.shape == (6, 5) and top.components_.shape == (4, 6)
    assert bottom.autoregressive_.shape[0] == 2 and bottom.past_to_hidden_.shape[0] == 3

    # The top layer is exactly a binary CRBM trained on the bottom layer's
    # hidden probabilities over its valid frames (first 3 of each sequence
    # dropped), with the same hyper-parameters and the seed it was given.
    hidden = bottom.transform(X, sequence_ids=ids)
    valid = np.concatenate([np.flatnonzero(ids == s)[3:] for s in np.unique(ids)])
    reference = ConditionalRBM(
        4,
        order=2,
        hidden_order=3,
        visible_type="binary",
        history_noise=0.0,  # the stack's defaults
        average_fraction=0.0,
        n_iter=5,
        random_state=top.random_state,
    ).fit(hidden[valid], sequence_ids=ids[valid])
    assert_allclose(top.components_, reference.components_)
    assert_allclose(top.autoregressive_, reference.autoregressive_)
    assert top.seed_windows_.shape[1:] == (3, 6)
    # the bottom layer is a plain ConditionalRBM on the data
    alone = ConditionalRBM(
        6,
        order=2,
        hidden_order=3,
        history_noise=0.0,
        average_fraction=0.0,
        n_iter=5,
        random_state=bottom.random_state,
    ).fit(X, sequence_ids=ids)
    assert_allclose(bottom.components_, alone.components_)


def test_single_int_gives_one_layer_equal_to_conditional_rbm():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack(n_components=5).fit(X, sequence_ids=ids)
    assert len(stack.layers_) == 1
    layer = stack.layers_[0]
    assert_allclose(
        stack.transform(X, sequence_ids=ids), layer.transform(X, sequence_ids=ids)
    )
    assert stack.score(X, sequence_ids=ids) == pytest.approx(
        layer.score(X, sequence_ids=ids)
    )


def test_three_layers_and_history_length():
    X, ids = make_oscillations(n_frames=30, n_features=5, random_state=0)
    stack = small_stack(n_components=(6, 5, 3), order=1, hidden_order=2).fit(
        X, sequence_ids=ids
    )
    assert stack.history_length == 6
    assert stack.transform(X, sequence_ids=ids).shape == (len(X), 3)
    assert stack.sample(7, n_sequences=2, random_state=0).shape == (14, 5)
    assert np.isfinite(stack.score(X, sequence_ids=ids))


def test_too_short_sequences_are_an_error_naming_the_length():
    X, ids = make_oscillations(n_frames=4, n_features=5, random_state=0)
    with pytest.raises(ValueError, match="at least 5 frames"):
        small_stack(order=2).fit(X, sequence_ids=ids)


def test_partial_fit_trains_every_layer_one_epoch_per_call():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack()
    for _ in range(3):
        assert stack.partial_fit(X, sequence_ids=ids) is stack
    assert [layer.n_iter_ for layer in stack.layers_] == [3, 3]
    assert stack.seed_windows_.shape[1:] == (4, 5)
    with pytest.raises(ValueError, match="features"):
        stack.partial_fit(X[:, :3], sequence_ids=ids)


# ---------------------------------------------------------------- inference
def test_transform_is_top_layer_on_bottom_probabilities():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack().fit(X, sequence_ids=ids)
    bottom, top = stack.layers_
    expected = top.transform(bottom.transform(X, sequence_ids=ids), sequence_ids=ids)
    assert_allclose(stack.transform(X, sequence_ids=ids), expected)
    assert_allclose(stack.fit_transform(X, sequence_ids=ids), expected)


def test_predict_next_goes_up_then_down_by_the_equations():
    X, ids = make_oscillations(n_sequences=1, n_frames=30, n_features=5, random_state=0)
    stack = small_stack().fit(X)
    bottom, top = stack.layers_
    H = bottom.transform(X)
    t = 10
    # top layer: mean-field prediction of H[t] from H[t-1], H[t-2]
    c_hat = top.intercept_visible_ + sum(
        top.autoregressive_[q - 1] @ H[t - q] for q in (1, 2)
    )
    b_hat = top.intercept_hidden_ + sum(
        top.past_to_hidden_[q - 1] @ H[t - q] for q in (1, 2)
    )
    h_pred = expit(c_hat)
    for _ in range(10):
        h_pred = expit(
            c_hat + top.components_.T @ expit(b_hat + top.components_ @ h_pred)
        )
    # bottom layer: visible mean given those hidden probabilities and X's past
    v_hat = bottom.intercept_visible_ + sum(
        bottom.autoregressive_[q - 1] @ X[t - q] for q in (1, 2)
    )
    expected = v_hat + bottom.components_.T @ h_pred
    assert_allclose(stack.predict_next(X)[t], expected, rtol=1e-6, atol=1e-8)


def exact_stack_log_likelihood(stack, X, t):
    """log p(x_t | past) of a two-layer stack, summing every hidden state."""
    bottom, top = stack.layers_
    H = bottom.transform(X)
    lags = (1, 2)
    c1 = bottom.intercept_visible_ + sum(
        bottom.autoregressive_[q - 1] @ X[t - q] for q in lags
    )
    c2 = top.intercept_visible_ + sum(
        top.autoregressive_[q - 1] @ H[t - q] for q in lags
    )
    b2 = top.intercept_hidden_ + sum(
        top.past_to_hidden_[q - 1] @ H[t - q] for q in lags
    )
    h1 = np.array(list(itertools.product([0.0, 1.0], repeat=len(c2))))
    h2 = np.array(list(itertools.product([0.0, 1.0], repeat=len(b2))))
    # top layer: p(h1) = sum_h2 exp(c2.h1 + b2.h2 + h1.W2^T h2) / Z
    joint = h1 @ c2 + (h2 @ b2)[:, None] + h2 @ top.components_ @ h1.T
    log_p_h1 = logsumexp(joint, axis=0) - logsumexp(joint)
    means = c1 + h1 @ bottom.components_
    log_p_x = -0.5 * np.sum((X[t] - means) ** 2, axis=1) - 0.5 * len(c1) * np.log(
        2 * np.pi
    )
    return logsumexp(log_p_x + log_p_h1)


def test_score_is_a_lower_bound_on_the_exact_stack_likelihood(monkeypatch):
    X, _ = make_oscillations(n_sequences=1, n_frames=30, n_features=5, random_state=0)
    stack = small_stack(n_components=(5, 3), n_iter=30, learning_rate=0.01).fit(X)
    frames = np.arange(4, 30)
    exact = np.array([exact_stack_log_likelihood(stack, X, t) for t in frames])
    bound = stack.score_samples(X)[frames]
    assert stack.score(X) == pytest.approx(bound.mean())
    weights = np.zeros(len(X))
    weights[frames[0]] = 1.0
    assert stack.score(X, sample_weight=weights) == pytest.approx(bound[0])
    assert bound.mean() < exact.mean()
    # more draws tighten the importance-weighted bound onto the likelihood
    monkeypatch.setattr(base_module, "BOUND_SAMPLES", 3000)
    tight = stack.score_samples(X)[frames]
    assert bound.mean() < tight.mean() <= exact.mean() + 0.01
    assert_allclose(tight, exact, atol=0.05)
    with pytest.raises(ValueError, match="4 past frames"):
        stack.score(X[:4])


def test_trained_stack_predicts_better_than_the_mean():
    X, ids = make_oscillations(n_sequences=6, n_frames=60, n_features=5, random_state=0)
    stack = small_stack(n_components=(16, 8), n_iter=60).fit(X, sequence_ids=ids)
    X_test, ids_test = make_oscillations(
        n_sequences=2, n_frames=60, n_features=5, random_state=1
    )
    error = -make_prediction_scorer()(stack, X_test, sequence_ids=ids_test)
    assert error < 0.5 * np.mean(np.var(X_test, 0))


# --------------------------------------------------------------- generation
def test_sample_is_top_down_as_gen2():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack().fit(X, sequence_ids=ids)
    bottom, top = stack.layers_
    seed = X[:4]
    frames = stack.sample(6, history=seed, n_gibbs=3, random_state=7)
    assert frames.shape == (6, 5)

    # Up: the bottom layer's hidden probabilities of the last 2 seed frames.
    H_seed = bottom.transform(seed)[2:]
    # Top: the top layer generates from them with the same random draws.
    rng_seed = int(
        np.random.default_rng(
            np.random.RandomState(7).randint(np.iinfo(np.int32).max)
        ).integers(np.iinfo(np.int32).max)
    )
    # (the stack has no drift; the top layer alone would have its default)
    H_new = top.sample(
        6, history=H_seed, n_gibbs=3, hidden_drift=0.0, random_state=rng_seed
    )
    # Down: visible means of the bottom layer given its own generated past.
    past = list(seed[2:])
    for t in range(6):
        v_hat = bottom.intercept_visible_ + sum(
            bottom.autoregressive_[q - 1] @ past[-q] for q in (1, 2)
        )
        past.append(v_hat + bottom.components_.T @ H_new[t])
    assert_allclose(frames, np.array(past[2:]), rtol=1e-6, atol=1e-8)


def test_sample_shapes_seeds_and_reproducibility():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack().fit(X.astype(np.float32), sequence_ids=ids)
    assert stack.seed_windows_.shape[1:] == (4, 5)
    default = stack.sample(5, n_sequences=3)
    assert default.shape == (15, 5) and default.dtype == np.float32
    assert_array_equal(default, stack.sample(5, n_sequences=3))
    assert not np.array_equal(
        stack.sample(5, n_sequences=3, random_state=1),
        stack.sample(5, n_sequences=3, random_state=2),
    )
    seeds = np.stack([X[:6], X[40:46]])
    per_sequence = stack.sample(4, history=seeds, random_state=0)
    assert per_sequence.shape == (8, 5)
    assert np.isfinite(per_sequence).all()
    # with one mean-field step: the default's many settle every chain of
    # this barely trained stack at the same point, noise or not
    noisy, quiet = (
        stack.sample(
            4, history=seeds, hidden_noise=noise, n_mean_field=1, random_state=0
        )
        for noise in (2.0, 0.0)
    )
    assert not np.array_equal(noisy, quiet)
    with pytest.raises(ValueError, match="at least 4 frames"):
        stack.sample(3, history=X[:3])
    with pytest.raises(ValueError, match="n_sequences"):
        stack.sample(3, history=seeds, n_sequences=3)
    with pytest.raises(ValueError, match="hidden_noise"):
        stack.sample(3, hidden_noise=-1.0)
    with pytest.raises(ValueError, match="NaN"):
        stack.sample(3, history=np.full((4, 5), np.nan))


def test_generated_oscillation_keeps_moving():
    X, ids = make_oscillations(n_sequences=8, n_frames=80, n_features=4, random_state=0)
    stack = StackedCRBM((32, 16), order=2, n_iter=150, random_state=0).fit(
        X, sequence_ids=ids
    )
    frames = stack.sample(120, history=X[:4], random_state=0)
    assert np.abs(frames).max() < 5
    late = frames[60:]
    assert late.std(axis=0).mean() > 0.2 * X.std(axis=0).mean()


# ------------------------------------------------------------------ routing
def test_pipeline_routes_sequence_ids():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    with sklearn.config_context(enable_metadata_routing=True):
        pipe = make_pipeline(StandardScaler(), small_stack())
        pipe.fit(X, sequence_ids=ids)
        routed = pipe.transform(X, sequence_ids=ids)
        unrouted = pipe.transform(X)
    stack = pipe[-1]
    Xs = pipe[0].transform(X)
    assert_allclose(routed, stack.transform(Xs, sequence_ids=ids))
    assert not np.allclose(routed, unrouted)


def test_feature_names_out():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack().fit(X, sequence_ids=ids)
    assert_array_equal(
        stack.get_feature_names_out(), [f"stackedcrbm{i}" for i in range(4)]
    )


# ------------------------------------------------------------ history noise
def test_history_noise_shrinks_the_directed_weights_and_only_affects_training():
    X, ids = make_oscillations(n_sequences=6, n_frames=60, n_features=5, random_state=0)
    params = dict(
        n_components=8,
        order=2,
        n_iter=100,
        learning_rate=1e-2,
        history_noise_fraction=1.0,  # every channel of the past is noisy
        random_state=0,
    )
    clean = ConditionalRBM(history_noise=0.0, **params).fit(X, sequence_ids=ids)
    noisy = ConditionalRBM(history_noise=1.0, **params).fit(X, sequence_ids=ids)
    # the past is less trustworthy, so the autoregressive weights lean on it less
    assert np.linalg.norm(noisy.autoregressive_) < 0.6 * np.linalg.norm(
        clean.autoregressive_
    )
    # inference and generation use the history as it is
    before = noisy.transform(X, sequence_ids=ids)
    noisy.set_params(history_noise=5.0)
    assert_allclose(noisy.transform(X, sequence_ids=ids), before)
    assert_array_equal(
        noisy.sample(5, random_state=0),
        noisy.set_params(history_noise=0.0).sample(5, random_state=0),
    )


def test_stack_passes_history_noise_to_every_layer():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack(history_noise=0.3, history_noise_fraction=0.7)
    stack.fit(X, sequence_ids=ids)
    assert [layer.history_noise for layer in stack.layers_] == [0.3, 0.3]
    assert [layer.history_noise_fraction for layer in stack.layers_] == [0.7, 0.7]
    per_layer = small_stack(history_noise=[0.5, 0.1]).fit(X, sequence_ids=ids)
    assert [layer.history_noise for layer in per_layer.layers_] == [0.5, 0.1]
    with pytest.raises(ValueError, match="one such number per layer"):
        small_stack(history_noise=[0.5]).fit(X, sequence_ids=ids)
    plain = small_stack().fit(X, sequence_ids=ids)
    assert not np.allclose(stack.layers_[0].components_, plain.layers_[0].components_)


def test_a_failed_fit_leaves_the_stack_unfitted():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    stack = small_stack()
    with pytest.raises(ValueError, match="at least 5 frames"):
        stack.fit(X, sequence_ids=np.arange(len(X)) // 3)
    with pytest.raises(NotFittedError, match="not fitted"):
        stack.transform(X)
    with pytest.raises(NotFittedError, match="not fitted"):
        stack.sample(3)


def test_it_stacks_any_layer_model():
    """Layers of another kind: clones of ``estimator``, labels and context
    passed up, the history the sum of the layers' pasts."""
    X, ids = make_oscillations(n_sequences=4, n_frames=50, random_state=0)
    labels = np.where(ids % 2 == 0, "a", "b")
    stack = StackedCRBM(
        (6, 4), estimator=LabelledCRBM(order=1, n_iter=3), random_state=0
    ).fit(X, labels, sequence_ids=ids)
    assert [type(m) for m in stack.layers_] == [LabelledCRBM, LabelledCRBM]
    assert [m.n_components for m in stack.layers_] == [6, 4]
    assert stack.history_length == 2 and stack.n_context_ == 2
    weights = np.eye(2)[ids % 2]
    assert stack.transform(X, sequence_ids=ids, context=weights).shape == (200, 4)
    # the top layer was trained on the bottom's hidden units and their labels
    top = stack.layers_[1]
    assert top.n_features_in_ == 6 and list(top.classes_) == ["a", "b"]
    context = np.where(ids[:, None] % 2 == 0, 1.0, -1.0)
    factored = FactoredCRBM(n_factors=3, n_style_features=2, order=2, n_iter=2)
    stack = StackedCRBM((6, 4), estimator=factored, random_state=0)
    stack.fit(X, sequence_ids=ids, context=context)
    assert stack.history_length == 4
    assert np.isfinite(stack.score(X, sequence_ids=ids, context=context))
    assert stack.sample(5, context=context[:1], random_state=0).shape == (5, 6)


def test_the_log_likelihood_of_chosen_frames_is_theirs_in_the_whole():
    X, ids = make_oscillations(n_sequences=2, n_frames=30, random_state=0)
    model = StackedCRBM([6, 4], order=2, n_iter=2, random_state=0).fit(
        X, sequence_ids=ids
    )
    sequences = base_module.check_sequence_ids(ids, len(X))
    whole = model._log_likelihood(X, sequences, rng=np.random.default_rng(0))
    frames = np.array([40, 5, 12])
    chosen = model._log_likelihood(
        X, sequences, rng=np.random.default_rng(0), frames=frames
    )
    assert_allclose(chosen.log_likelihood, whole.log_likelihood[frames])
