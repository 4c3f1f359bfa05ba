"""``centering=True``: training in centred coordinates, pinned exactly.

In centred coordinates the hidden units see the residual against the dynamic
visible bias, ``b' + B' x_past + W ((v - c_hat) / s)``.  That is the same
model as the standard form with ``b = b' - W (c / s)`` and ``B_q = B'_q - W
diag(1 / s) A_q``; only the gradient steps differ.  Below: the reparametrisation
on tiny models, the centred statistics against the chain rule applied to the
standard ones (same random draws) and against the centred energy written out,
the estimator's behaviour, and the gain on the real data that motivates it.
"""

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import expit

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_oscillations
from sklearn_crbm.layers._crbm import CRBMLayer, shift_centred
from sklearn_crbm.preprocessing import make_motion_preprocessor

N_FEATURES, N_COMPONENTS, ORDER = 3, 4, 2
VARIANCES = ["unit", "fixed", "learned"]


def tiny_params(variance, hidden_order=ORDER, seed=0):
    rng = np.random.default_rng(seed)
    params = CRBMLayer(
        N_FEATURES,
        N_COMPONENTS,
        ORDER,
        hidden_order,
        "gaussian",
        np.float64,
        learned_variance=variance == "learned",
        fixed_variance=variance == "fixed",
    )
    params.weights[...] = rng.normal(size=params.weights.shape)
    params.hidden_bias[...] = rng.normal(size=N_COMPONENTS)
    params.visible_bias[...] = rng.normal(size=N_FEATURES)
    params.dynamic[...] = 0.5 * rng.normal(size=params.dynamic.shape)
    params.dynamic[...] *= params.dynamic_mask()
    if variance != "unit":
        params.log_visible_variance[...] = rng.uniform(-2.0, 0.5, size=N_FEATURES)
    return params


def std_of(params):
    return np.sqrt(params.visible_variance)


def centred_layer(params):
    """``params`` moved to centred coordinates, as a layer that trains in them."""
    layer = shift_centred(params.copy(), 1)
    layer.centered = True
    return layer


def cd_statistics(params, visible, history, cd_steps, rng, *, scale):
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


@pytest.mark.parametrize("hidden_order", [ORDER, ORDER + 1])
@pytest.mark.parametrize("variance", VARIANCES)
def test_centred_coordinates_are_the_same_model(variance, hidden_order):
    params = tiny_params(variance, hidden_order)
    centred = shift_centred(params.copy(), 1)
    rng = np.random.default_rng(1)
    visible = rng.normal(size=(6, N_FEATURES))
    history = rng.normal(size=(6, hidden_order * N_FEATURES))
    s = std_of(params)
    c_hat, b_hat = params.dynamic_biases(history)
    c_centred, b_centred = centred.dynamic_biases(history)
    assert_allclose(c_centred, c_hat, rtol=1e-12)  # the visible side is untouched
    standard_input = b_hat + (visible / s) @ params.weights.T
    centred_input = b_centred + ((visible - c_hat) / s) @ centred.weights.T
    assert_allclose(centred_input, standard_input, rtol=1e-10, atol=1e-12)
    back = shift_centred(centred, -1)
    assert_allclose(back.flat, params.flat, rtol=1e-12, atol=1e-12)


def chain_rule(params, g):
    """Centred statistics from the standard ones ``g`` of the standard model ``params``.

    ``g`` follows the package's scaling: the visible bias and autoregressive
    statistics are gradients times ``s^2``, the others gradients.
    """
    n = N_FEATURES
    width = ORDER * n
    s = std_of(params)
    W = params.weights
    A = params.dynamic[:n, :width]  # (n, order * n)
    g_hidden = g.hidden_bias
    g_past = g.dynamic[n:, :width]  # the lags that A feeds
    expected = {
        "weights": g.weights
        - np.outer(g_hidden, params.visible_bias / s)
        - (g_past @ A.T) / s,
        "hidden_bias": g_hidden,
        "visible_bias": g.visible_bias - s * (W.T @ g_hidden),
        "log_visible_variance": g.log_visible_variance,
    }
    dynamic = g.dynamic.copy()
    dynamic[:n, :width] -= s[:, None] * (W.T @ g_past)
    expected["dynamic"] = dynamic
    if params.learned_variance:
        expected["log_visible_variance"] = g.log_visible_variance + (
            params.visible_bias * (W.T @ g_hidden) + np.sum((W.T @ g_past) * A, axis=1)
        ) / (2 * s)
    return expected


@pytest.mark.parametrize("cd_steps", [1, 2])
@pytest.mark.parametrize("hidden_order", [ORDER, ORDER + 1])
@pytest.mark.parametrize("variance", VARIANCES)
def test_centred_statistics_are_the_chain_rule_of_the_standard_ones(
    variance, hidden_order, cd_steps
):
    params = tiny_params(variance, hidden_order)
    rng = np.random.default_rng(2)
    n = 5
    visible = rng.normal(size=(n, N_FEATURES))
    history = rng.normal(size=(n, hidden_order * N_FEATURES))

    def statistics(model):
        return cd_statistics(
            model,
            visible.copy(),
            history,
            cd_steps,
            np.random.default_rng(3),  # the same draws: the same hidden states
            scale=0.1,
        )

    standard, error = statistics(params)
    centred, centred_error = statistics(centred_layer(params))
    assert centred_error == pytest.approx(error, rel=1e-12)
    for name, value in chain_rule(params, standard).items():
        assert_allclose(getattr(centred, name), value, rtol=1e-9, atol=1e-12)


def test_one_centred_update_against_the_equations():
    """CD-1 of the centred energy, written out (fixed variances)."""
    params = tiny_params("fixed")
    centred = centred_layer(params)
    rng = np.random.default_rng(4)
    n = 5
    visible = rng.normal(size=(n, N_FEATURES))
    history = rng.normal(size=(n, ORDER * N_FEATURES))
    scale = 0.1
    gradients, _ = cd_statistics(
        centred, visible.copy(), history, 1, np.random.default_rng(7), scale=scale
    )
    draws = np.random.default_rng(7)
    W, s = centred.weights, std_of(centred)
    c = centred.visible_bias + history @ centred.dynamic[:N_FEATURES].T
    b = centred.hidden_bias + history @ centred.dynamic[N_FEATURES:].T
    h0 = (draws.random((n, N_COMPONENTS)) < expit(b + ((visible - c) / s) @ W.T)) * 1
    reconstruction = c + s * (h0 @ W)
    p = expit(b + ((reconstruction - c) / s) @ W.T)
    # -dE/dc of E = sum (v - c)^2 / (2 s^2) - b.h - ((v - c) / s).(W.T h), times s^2
    visible_delta = (visible - s * (h0 @ W)) - (reconstruction - s * (p @ W))
    expected = {
        "weights": h0.T @ ((visible - c) / s) - p.T @ ((reconstruction - c) / s),
        "hidden_bias": (h0 - p).sum(axis=0),
        "visible_bias": visible_delta.sum(axis=0),
        "dynamic": np.hstack([visible_delta, h0 - p]).T @ history,
    }
    for name, value in expected.items():
        assert_allclose(getattr(gradients, name), scale * value, rtol=1e-10)
    assert_array_equal(gradients.log_visible_variance, 0)


@pytest.fixture
def data():
    return make_oscillations(n_sequences=4, n_frames=40, n_features=3, random_state=0)


def test_centering_changes_training_not_the_model_form(data):
    X, ids = data
    params = dict(n_components=6, order=2, random_state=0, init="autoregressive")
    centred = ConditionalRBM(centering=True, n_iter=4, **params).fit(
        X, sequence_ids=ids
    )
    plain = ConditionalRBM(n_iter=4, **params).fit(X, sequence_ids=ids)
    assert not np.allclose(centred.past_to_hidden_, plain.past_to_hidden_)
    # the fitted model is in the standard form: its hidden units see v itself
    history = np.hstack([X[1:-1], X[:-2]])
    hidden = centred.transform(X, sequence_ids=np.zeros(len(X)))[2:]
    expected = expit(
        centred.intercept_hidden_
        + history @ np.hstack(list(centred.past_to_hidden_)).T
        + X[2:] @ centred.components_.T
    )
    assert_allclose(hidden, expected, rtol=1e-10)


def test_epochs_of_partial_fit_continue_as_fit_does(data):
    X, ids = data
    params = dict(
        n_components=6,
        order=2,
        random_state=0,
        centering=True,
        visible_variance="residual",
    )
    fitted = ConditionalRBM(n_iter=3, **params).fit(X, sequence_ids=ids)
    stepped = ConditionalRBM(**params)
    for _ in range(3):
        stepped.partial_fit(X, sequence_ids=ids)
    for name in ("components_", "past_to_hidden_", "intercept_hidden_"):
        assert_allclose(getattr(stepped, name), getattr(fitted, name), rtol=1e-9)
    again = ConditionalRBM(n_iter=3, **params).fit(X, sequence_ids=ids)
    assert_array_equal(again.past_to_hidden_, fitted.past_to_hidden_)


@pytest.mark.parametrize(
    "params, match",
    [
        (dict(visible_type="binary", centering=True), "needs Gaussian visibles"),
        (dict(visible_type="binary", visible_variance="residual"), "no variance"),
        (dict(order=3, hidden_order=1, centering=True), "hidden_order >= order"),
    ],
)
def test_settings_centering_cannot_train_say_so(params, match):
    X = (np.random.default_rng(0).random((40, 3)) > 0.5).astype(float)
    with pytest.raises(ValueError, match=match):
        ConditionalRBM(4, n_iter=2, **params).fit(X)


def test_centred_training_models_held_out_motion_better(data_home, one_blas_thread):
    """CMU 35, the AR's variances fixed, 40 epochs from the ridge AR.

    Held out: the walk and jog of the paper's fill-in split.  Measured with
    ``benchmarks/likelihood_baselines.py``: about 7 nats per frame more with
    centering on this split (see the README).
    """
    cmu = load_cmu35(data_home)
    names = list(cmu.sequence_names)
    held = np.isin(cmu.sequence_ids, [names.index("35_29"), names.index("35_18")])
    ids = cmu.sequence_ids
    with sklearn.config_context(enable_metadata_routing=True):
        encode = make_motion_preprocessor(cmu.skeleton, reference="rest", roll="taylor")
        X_train = encode.fit_transform(cmu.data[~held], sequence_ids=ids[~held])
        X_test = encode.transform(cmu.data[held], sequence_ids=ids[held])
    scores = {}
    for centering in (False, True):
        model = ConditionalRBM(
            100,
            init="autoregressive",
            visible_variance="residual",
            centering=centering,
            history_noise=0,
            n_iter=40,
            random_state=0,
        ).fit(X_train.astype(np.float32), sequence_ids=ids[~held])
        scores[centering] = model.score(
            X_test.astype(np.float32), sequence_ids=ids[held]
        )
    assert scores[True] > scores[False] + 3
