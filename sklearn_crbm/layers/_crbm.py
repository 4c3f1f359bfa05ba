"""The conditional RBM layer (Taylor, Hinton & Roweis, 2006): parameters and math.

Notation (paper, Section 2): visible frame ``v`` (``n_features``), hidden
units ``h`` (``n_components``), symmetric weights ``W`` (``components_``),
hidden bias ``b``, visible bias ``c``, and the history ``x[t-1], ...,
x[t-L]`` flattened lag-major into one row.  The directed connections are
packed into a single matrix ``dynamic`` of shape ``(n_features +
n_components, L * n_features)``: its first ``n_features`` rows are the
autoregressive weights ``A`` (past -> visible), the remaining rows the
weights ``B`` (past -> hidden).  Both dynamic biases thus come out of one
matrix product::

    [c_hat, b_hat] = history @ dynamic.T + [c, b]

A per-frame context ``y_t`` (``n_context`` real values: a control signal,
or label weights) adds to both through the weights ``context_weights`` of
shape ``(n_features + n_components, n_context)``, stacked as ``dynamic``
is::

    [c_hat, b_hat] = history @ dynamic.T + [c, b] + y_t @ context_weights.T

When ``order != hidden_order`` the blocks of lags a group does not use are
kept at exactly zero.  Every frame shares ``W``: the frame RBMs differ in
their biases only.  The paper fixes the visible standard deviation ``s`` at
1; with learned variances (Cho, Raiko & Ilin 2011) the group
``log_visible_variance`` holds ``z = log s^2``.
"""

import math
from numbers import Integral

import numpy as np
from sklearn.utils._param_validation import Interval

from .._engines._gibbs import HiddenSampler
from ..utils._array_api import array_ops, same_memory
from ._base import ConditionalLayer, FrameRBMs, TrainingWorkspace
from ._parameters import ParameterGroup, small_normal

__all__ = [
    "MIN_LOG_VARIANCE",
    "ORDER_CONSTRAINTS",
    "CRBMFrames",
    "CRBMLayer",
    "hidden_order_of",
    "shift_centred",
]

# The past frames of a CRBM: ``order`` feed the visibles, ``hidden_order``
# (None: ``order``) the hidden units.
ORDER_CONSTRAINTS = {
    "order": [Interval(Integral, 0, None, closed="left")],
    "hidden_order": [None, Interval(Integral, 0, None, closed="left")],
}


def hidden_order_of(model):
    """A CRBM model's ``hidden_order``, None standing for its ``order``."""
    return model.order if model.hidden_order is None else model.hidden_order


# Learned visible variances are kept at or above 1e-4 (s >= 0.01, in the units
# of standardised data): a channel that its past predicts almost exactly
# would otherwise shrink s towards 0 and blow up the hidden input v / s.
MIN_LOG_VARIANCE = math.log(1e-4)


def _initial_dynamic(layer, rng):
    return small_normal(rng, layer.dynamic.shape, layer.dtype) * layer.dynamic_mask()


# The original code's initialisation: W, A, B and the visible bias are
# N(0, 0.01^2); the hidden bias is -1 + N(0, 0.01^2), so that hidden units
# start mostly off; visible variances start at 1.
CRBM_GROUPS = (
    ParameterGroup(
        "dynamic",
        lambda p: (p.n_features + p.n_components, p.n_lags * p.n_features),
        _initial_dynamic,
        decayed=True,
    ),
    ParameterGroup(
        "weights",
        lambda p: (p.n_components, p.n_features),
        lambda p, rng: small_normal(rng, p.weights.shape, p.dtype),
        decayed=True,
    ),
    ParameterGroup(
        "hidden_bias",
        lambda p: (p.n_components,),
        lambda p, rng: small_normal(rng, p.hidden_bias.shape, p.dtype) - 1,
        decayed=False,
    ),
    ParameterGroup(
        "visible_bias",
        lambda p: (p.n_features,),
        lambda p, rng: small_normal(rng, p.visible_bias.shape, p.dtype),
        decayed=False,
    ),
    # z = log s^2; stays 0 (unit variance) unless learned
    ParameterGroup(
        "log_visible_variance",
        lambda p: (p.n_features,),
        lambda p, rng: np.zeros(p.n_features, p.dtype),
        decayed=False,
    ),
    # last: without context it is empty and draws nothing
    ParameterGroup(
        "context_weights",
        lambda p: (p.n_features + p.n_components, p.n_context),
        lambda p, rng: small_normal(rng, p.context_weights.shape, p.dtype),
        decayed=True,
    ),
)


class CRBMFrames(FrameRBMs):
    """Frame RBMs of a CRBM layer: every frame has the layer's weights ``W``.

    Parameters
    ----------
    visible_bias, hidden_bias, visible_std, units, frame_invariant
        As :class:`~sklearn_crbm.layers.FrameRBMs`.
    weights : ndarray of shape (n_components, n_features)
        ``W``.
    input_weights : ndarray of shape (n_components, n_features), default=None
        ``W / s`` if the caller keeps it at hand.
    """

    _shared_arrays = ("visible_std", "weights", "input_weights")

    def __init__(
        self,
        visible_bias,
        hidden_bias,
        visible_std,
        units,
        weights,
        input_weights=None,
        frame_invariant=False,
    ):
        super().__init__(visible_bias, hidden_bias, visible_std, units, frame_invariant)
        self.weights = weights
        if input_weights is None:
            input_weights = weights if visible_std is None else weights / visible_std
        self.input_weights = input_weights

    @property
    def shared_weights(self):
        return self.weights

    def interaction_input(self, visible, out=None):
        return self.ops.matmul(visible, self.input_weights.T, out=out)

    def interaction_field(self, hidden, out=None):
        field = self.ops.matmul(hidden, self.weights, out=out)
        if self.visible_std is not None:
            field *= self.visible_std
        return field


class CRBMWorkspace(TrainingWorkspace):
    """Buffers that :meth:`CRBMLayer.cd_statistics` reuses between minibatches."""

    def __init__(self, layer, batch_size):
        n, d, h = batch_size, layer.n_features, layer.n_components
        dtype, ops = layer.dtype, layer.ops
        self.batch_size = batch_size
        # [v; v_recon] and [h_data; h_recon]: the W statistics are one product
        self.visible_stack = ops.empty((2 * n, d), dtype)
        self._visible = self.visible_stack
        self.hidden_stack = ops.empty((2 * n, h), dtype)
        self.hidden = ops.empty((n, h), dtype)
        self.biases = ops.empty((n, d + h), dtype)
        self.delta = ops.empty((n, d + h), dtype)
        self.history = ops.empty((n, layer.n_lags * d), dtype)
        self.ones = ops.ones(n, dtype)
        self.bias_sums = ops.empty(d + h, dtype)
        # s * W.T h of the first reconstruction (learned variances, CD-k > 1)
        self.first_mean = ops.empty((n, d), dtype) if layer.learned_variance else None
        self.dynamic_mask = None
        if layer.order != layer.hidden_order:
            self.dynamic_mask = ops.zeros_like(layer.dynamic)
            self.dynamic_mask[...] = layer.dynamic_mask()  # in the layout of dynamic


class CRBMLayer(ConditionalLayer):
    """The parameters of one CRBM and its math, packed in one flat buffer.

    Groups (views of :attr:`flat`): ``weights`` ``W`` (n_components,
    n_features), ``hidden_bias`` (n_components,), ``visible_bias``
    (n_features,), ``dynamic`` (n_features + n_components, n_lags *
    n_features), the directed weights ``[A; B]`` (see the module docstring),
    ``log_visible_variance`` (n_features,) and ``context_weights``
    (n_features + n_components, n_context).

    Parameters
    ----------
    n_features, n_components, order, hidden_order : int
    visible_type : {"gaussian", "binary"}
    dtype : dtype
    n_context : int, default=0
        Columns of the per-frame context.
    flat : ndarray of shape (n_parameters,), default=None
        The buffer to view; zeros if None.
    layout : {"C", "F"}, default="C"
    learned_variance : bool, default=False
        Whether ``log_visible_variance`` is trained (Gaussian visibles
        only).
    fixed_variance : bool, default=False
        Whether ``log_visible_variance`` holds variances that training
        keeps as they are.  With neither flag it is 0 and the math takes
        the unit-variance path.
    centered : bool, default=False
        Whether training steps in centred coordinates (see
        :meth:`cd_statistics`).
    ops : module or ArrayOps, default=numpy
    """

    groups = CRBM_GROUPS
    # layers pickled before contexts had none
    n_context = 0

    def __init__(
        self,
        n_features,
        n_components,
        order,
        hidden_order,
        visible_type,
        dtype,
        *,
        n_context=0,
        flat=None,
        layout="C",
        learned_variance=False,
        fixed_variance=False,
        centered=False,
        ops=np,
    ):
        self.n_features = n_features
        self.n_components = n_components
        self.order = order
        self.hidden_order = hidden_order
        self.visible_type = visible_type
        self.n_context = n_context
        self.learned_variance = learned_variance
        self.fixed_variance = fixed_variance
        self.centered = centered
        self._allocate(dtype, flat=flat, layout=layout, ops=ops)

    @property
    def n_lags(self):
        return max(self.order, self.hidden_order)

    @property
    def visible_std(self):
        if not (self.learned_variance or self.fixed_variance):
            return None
        return self.ops.exp(0.5 * self.log_visible_variance)

    @property
    def visible_variance(self):
        """``s^2``, shape ``(n_features,)``: ones unless learned (a new array)."""
        return self.ops.exp(self.log_visible_variance)

    @visible_variance.setter
    def visible_variance(self, value):
        if not (self.learned_variance or self.fixed_variance):
            raise ValueError(
                "This model's visible units have unit variance "
                "(visible_variance='unit'), which assigning cannot change. Fit "
                "with visible_variance='learned' or 'residual' for other variances."
            )
        self.log_visible_variance[...] = self.ops.log(value)

    @property
    def autoregressive(self):
        """``A`` as a view of shape ``(order, n_features, n_features)``.

        Block ``q - 1`` acts on ``x[t - q]``.
        """
        n = self.n_features
        return _lag_blocks(self.dynamic[:n, : self.order * n], self.order, n)

    @property
    def past_to_hidden(self):
        """``B`` as a view of shape ``(hidden_order, n_components, n_features)``."""
        n = self.n_features
        block = self.dynamic[n:, : self.hidden_order * n]
        return _lag_blocks(block, self.hidden_order, n)

    @property
    def context_to_visible(self):
        """``L_v``, shape ``(n_features, n_context)``: context to visible biases."""
        return self.context_weights[: self.n_features, ...]

    @property
    def context_to_hidden(self):
        """``L_h``, shape ``(n_components, n_context)``: context to hidden biases."""
        return self.context_weights[self.n_features :, ...]

    def dynamic_mask(self):
        """1 where a directed weight exists, 0 on the lags a group does not use."""
        n = self.n_features
        mask = self.ops.zeros(self.dynamic.shape, dtype=self.dtype)
        mask[:n, : self.order * n] = 1
        mask[n:, : self.hidden_order * n] = 1
        return mask

    # --------------------------------------------------------- frame RBMs

    def dynamic_biases(self, history, context=None, out=None, static=None):
        """``c_hat`` and ``b_hat`` of each frame given its history and context.

        Views of one array ``out`` of shape ``(n, n_features +
        n_components)``; ``static`` is ``[c, b]`` if the caller keeps it at
        hand.
        """
        n = self.n_features
        ops = self.ops
        if out is None:
            out = ops.empty((history.shape[0], n + self.n_components), self.dtype)
        # one contiguous add is several times faster than two on strided halves
        if static is None:
            static = ops.concatenate((self.visible_bias, self.hidden_bias))
        inputs = self.bias_inputs(history, context)
        if not inputs:
            out[...] = static
        for k, (name, values) in enumerate(inputs):
            if k == 0:
                out = ops.matmul(values, getattr(self, name).T, out=out)
                out += static
            else:
                out += ops.matmul(values, getattr(self, name).T)
        return out[:, :n], out[:, n:]

    def bias_inputs(self, history, context):
        """The inputs of the dynamic biases: ``(group, values)`` pairs.

        Each adds ``values @ group.T`` to ``[c_hat, b_hat]``, and its
        statistic in :meth:`cd_statistics` is that of the group.  The
        history (through ``dynamic``) and the context (through
        ``context_weights``), those the layer has.
        """
        inputs = []
        if self.n_lags:
            inputs.append(("dynamic", history))
        if self.n_context:
            inputs.append(("context_weights", context))
        return inputs

    def frame_invariants(self):
        std = self.visible_std
        return {
            "static": self.ops.concatenate((self.visible_bias, self.hidden_bias)),
            "std": std,
            "input_weights": self.weights if std is None else self.weights / std,
        }

    def build_frame_rbms(self, invariants, history, context=None, *, out=None):
        visible_bias, hidden_bias = self.dynamic_biases(
            history, context, out=out, static=invariants["static"]
        )
        return CRBMFrames(
            visible_bias,
            hidden_bias,
            invariants["std"],
            self.visible_units,
            self.weights,
            invariants["input_weights"],
            frame_invariant=self.n_lags == 0 and self.n_context == 0,
        )

    # ------------------------------------------------------------ training

    def new_workspace(self, batch_size):
        return CRBMWorkspace(self, batch_size)

    def training_copy(self):
        params = self.copy(layout="F")
        return shift_centred(params, 1) if self.centered else params

    def fitted_copy(self):
        params = self.copy(layout="C")
        return shift_centred(params, -1) if self.centered else params

    def after_update(self):
        if self.learned_variance:
            self.ops.maximum(
                self.log_visible_variance,
                MIN_LOG_VARIANCE,
                out=self.log_visible_variance,
            )

    def cd_statistics(
        self, visible, history, context, cd_steps, rng, *, out, scale, workspace
    ):
        """Contrastive-divergence statistics of one minibatch (paper Eqs. 4-7, §2.2).

        Positive phase: hidden probabilities from the data, binary hidden
        states sampled and used in the positive statistics.  Each
        reconstruction sets the visibles to their mean given sampled hidden
        states; the negative statistics use the hidden *probabilities* of the
        last reconstruction.  The visible bias and autoregressive gradients
        use the residual against the dynamic visible bias, which reduces to
        ``v - v_recon``.

        With learned visible variances the weight statistics use ``v / s``
        and ``v_recon / s``; the visible bias and autoregressive statistics
        stay ``v - v_recon``, the gradient times ``s^2`` (the natural-gradient
        scaling of a Gaussian mean, so that their steps do not grow as ``s``
        shrinks); and the statistic of ``z_i = log s_i^2`` is, per frame,

            ((v - c_hat)^2 + c_hat * m_last - v * m_first) / (2 s^2) - 1/2

        with ``m = s * (W.T h)`` for the hidden states behind the first and
        the last reconstruction: the positive term ``-dE/dz`` at the data and
        the sampled ``h_0``, minus the negative term averaged exactly over
        ``v_k ~ p(v | h_{k-1})`` (Rao-Blackwellised).

        The weight statistics ``h_data.T @ v - h_recon.T @ v_recon`` are one
        matrix product of the stacked ``[h_data; h_recon]`` and ``[v;
        -v_recon]``; those of both directed groups are one product of ``[v -
        v_recon, h_data - h_recon]`` with the history; ``scale`` multiplies
        these small factors, not the products.

        With :attr:`centered`, the parameters are the centred coordinates
        of :func:`shift_centred` (the hidden units see ``(v - c_hat) / s``)
        and the statistics are their gradients: by the chain rule, those
        above with, per frame and with ``dh = h_data - h_recon``, ``-dh
        (c_hat / s)`` added to the weights', ``-s * (W.T dh)`` to the visible
        delta and ``c_hat (W.T dh) / (2 s)`` to that of ``log s^2``.  Their
        steps do not drag the hidden units' dynamic biases along with every
        change of the visible mean (Montavon & Müller's centring, Cho, Raiko
        & Ilin's enhanced gradient).

        Every input of the dynamic biases (:meth:`bias_inputs`: the
        history, the context) has the statistic ``delta.T @ input``.
        """
        n, d = visible.shape
        ops = self.ops
        stacked_visible = workspace.visible_stack[: 2 * n, ...]
        stacked_hidden = workspace.hidden_stack[: 2 * n, ...]
        data, reconstruction = stacked_visible[:n, ...], stacked_visible[n:, ...]
        positive_states, negative_probabilities = (
            stacked_hidden[:n, ...],
            stacked_hidden[n:, ...],
        )
        if not same_memory(visible, data):
            ops.copyto(data, visible)

        rbms = self.frame_rbms(history, context, out=workspace.biases[:n, ...])
        visible_bias = rbms.visible_bias
        std = rbms.visible_std
        if (
            self.centered
        ):  # the hidden input of the standard form: b_hat - W (c_hat / s)
            centre = visible_bias if std is None else visible_bias / std
            rbms.hidden_bias -= ops.matmul(centre, self.weights.T)
        sample_hidden = HiddenSampler(rbms)
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            sample_hidden(
                data, rng, out=positive_states, work=workspace.hidden[:n, ...]
            )

        hidden = positive_states
        learned = self.learned_variance
        for step in range(cd_steps):
            rbms.visible_mean(hidden, out=reconstruction)
            if learned and step == 0:
                ops.subtract(
                    reconstruction, visible_bias, out=workspace.first_mean[:n, ...]
                )
            if step + 1 < cd_steps:
                with np.errstate(over="ignore", under="ignore", invalid="ignore"):
                    hidden = sample_hidden(
                        reconstruction,
                        rng,
                        out=workspace.hidden[:n, ...],
                        work=negative_probabilities,
                    )
            else:
                rbms.hidden_probabilities(reconstruction, out=negative_probabilities)

        delta = workspace.delta[:n, ...]
        visible_delta = ops.subtract(data, reconstruction, out=delta[:, :d])
        ops.subtract(positive_states, negative_probabilities, out=delta[:, d:])
        squared_error = ops.einsum("ij,ij->", visible_delta, visible_delta)
        if ops is np:  # elsewhere it stays on the device: no sync per minibatch
            squared_error = float(squared_error)

        if learned:
            self._log_variance_statistic(
                data,
                reconstruction,
                visible_bias,
                workspace.first_mean[:n, ...],
                scale,
                out=out.log_visible_variance,
            )
        else:
            out.log_visible_variance[...] = 0
        if self.centered:
            self._centre_statistics(std, visible_bias, delta, d, scale, out)
        # the scale goes into the small factors: [v; -v_recon] and delta; W's
        # statistics are those of v / s
        visible_scale = scale if std is None else scale / std
        data *= visible_scale
        ops.multiply(reconstruction, -visible_scale, out=reconstruction)
        delta *= scale
        ops.matmul(stacked_hidden.T, stacked_visible, out=out.weights)
        if self.centered:
            out.weights -= ops.matmul(delta[:, d:].T, centre)
        bias_sums = ops.dot(workspace.ones[:n], delta, out=workspace.bias_sums)
        out.visible_bias[...] = bias_sums[:d]
        out.hidden_bias[...] = bias_sums[d:]
        for name, values in self.bias_inputs(history, context):
            ops.matmul(delta.T, values, out=getattr(out, name))
        if workspace.dynamic_mask is not None:
            out.dynamic *= workspace.dynamic_mask
        return out, squared_error

    def _centre_statistics(self, std, visible_bias, delta, d, scale, out):
        """The chain-rule terms of the centred coordinates (see cd_statistics).

        Changes the visible part of ``delta`` (not yet scaled) and, with
        learned variances, the statistic of ``log s^2`` in ``out``.
        """
        ops = self.ops
        back = ops.matmul(delta[:, d:], self.weights)  # W.T dh, frame by frame
        if self.learned_variance:
            term = ops.sum(visible_bias * back, axis=0) / (2 * std)
            out.log_visible_variance[...] = out.log_visible_variance + scale * term
        if std is not None:
            back *= std
        delta[:, :d] -= back

    def _log_variance_statistic(
        self, data, reconstruction, visible_bias, first, scale, out
    ):
        """``scale`` times the summed CD statistic of ``z = log s^2``."""
        ops = self.ops
        last = reconstruction - visible_bias
        statistic = ops.square(data - visible_bias)
        statistic += visible_bias * last
        statistic -= data * first
        total = ops.sum(statistic, axis=0)
        total /= 2 * self.visible_variance
        total -= 0.5 * data.shape[0]
        return ops.multiply(total, scale, out=out)


def shift_centred(layer, direction):
    """Move ``layer`` in place to centred coordinates (``+1``) or back (``-1``).

    In centred coordinates the hidden units see the residual against the
    dynamic visible bias, ``b' + B' x_past + L'_h y + W ((v - c_hat) / s)``:
    the same model as the standard form ``b + B x_past + L_h y + W (v / s)``
    with ``b = b' - W (c / s)``, ``B_q = B'_q - W diag(1 / s) A_q`` and
    ``L_h = L'_h - W diag(1 / s) L_v``, where ``c``, ``A`` and ``L_v`` are
    the static visible bias, the autoregressive and the context-to-visible
    weights.  Needs ``hidden_order >= order``.
    """
    ops = layer.ops
    n = layer.n_features
    std = layer.visible_std
    weights = layer.weights if std is None else layer.weights / std
    layer.hidden_bias[...] = layer.hidden_bias + direction * ops.matmul(
        weights, layer.visible_bias
    )
    width = layer.order * n
    if width:
        shift = ops.matmul(weights, layer.dynamic[:n, :width])
        layer.dynamic[n:, :width] = layer.dynamic[n:, :width] + direction * shift
    if layer.n_context:
        shift = ops.matmul(weights, layer.context_weights[:n, ...])
        layer.context_weights[n:, ...] = layer.context_weights[n:, ...] + (
            direction * shift
        )
    return layer


def _lag_blocks(matrix, q, n):
    """(rows, q * n) -> a (q, rows, n) view; block ``q-1`` is columns ``(q-1)n:qn``."""
    if not isinstance(matrix, np.ndarray):
        xp = array_ops(matrix).xp
        return xp.permute_dims(xp.reshape(matrix, (matrix.shape[0], q, n)), (1, 0, 2))
    blocks = matrix.view()
    blocks.shape = (matrix.shape[0], q, n)  # raises rather than copy
    return blocks.transpose(1, 0, 2)
