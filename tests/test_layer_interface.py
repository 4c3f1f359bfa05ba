"""A new kind of layer is one class and its estimator, in this module alone.

The layer below is a CRBM whose hidden biases also take a one-hot context
(a label per frame) through a weight matrix ``C``: ``b_hat = b + B x_past
+ C y``.  Written against the layer interface (:mod:`sklearn_crbm._layer`)
and the style base class, without a change to the training loop, on-line
sampling, the likelihood or the imputer, it trains, generates, scores
exactly (against a sum over hidden states written from its energy here)
and fills in, with the style given or inferred.
"""

import itertools

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import logsumexp

from sklearn_crbm._crbm_layer import CRBM_GROUPS, CRBMLayer
from sklearn_crbm._parameters import ParameterGroup, small_normal
from sklearn_crbm._style_model import BaseStyleModel
from sklearn_crbm.datasets import make_styled_oscillations
from sklearn_crbm.impute import CRBMImputer

CONTEXT_GROUPS = CRBM_GROUPS + (
    ParameterGroup(
        "label_weights",
        lambda p: (p.n_components, p.n_classes),
        lambda p, rng: small_normal(rng, (p.n_components, p.n_classes), p.dtype),
        decayed=True,
    ),
)


class ContextLayer(CRBMLayer):
    """A CRBM layer whose hidden units also see the frame's label weights."""

    groups = CONTEXT_GROUPS

    def __init__(self, n_features, n_components, n_classes, order, dtype):
        self.n_classes = n_classes
        super().__init__(n_features, n_components, order, order, "gaussian", dtype)

    def frame_rbms(self, history, context=None, *, out=None):
        rbms = super().frame_rbms(history, out=out)
        rbms.hidden_bias += self.ops.matmul(context, self.label_weights.T)
        return rbms

    def conditioner(self):
        return self.frame_rbms

    def cd_statistics(self, visible, history, context, *args, out, **kwargs):
        out, error = super().cd_statistics(
            visible, history, context, *args, out=out, **kwargs
        )
        n = visible.shape[0]
        hidden_delta = kwargs["workspace"].delta[:n, self.n_features :]  # scaled
        out.label_weights[...] = self.ops.matmul(hidden_delta.T, context)
        return out, error


class ContextCRBM(BaseStyleModel):
    """The estimator of a ContextLayer: a style per frame, one-hot."""

    def __init__(
        self,
        n_components=8,
        *,
        order=2,
        learning_rate=1e-2,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=2e-4,
        cd_steps=1,
        batch_size=50,
        batching="shuffled",
        history_noise=0.0,
        history_noise_fraction=1.0,
        average_fraction=0.0,
        n_iter=100,
        n_gibbs=30,
        priors=None,
        ais_steps=50,
        ais_chains=2,
        early_stopping=False,
        validation_fraction=0.1,
        n_iter_no_change=50,
        validation_interval=10,
        tol=1e-3,
        random_state=None,
        verbose=0,
    ):
        self.n_components = n_components
        self.order = order
        self.learning_rate = learning_rate
        self.momentum = momentum
        self.momentum_delay = momentum_delay
        self.weight_decay = weight_decay
        self.cd_steps = cd_steps
        self.batch_size = batch_size
        self.batching = batching
        self.history_noise = history_noise
        self.history_noise_fraction = history_noise_fraction
        self.average_fraction = average_fraction
        self.n_iter = n_iter
        self.n_gibbs = n_gibbs
        self.priors = priors
        self.ais_steps = ais_steps
        self.ais_chains = ais_chains
        self.early_stopping = early_stopping
        self.validation_fraction = validation_fraction
        self.n_iter_no_change = n_iter_no_change
        self.validation_interval = validation_interval
        self.tol = tol
        self.random_state = random_state
        self.verbose = verbose

    @property
    def _hidden_order(self):
        return self.order

    def _new_layer(self, n_features, n_context, dtype):
        return ContextLayer(n_features, self.n_components, n_context, self.order, dtype)


def styled_data(random_state=0, switching=True, n_sequences=8):
    return make_styled_oscillations(
        n_sequences, switching=switching, random_state=random_state
    )


@pytest.fixture(scope="module")
def fitted():
    X, ids, styles = styled_data()
    return ContextCRBM(random_state=0).fit(X, styles, sequence_ids=ids)


def test_it_trains(fitted):
    layer = fitted._layer
    assert fitted.n_iter_ == 100 and layer.is_finite()
    assert_array_equal(fitted.classes_, ["high", "low"])
    # the context weights moved from their small start, and apart by style
    difference = layer.label_weights[:, 0] - layer.label_weights[:, 1]
    assert np.abs(difference).max() > 0.1
    X, ids, styles = styled_data(random_state=1)
    # one-step predictions given the right style beat those given the wrong one
    right = fitted.predict_next(X, style=styles, sequence_ids=ids)
    wrong = fitted.predict_next(
        X, style=np.where(styles == "low", "high", "low"), sequence_ids=ids
    )
    assert np.mean((X - right)[:, 0] ** 2) < 0.25 * np.mean((X - wrong)[:, 0] ** 2)
    X, ids, styles = styled_data(random_state=1, switching=False)
    assert_array_equal(fitted.predict(X, sequence_ids=ids), styles)


def test_it_generates_each_style(fitted):
    X, ids, styles = styled_data()
    seed = X[:5]
    means = {
        style: fitted.sample(80, history=seed, style=style, random_state=0)[:, 0].mean()
        for style in ("low", "high")
    }
    assert means["high"] > 0.5 and means["low"] < -0.5
    blend = fitted.sample(
        80, history=seed, style=np.tile([0.5, 0.5], (80, 1)), random_state=0
    )
    assert np.all(np.isfinite(blend))


def exact_log_likelihood(layer, X, ids, labels):
    """``log p(x_t | past, y_t)`` summed over the hidden states, from the energy.

    ``E(v, h) = ||v - c_hat||^2 / 2 - (b + B p + C y) . h - v . W.T h``;
    the visibles integrate in closed form for each ``h``.
    """
    d, order = layer.n_features, layer.order
    W, C = layer.weights, layer.label_weights
    A, B = layer.dynamic[:d], layer.dynamic[d:]
    states = np.array(list(itertools.product([0, 1], repeat=layer.n_components)))
    result = []
    for t in range(len(X)):
        start = np.flatnonzero(ids == ids[t])[0]
        past = np.concatenate([X[max(t - q, start)] for q in range(1, order + 1)])
        c_hat = layer.visible_bias + A @ past
        b_hat = layer.hidden_bias + B @ past + C @ labels[t]
        u = states @ W  # W.T h for every h
        # -E(v, h) = -||v - c_hat - u||^2 / 2 + b_hat.h + c_hat.u + ||u||^2 / 2
        v = X[t]
        joint = -0.5 * np.sum((v - c_hat - u) ** 2, axis=1) + states @ b_hat
        joint += u @ c_hat + 0.5 * np.sum(u**2, axis=1)
        log_z = logsumexp(states @ b_hat + u @ c_hat + 0.5 * np.sum(u**2, axis=1))
        log_z += 0.5 * d * np.log(2 * np.pi)
        result.append(logsumexp(joint) - log_z)
    return np.array(result)


def test_it_scores_exactly():
    X, ids, styles = styled_data()
    model = ContextCRBM(4, n_iter=20, random_state=0).fit(X, styles, sequence_ids=ids)
    rng = np.random.default_rng(0)
    layer = model._layer
    layer.label_weights[...] = rng.standard_normal(layer.label_weights.shape)
    labels = np.eye(2)[np.searchsorted(model.classes_, styles)]
    expected = exact_log_likelihood(layer, X, ids, labels)
    got = model.score_samples(X, style=styles, sequence_ids=ids)
    assert_allclose(got, expected, rtol=1e-9, atol=1e-9)
    # the style unknown: each frame's mixture over the styles, weighted by
    # their posterior given the frames before it in its sequence
    X, ids, styles = styled_data(random_state=1, switching=False)
    per_style = np.stack(
        [model.score_samples(X, style=s, sequence_ids=ids) for s in model.classes_],
        axis=1,
    )
    mixture = model.score_samples(X, sequence_ids=ids)
    for sequence in np.unique(ids):
        rows = np.flatnonzero(ids == sequence)
        evidence = np.cumsum(per_style[rows[model.order :]], axis=0)
        log_post = np.vstack([np.zeros((model.order + 1, 2)), evidence[:-1]])
        log_post -= logsumexp(log_post, axis=1, keepdims=True)
        expected = logsumexp(log_post + per_style[rows], axis=1)
        assert_allclose(mixture[rows], expected, rtol=1e-9, atol=1e-9)


def test_it_fills_in_with_the_style_given_or_inferred(fitted):
    X_train, ids_train, styles_train = styled_data()
    X, ids, styles = styled_data(random_state=1, switching=False)
    one = ids == 1  # a "high" sequence
    X_missing = X[one].copy()
    X_missing[30:, 0] = np.nan
    imputer = CRBMImputer(
        fitted, n_particles=10, offset_shrinkage=None, random_state=0
    ).fit(X_train, styles_train, sequence_ids=ids_train)
    errors = {}
    for style in ("high", "low", None):
        filled = imputer.transform(X_missing, style=style)
        assert_array_equal(filled[:, 1:], X[one][:, 1:])
        errors[style] = np.mean((filled[30:, 0] - X[one][30:, 0]) ** 2)
    assert errors["high"] < 0.1 * errors["low"]
    assert errors[None] < 0.1 * errors["low"]
