"""The factored, style-gated CRBM layer (Taylor & Hinton, ICML 2009).

A frame ``v`` (``n_features`` Gaussian units of unit variance), binary
hidden units ``h`` (``n_components``), the flattened past ``p`` (``n_lags``
frames, lag-major) and the frame's *context* ``y`` (``n_context`` real
values: label weights, one-hot for a labelled frame, or control signals).
The context gives real-valued style features ``z = y R``, and every
interaction goes through factors that the style features gate (three-way
multiplicative interactions)::

    c_hat = c + ((p P_A) * (z Z_A)) A_v.T        dynamic visible bias
    b_hat = b + ((p P_B) * (z Z_B)) B_h.T        dynamic hidden bias
    E(v, h) = ||v - c_hat||^2 / 2 - b_hat . h - sum_f (v W_v)_f (h W_h)_f (z Z_W)_f

so that, with the gates ``g = z Z_W`` of the frame, ``p(h = 1 | v) =
sigmoid(b_hat + ((v W_v) * g) W_h.T)`` and ``v | h ~ N(c_hat + ((h W_h) *
g) W_v.T, 1)``: each frame's RBM has the weights ``W_t = W_h diag(g) W_v.T``.
With ``shared_style_weights`` one matrix ``Z`` stands for ``Z_A``, ``Z_B``
and ``Z_W`` (the released code's default), and the three kinds of factor
are equally many.
"""

import functools

import numpy as np

from .._engines._gibbs import HiddenSampler
from ..utils._random import sample_bernoulli
from ._base import (
    GAUSSIAN,
    VISIBLE_UNITS,
    ConditionalLayer,
    FrameRBMs,
    TrainingWorkspace,
)
from ._parameters import ParameterGroup, small_normal

__all__ = ["FactoredFrames", "FactoredLayer"]

# Relative learning rates (of the estimator's ``learning_rate``) of the
# groups that do not take the full rate, as in the released code: the
# autoregressive factors (past to visible) and the label features ``R``.
RATES = {
    "past_visible_factors": 0.1,
    "visible_from_factors": 0.1,
    "label_features": 0.1,
}


def _weights(shape):
    return lambda layer, rng: small_normal(rng, shape(layer), layer.dtype)


def _biases(shape):
    return lambda layer, rng: np.zeros(shape(layer), layer.dtype)


def _group(name, shape, *, decayed=True, initial=None):
    return ParameterGroup(
        name,
        shape,
        initial or _weights(shape),
        decayed=decayed,
        rate=RATES.get(name, 1.0),
    )


def _bias(name, shape):
    """Biases start at zero, as in the released code, and are not decayed."""
    return _group(name, shape, decayed=False, initial=_biases(shape))


@functools.cache
def _groups(shared):
    """The trainable arrays of a factored layer (decayed first, then biases)."""
    past = lambda p: p.n_lags * p.n_features  # noqa: E731
    groups = [
        _group("visible_factors", lambda p: (p.n_features, p.n_factors)),
        _group("hidden_factors", lambda p: (p.n_components, p.n_factors)),
        _group("past_hidden_factors", lambda p: (past(p), p.n_factors)),
        _group("hidden_from_factors", lambda p: (p.n_components, p.n_factors)),
        _group(
            "past_visible_factors",
            lambda p: (past(p), p.n_factors),
        ),
        _group(
            "visible_from_factors",
            lambda p: (p.n_features, p.n_factors),
        ),
        _group("label_features", lambda p: (p.n_context, p.n_style_features)),
    ]
    style = (
        ["style_factors"]
        if shared
        else [
            "style_undirected",
            "style_hidden",
            "style_visible",
        ]
    )
    for name in style:
        groups.append(_group(name, lambda p: (p.n_style_features, p.n_factors)))
    groups += [
        _bias("hidden_bias", lambda p: (p.n_components,)),
        _bias("visible_bias", lambda p: (p.n_features,)),
    ]
    return tuple(groups)


class FactoredFrames(FrameRBMs):
    """Frame RBMs of a factored layer: each frame's gates ``g = z Z_W``.

    When every frame has the same gates (one style, or one blend, for all
    the frames: generation, a sequence of one style) the weights ``W_t =
    W_h diag(g) W_v.T`` are one matrix, formed once: each Gibbs step is then
    one product instead of two.

    Parameters
    ----------
    visible_bias, hidden_bias : ndarray
        ``c_hat`` and ``b_hat`` of every frame.
    gates : ndarray of shape (n_frames, n_factors)
    visible_factors, hidden_factors : ndarray
        ``W_v`` (n_features, n_factors) and ``W_h`` (n_components,
        n_factors).
    """

    _row_arrays = ("visible_bias", "hidden_bias", "gates")
    _shared_arrays = ("visible_std", "visible_factors", "hidden_factors", "weights")

    def __init__(
        self, visible_bias, hidden_bias, gates, visible_factors, hidden_factors
    ):
        super().__init__(visible_bias, hidden_bias, None, VISIBLE_UNITS[GAUSSIAN])
        self.gates = gates
        self.visible_factors = visible_factors
        self.hidden_factors = hidden_factors
        self.weights = None
        ops = self.ops
        first = gates[:1, ...]
        if gates.shape[0] and bool(ops.all(gates == first)):
            self.weights = ops.matmul(hidden_factors * first, visible_factors.T)

    @property
    def shared_weights(self):
        return self.weights

    def interaction_input(self, visible, out=None):
        ops = self.ops
        if self.weights is not None:
            return ops.matmul(visible, self.weights.T, out=out)
        factors = ops.matmul(visible, self.visible_factors)
        factors *= self.gates
        return ops.matmul(factors, self.hidden_factors.T, out=out)

    def interaction_field(self, hidden, out=None):
        ops = self.ops
        if self.weights is not None:
            return ops.matmul(hidden, self.weights, out=out)
        factors = ops.matmul(hidden, self.hidden_factors)
        factors *= self.gates
        return ops.matmul(factors, self.visible_factors.T, out=out)


class FactoredWorkspace(TrainingWorkspace):
    """Buffers of :meth:`FactoredLayer.cd_statistics`."""

    def __init__(self, layer, batch_size):
        super().__init__(layer, batch_size)
        n, h = batch_size, layer.n_components
        ops, dtype = layer.ops, layer.dtype
        self.reconstruction = ops.empty((n, layer.n_features), dtype)
        self.positive = ops.empty((n, h), dtype)
        self.negative = ops.empty((n, h), dtype)
        self.hidden = ops.empty((n, h), dtype)


class FactoredLayer(ConditionalLayer):
    """The parameters of one factored CRBM and its math (see the module docstring).

    Parameters
    ----------
    n_features, n_components, n_factors, n_style_features, n_context, order : int
    dtype : dtype
    shared_style_weights : bool, default=True
        One style-feature-to-factor matrix for the three kinds of factor.
    layout : {"C", "F"}, default="C"
    ops : module or ArrayOps, default=numpy

    Attributes
    ----------
    visible_factors, hidden_factors : ndarray
        ``W_v`` (n_features, n_factors), ``W_h`` (n_components, n_factors).
    past_visible_factors, visible_from_factors : ndarray
        ``P_A`` (n_lags * n_features, n_factors), ``A_v`` (n_features,
        n_factors).
    past_hidden_factors, hidden_from_factors : ndarray
        ``P_B`` (n_lags * n_features, n_factors), ``B_h`` (n_components,
        n_factors).
    label_features : ndarray of shape (n_context, n_style_features)
        ``R``.
    style_factors or style_undirected, style_hidden, style_visible : ndarray
        ``Z`` (shared) or ``Z_W``, ``Z_B``, ``Z_A``, each (n_style_features,
        n_factors).
    hidden_bias, visible_bias : ndarray
        ``b`` and ``c``.
    """

    def __init__(
        self,
        n_features,
        n_components,
        n_factors,
        n_style_features,
        n_context,
        order,
        dtype,
        *,
        shared_style_weights=True,
        layout="C",
        ops=np,
    ):
        self.n_features = n_features
        self.n_components = n_components
        self.n_factors = n_factors
        self.n_style_features = n_style_features
        self.n_context = n_context
        self.order = order
        self.shared_style_weights = shared_style_weights
        self._allocate(dtype, layout=layout, ops=ops)

    @property
    def groups(self):
        return _groups(self.shared_style_weights)

    @property
    def n_lags(self):
        return self.order

    def style_features(self, context):
        """``z = y R`` of every frame (``context`` holds ``y``)."""
        return self.ops.matmul(context, self.label_features)

    def _terms(self, history, context):
        """Every factor's inputs of a batch of frames, for statistics and biases."""
        ops = self.ops
        z = self.style_features(context)
        if self.shared_style_weights:  # one product gates every kind of factor
            gates = ops.matmul(z, self.style_factors)
            terms = {"z": z, "gates": gates}
            terms["hidden_gates"] = terms["visible_gates"] = gates
        else:
            terms = {
                "z": z,
                "gates": ops.matmul(z, self.style_undirected),
                "hidden_gates": ops.matmul(z, self.style_hidden),
                "visible_gates": ops.matmul(z, self.style_visible),
            }
        if self.n_lags:
            terms["hidden_past"] = ops.matmul(history, self.past_hidden_factors)
            terms["visible_past"] = ops.matmul(history, self.past_visible_factors)
        else:
            zeros = ops.zeros((history.shape[0], self.n_factors), self.dtype)
            terms["hidden_past"] = terms["visible_past"] = zeros
        return terms

    def _rbms(self, terms):
        ops = self.ops
        hidden_bias = ops.matmul(
            terms["hidden_past"] * terms["hidden_gates"], self.hidden_from_factors.T
        )
        hidden_bias += self.hidden_bias
        visible_bias = ops.matmul(
            terms["visible_past"] * terms["visible_gates"], self.visible_from_factors.T
        )
        visible_bias += self.visible_bias
        return FactoredFrames(
            visible_bias,
            hidden_bias,
            terms["gates"],
            self.visible_factors,
            self.hidden_factors,
        )

    def build_frame_rbms(self, invariants, history, context=None, *, out=None):
        if context is None:
            raise ValueError("A factored layer needs every frame's context.")
        return self._rbms(self._terms(history, context))

    # ------------------------------------------------------------ training

    def new_workspace(self, batch_size):
        return FactoredWorkspace(self, batch_size)

    def cd_statistics(
        self, visible, history, context, cd_steps, rng, *, out, scale, workspace
    ):
        """Contrastive-divergence statistics of a minibatch (CD-k), times ``scale``.

        As the released code computes them: the hidden probabilities of the
        data and of the last reconstruction in the statistics, sampled
        hidden states driving the chain, visible means in the
        reconstructions; the directed statistics use ``v - v_recon`` and
        ``p(h | v) - p(h | v_recon)``.  Each factor's statistics
        are the chain rule through its three-way product.
        """
        n = visible.shape[0]
        ops = self.ops
        terms = self._terms(history, context)
        rbms = self._rbms(terms)
        data = visible
        reconstruction = workspace.reconstruction[:n, ...]
        positive = workspace.positive[:n, ...]
        negative = workspace.negative[:n, ...]
        sample_hidden = HiddenSampler(rbms)
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            # the statistics take probabilities, the chain sampled states
            rbms.hidden_probabilities(data, out=positive)
            hidden = sample_bernoulli(positive, rng, out=workspace.hidden[:n, ...])
            for step in range(cd_steps):
                rbms.visible_mean(hidden, out=reconstruction)
                if step + 1 < cd_steps:
                    hidden = sample_hidden(
                        reconstruction,
                        rng,
                        out=workspace.hidden[:n, ...],
                        work=negative,
                    )
            rbms.hidden_probabilities(reconstruction, out=negative)

        visible_delta = data - reconstruction
        hidden_delta = positive - negative
        squared_error = ops.einsum("ij,ij->", visible_delta, visible_delta)
        if ops is np:
            squared_error = float(squared_error)
        visible_delta *= scale
        hidden_delta *= scale
        gates = terms["gates"]

        # undirected factors: data minus reconstruction, through the gates
        visible_in = [ops.matmul(data, self.visible_factors)]
        visible_in.append(ops.matmul(reconstruction, self.visible_factors))
        hidden_in = [ops.matmul(positive, self.hidden_factors)]
        hidden_in.append(ops.matmul(negative, self.hidden_factors))
        out.visible_factors[...] = scale * (
            ops.matmul(data.T, hidden_in[0] * gates)
            - ops.matmul(reconstruction.T, hidden_in[1] * gates)
        )
        out.hidden_factors[...] = scale * (
            ops.matmul(positive.T, visible_in[0] * gates)
            - ops.matmul(negative.T, visible_in[1] * gates)
        )
        gate_statistic = scale * (
            visible_in[0] * hidden_in[0] - visible_in[1] * hidden_in[1]
        )

        # past -> hidden factors
        hidden_back = ops.matmul(hidden_delta, self.hidden_from_factors)
        out.hidden_from_factors[...] = ops.matmul(
            hidden_delta.T, terms["hidden_past"] * terms["hidden_gates"]
        )
        out.past_hidden_factors[...] = ops.matmul(
            history.T, hidden_back * terms["hidden_gates"]
        )
        hidden_gate_statistic = hidden_back * terms["hidden_past"]

        # autoregressive factors
        visible_back = ops.matmul(visible_delta, self.visible_from_factors)
        out.visible_from_factors[...] = ops.matmul(
            visible_delta.T, terms["visible_past"] * terms["visible_gates"]
        )
        out.past_visible_factors[...] = ops.matmul(
            history.T, visible_back * terms["visible_gates"]
        )
        visible_gate_statistic = visible_back * terms["visible_past"]

        # style features -> factors, and labels -> style features
        z = terms["z"]
        if self.shared_style_weights:
            gate_total = gate_statistic + hidden_gate_statistic + visible_gate_statistic
            out.style_factors[...] = ops.matmul(z.T, gate_total)
            feature_statistic = ops.matmul(gate_total, self.style_factors.T)
        else:
            out.style_undirected[...] = ops.matmul(z.T, gate_statistic)
            out.style_hidden[...] = ops.matmul(z.T, hidden_gate_statistic)
            out.style_visible[...] = ops.matmul(z.T, visible_gate_statistic)
            feature_statistic = (
                ops.matmul(gate_statistic, self.style_undirected.T)
                + ops.matmul(hidden_gate_statistic, self.style_hidden.T)
                + ops.matmul(visible_gate_statistic, self.style_visible.T)
            )
        out.label_features[...] = ops.matmul(context.T, feature_statistic)

        out.hidden_bias[...] = ops.sum(hidden_delta, axis=0)
        out.visible_bias[...] = ops.sum(visible_delta, axis=0)
        return out, squared_error
