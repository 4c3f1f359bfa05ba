"""The conditional layer: what every kind of layer provides, and its per-frame RBMs.

A conditional layer models a frame ``v_t`` (visible units) with binary
hidden units ``h``, given the frame's past ``x_{t-1}, ..., x_{t-L}`` (its
*history*, ``L = n_lags`` frames flattened lag-major into one row) and,
optionally, a per-frame *context* ``y_t`` (``n_context`` real values:
control signals such as speed, or label weights).  Given both, the layer
is an RBM of the frame alone, with frame-specific parameters: a *frame
RBM*.  Everything else in the package (training, generation and fill-in,
the likelihood, the imputers) talks to layers only through this
interface, so a new kind of layer is one new class (and its estimator).

The context reaches a layer from one keyword of every estimator method
that depends on time (:class:`~sklearn_crbm.models._base.BaseCRBM`):
``fit(X, y=None, *, sequence_ids=None, context=None)`` (and
``partial_fit``, ``fit_transform``, ``score`` alike), ``transform``,
``predict_next``, ``score_samples`` and ``estimate_log_likelihood`` with
``(X, *, sequence_ids=None, context=None, style=None)``, and
``sample(n_samples, *, history=None, context=None, style=None, ...)``;
``context`` has shape ``(n_frames, n_context)`` (for ``sample``, one row
per generated frame or one row for all), and the style models' labels
(``y``, ``style=``) are turned into it.

The interface
-------------
A layer is a :class:`~sklearn_crbm.layers._parameters.PackedParameters` (its
trainable arrays in one flat buffer) with

``n_features``, ``n_components``, ``n_lags``, ``n_context``, ``visible_type``
    Visible units (the frame's channels), hidden units, past frames used,
    columns of context, and ``"gaussian"`` or ``"binary"`` visibles.
``visible_std``
    The standard deviation ``s`` of the Gaussian visibles, shape
    ``(n_features,)``, or None for unit variance.
``frame_invariants()`` and ``build_frame_rbms(invariants, history,
context=None)``
    What every frame's RBM shares (a dict; a kind of layer that computes
    nothing once returns ``{}``), and the RBMs of ``n`` frames
    (:class:`FrameRBMs`) given it, their histories, shape ``(n, n_lags *
    n_features)``, and contexts, shape ``(n, n_context)`` or None.  The
    base class derives from these both ``frame_rbms(history, context)``
    and ``conditioner()``, the same callable for a model that does not
    change while it is used (generation, fill-in), with the invariants
    computed once: the two cannot disagree about the context.
``product_size()``
    Multiply-adds per frame of the layer's largest matrix product (the
    default: its largest weight matrix), which sizes the BLAS threads.
``new_workspace(batch_size)`` and ``cd_statistics(visible, history,
context, cd_steps, rng, *, out, scale, workspace)``
    Training: the contrastive-divergence statistics of a minibatch, each
    group's ascent direction times ``scale``, written into ``out`` (a
    buffer laid out like the layer), and the minibatch's summed squared
    reconstruction error.
``training_copy()``, ``fitted_copy()``, ``after_update()``
    Hooks of the training loop (defaults: Fortran-ordered copy, C-ordered
    copy, nothing): a copy in the coordinates training steps in, a copy of
    those in the coordinates the fitted model keeps, and a projection after
    every update.

A :class:`FrameRBMs` holds each frame's dynamic biases ``c_hat_t``
(visible) and ``b_hat_t`` (hidden), the math of the visible units
(:class:`GaussianUnits` or :class:`BinaryUnits`, which the engines call
without asking which they are) and whether every frame has the same RBM
(``frame_invariant``), and provides the frame's interaction, the only
part that differs between kinds of layers:

``interaction_input(v)``
    ``W_t (v / s)``, what the visibles add to each hidden unit's input;
``interaction_field(h)``
    ``s * (W_t^T h)``, what the hidden units add to each visible mean;
``shared_weights``
    ``W`` when every frame's ``W_t`` is the same matrix (the plain CRBM),
    else None (a style-gated layer), so that the likelihood can enumerate
    hidden configurations once for all frames.

The energy of frame ``t``, in the form of Hinton's practical guide, is then

    E(v, h) = sum_i (v_i - c_hat_i)^2 / (2 s_i^2) - b_hat . h - (v / s) . (W_t^T h)

(binary visibles: ``-c_hat . v`` for the quadratic term, ``s = 1``), with
``p(h_j = 1 | v) = sigmoid(b_hat_j + (W_t (v / s))_j)`` and ``p(v | h) =
N(c_hat + s (W_t^T h), diag(s^2))`` (binary: ``sigmoid`` of it).
"""

import functools
import math
from abc import ABCMeta, abstractmethod

import numpy as np

from ..utils._array_api import array_ops
from ..utils._random import sample_bernoulli
from ..utils._sequences import CHUNK_FRAMES, frame_history
from ._parameters import PackedParameters

__all__ = [
    "BINARY",
    "GAUSSIAN",
    "VISIBLE_UNITS",
    "BinaryUnits",
    "ConditionalLayer",
    "FrameRBMs",
    "GaussianUnits",
    "TrainingWorkspace",
    "clipped_logit",
    "draw_bernoulli",
    "logistic",
    "sequence_frame_rbms",
    "sequence_hidden_probabilities",
]

GAUSSIAN = "gaussian"
BINARY = "binary"
_LOG_SQRT_2PI = 0.5 * math.log(2 * math.pi)
# Probabilities are kept this far from 0 and 1 where their logits are taken.
LOGIT_CLIP = 1e-4


def logistic(activation, out=None):
    """The logistic sigmoid ``1 / (1 + exp(-a))``, elementwise, in the dtype of ``a``.

    The same formula as :func:`scipy.special.expit`, built from numpy's
    vectorised ``exp`` (several times faster than ``expit`` on the arrays of a
    minibatch); ``out`` may be ``activation`` itself.  Very negative inputs
    overflow ``exp`` to ``inf`` and give exactly 0, very positive ones
    underflow it to 0 and give exactly 1, without a warning.
    """
    ops = array_ops(activation)
    out = ops.negative(activation, out=out)
    with np.errstate(over="ignore", under="ignore"):
        out = ops.exp(out, out=out)
    out += 1
    return ops.divide(1, out, out=out)  # numpy's reciprocal is not vectorised


def clipped_logit(probability):
    """``log(p / (1 - p))`` of ``p`` clipped to ``[LOGIT_CLIP, 1 - LOGIT_CLIP]``."""
    ops = array_ops(probability)
    p = ops.clip(probability, LOGIT_CLIP, 1 - LOGIT_CLIP)
    return ops.log(p) - ops.log1p(-p)


def draw_bernoulli(probability, rng):
    """0/1 draws with the given probabilities, in their dtype."""
    ops = array_ops(probability)
    draws = rng.random(probability.shape, dtype=probability.dtype)
    return ops.astype(ops.less(draws, probability), probability.dtype)


class GaussianUnits:
    """The math of Gaussian visible units of standard deviation ``s``.

    Each method takes the frame RBMs whose visibles these are (their
    ``scale`` is ``s``) or the arrays it needs.  A visible unit's *field*
    is its input ``c_hat + s (W_t^T h)``: the Gaussian's mean.
    """

    def activate(self, field):
        """The mean of the visibles given their field (in place)."""
        return field

    def mean_copy(self, field):
        """:meth:`activate` of ``field``, leaving ``field`` alone where it copies."""
        return field

    def field_of(self, visible):
        """The field whose mean ``visible`` is (a new float64 array)."""
        return array_ops(visible).astype(visible, array_ops(visible).float64, copy=True)

    def base_field(self, field):
        """The field of a factorial annealing base (clipped for binary units)."""
        return field

    def log_normaliser(self, rbms):
        """``sum_i log(sqrt(2 pi) s_i)``: the visible integral's constant."""
        ops = rbms.ops
        return float(ops.sum(ops.log(rbms.scale)) + rbms.n_features * _LOG_SQRT_2PI)

    def free_energy_term(self, rbms, visible):
        """The visibles' part of ``-F(v)``: ``-||(v - c_hat) / s||^2 / 2``."""
        residual = (visible - rbms.visible_bias) / rbms.scale
        return -0.5 * rbms.ops.einsum("ij,ij->i", residual, residual)

    def add_configuration_terms(self, rbms, u, terms):
        """Add to ``terms`` (frames x configurations) the visibles integrated
        out for configurations with ``W.T h = u``: ``(c_hat / s) . u +
        ||u||^2 / 2``."""
        terms += (rbms.visible_bias / rbms.scale) @ u.T
        terms += 0.5 * rbms.ops.einsum("ij,ij->i", u, u)
        return terms

    def exact_block(self, block, rbms):
        """Hidden configurations the exact enumeration sums at once."""
        return block

    def sample(self, rbms, means, rng, out=None):
        """Draws from ``p(v | h)`` given its means: ``N(mean, s^2)``."""
        noise = rng.standard_normal(means.shape, dtype=means.dtype, out=out)
        if rbms.visible_std is not None:
            noise *= rbms.visible_std
        return rbms.ops.add(means, noise, out=noise)

    def sample_field(self, field, scale, rng):
        """Draws of visibles of field ``field`` (changed in place) and ``scale``."""
        noise = rng.standard_normal(field.shape, dtype=field.dtype)
        noise *= scale
        field += noise
        return field

    def log_density(self, rbms, visible, field):
        """``log p(v | h)`` per row, ``field`` holding ``s (W_t^T h)``."""
        residual = (visible - rbms.visible_bias - field) / rbms.scale
        ops = rbms.ops
        return -0.5 * ops.einsum("ij,ij->i", residual, residual) - (
            rbms.log_normaliser()
        )

    def observed_log_likelihood(self, rbms, prediction, visible, observed_mask):
        """Log-likelihood of observed entries under a prediction, up to a constant."""
        ops = array_ops(prediction)
        residual = ops.where(observed_mask, visible - prediction, 0)
        if rbms.visible_std is not None:
            residual /= rbms.visible_std
        return -0.5 * ops.einsum("ij,ij->i", residual, residual)

    def clip(self, values):
        """``values`` within the visibles' range."""
        return values

    # ------------------------------------------------------------ annealing

    def base_log_normaliser(self, rbms, visible_base, rows):
        """``log Z_0`` of the base's visibles, per annealing row."""
        return rbms.log_normaliser()

    def change_gradient(self, shift, scale):
        """``g``'s linear coefficient given ``c_hat - m``: ``(c_hat - m) / s^2``."""
        return shift / scale**2

    def change_offset(self, rbms, visible_base, gradient, rows):
        """``g``'s constant, per annealing row: ``g . (c_hat + m) / 2``."""
        ops = rbms.ops
        middle = 0.5 * (rbms.visible_bias + visible_base)
        return ops.take(ops.einsum("ij,ij->i", gradient, middle), rows)


class BinaryUnits(GaussianUnits):
    """The math of binary visible units; their field is the logit of the mean."""

    def activate(self, field):
        return logistic(field, out=field)

    def mean_copy(self, field):
        return logistic(field)

    def field_of(self, visible):
        return clipped_logit(visible)

    def base_field(self, field):
        return clipped_logit(logistic(field))

    def log_normaliser(self, rbms):
        return 0.0

    def free_energy_term(self, rbms, visible):
        return rbms.ops.einsum("ij,ij->i", visible, rbms.visible_bias)

    def add_configuration_terms(self, rbms, u, terms):
        softplus = rbms.ops.logaddexp(0, rbms.visible_bias[:, None, :] + u)
        terms += rbms.ops.sum(softplus, axis=2)
        return terms

    def exact_block(self, block, rbms):
        # the softplus term is (frames, block, features)
        return max(1, min(block, (1 << 22) // max(1, rbms.n_frames * rbms.n_features)))

    def sample(self, rbms, means, rng, out=None):
        return sample_bernoulli(means, rng, out=out)

    def sample_field(self, field, scale, rng):
        return draw_bernoulli(logistic(field, out=field), rng)

    def log_density(self, rbms, visible, field):
        field += rbms.visible_bias
        ops = rbms.ops
        return ops.sum(visible * field - ops.logaddexp(0, field), axis=1)

    def observed_log_likelihood(self, rbms, prediction, visible, observed_mask):
        ops = array_ops(prediction)
        eps = ops.finfo(prediction.dtype).eps
        prediction = ops.clip(prediction, eps, 1 - eps)
        terms = ops.where(visible > 0.5, ops.log(prediction), ops.log1p(-prediction))
        return ops.sum(ops.where(observed_mask, terms, 0), axis=1)

    def clip(self, values):
        return array_ops(values).clip(values, 0, 1)

    def base_log_normaliser(self, rbms, visible_base, rows):
        ops = rbms.ops
        return ops.take(ops.sum(ops.logaddexp(0, visible_base), axis=1), rows)

    def change_gradient(self, shift, scale):
        return shift

    def change_offset(self, rbms, visible_base, gradient, rows):
        return 0.0


VISIBLE_UNITS = {GAUSSIAN: GaussianUnits(), BINARY: BinaryUnits()}


class FrameRBMs(metaclass=ABCMeta):
    """The RBMs of a set of frames: one layer given each frame's past and context.

    Subclasses (one per kind of layer) compute the interaction of each
    frame's visible and hidden units; this class holds the dynamic biases
    and everything that follows from the interaction.

    Parameters
    ----------
    visible_bias : ndarray of shape (n_frames, n_features)
        ``c_hat`` of every frame.
    hidden_bias : ndarray of shape (n_frames, n_components)
        ``b_hat`` of every frame.
    visible_std : ndarray of shape (n_features,) or None
        ``s`` of the Gaussian visibles; None for unit variance (and binary
        visibles).
    units : GaussianUnits or BinaryUnits
        The math of the visible units (:data:`VISIBLE_UNITS`).
    frame_invariant : bool, default=False
        Whether every frame has the same RBM (a layer without history or
        context), so that its partition function is one.
    """

    # arrays with one row per frame, which take() selects
    _row_arrays = ("visible_bias", "hidden_bias")
    # arrays shared by every frame, which astype() converts with the rows
    _shared_arrays = ("visible_std",)

    def __init__(
        self, visible_bias, hidden_bias, visible_std, units, frame_invariant=False
    ):
        self.visible_bias = visible_bias
        self.hidden_bias = hidden_bias
        self.visible_std = visible_std
        self.units = units
        self.frame_invariant = frame_invariant

    # ------------------------------------------------------------ subclasses

    @property
    def shared_weights(self):
        """``W`` (n_components, n_features) when it is every frame's, else None."""
        return None

    @abstractmethod
    def interaction_input(self, visible, out=None):
        """``W_t (v / s)`` of every frame's row of ``visible``."""

    @abstractmethod
    def interaction_field(self, hidden, out=None):
        """``s * (W_t^T h)`` of every frame's row of ``hidden``."""

    # -------------------------------------------------------------- generic

    @property
    def ops(self):
        return array_ops(self.visible_bias)

    @property
    def dtype(self):
        return self.visible_bias.dtype

    @property
    def n_frames(self):
        return self.visible_bias.shape[0]

    @property
    def n_features(self):
        return self.visible_bias.shape[1]

    @property
    def n_components(self):
        return self.hidden_bias.shape[1]

    @property
    def scale(self):
        """``s``, ones for unit variance."""
        if self.visible_std is not None:
            return self.visible_std
        return self.ops.ones(self.n_features, dtype=self.dtype)

    def _replace(self, **arrays):
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.__dict__.update(arrays)
        return new

    def take(self, rows):
        """The RBMs of frames ``rows`` (an index array or a slice)."""
        ops = self.ops
        arrays = {}
        for name in self._row_arrays:
            value = getattr(self, name)
            if value is not None:
                arrays[name] = (
                    value[rows, ...]
                    if isinstance(rows, slice)
                    else ops.take(value, rows, axis=0)
                )
        return self._replace(**arrays)

    def astype(self, dtype):
        """The same RBMs computing in ``dtype``."""
        if dtype == self.dtype:
            return self
        ops = self.ops
        arrays = {}
        for name in (*self._row_arrays, *self._shared_arrays):
            value = getattr(self, name)
            if value is not None:
                arrays[name] = ops.astype(value, dtype)
        return self._replace(**arrays)

    def hidden_input(self, visible, out=None):
        """``b_hat + W_t (v / s)``: each hidden unit's input."""
        activation = self.interaction_input(visible, out=out)
        activation += self.hidden_bias
        return activation

    def hidden_probabilities(self, visible, out=None):
        """``p(h = 1 | v, past) = sigmoid(b_hat + W_t (v / s))`` (paper Eq. 2)."""
        activation = self.hidden_input(visible, out=out)
        return logistic(activation, out=activation)

    def visible_mean(self, hidden, out=None):
        """``E[v | h, past] = c_hat + s (W_t^T h)`` (paper Eq. 3), or its sigmoid."""
        mean = self.interaction_field(hidden, out=out)
        mean += self.visible_bias
        return self.units.activate(mean)

    def sample_visibles(self, means, rng, out=None):
        """Draws from ``p(v | h, past)`` given its means (``out`` if given)."""
        return self.units.sample(self, means, rng, out=out)

    def log_normaliser(self):
        """``sum_i log(sqrt(2 pi) s_i)``: the visible integral's constant (or 0)."""
        return self.units.log_normaliser(self)

    def negative_free_energy(self, visible):
        """``-F(v)`` of every frame's own row of ``visible``: ``log sum_h exp(-E)``."""
        ops = self.ops
        softplus = ops.sum(ops.logaddexp(0, self.hidden_input(visible)), axis=1)
        return self.units.free_energy_term(self, visible) + softplus


class TrainingWorkspace:
    """Buffers a training loop gathers each minibatch into, reused between them.

    ``visible(n)`` and ``history`` hold the minibatch's frames and their
    histories; a layer's workspace adds the buffers its ``cd_statistics``
    needs.
    """

    def __init__(self, layer, batch_size):
        ops, dtype = layer.ops, layer.dtype
        self.batch_size = batch_size
        self._visible = ops.empty((batch_size, layer.n_features), dtype)
        self.history = ops.empty((batch_size, layer.n_lags * layer.n_features), dtype)

    def visible(self, n):
        """Where to gather the visible frames of a minibatch of ``n`` frames."""
        return self._visible[:n, ...]


class ConditionalLayer(PackedParameters, metaclass=ABCMeta):
    """Base class of the kinds of conditional layer (see the module docstring).

    Attributes
    ----------
    n_features, n_components, n_lags : int
    visible_type : {"gaussian", "binary"}
    """

    n_features: int
    n_components: int
    n_lags: int
    visible_type: str = GAUSSIAN

    @property
    def binary(self):
        return self.visible_type == BINARY

    @property
    def visible_units(self):
        """The math of the visible units (:data:`VISIBLE_UNITS`)."""
        return VISIBLE_UNITS[self.visible_type]

    @property
    def visible_std(self):
        """``s``, shape ``(n_features,)``; None for unit variance."""
        return None

    def frame_rbms(self, history, context=None, *, out=None):
        """The frame RBMs of ``n`` frames given their histories and contexts.

        Not to be overridden: a kind of layer provides
        :meth:`frame_invariants` and :meth:`build_frame_rbms`, which this
        and :meth:`conditioner` share.  ``out`` is a buffer the layer may
        build the dynamic biases in.
        """
        return self.build_frame_rbms(self.frame_invariants(), history, context, out=out)

    def conditioner(self):
        """:meth:`frame_rbms` for a model that stays as it is while it is used.

        Its :meth:`frame_invariants` are computed once, here.
        """
        return functools.partial(self.build_frame_rbms, self.frame_invariants())

    def frame_invariants(self):
        """What every frame's RBM shares (a dict), for :meth:`build_frame_rbms`."""
        return {}

    @abstractmethod
    def build_frame_rbms(self, invariants, history, context=None, *, out=None):
        """The frame RBMs of ``n`` frames, given :meth:`frame_invariants`."""

    def product_size(self):
        """Multiply-adds per frame of the layer's largest matrix product.

        The size of its largest weight matrix (every weight matrix multiplies
        a batch of frames, one row per frame); the package sizes its BLAS
        threads by it (:mod:`sklearn_crbm.utils._threads`).
        """
        return max(math.prod(shape) for shape in self._shapes() if len(shape) == 2)

    def new_workspace(self, batch_size):
        return TrainingWorkspace(self, batch_size)

    def __setstate__(self, state):
        # layers pickled before real-valued contexts named their width n_classes
        state = dict(state)
        if "n_classes" in state and "n_context" not in state:
            state["n_context"] = state.pop("n_classes")
        super().__setstate__(state)

    @abstractmethod
    def cd_statistics(
        self, visible, history, context, cd_steps, rng, *, out, scale, workspace
    ):
        """Contrastive-divergence statistics of a minibatch times ``scale``, in ``out``.

        Returns ``out`` and the summed squared reconstruction error (a float
        on numpy, a 0-d array of the namespace otherwise).
        """

    def training_copy(self):
        """The parameters training updates: a copy in the layout BLAS runs fastest."""
        return self.copy(layout="F")

    def fitted_copy(self):
        """Parameters from :meth:`training_copy` as the fitted model keeps them."""
        return self.copy(layout="C")

    def after_update(self):
        """Called after every training update of these parameters."""


def sequence_frame_rbms(layer, X, sequences, frames=None, context=None):
    """Yield ``(rows, rbms)`` for frames of ``X``, chunk by chunk.

    The frame RBMs of every frame in ``frames`` (default: all) given its past
    frames in its own sequence and its row of ``context``; a lag reaching
    before the start of a sequence reads the sequence's first frame instead
    (edge padding).

    Parameters
    ----------
    layer : ConditionalLayer
    X : ndarray of shape (n_frames, n_features)
        Long format.
    sequences : Sequences
        From :func:`~sklearn_crbm.utils._sequences.check_sequence_ids`.
    frames : ndarray of int, default=None
    context : ndarray of shape (n_frames, n_context), default=None

    Yields
    ------
    rows : ndarray of int
        Up to ``CHUNK_FRAMES`` entries of ``frames``.
    rbms : FrameRBMs
    """
    frames = np.arange(X.shape[0]) if frames is None else frames
    starts = sequences.frame_starts()
    ops = array_ops(X)
    for lo in range(0, len(frames), CHUNK_FRAMES):
        rows = frames[lo : lo + CHUNK_FRAMES]
        history = frame_history(X, rows, layer.n_lags, starts[rows])
        rows_context = None if context is None else ops.take(context, rows, axis=0)
        yield rows, layer.frame_rbms(history, rows_context)


def sequence_hidden_probabilities(layer, X, sequences, context=None):
    """``p(h = 1 | x_t, history)`` of every frame of ``X``, edge padded."""
    ops = layer.ops
    hidden = ops.empty((X.shape[0], layer.n_components), dtype=X.dtype)
    for rows, rbms in sequence_frame_rbms(layer, X, sequences, context=context):
        if ops is not np:  # every frame: ranges, basic indexing
            rows = slice(int(rows[0]), int(rows[-1]) + 1)
        hidden[rows, ...] = rbms.hidden_probabilities(X[rows, ...])
    return hidden
