"""Tests of ConditionalRBM against exact quantities of tiny models.

A Gaussian CRBM with a handful of hidden units has an exact conditional
density: integrating the visibles out of exp(-E) gives

    p(h | history) ∝ exp(b̂·h + ĉ·Wᵀh + ||Wᵀh||² / 2)
    p(v | history) = Σ_h p(h | history) N(v; ĉ + Wᵀh, I)

with ĉ = c + Σ_q A_q x[t-q] and b̂ = b + Σ_q B_q x[t-q], so every test here
compares against sums over the 2^H hidden configurations.
"""

import copy
import itertools
import re
import warnings

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import expit, logsumexp
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from sklearn_crbm import ConditionalRBM, TrainingDivergedError
from sklearn_crbm.datasets import load_cmu35, make_oscillations
from sklearn_crbm.layers._crbm import CRBMFrames
from sklearn_crbm.metrics import divergence
from sklearn_crbm.model_selection import make_prediction_scorer
from sklearn_crbm.utils._random import rng_from, standard_normal, uniform
from sklearn_crbm.utils._sequences import balanced_batches, frame_history


# --------------------------------------------------------------- helpers
def random_model(
    n_features=3, n_components=4, order=2, hidden_order=None, seed=0, scale=0.5
):
    """A ConditionalRBM with random parameters set by hand (no training)."""
    hidden_order = order if hidden_order is None else hidden_order
    rng = np.random.default_rng(seed)
    model = ConditionalRBM(
        n_components, order=order, hidden_order=hidden_order, n_iter=1, random_state=0
    )
    X = rng.standard_normal((max(order, hidden_order) + 5, n_features))
    model.fit(X)
    model.components_ = scale * rng.standard_normal((n_components, n_features))
    model.intercept_hidden_ = scale * rng.standard_normal(n_components)
    model.intercept_visible_ = scale * rng.standard_normal(n_features)
    model.autoregressive_ = 0.3 * rng.standard_normal((order, n_features, n_features))
    model.past_to_hidden_ = scale * rng.standard_normal(
        (hidden_order, n_components, n_features)
    )
    return model


def exact_dynamic_biases(model, past):
    """ĉ and b̂ of one frame from its past frames, ``past[q-1] = x[t-q]``, by the equations."""
    c_hat = model.intercept_visible_.copy()
    b_hat = model.intercept_hidden_.copy()
    for q in range(1, len(model.autoregressive_) + 1):
        c_hat = c_hat + model.autoregressive_[q - 1] @ past[q - 1]
    for q in range(1, len(model.past_to_hidden_) + 1):
        b_hat = b_hat + model.past_to_hidden_[q - 1] @ past[q - 1]
    return c_hat, b_hat


def hidden_configurations(n_components):
    return np.array(list(itertools.product([0.0, 1.0], repeat=n_components)))


def exact_hidden_posterior_given_history(model, c_hat, b_hat):
    """p(h | history) over all 2^H configurations (visibles integrated out)."""
    H = hidden_configurations(model.n_components)
    top_down = H @ model.components_
    log_weight = H @ b_hat + top_down @ c_hat + 0.5 * np.sum(top_down**2, axis=1)
    return H, np.exp(log_weight - logsumexp(log_weight))


def exact_log_likelihood(model, X, sequence_ids):
    """Mean exact log p(x_t | history) over frames with a full history."""
    L = max(model.order, model.hidden_order or model.order)
    d = X.shape[1]
    total, count = 0.0, 0
    for sid in np.unique(sequence_ids):
        seq = X[sequence_ids == sid]
        for t in range(L, len(seq)):
            past = seq[t - L : t][::-1]
            c_hat, b_hat = exact_dynamic_biases(model, past)
            H, p_h = exact_hidden_posterior_given_history(model, c_hat, b_hat)
            means = c_hat + H @ model.components_
            log_normal = -0.5 * np.sum(
                (seq[t] - means) ** 2, axis=1
            ) - 0.5 * d * np.log(2 * np.pi)
            total += logsumexp(log_normal + np.log(p_h))
            count += 1
    return total / count


def sample_from_model(model, n_sequences, n_frames, seed):
    """Exact ancestral sampling from a Gaussian CRBM: h ~ p(h|hist), v ~ N(ĉ + Wᵀh, I)."""
    rng = np.random.default_rng(seed)
    L = max(model.order, model.hidden_order)
    d = model.n_features_in_
    sequences = []
    for _ in range(n_sequences):
        seq = list(rng.standard_normal((L, d)))
        for _ in range(n_frames - L):
            past = np.array(seq[-L:][::-1])
            c_hat, b_hat = exact_dynamic_biases(model, past)
            H, p_h = exact_hidden_posterior_given_history(model, c_hat, b_hat)
            h = H[rng.choice(len(H), p=p_h)]
            seq.append(c_hat + h @ model.components_ + rng.standard_normal(d))
        sequences.append(np.array(seq))
    return np.concatenate(sequences), np.repeat(np.arange(n_sequences), n_frames)


# ------------------------------------------------------------ attributes
@pytest.mark.parametrize(
    "order, hidden_order, expected_lags",
    [(3, None, 3), (0, None, 0), (1, 3, 3), (2, 0, 2)],
)
def test_fitted_attribute_shapes(order, hidden_order, expected_lags):
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(
        7, order=order, hidden_order=hidden_order, n_iter=2, random_state=0
    )
    model.fit(X, sequence_ids=ids)
    hidden_order = order if hidden_order is None else hidden_order
    assert model.components_.shape == (7, 5)
    assert model.intercept_hidden_.shape == (7,)
    assert model.intercept_visible_.shape == (5,)
    assert model.autoregressive_.shape == (order, 5, 5)
    assert model.past_to_hidden_.shape == (hidden_order, 7, 5)
    assert model.seed_windows_.shape[1:] == (max(expected_lags, 1), 5)
    assert model.n_iter_ == 2
    assert model.n_features_in_ == 5
    assert_array_equal(
        model.get_feature_names_out(), [f"conditionalrbm{i}" for i in range(7)]
    )


def test_initialisation_follows_original_code():
    X, ids = make_oscillations(n_frames=200, n_features=20, random_state=0)
    model = ConditionalRBM(300, order=3, n_iter=1, learning_rate=1e-12, random_state=0)
    model.fit(X, sequence_ids=ids)
    assert np.std(model.components_) == pytest.approx(0.01, rel=0.05)
    assert np.mean(model.intercept_hidden_) == pytest.approx(-1, abs=0.003)
    assert np.std(model.intercept_hidden_) == pytest.approx(0.01, rel=0.2)
    assert np.std(model.autoregressive_) == pytest.approx(0.01, rel=0.05)
    assert np.std(model.past_to_hidden_) == pytest.approx(0.01, rel=0.05)


# ------------------------------------------------------- exact conditionals
@pytest.mark.parametrize("order, hidden_order", [(2, 2), (1, 3), (3, 0)])
def test_hidden_probabilities_match_equation(order, hidden_order):
    model = random_model(order=order, hidden_order=hidden_order)
    X, ids = make_oscillations(n_sequences=2, n_frames=12, n_features=3, random_state=0)
    H = model.transform(X, sequence_ids=ids)
    L = max(order, hidden_order)
    for sid in (0, 1):
        seq = X[ids == sid]
        for t in range(L, len(seq)):
            _, b_hat = exact_dynamic_biases(model, seq[t - L : t][::-1])
            expected = expit(b_hat + model.components_ @ seq[t])
            assert_allclose(H[ids == sid][t], expected, rtol=1e-12)


def test_first_frames_use_edge_padded_history():
    model = random_model(order=2)
    X, _ = make_oscillations(n_sequences=1, n_frames=6, n_features=3, random_state=0)
    H = model.transform(X)
    # frame 1 has one real past frame; the missing x[-1] is replaced by x[0]
    _, b_hat = exact_dynamic_biases(model, np.array([X[0], X[0]]))
    assert_allclose(H[1], expit(b_hat + model.components_ @ X[1]), rtol=1e-12)


def test_score_samples_is_the_exact_conditional_density():
    """score_samples is log p(v|hist), summed over h as a mixture of Gaussians."""
    model = random_model(n_features=3, n_components=4, order=2)
    X, _ = make_oscillations(n_sequences=1, n_frames=10, n_features=3, random_state=0)
    log_likelihood = model.score_samples(X)
    for t in range(2, len(X)):
        c_hat, b_hat = exact_dynamic_biases(model, X[t - 2 : t][::-1])
        H, p_h = exact_hidden_posterior_given_history(model, c_hat, b_hat)
        means = c_hat + H @ model.components_
        log_p = logsumexp(
            -0.5 * np.sum((X[t] - means) ** 2, axis=1) + np.log(p_h)
        ) - 1.5 * np.log(2 * np.pi)
        assert log_likelihood[t] == pytest.approx(log_p, rel=1e-10)


def test_long_gibbs_chains_match_exact_conditional_moments():
    model = random_model(n_features=3, n_components=4, order=2, seed=3, scale=0.8)
    past = np.array([[0.3, -0.2, 0.5], [0.1, 0.4, -0.6]])  # x[t-1], x[t-2]
    c_hat, b_hat = exact_dynamic_biases(model, past)
    H, p_h = exact_hidden_posterior_given_history(model, c_hat, b_hat)
    top_down = H @ model.components_
    exact_mean = c_hat + p_h @ top_down
    centred = top_down - p_h @ top_down
    exact_cov = np.eye(3) + centred.T @ (p_h[:, None] * centred)

    n_chains = 20000
    samples = model.sample(
        1,
        history=past[::-1],
        n_sequences=n_chains,
        n_gibbs=60,
        sample_visibles=True,
        random_state=0,
    )
    standard_error = np.sqrt(np.diag(exact_cov) / n_chains)
    assert np.all(np.abs(samples.mean(axis=0) - exact_mean) < 4 * standard_error)
    assert_allclose(np.cov(samples.T), exact_cov, atol=0.06)


def test_training_on_crbm_data_raises_exact_likelihood():
    truth = random_model(n_features=3, n_components=3, order=1, seed=7, scale=1.0)
    X, ids = sample_from_model(truth, n_sequences=6, n_frames=80, seed=1)
    X_test, ids_test = sample_from_model(truth, n_sequences=3, n_frames=60, seed=2)
    model = ConditionalRBM(
        3, order=1, learning_rate=0.01, batch_size=20, n_iter=1, random_state=0
    )
    model.fit(X, sequence_ids=ids)
    before = exact_log_likelihood(model, X_test, ids_test)
    for _ in range(150):
        model.partial_fit(X, sequence_ids=ids)
    after = exact_log_likelihood(model, X_test, ids_test)
    best = exact_log_likelihood(truth, X_test, ids_test)
    assert after > before + 0.5
    assert after > best - 0.5


# ------------------------------------------------------------ CD update
@pytest.mark.parametrize(
    "n_components, n_features, n_frames, history_noise, fraction",
    [
        (5, 4, 15, 0.0, 1.0),  # few draws: numpy's float64 uniforms
        # >= 4096 draws per minibatch: 23-bit uniforms, float32 Box-Muller noise
        (40, 12, 60, 0.5, 1.0),
        (40, 12, 60, 0.5, 0.5),  # noise on about half the channels of each frame
    ],
)
def test_one_cd1_update_equals_paper_equations(
    n_components, n_features, n_frames, history_noise, fraction
):
    order = 3
    X, ids = make_oscillations(
        n_sequences=2, n_frames=n_frames, n_features=n_features, random_state=0
    )
    model = ConditionalRBM(
        n_components,
        order=order,
        batch_size=1000,
        n_iter=1,
        history_noise=history_noise,
        history_noise_fraction=fraction,
        random_state=0,
    )
    model.partial_fit(X, sequence_ids=ids)  # epoch 1; the update we check is epoch 2
    before = copy.deepcopy(model)

    # replay the random stream the second epoch will use
    rng = rng_from(copy.deepcopy(model.random_state_))
    frames = np.concatenate(
        [np.arange(order, n_frames), np.arange(n_frames + order, 2 * n_frames)]
    )
    (batch,) = balanced_batches(frames, 1000, rng)
    shape = (len(batch), n_components)
    noise = np.zeros((len(batch), order * n_features))
    noised = np.ones((len(batch), n_features))  # which channels get noise
    if history_noise and fraction < 1:
        noised = rng.random(noised.shape) < fraction
    if history_noise:
        noise = history_noise * standard_normal(rng, noise.shape, np.float32)
        noise = noise * np.tile(noised, order)
    if len(batch) * n_components >= 4096:  # 2u - 1 from 23 random bits
        uniform_draws = (uniform(rng, shape, np.float32, symmetric=True) + 1.0) / 2
    else:
        uniform_draws = rng.random(shape)

    W, A, B = before.components_, before.autoregressive_, before.past_to_hidden_
    b, c = before.intercept_hidden_, before.intercept_visible_
    grad = {k: 0.0 for k in "WbcAB"}
    for row, t in enumerate(batch):
        # noise on the history only, independent for every lag of every row
        v = X[t]
        past = X[[t - q for q in range(1, order + 1)]]
        past = past + noise[row].reshape(order, n_features)
        c_hat = c + sum(A[q] @ past[q] for q in range(order))
        b_hat = b + sum(B[q] @ past[q] for q in range(order))
        # binary states (§2.2)
        h_data = (uniform_draws[row] < expit(b_hat + W @ v)).astype(float)
        v_recon = c_hat + W.T @ h_data  # visible mean from binary states
        h_recon = expit(b_hat + W @ v_recon)  # probabilities under the reconstruction
        grad["W"] += np.outer(h_data, v) - np.outer(h_recon, v_recon)  # Eq. 4
        grad["b"] += h_data - h_recon  # Eq. 5
        grad["c"] += (v - c_hat) - (v_recon - c_hat)
        grad["B"] += np.stack([np.outer(h_data - h_recon, p) for p in past])  # Eq. 6
        grad["A"] += np.stack([np.outer(v - v_recon, p) for p in past])  # Eq. 7
    n, lr, wd = len(batch), model.learning_rate, model.weight_decay
    # momentum is 0 in epoch 2
    model.partial_fit(X, sequence_ids=ids)
    assert_allclose(model.components_, W + lr * (grad["W"] / n - wd * W), rtol=1e-10)
    assert_allclose(model.intercept_hidden_, b + lr * grad["b"] / n, rtol=1e-10)
    assert_allclose(model.intercept_visible_, c + lr * grad["c"] / n, rtol=1e-10)
    assert_allclose(
        model.autoregressive_, A + lr * (grad["A"] / n - wd * A), rtol=1e-10
    )
    assert_allclose(
        model.past_to_hidden_, B + lr * (grad["B"] / n - wd * B), rtol=1e-10
    )


def test_momentum_starts_after_delay():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(4, order=1, momentum_delay=2, n_iter=1, random_state=0)
    model.partial_fit(X, sequence_ids=ids)
    assert model.n_iter_ == 1
    velocity_norms = []
    for _ in range(3):
        before = model.components_.copy()
        model.partial_fit(X, sequence_ids=ids)
        velocity_norms.append(np.linalg.norm(model.components_ - before))
    # without momentum the step is lr * gradient; with momentum it accumulates
    assert velocity_norms[2] > 1.5 * velocity_norms[0]


def test_cd_k_runs_k_reconstructions():
    model = random_model(order=1)
    layer = model._layer
    X, _ = make_oscillations(n_sequences=1, n_frames=30, n_features=3, random_state=0)
    history = frame_history(X, np.arange(1, 30), 1)

    def cd_statistics(cd_steps):
        return layer.cd_statistics(
            X[1:],
            history,
            None,
            cd_steps,
            np.random.default_rng(0),
            out=layer.zeros_like(),
            scale=1,
            workspace=layer.new_workspace(29),
        )

    g1, e1 = cd_statistics(1)
    g5, e5 = cd_statistics(5)
    assert not np.allclose(g1.weights, g5.weights)
    assert e5 > e1  # later reconstructions wander further from the data


# ------------------------------------------------------------ sequences
def test_history_never_crosses_sequence_boundary():
    model = random_model(order=2)
    X, ids = make_oscillations(n_sequences=3, n_frames=10, n_features=3, random_state=0)
    together = [
        model.transform(X, sequence_ids=ids),
        model.score_samples(X, sequence_ids=ids),
        model.predict_next(X, sequence_ids=ids),
    ]
    for sid in range(3):
        alone = X[ids == sid]
        for whole, method in zip(
            together, ("transform", "score_samples", "predict_next"), strict=True
        ):
            assert_allclose(
                whole[ids == sid], getattr(model, method)(alone), rtol=1e-12
            )
    # changing one sequence changes nothing in the others
    X_changed = X.copy()
    X_changed[ids == 0] += 5.0
    assert_allclose(
        model.transform(X_changed, sequence_ids=ids)[ids != 0], together[0][ids != 0]
    )


def test_training_skips_frames_without_full_history():
    """Frames of a sequence shorter than the history never reach the model."""
    X, ids = make_oscillations(n_sequences=3, n_frames=30, n_features=3, random_state=0)
    short = np.full((3, 3), 1e6)  # would blow training up if used as current frame
    X_all = np.concatenate([X, short])
    ids_all = np.concatenate([ids, [7, 7, 7]])
    a = ConditionalRBM(4, order=3, n_iter=3, random_state=0).fit(
        X_all, sequence_ids=ids_all
    )
    b = ConditionalRBM(4, order=3, n_iter=3, random_state=0).fit(X, sequence_ids=ids)
    assert_allclose(a.components_, b.components_)


def test_prediction_scorer_is_mean_squared_one_step_error_on_valid_frames():
    model = random_model(order=2)
    X, ids = make_oscillations(n_sequences=2, n_frames=12, n_features=3, random_state=0)
    predicted = model.predict_next(X, sequence_ids=ids)
    valid = np.concatenate([np.arange(2, 12), np.arange(14, 24)])
    scorer = make_prediction_scorer()
    assert scorer(model, X, sequence_ids=ids) == pytest.approx(
        -np.mean((X[valid] - predicted[valid]) ** 2)
    )


def test_score_prefers_history_on_held_out_sequences():
    X, ids = make_oscillations(n_sequences=6, n_frames=60, n_features=5, random_state=0)
    train, test = ids < 4, ids >= 4
    scores = {
        order: ConditionalRBM(
            20, order=order, n_iter=100, learning_rate=0.01, random_state=0
        )
        .fit(X[train], sequence_ids=ids[train])
        .score(X[test], sequence_ids=ids[test])
        for order in (0, 2)
    }
    assert scores[2] > scores[0] + 0.2


# ----------------------------------------------------------- generation
def test_sample_shapes_and_seeds():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(8, order=2, n_iter=5, random_state=0).fit(
        X, sequence_ids=ids
    )
    assert model.sample(7).shape == (7, 5)
    assert model.sample(7, n_sequences=4).shape == (28, 5)
    seeds = np.stack([X[:2], X[40:42], X[80:82]])
    assert model.sample(5, history=seeds).shape == (15, 5)
    # a 2-D history seeds every sequence alike: with zero noise they agree
    out = model.sample(4, history=X[:10], n_sequences=2, n_gibbs=0)
    assert_allclose(out[:4], out[4:], atol=0.1)
    with pytest.raises(ValueError, match="at least 2 frames"):
        model.sample(3, history=X[:1])
    with pytest.raises(ValueError, match="n_sequences"):
        model.sample(3, history=seeds, n_sequences=2)
    with pytest.raises(ValueError, match="history must have shape"):
        model.sample(3, history=X[0])
    with pytest.raises(ValueError, match="n_samples"):
        model.sample(0)
    with pytest.raises(ValueError, match="hidden_noise"):
        model.sample(3, hidden_noise=-1)


def test_sample_follows_the_seed_dynamics():
    """Seeded with a sequence, generation continues it (the AR part alone would too)."""
    X, ids = make_oscillations(n_sequences=6, n_frames=80, n_features=5, random_state=0)
    model = ConditionalRBM(30, order=3, n_iter=150, learning_rate=0.01, random_state=0)
    model.fit(X, sequence_ids=ids)
    generated = model.sample(40, history=X[:3], random_state=1)
    assert np.all(np.abs(generated) < 3)
    assert np.std(generated, axis=0).min() > 0.3  # keeps oscillating, does not die out


def test_sample_settles_each_frame_by_mean_field():
    """The default's mean-field steps take out the shake of the original one
    step (jerk above the real sequences') and keep the oscillation."""
    X, ids = make_oscillations(n_sequences=6, n_frames=80, n_features=5, random_state=0)
    model = ConditionalRBM(30, order=3, n_iter=150, learning_rate=0.01, random_state=0)
    model.fit(X, sequence_ids=ids)

    def jerk(frames):
        return np.abs(np.diff(frames, 3, axis=0)).mean()

    given = dict(history=X[:3], hidden_drift=0.0, random_state=1)
    original = model.sample(40, n_mean_field=1, **given)
    settled = model.sample(40, **given)
    assert jerk(original) > jerk(X[:80]) > 5 * jerk(settled)
    assert np.std(settled, axis=0).min() > 0.3
    assert_allclose(np.std(settled, axis=0), np.std(original, axis=0), rtol=0.05)
    with pytest.raises(ValueError, match="n_mean_field must be an integer >= 1"):
        model.sample(3, n_mean_field=0)


def test_hidden_drift_keeps_sequences_from_one_seed_apart_and_smooth():
    """Without drift, the mean-field steps make sequences from one seed
    copies; the drift parts them without bringing back the shake of one
    step."""
    X, ids = make_oscillations(n_sequences=6, n_frames=80, n_features=5, random_state=0)
    model = ConditionalRBM(30, order=3, n_iter=150, learning_rate=0.01, random_state=0)
    model.fit(X, sequence_ids=ids)
    seed = np.repeat(X[None, :3], 4, axis=0)
    sequence_ids = np.repeat(np.arange(4), 200)

    def jerk(frames):
        return np.abs(np.diff(frames, 3, axis=0)).mean()

    copies = model.sample(200, history=seed, hidden_drift=0.0, random_state=1)
    apart = model.sample(200, history=seed, random_state=1)  # the default drift
    shaky = model.sample(200, history=seed, n_mean_field=1, hidden_drift=0.0)
    assert divergence(copies, sequence_ids=sequence_ids, frames=slice(100, 200)) < 0.1
    assert divergence(apart, sequence_ids=sequence_ids, frames=slice(100, 200)) > 0.3
    assert jerk(shaky) > 3 * jerk(apart)
    assert np.std(apart, axis=0).min() > 0.3


def test_sampler_settings_are_parameters():
    """set_params (a search, a pipeline) sets what sample does by default;
    sample's keywords still override it."""
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(8, order=2, n_iter=5, random_state=0).fit(
        X, sequence_ids=ids
    )
    assert model.get_params()["n_mean_field"] == 10
    assert model.get_params()["hidden_drift"] == 0.3
    given = dict(n_sequences=2, random_state=0)
    by_keyword = model.sample(10, n_mean_field=1, hidden_drift=0.0, **given)
    model.set_params(n_mean_field=1, hidden_drift=0.0)
    assert_array_equal(model.sample(10, **given), by_keyword)
    assert not np.allclose(model.sample(10, hidden_drift=1.0, **given), by_keyword)
    with pytest.raises(ValueError, match="hidden_drift must be a non-negative"):
        model.sample(3, hidden_drift=-1.0)
    with pytest.raises(ValueError, match="n_mean_field"):
        ConditionalRBM(n_mean_field=0).fit(X, sequence_ids=ids)


def test_hidden_noise_changes_samples():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(8, order=2, n_iter=5, random_state=0).fit(
        X, sequence_ids=ids
    )
    # one mean-field step: the many of the default settle every chain of a
    # 5-epoch model at the same point, noise or not
    quiet = model.sample(10, n_mean_field=1, hidden_drift=0.0, random_state=0)
    noisy = model.sample(
        10, hidden_noise=1.0, n_mean_field=1, hidden_drift=0.0, random_state=0
    )
    assert not np.allclose(quiet, noisy)


# ------------------------------------------------------- reproducibility
def test_same_random_state_same_model_transform_and_samples():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    a = ConditionalRBM(8, order=2, n_iter=5, random_state=42).fit(X, sequence_ids=ids)
    b = ConditionalRBM(8, order=2, n_iter=5, random_state=42).fit(X, sequence_ids=ids)
    for name in (
        "components_",
        "intercept_hidden_",
        "intercept_visible_",
        "autoregressive_",
        "past_to_hidden_",
    ):
        assert_array_equal(getattr(a, name), getattr(b, name))
    assert_array_equal(
        a.transform(X, sequence_ids=ids), b.transform(X, sequence_ids=ids)
    )
    assert_array_equal(a.sample(10, n_sequences=3), b.sample(10, n_sequences=3))
    assert_array_equal(a.sample(10, random_state=5), b.sample(10, random_state=5))
    c = ConditionalRBM(8, order=2, n_iter=5, random_state=43).fit(X, sequence_ids=ids)
    assert not np.allclose(a.components_, c.components_)


def test_partial_fit_epochs_equal_fit():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    fitted = ConditionalRBM(6, order=2, n_iter=3, random_state=0).fit(
        X, sequence_ids=ids
    )
    stepped = ConditionalRBM(6, order=2, random_state=0)
    for _ in range(3):
        assert stepped.partial_fit(X, sequence_ids=ids) is stepped
    assert stepped.n_iter_ == 3
    assert_allclose(stepped.components_, fitted.components_)
    assert_allclose(stepped.autoregressive_, fitted.autoregressive_)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_dtype_is_preserved_end_to_end(dtype):
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(6, order=2, n_iter=3, random_state=0).fit(
        X.astype(dtype), sequence_ids=ids
    )
    for name in (
        "components_",
        "intercept_hidden_",
        "intercept_visible_",
        "autoregressive_",
        "past_to_hidden_",
        "seed_windows_",
    ):
        assert getattr(model, name).dtype == dtype
    assert model.transform(X.astype(dtype)).dtype == dtype
    assert model.score_samples(X.astype(dtype)).dtype == dtype
    assert model.sample(3).dtype == dtype


def test_float32_and_float64_learn_alike():
    """The two precisions draw different random bits, so compare what they learn."""
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    a = ConditionalRBM(10, order=2, n_iter=60, learning_rate=0.01, random_state=0).fit(
        X, sequence_ids=ids
    )
    b = ConditionalRBM(10, order=2, n_iter=60, learning_rate=0.01, random_state=0).fit(
        X.astype(np.float32), sequence_ids=ids
    )
    assert b.reconstruction_error_ == pytest.approx(a.reconstruction_error_, rel=0.2)
    assert b.score(X, sequence_ids=ids) == pytest.approx(
        a.score(X, sequence_ids=ids), rel=0.2
    )


# -------------------------------------------------------------- variants
def test_order_zero_is_a_plain_rbm():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(6, order=0, n_iter=3, random_state=0).fit(
        X, sequence_ids=ids
    )
    assert model.autoregressive_.shape == (0, 5, 5)
    expected = expit(X @ model.components_.T + model.intercept_hidden_)
    assert_allclose(model.transform(X), expected, rtol=1e-12)
    # row order does not matter without history
    perm = np.random.default_rng(0).permutation(len(X))
    assert_allclose(model.transform(X[perm]), expected[perm], rtol=1e-12)


def test_binary_visibles():
    rng = np.random.default_rng(0)
    X = (rng.random((120, 6)) < 0.3).astype(float)
    model = ConditionalRBM(
        5, order=1, visible_type="binary", n_iter=3, random_state=0
    ).fit(X)
    samples = model.sample(5, n_sequences=2)
    assert np.all((samples >= 0) & (samples <= 1))
    layer = model._layer
    hidden_bias = layer.hidden_bias + X[:-1] @ model.past_to_hidden_[0].T
    visible_bias = np.zeros((len(X) - 1, layer.n_features))  # unused by p(h | v)
    rbms = CRBMFrames(
        visible_bias, hidden_bias, layer.visible_std, layer.visible_units, layer.weights
    )
    H = rbms.hidden_probabilities(X[1:])
    assert_allclose(model.transform(X)[1:], H, rtol=1e-12)
    with pytest.raises(ValueError, match=r"binary.*\[0, 1\]"):
        ConditionalRBM(5, visible_type="binary").fit(X * 3)


def test_verbose_reports_progress(capsys):
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    ConditionalRBM(4, n_iter=4, verbose=2, random_state=0).fit(X, sequence_ids=ids)
    explanation, *lines = capsys.readouterr().out.strip().splitlines()
    assert explanation.startswith("[ConditionalRBM] one-step error: RMS error")
    assert "tends to die out" in explanation
    number = r"(\d+\.\d{4})"
    pattern = (
        rf"\[ConditionalRBM\] epoch (\d+): one-step error {number} \((better|"
        rf"WORSE) than repeating the previous frame: {number}\), reconstruction "
        rf"error {number}, time \d+\.\ds"
    )
    matches = [re.fullmatch(pattern, line) for line in lines]
    assert len(lines) == 2 and all(matches), lines
    assert [int(match[1]) for match in matches] == [2, 4]
    for match in matches:
        better = float(match[2]) < float(match[4])
        assert match[3] == ("better" if better else "WORSE")
    # repeating the previous frame: the RMS error of X[t - 1] for X[t] over
    # every trainable frame (those after the first order=3 of each sequence)
    frames = [t for t in range(3, len(X)) if ids[t - 3] == ids[t]]
    previous_frame = np.sqrt(np.mean(np.square(X[frames] - X[np.subtract(frames, 1)])))
    for match in matches:
        assert float(match[4]) == pytest.approx(previous_frame, abs=1e-4)


def test_divergence_raises_naming_the_learning_rate():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(
        8, order=2, learning_rate=50.0, momentum_delay=0, n_iter=50, random_state=0
    )
    with (
        np.errstate(all="ignore"),
        pytest.raises(TrainingDivergedError, match="learning_rate=50.0"),
    ):
        model.fit(X * 100, sequence_ids=ids)


def test_unscaled_data_gives_the_clear_error_and_no_overflow_warning(data_home):
    cmu = load_cmu35(data_home, subset="train")  # Euler angles in degrees
    model = ConditionalRBM(50, n_iter=20, random_state=0)
    with (
        warnings.catch_warnings(),
        np.errstate(all="warn"),
        pytest.raises(TrainingDivergedError, match="standardise the data"),
    ):
        warnings.simplefilter("error")
        model.fit(cmu.data, sequence_ids=cmu.sequence_ids)


def test_pipeline_routes_sequence_ids():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    direct = ConditionalRBM(6, order=2, n_iter=3, random_state=0)
    direct.fit(StandardScaler().fit_transform(X), sequence_ids=ids)
    with sklearn.config_context(enable_metadata_routing=True):
        pipe = make_pipeline(
            StandardScaler(), ConditionalRBM(6, order=2, n_iter=3, random_state=0)
        )
        pipe.fit(X, sequence_ids=ids)
        assert_allclose(pipe[-1].components_, direct.components_)
        assert_allclose(
            pipe.transform(X, sequence_ids=ids),
            direct.transform(StandardScaler().fit_transform(X), sequence_ids=ids),
        )
        assert pipe.score(X, sequence_ids=ids) == pytest.approx(
            direct.score(StandardScaler().fit_transform(X), sequence_ids=ids)
        )


def test_fit_transform_uses_sequence_ids():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(6, order=2, n_iter=3, random_state=0)
    assert_allclose(
        model.fit_transform(X, sequence_ids=ids), model.transform(X, sequence_ids=ids)
    )


# ------------------------------------------------------------ bad input
def test_bad_input_gets_clear_errors():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(4, order=2, n_iter=1, random_state=0)
    X_nan = X.copy()
    X_nan[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        model.fit(X_nan)
    with pytest.raises(ValueError, match="infinity"):
        model.fit(np.where(X > 0.9, np.inf, X))
    with pytest.raises(ValueError, match="one sequence id per row"):
        model.fit(X, sequence_ids=ids[:-1])
    with pytest.raises(ValueError, match="more than one contiguous run"):
        model.fit(X, sequence_ids=np.tile([0, 1], len(X) // 2))
    with pytest.raises(ValueError, match="past frames"):
        model.fit(X, sequence_ids=np.arange(len(X)) // 2)
    with pytest.raises(ValueError, match="2D array"):
        model.fit(X[:, 0])
    with pytest.raises(ValueError):
        model.fit(np.array([["a", "b"], ["c", "d"]]))
    with pytest.raises(TypeError, match="(?i)sparse"):
        model.fit(__import__("scipy.sparse").sparse.csr_matrix(X))
    with pytest.raises(TypeError, match="integers"):
        model.fit(X, sequence_ids=ids + 0.5)
    model.fit(X, sequence_ids=ids)
    with pytest.raises(ValueError, match="features"):
        model.transform(X[:, :3])
    with pytest.raises(ValueError, match="NaN"):
        model.sample(3, history=np.full((3, 5), np.nan))


def test_sample_n_jobs_gives_the_same_frames():
    X, ids = make_oscillations(n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(6, order=2, n_iter=2, random_state=0).fit(
        X, sequence_ids=ids
    )
    serial = model.sample(3, n_sequences=600, random_state=3)  # three blocks
    parallel = model.sample(3, n_sequences=600, random_state=3, n_jobs=2)
    assert serial.shape == (1800, 5)
    assert_array_equal(serial, parallel)
    # up to 256 sequences are one vectorised block, which n_jobs leaves alone
    assert_array_equal(
        model.sample(5, n_sequences=3, random_state=3),
        model.sample(5, n_sequences=3, random_state=3, n_jobs=2),
    )
