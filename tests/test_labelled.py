"""Tests of LabelledCRBM: style labels as additive inputs to the dynamic biases."""

import itertools

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import logsumexp

from sklearn_crbm import CRBMImputer, LabelledCRBM
from sklearn_crbm.datasets import make_styled_oscillations


def styled_data(random_state=0, switching=True, n_sequences=8):
    return make_styled_oscillations(
        n_sequences, switching=switching, random_state=random_state
    )


@pytest.fixture(scope="module")
def fitted():
    X, ids, styles = styled_data()
    model = LabelledCRBM(8, order=2, n_iter=100, learning_rate=1e-2, random_state=0)
    return model.fit(X, styles, sequence_ids=ids)


def test_the_labels_move_the_biases(fitted):
    high, low = np.searchsorted(fitted.classes_, ["high", "low"])
    shift = fitted.label_to_visible_[0, high] - fitted.label_to_visible_[0, low]
    assert shift > 1.0  # channel 0 sits 2 higher in style "high"
    assert fitted.label_to_hidden_.shape == (8, 2)
    X, ids, styles = styled_data(random_state=1, switching=False)
    assert_array_equal(fitted.predict(X, sequence_ids=ids), styles)
    seed = X[:5]
    for style, sign in (("high", 1), ("low", -1)):
        frames = fitted.sample(50, history=seed, style=style, random_state=0)
        assert sign * frames[:, 0].mean() > 0.5


def test_score_samples_is_exact_for_a_tiny_model():
    X, ids, styles = styled_data()
    model = LabelledCRBM(4, order=1, n_iter=3, random_state=0)
    model.fit(X, styles, sequence_ids=ids)
    rng = np.random.default_rng(0)
    layer = model._layer
    layer.flat[...] = 0.3 * rng.standard_normal(layer.flat.shape)
    layer.dynamic *= layer.dynamic_mask()
    weights = rng.dirichlet([1, 1], size=len(X))
    d = layer.n_features
    states = np.array(list(itertools.product([0, 1], repeat=4)))
    expected = []
    for t in range(len(X)):
        start = np.flatnonzero(ids == ids[t])[0]
        past = X[max(t - 1, start)]
        c_hat = layer.visible_bias + layer.dynamic[:d] @ past
        c_hat = c_hat + layer.context_weights[:d] @ weights[t]
        b_hat = layer.hidden_bias + layer.dynamic[d:] @ past
        b_hat = b_hat + layer.context_weights[d:] @ weights[t]
        u = states @ layer.weights
        joint = -0.5 * np.sum((X[t] - c_hat - u) ** 2, axis=1) + states @ b_hat
        joint += u @ c_hat + 0.5 * np.sum(u**2, axis=1)
        log_z = logsumexp(states @ b_hat + u @ c_hat + 0.5 * np.sum(u**2, axis=1))
        expected.append(logsumexp(joint) - log_z - 0.5 * d * np.log(2 * np.pi))
    got = model.score_samples(X, style=weights, sequence_ids=ids)
    assert_allclose(got, expected, rtol=1e-9, atol=1e-9)


def test_imputer_fills_in_with_the_style_given_or_inferred(fitted):
    X_train, ids_train, styles_train = styled_data()
    X, ids, _ = styled_data(random_state=1, switching=False)
    one = ids == 1  # a "high" sequence
    X_missing = X[one].copy()
    X_missing[30:, 0] = np.nan
    imputer = CRBMImputer(
        fitted, n_particles=10, offset_shrinkage=None, random_state=0
    ).fit(X_train, styles_train, sequence_ids=ids_train)
    errors = {
        style: np.mean(
            (imputer.transform(X_missing, style=style)[30:, 0] - X[one][30:, 0]) ** 2
        )
        for style in ("high", "low", None)
    }
    assert errors["high"] < 0.1 * errors["low"]
    assert errors[None] < 0.1 * errors["low"]


def test_frames_end_with_ten_mean_field_steps_and_a_drift(fitted):
    """As ConditionalRBM: ten mean-field steps, a hidden drift of 0.3."""
    seed = styled_data(random_state=1, switching=False)[0][:5]
    given = dict(history=seed, style="high", random_state=0)
    default = fitted.sample(30, **given)
    settings = dict(n_mean_field=10, hidden_drift=0.3)
    assert_array_equal(default, fitted.sample(30, **settings, **given))
    assert not np.allclose(default, fitted.sample(30, n_mean_field=1, **given))
    assert not np.allclose(default, fitted.sample(30, hidden_drift=0.0, **given))
