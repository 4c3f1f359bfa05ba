"""``init="autoregressive"``: the CRBM starts as a ridge AR model, pinned exactly.

With ``W = 0`` and no past-to-hidden weights the hidden units no longer
depend on the frame, so ``p(v_t | past) = N(c + sum_q A_q x_{t-q},
diag(s^2))`` exactly.  Right after the autoregressive start (training
switched off) that must be the ridge AR of scikit-learn's ``Ridge`` on the
same windows, with per-channel residual variances, computed here without
the package's code.
"""

import itertools

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from scipy.stats import norm
from sklearn.externals import array_api_compat
from sklearn.linear_model import Ridge

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import make_oscillations

ORDER, HIDDEN_ORDER = 2, 3


@pytest.fixture
def data():
    X, ids = make_oscillations(n_sequences=4, n_frames=40, n_features=3, random_state=0)
    return X, ids


def windows(X, ids, n_lags, order, sequences=None):
    """Every frame with ``n_lags`` past frames in its sequence: ``[x_{t-1}, ...]``, x_t."""
    rows, targets = [], []
    for k in np.unique(ids) if sequences is None else sequences:
        seq = X[ids == k]
        for t in range(n_lags, len(seq)):
            rows.append(np.concatenate([seq[t - q] for q in range(1, order + 1)]))
            targets.append(seq[t])
    return np.array(rows), np.array(targets)


def ridge(features, targets):
    """scikit-learn's Ridge (alpha 1): A of shape (order, d, d), intercept, residual."""
    d = targets.shape[1]
    fit = Ridge(alpha=1.0).fit(features, targets)
    coef = fit.coef_.reshape(d, -1, d).transpose(1, 0, 2)
    return coef, fit.intercept_, targets - fit.predict(features)


def no_training(monkeypatch):
    """Epochs that count but change nothing: fit leaves the start as it is."""

    def count(self, X, frames, n_epochs, *other_arguments, **options):
        self.n_iter_ += n_epochs

    monkeypatch.setattr(ConditionalRBM, "_train", count)


def started(monkeypatch, X, ids, **params):
    """A model fitted with training switched off: its parameters at the start."""
    no_training(monkeypatch)
    model = ConditionalRBM(
        3,
        order=ORDER,
        hidden_order=HIDDEN_ORDER,
        init="autoregressive",
        random_state=0,
        **params,
    )
    return model.fit(X, sequence_ids=ids)


@pytest.mark.parametrize("visible_variance", ["unit", "learned", "residual"])
def test_start_is_sklearn_ridge_on_the_training_windows(
    monkeypatch, data, visible_variance
):
    X, ids = data
    model = started(monkeypatch, X, ids, visible_variance=visible_variance)
    # the windows training uses: max(order, hidden_order) past frames
    coef, intercept, residual = ridge(*windows(X, ids, HIDDEN_ORDER, ORDER))
    assert_allclose(model.autoregressive_, coef, atol=1e-10)
    assert_allclose(model.intercept_visible_, intercept, atol=1e-10)
    expected = np.mean(residual**2, axis=0) if visible_variance != "unit" else 1.0
    assert_allclose(model.visible_variance_, np.broadcast_to(expected, (3,)))
    # the other groups keep the random start, drawn as init="random" draws it
    random = ConditionalRBM(
        3,
        order=ORDER,
        hidden_order=HIDDEN_ORDER,
        visible_variance=visible_variance,
        random_state=0,
    ).fit(X, sequence_ids=ids)
    for name in ("components_", "past_to_hidden_", "intercept_hidden_"):
        assert_array_equal(getattr(model, name), getattr(random, name))
    assert 0 < np.abs(model.components_).max() < 0.1


def test_with_zero_weights_the_exact_likelihood_is_the_ridge_gaussian(
    monkeypatch, data
):
    X, ids = data
    model = started(monkeypatch, X, ids, visible_variance="learned")
    model.components_ = np.zeros_like(model.components_)
    model.past_to_hidden_ = np.zeros_like(model.past_to_hidden_)
    result = model.estimate_log_likelihood(X, sequence_ids=ids, method="exact")
    coef, intercept, residual = ridge(*windows(X, ids, HIDDEN_ORDER, ORDER))
    std = np.sqrt(np.mean(residual**2, axis=0))
    for k in np.unique(ids):
        seq, got = X[ids == k], result.log_likelihood[ids == k]
        for t in range(HIDDEN_ORDER, len(seq)):
            mean = intercept + sum(coef[q - 1] @ seq[t - q] for q in (1, 2))
            expected = norm.logpdf(seq[t], loc=mean, scale=std).sum()
            assert got[t] == pytest.approx(expected, rel=1e-9, abs=1e-9)


def test_early_stopping_starts_from_the_training_sequences_only(monkeypatch, data):
    X, ids = data
    model = started(
        monkeypatch,
        X,
        ids,
        visible_variance="learned",
        early_stopping=True,
        validation_fraction=0.2,
        n_iter=10,
    )
    matches = []
    for held in itertools.combinations(np.unique(ids), 1):
        kept = [k for k in np.unique(ids) if k not in held]
        coef, _, _ = ridge(*windows(X, ids, HIDDEN_ORDER, ORDER, kept))
        matches.append(np.allclose(model.autoregressive_, coef, atol=1e-10))
    assert sum(matches) == 1


def test_reproducible_and_different_from_the_random_start(data):
    X, ids = data
    params = dict(order=ORDER, n_iter=5, visible_variance="learned", random_state=3)
    first = ConditionalRBM(4, init="autoregressive", **params).fit(X, sequence_ids=ids)
    again = ConditionalRBM(4, init="autoregressive", **params).fit(X, sequence_ids=ids)
    random = ConditionalRBM(4, **params).fit(X, sequence_ids=ids)
    assert_array_equal(first._layer.flat, again._layer.flat)
    assert not np.allclose(first.autoregressive_, random.autoregressive_, atol=0.05)


def test_partial_fit_starts_from_its_first_batch(monkeypatch, data):
    X, ids = data
    no_training(monkeypatch)
    model = ConditionalRBM(3, order=ORDER, init="autoregressive")
    first = ids < 2
    model.partial_fit(X[first], sequence_ids=ids[first])
    coef, intercept, _ = ridge(*windows(X, ids, ORDER, ORDER, [0, 1]))
    assert_allclose(model.autoregressive_, coef, atol=1e-10)
    model.partial_fit(X[~first], sequence_ids=ids[~first])  # not restarted
    assert_allclose(model.autoregressive_, coef, atol=1e-10)


def test_residual_variances_stay_as_the_ridge_residuals_left_them(data):
    """``visible_variance="residual"``: set from the ridge AR, never trained."""
    X, ids = data
    model = ConditionalRBM(
        3, order=ORDER, hidden_order=HIDDEN_ORDER, visible_variance="residual"
    )
    model.set_params(n_iter=20, random_state=0).fit(X, sequence_ids=ids)
    _, _, residual = ridge(*windows(X, ids, HIDDEN_ORDER, ORDER))
    assert_allclose(model.visible_variance_, np.mean(residual**2, axis=0))
    # with init="random" only the variances come from the AR
    random = ConditionalRBM(3, order=ORDER, hidden_order=HIDDEN_ORDER, n_iter=20)
    random.set_params(random_state=0).fit(X, sequence_ids=ids)
    assert np.abs(model.autoregressive_ - random.autoregressive_).max() > 0
    assert np.abs(model.autoregressive_).max() < 0.5


def test_binary_visibles_cannot_start_autoregressive():
    X = (np.random.default_rng(0).random((30, 3)) > 0.5).astype(float)
    model = ConditionalRBM(3, visible_type="binary", init="autoregressive")
    with pytest.raises(ValueError, match="init='autoregressive'.*Gaussian"):
        model.fit(X)


def test_start_on_another_namespace_is_the_numpy_start(
    monkeypatch, data, other_namespace
):
    xp = other_namespace
    X, ids = data
    expected = started(monkeypatch, X, ids, visible_variance="learned")
    with sklearn.config_context(array_api_dispatch=True):
        model = started(monkeypatch, xp.asarray(X), ids, visible_variance="learned")
        for name in ("autoregressive_", "intercept_visible_", "visible_variance_"):
            got = getattr(model, name)
            assert array_api_compat.array_namespace(got) is (
                array_api_compat.array_namespace(xp.asarray(X))
            )
            assert_allclose(np.asarray(got), getattr(expected, name), rtol=1e-12)
