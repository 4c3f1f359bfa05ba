"""A new kind of layer is one class and its estimator, in this module alone.

The layer below is written against the layer interface
(:class:`~sklearn_crbm.layers.ConditionalLayer`), not derived from the CRBM
layer: Gaussian visibles of unit variance ``v``, binary hidden units ``h``,
the past ``p`` (``order`` frames) and a real-valued per-frame context ``y``
(control signals), with

    c_hat = c + A p + C_v y        b_hat = b + B p + C_h y
    E(v, h) = ||v - c_hat||^2 / 2 - b_hat . h - v . (W.T h)

Without a change to the training loop, on-line sampling, the likelihood or
the imputer, it trains, generates, scores exactly (against a sum over the
hidden states written from its energy here) and fills in, and each of them
follows the context: the tests fail if any drops it.
"""

import itertools
import warnings
from numbers import Integral

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.special import logsumexp
from sklearn.frozen import FrozenEstimator
from sklearn.utils._param_validation import Interval

from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.exceptions import GenerationWarning
from sklearn_crbm.impute import CRBMImputer
from sklearn_crbm.layers import (
    ConditionalLayer,
    FrameRBMs,
    GaussianUnits,
    ParameterGroup,
)
from sklearn_crbm.layers._parameters import small_normal
from sklearn_crbm.models._one_layer import BaseLayerModel


def _group(name, shape, decayed=True):
    def initial(layer, rng):
        value = small_normal(rng, shape(layer), layer.dtype)
        return value if decayed else 0 * value

    return ParameterGroup(name, shape, initial, decayed=decayed)


def _past(layer):
    return layer.n_lags * layer.n_features


class ToyFrames(FrameRBMs):
    """Every frame's RBM has the layer's weights ``W``."""

    _shared_arrays = ("visible_std", "weights")

    def __init__(self, visible_bias, hidden_bias, weights):
        super().__init__(visible_bias, hidden_bias, None, GaussianUnits())
        self.weights = weights

    @property
    def shared_weights(self):
        return self.weights

    def interaction_input(self, visible, out=None):
        return self.ops.matmul(visible, self.weights.T, out=out)

    def interaction_field(self, hidden, out=None):
        return self.ops.matmul(hidden, self.weights, out=out)


class ToyLayer(ConditionalLayer):
    """The layer of the module docstring."""

    groups = (
        _group("weights", lambda p: (p.n_components, p.n_features)),
        _group("past_visible", lambda p: (p.n_features, _past(p))),
        _group("past_hidden", lambda p: (p.n_components, _past(p))),
        _group("context_visible", lambda p: (p.n_features, p.n_context)),
        _group("context_hidden", lambda p: (p.n_components, p.n_context)),
        _group("hidden_bias", lambda p: (p.n_components,), decayed=False),
        _group("visible_bias", lambda p: (p.n_features,), decayed=False),
    )

    def __init__(self, n_features, n_components, n_lags, n_context, dtype):
        self.n_features = n_features
        self.n_components = n_components
        self.n_lags = n_lags
        self.n_context = n_context
        self._allocate(dtype)

    def build_frame_rbms(self, invariants, history, context=None, *, out=None):
        ops = self.ops
        visible_bias = ops.matmul(history, self.past_visible.T)
        visible_bias += ops.matmul(context, self.context_visible.T)
        visible_bias += self.visible_bias
        hidden_bias = ops.matmul(history, self.past_hidden.T)
        hidden_bias += ops.matmul(context, self.context_hidden.T)
        hidden_bias += self.hidden_bias
        return ToyFrames(visible_bias, hidden_bias, self.weights)

    def cd_statistics(
        self, visible, history, context, cd_steps, rng, *, out, scale, workspace
    ):
        """CD-1: hidden probabilities in the statistics, sampled states drive."""
        ops = self.ops
        rbms = self.frame_rbms(history, context)
        positive = rbms.hidden_probabilities(visible)
        states = ops.astype(rng.random(positive.shape) < positive, visible.dtype)
        reconstruction = rbms.visible_mean(states)
        negative = rbms.hidden_probabilities(reconstruction)
        visible_delta = (visible - reconstruction) * scale
        hidden_delta = (positive - negative) * scale
        out.weights[...] = scale * (
            ops.matmul(positive.T, visible) - ops.matmul(negative.T, reconstruction)
        )
        out.past_visible[...] = ops.matmul(visible_delta.T, history)
        out.past_hidden[...] = ops.matmul(hidden_delta.T, history)
        out.context_visible[...] = ops.matmul(visible_delta.T, context)
        out.context_hidden[...] = ops.matmul(hidden_delta.T, context)
        out.visible_bias[...] = ops.sum(visible_delta, axis=0)
        out.hidden_bias[...] = ops.sum(hidden_delta, axis=0)
        error = visible - reconstruction
        return out, float(ops.sum(error * error))


class ToyModel(BaseLayerModel):
    """The estimator of a :class:`ToyLayer`."""

    _parameter_constraints: dict = {
        **BaseLayerModel._parameter_constraints,
        "n_components": [Interval(Integral, 1, None, closed="left")],
        "order": [Interval(Integral, 0, None, closed="left")],
    }

    def __init__(
        self,
        n_components=8,
        *,
        order=1,
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
        ais_steps=50,
        ais_chains=2,
        early_stopping=False,
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
        self.ais_steps = ais_steps
        self.ais_chains = ais_chains
        self.early_stopping = early_stopping
        self.random_state = random_state
        self.verbose = verbose

    def _new_layer(self, n_features, n_context, dtype):
        return ToyLayer(n_features, self.n_components, self.order, n_context, dtype)


def driven_data(random_state=0):
    """Oscillations whose first channel's level follows the context's sign."""
    X, ids = make_oscillations(
        n_sequences=6, n_frames=60, n_features=4, random_state=random_state
    )
    sign = np.where(ids % 2 == 0, 1.0, -1.0)
    context = np.column_stack([sign, np.linspace(-1, 1, len(X))])
    X = X.copy()
    X[:, 0] += 1.5 * sign
    return X, ids, context


@pytest.fixture(scope="module")
def fitted():
    X, ids, context = driven_data()
    return ToyModel(random_state=0).fit(X, sequence_ids=ids, context=context)


def test_it_trains_on_the_context(fitted):
    layer = fitted._layer
    assert fitted.n_iter_ == 100 and layer.is_finite()
    assert fitted.n_context_ == 2 and fitted.history_length == 1
    assert np.abs(layer.context_visible[0, 0]) > 0.2  # moved from its 0.01 start
    X, ids, context = driven_data(random_state=1)
    right = fitted.predict_next(X, sequence_ids=ids, context=context)
    wrong = fitted.predict_next(X, sequence_ids=ids, context=-context)
    assert np.mean((X - right)[:, 0] ** 2) < 0.2 * np.mean((X - wrong)[:, 0] ** 2)


def test_it_generates_what_the_context_asks(fitted):
    X, ids, _ = driven_data()
    seed = X[ids == 0][:5]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GenerationWarning)
        levels = {
            sign: fitted.sample(
                60, history=seed, context=[[sign, 0.0]], random_state=0
            )[20:, 0].mean()
            for sign in (1.0, -1.0)
        }
        # a context that changes over the frames steers the sequence
        ramp = np.column_stack([np.linspace(-1, 1, 60), np.zeros(60)])
        steered = fitted.sample(60, history=seed, context=ramp, random_state=0)
    assert levels[1.0] - levels[-1.0] > 2
    assert steered[-15:, 0].mean() - steered[5:20, 0].mean() > 1


def exact_log_likelihood(layer, X, ids, context):
    """``log p(x_t | past, y_t)`` summed over the hidden states, from the energy.

    The visibles integrate in closed form for each ``h``: with ``u = W.T h``,
    ``-E(v, h) = -||v - c_hat - u||^2 / 2 + b_hat . h + c_hat . u +
    ||u||^2 / 2``.
    """
    d = layer.n_features
    states = np.array(list(itertools.product([0, 1], repeat=layer.n_components)))
    u = states @ layer.weights
    result = []
    for t in range(len(X)):
        start = np.flatnonzero(ids == ids[t])[0]
        past = np.concatenate(
            [X[max(t - q, start)] for q in range(1, layer.n_lags + 1)]
        )
        c_hat = layer.visible_bias + layer.past_visible @ past
        c_hat = c_hat + layer.context_visible @ context[t]
        b_hat = layer.hidden_bias + layer.past_hidden @ past
        b_hat = b_hat + layer.context_hidden @ context[t]
        shared = states @ b_hat + u @ c_hat + 0.5 * np.sum(u**2, axis=1)
        joint = shared - 0.5 * np.sum((X[t] - c_hat - u) ** 2, axis=1)
        log_z = logsumexp(shared) + 0.5 * d * np.log(2 * np.pi)
        result.append(logsumexp(joint) - log_z)
    return np.array(result)


def test_it_scores_exactly():
    X, ids, context = driven_data()
    model = ToyModel(4, order=2, n_iter=5, random_state=0)
    model.fit(X, sequence_ids=ids, context=context)
    layer = model._layer
    layer.flat[...] = 0.3 * np.random.default_rng(0).standard_normal(layer.flat.size)

    # the estimator gives its layer the standardised context
    def standardised(context):
        return (context - model.context_mean_) / model.context_scale_

    expected = exact_log_likelihood(layer, X, ids, standardised(context))
    got = model.score_samples(X, sequence_ids=ids, context=context)
    assert_allclose(got, expected, rtol=1e-9, atol=1e-9)
    estimate = model.estimate_log_likelihood(
        X, sequence_ids=ids, context=context, method="exact"
    )
    assert_allclose(estimate.log_likelihood, expected, rtol=1e-9, atol=1e-9)
    # another context, another likelihood: exactly that of the energy
    other = exact_log_likelihood(layer, X, ids, standardised(-context))
    assert_allclose(
        model.score_samples(X, sequence_ids=ids, context=-context), other, rtol=1e-9
    )
    assert np.abs(other - expected).max() > 0.1


def test_it_fills_in_given_the_context(fitted):
    X_train, ids_train, context_train = driven_data()
    X, ids, context = driven_data(random_state=1)
    one = ids == 2
    X_missing = X[one].copy()
    X_missing[20:, 0] = np.nan
    imputer = CRBMImputer(
        FrozenEstimator(fitted), n_particles=5, offset_shrinkage=None, random_state=0
    ).fit(X_train, sequence_ids=ids_train, context=context_train)
    errors = {}
    for name, given in (("right", context[one]), ("flipped", -context[one])):
        filled = imputer.transform(X_missing, context=given)
        assert np.array_equal(filled[:, 1:], X[one][:, 1:])
        errors[name] = np.mean((filled[20:, 0] - X[one][20:, 0]) ** 2)
    assert errors["right"] < 0.2 * errors["flipped"]
