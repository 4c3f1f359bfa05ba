"""The mathematics of the conditional RBM, in one place.

Every estimator (ConditionalRBM, StackedCRBM, CRBMImputer) calls these
functions; none re-derives an energy, a conditional or a gradient.

Notation (paper, Section 2): visible frame ``v`` (``n_features``), hidden
units ``h`` (``n_components``), symmetric weights ``W`` (``components_``),
hidden bias ``b``, visible bias ``c``, and the history ``x[t-1], ..., x[t-L]``
flattened lag-major into one row.  The directed connections are packed into
a single matrix ``dynamic`` of shape ``(n_features + n_components, L *
n_features)``: its first ``n_features`` rows are the autoregressive weights
``A`` (past -> visible), the remaining rows the weights ``B`` (past ->
hidden).  Both dynamic biases thus come out of one matrix product::

    [c_hat, b_hat] = history @ dynamic.T + [c, b]

When ``order != hidden_order`` the blocks of lags a group does not use are
kept at exactly zero.

With Gaussian visibles of standard deviation ``s`` (one per channel) the
energy given the history is, in the form of Hinton's practical guide,

    E(v, h) = sum_i (v_i - c_hat_i)^2 / (2 s_i^2) - b_hat . h - (v / s) . (W.T h)

so that ``p(h_j = 1 | v) = sigmoid(b_hat_j + W_j . (v / s))`` and ``p(v | h)
= N(c_hat + s * (W.T h), diag(s^2))``.  The paper fixes ``s = 1``; with
learned variances (Cho, Raiko & Ilin 2011) the group ``log_visible_variance``
holds ``z = log s^2``.  With binary visibles the quadratic term becomes
``-c_hat . v`` (and ``s = 1``), and ``p(v_i = 1 | h) = sigmoid(c_hat_i +
(W.T h)_i)``.
"""

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .utils._array_api import array_ops, copy_array, same_memory
from .utils._sequences import frame_history

GAUSSIAN = "gaussian"
BINARY = "binary"

# float32 exponents of 1.0 and 2.0: OR-ed onto 23 random mantissa bits they
# give floats uniform on [1, 2) and [2, 4) without integer-to-float conversion
_FLOAT32_ONE_BITS = np.uint32(0x3F800000)
_FLOAT32_TWO_BITS = np.uint32(0x40000000)
_MIN_BIT_DRAWS = 4096


def _mantissa_floats(rng, size, exponent_bits):
    """``size`` float32 values in [1, 2) (or [2, 4)) from 23 random bits each.

    Two per 64-bit output of ``rng``'s bit generator, as the mantissa under
    ``exponent_bits`` (:data:`_FLOAT32_ONE_BITS` or :data:`_FLOAT32_TWO_BITS`).
    """
    bits = rng.bit_generator.random_raw((size + 1) // 2).view(np.uint32)[:size]
    np.right_shift(bits, 9, out=bits)
    np.bitwise_or(bits, exponent_bits, out=bits)
    return bits.view(np.float32)


def uniform(rng, shape, dtype, out=None, *, symmetric=False):
    """Uniform draws on [0, 1), or on [-1, 1) if ``symmetric``, in ``dtype``.

    float64 draws come from ``rng.random`` (53 random bits).  float32 draws
    take 23 random bits each, two per 64-bit output of the bit generator,
    as the mantissa of a float in [1, 2) (or [2, 4) if ``symmetric``) from
    which 1 (or 3) is subtracted: no integer-to-float conversion, about
    two thirds of the time of ``rng.random(dtype=np.float32)``, which
    matters in Gibbs sampling where these draws are a large part of every
    step.  Fewer than ``_MIN_BIT_DRAWS`` float32 draws (one sequence, where
    the extra numpy calls cost more than they save) come from
    ``rng.random`` too.  All are reproducible from ``rng``'s state.  Another
    namespace's generator (:class:`~sklearn_crbm.utils._array_api.ArrayRandom`)
    draws with its own ``random``.
    """
    if not isinstance(rng, np.random.Generator):
        draws = rng.random(shape, dtype=dtype, out=out)
        if symmetric:
            draws *= 2
            draws -= 1
        return draws
    dtype = np.dtype(dtype)
    size = math.prod(shape)
    if dtype != np.float32 or size < _MIN_BIT_DRAWS:
        draws = rng.random(shape, dtype=dtype, out=out)
        if symmetric:
            draws *= 2
            draws -= 1
        return draws
    floats = _mantissa_floats(
        rng, size, _FLOAT32_TWO_BITS if symmetric else _FLOAT32_ONE_BITS
    ).reshape(shape)
    return np.subtract(floats, 3 if symmetric else 1, out=out)


def standard_normal(rng, shape, dtype, out=None):
    """Standard normal draws in ``dtype``.

    Fewer than ``_MIN_BIT_DRAWS`` draws (and any other namespace's) are
    ``rng.standard_normal``'s.  Larger arrays, float32 or float64, come
    from the Box-Muller transform, in float32, of 23-bit uniforms ``u, u'``
    (:func:`uniform`'s), ``sqrt(-2 log(1 - u)) * (cos, sin)(2 pi u')``: a
    pair of normals per 64 random bits in a few vectorised passes, about
    five times faster than numpy's ziggurat (which draws one at a time, in
    either dtype), and the history noise of every training minibatch is
    that many draws.  float64 draws are these float32 values, converted:
    plenty for noise.  The tails stop at ``sqrt(46 log 2) =
    5.65`` standard deviations (probability 2e-8 beyond).
    """
    size = math.prod(shape)
    if not isinstance(rng, np.random.Generator) or size < _MIN_BIT_DRAWS:
        return rng.standard_normal(shape, dtype=dtype, out=out)
    half = (size + 1) // 2
    radius, angle = _mantissa_floats(rng, 2 * half, _FLOAT32_ONE_BITS).reshape(2, half)
    np.subtract(2, radius, out=radius)  # 1 - u in (0, 1]: log(0) never taken
    np.log(radius, out=radius)
    radius *= -2
    np.sqrt(radius, out=radius)
    angle -= 1
    angle *= np.float32(2 * np.pi)
    draws = out
    if out is None or out.dtype != np.float32 or not out.flags.c_contiguous:
        draws = np.empty(shape, np.float32)
    # cosines, then sines, each times its radius
    flat = draws.reshape(-1)
    np.cos(angle, out=flat[:half])
    flat[:half] *= radius
    np.sin(angle[: size - half], out=flat[half:])
    flat[half:] *= radius[: size - half]
    if out is None:
        return draws.astype(dtype, copy=False)
    if draws is not out:
        out[...] = draws
    return out


def add_normal_noise(rng, array, scale, work=None):
    """``array += scale * N(0, 1)``, elementwise and in place; returns ``array``.

    The draws are :func:`standard_normal`'s, in float32 where that routine
    computes them in float32 anyway (at least ``_MIN_BIT_DRAWS`` of them
    from a numpy Generator), else in ``array``'s dtype.  ``work``, scratch
    of ``array``'s shape, receives them if it has that dtype.
    """
    noise = _noise_draws(rng, array, work)
    noise *= scale
    array += noise
    return array


def _noise_draws(rng, array, work):
    """Standard normals of ``array``'s shape, in the dtype add_normal_noise uses."""
    dtype = array.dtype
    if isinstance(rng, np.random.Generator) and math.prod(array.shape) >= (
        _MIN_BIT_DRAWS
    ):
        dtype = np.float32
    if work is not None and work.dtype != dtype:
        work = None
    return standard_normal(rng, array.shape, dtype, work)


def add_history_noise(rng, history, scale, n_features, fraction=1.0, work=None):
    """Noise on a random ``fraction`` of the channels of each frame's history.

    ``history`` (shape ``(n, n_lags * n_features)``, lag blocks of
    ``n_features`` channels) gets ``scale * N(0, 1)`` added in place where
    channel ``i`` of frame ``k`` is drawn to be noised, with probability
    ``fraction``, independently for every frame and channel, and then at
    every lag of that channel; the other channels' past stays clean.  The
    noised channels are drawn first (one uniform per frame and channel),
    then the noise as :func:`add_normal_noise` draws it; ``fraction=1``
    draws no uniforms and is :func:`add_normal_noise` itself.  Returns
    ``history``.
    """
    if fraction >= 1:
        return add_normal_noise(rng, history, scale, work)
    ops = array_ops(history)
    xp = np if ops is np else ops.xp
    n = history.shape[0]
    draws = uniform(rng, (n, n_features), history.dtype)
    noise = _noise_draws(rng, history, work)
    noised = ops.astype(ops.less(draws, fraction), noise.dtype)
    noised *= scale
    blocks = xp.reshape(noise, (n, -1, n_features))
    blocks *= xp.reshape(noised, (n, 1, n_features))
    history += xp.reshape(blocks, history.shape)
    return history


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


# Learned visible variances are kept at or above 1e-4 (s >= 0.01, in the units
# of standardised data): a channel that its past predicts almost exactly
# would otherwise shrink s towards 0 and blow up the hidden input v / s.
MIN_LOG_VARIANCE = math.log(1e-4)


def _small_normal(rng, shape, dtype):
    return (0.01 * rng.standard_normal(shape)).astype(dtype, copy=False)


@dataclass(frozen=True)
class ParameterGroup:
    """One trainable array of a CRBM: its shape, start value and penalty.

    Parameters
    ----------
    name : str
        Attribute of :class:`CRBMParameters` that views it.
    shape : callable
        ``shape(params)`` gives its shape from ``n_features``,
        ``n_components`` and ``n_lags``.
    initial : callable
        ``initial(params, rng)`` gives its start value (float64 or the
        parameters' dtype); ``rng`` draws in the order of ``GROUPS``.
    decayed : bool
        Whether weight decay applies to it.
    """

    name: str
    shape: Callable
    initial: Callable
    decayed: bool


def _initial_dynamic(params, rng):
    return (
        _small_normal(rng, params.dynamic.shape, params.dtype) * params.dynamic_mask()
    )


# Every trainable array, in the order its start value is drawn.  A new group
# (say, learned visible variances) is one entry here: storage, views,
# momentum, decay, pickling and the statistics buffers follow from it; its
# gradient goes into ``cd_gradients`` and its public name onto the estimator.
GROUPS = (
    ParameterGroup(
        "dynamic",
        lambda p: (p.n_features + p.n_components, p.n_lags * p.n_features),
        _initial_dynamic,
        decayed=True,
    ),
    ParameterGroup(
        "weights",
        lambda p: (p.n_components, p.n_features),
        lambda p, rng: _small_normal(rng, p.weights.shape, p.dtype),
        decayed=True,
    ),
    ParameterGroup(
        "hidden_bias",
        lambda p: (p.n_components,),
        # hidden units start mostly off
        lambda p, rng: _small_normal(rng, p.hidden_bias.shape, p.dtype) - 1,
        decayed=False,
    ),
    ParameterGroup(
        "visible_bias",
        lambda p: (p.n_features,),
        lambda p, rng: _small_normal(rng, p.visible_bias.shape, p.dtype),
        decayed=False,
    ),
    # z = log s^2; stays 0 (unit variance) unless learned_variance
    ParameterGroup(
        "log_visible_variance",
        lambda p: (p.n_features,),
        lambda p, rng: np.zeros(p.n_features, p.dtype),
        decayed=False,
    ),
)


class CRBMParameters:
    """Every trainable array of one CRBM, packed in one flat buffer.

    Each group of :data:`GROUPS` is an attribute viewing its part of
    :attr:`flat`: ``weights`` ``W`` (n_components, n_features),
    ``hidden_bias`` (n_components,), ``visible_bias`` (n_features,) and
    ``dynamic`` (n_features + n_components, n_lags * n_features), the
    directed weights ``[A; B]`` (see the module docstring).  The decayed
    groups come first, so weight decay is one pass over a prefix of
    :attr:`flat`, and a momentum update one pass over all of it.  The
    estimators' fitted attributes are views of the same buffer.

    Parameters
    ----------
    n_features, n_components, order, hidden_order : int
    visible_type : {"gaussian", "binary"}
    dtype : dtype
    flat : ndarray of shape (n_parameters,), default=None
        The buffer to view; zeros if None.
    learned_variance : bool, default=False
        Whether ``log_visible_variance`` is trained (Gaussian visibles
        only).
    fixed_variance : bool, default=False
        Whether ``log_visible_variance`` holds variances that training
        keeps as they are.  With neither flag it is 0 and the math takes
        the unit-variance path.
    layout : {"C", "F"}, default="C"
        Memory order of the 2-D groups inside ``flat``.  Training works in
        "F", the orientation in which BLAS runs its products fastest;
        fitted models keep "C" (the same numbers, but a matrix-vector
        product rounds differently in the two orders).

    Attributes
    ----------
    flat : ndarray of shape (n_parameters,)
    weights, hidden_bias, visible_bias, dynamic : ndarray
        Views of ``flat``.
    """

    def __init__(
        self,
        n_features,
        n_components,
        order,
        hidden_order,
        visible_type,
        dtype,
        *,
        flat=None,
        layout="C",
        learned_variance=False,
        fixed_variance=False,
        ops=np,
    ):
        self.n_features = n_features
        self.learned_variance = learned_variance
        self.fixed_variance = fixed_variance
        self.n_components = n_components
        self.order = order
        self.hidden_order = hidden_order
        self.visible_type = visible_type
        shapes = [group.shape(self) for group in GROUPS]
        size = sum(math.prod(shape) for shape in shapes)
        self.flat = ops.zeros(size, dtype) if flat is None else flat
        # Fortran order is numpy's alone (the array API reshapes in C order)
        self.layout = layout if isinstance(self.flat, np.ndarray) else "C"
        self._bind(shapes)

    def _bind(self, shapes=None):
        shapes = [group.shape(self) for group in GROUPS] if shapes is None else shapes
        for name, view in self.views(self.flat, shapes).items():
            setattr(self, name, view)

    def views(self, flat, shapes=None):
        """``{group name: view}`` of a buffer laid out like :attr:`flat`."""
        shapes = [group.shape(self) for group in GROUPS] if shapes is None else shapes
        views, offset = {}, 0
        for group, shape in sorted(
            zip(GROUPS, shapes, strict=True), key=lambda pair: not pair[0].decayed
        ):
            size = math.prod(shape)
            part = flat[offset : offset + size]
            if isinstance(part, np.ndarray):
                views[group.name] = part.reshape(shape, order=self.layout)
            else:
                views[group.name] = array_ops(part).xp.reshape(part, shape)
            offset += size
        return views

    @property
    def n_lags(self):
        return max(self.order, self.hidden_order)

    @property
    def visible_std(self):
        """``s``, shape ``(n_features,)``; None for unit variance (the fast path)."""
        if not (self.learned_variance or self.fixed_variance):
            return None
        return self.ops.exp(0.5 * self.log_visible_variance)

    @property
    def visible_variance(self):
        """``s^2``, shape ``(n_features,)``: ones unless learned (a new array)."""
        return self.ops.exp(self.log_visible_variance)

    @visible_variance.setter
    def visible_variance(self, value):
        self.log_visible_variance[...] = self.ops.log(value)

    @property
    def dtype(self):
        return self.flat.dtype

    @property
    def ops(self):
        """The array functions of :attr:`flat`'s namespace (numpy for numpy)."""
        return array_ops(self.flat)

    @property
    def decayed(self):
        """The prefix of :attr:`flat` that weight decay applies to."""
        size = sum(math.prod(getattr(self, g.name).shape) for g in GROUPS if g.decayed)
        return slice(0, size)

    @classmethod
    def initialize(
        cls,
        n_features,
        n_components,
        order,
        hidden_order,
        visible_type,
        dtype,
        rng,
        *,
        learned_variance=False,
        fixed_variance=False,
    ):
        """The original code's initialisation (its ``gaussiancrbm.m``).

        ``W``, ``A``, ``B`` and the visible bias are N(0, 0.01^2); the hidden
        bias is -1 + N(0, 0.01^2) so that hidden units start mostly off;
        visible variances start at 1.
        """
        params = cls(
            n_features,
            n_components,
            order,
            hidden_order,
            visible_type,
            dtype,
            learned_variance=learned_variance,
            fixed_variance=fixed_variance,
        )
        for group in GROUPS:
            getattr(params, group.name)[...] = group.initial(params, rng)
        return params

    def copy(self, layout=None):
        """The same values in a new buffer (laid out ``layout``, default the same)."""
        new = self.zeros_like(layout)
        for name, view in new.views(new.flat).items():
            view[...] = getattr(self, name)
        return new

    def zeros_like(self, layout=None):
        """Parameters of the same shape, all zero: velocities, gradients."""
        return type(self)(
            self.n_features,
            self.n_components,
            self.order,
            self.hidden_order,
            self.visible_type,
            self.dtype,
            layout=self.layout if layout is None else layout,
            learned_variance=self.learned_variance,
            fixed_variance=self.fixed_variance,
            ops=self.ops,
        )

    def __sklearn_array_api_convert__(self, converter):
        """The same parameters with :attr:`flat` converted (C order).

        What :func:`sklearn.utils._array_api.move_estimator_to` calls.  The
        buffer is a copy: a converter may share memory (DLPack on the CPU),
        and training updates it in place.
        """
        source = self if self.layout == "C" else self.copy(layout="C")
        new = copy.copy(source)
        new.flat = copy_array(converter(source.flat))
        new.layout = "C"
        new._bind()
        return new

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

    def dynamic_mask(self):
        """1 where a directed weight exists, 0 on the lags a group does not use."""
        n = self.n_features
        mask = self.ops.zeros(self.dynamic.shape, dtype=self.dtype)
        mask[:n, : self.order * n] = 1
        mask[n:, : self.hidden_order * n] = 1
        return mask

    def is_finite(self):
        ops = self.ops
        return bool(ops.all(ops.isfinite(self.flat)))

    def __getstate__(self):
        # the views would be pickled as copies: keep the buffer, view it again
        state = dict(vars(self))
        for group in GROUPS:
            del state[group.name]
        return state

    def __setstate__(self, state):
        vars(self).update(state)
        self.__dict__.setdefault("fixed_variance", False)
        if "learned_variance" not in state:  # pickled before variances were a group
            self.learned_variance = False
            self.flat = np.concatenate(
                (self.flat, np.zeros(self.n_features, self.dtype))
            )
        self._bind()


def _lag_blocks(matrix, q, n):
    """(rows, q * n) -> a (q, rows, n) view; block ``q-1`` is columns ``(q-1)n:qn``."""
    if not isinstance(matrix, np.ndarray):
        xp = array_ops(matrix).xp
        return xp.permute_dims(xp.reshape(matrix, (matrix.shape[0], q, n)), (1, 0, 2))
    blocks = matrix.view()
    blocks.shape = (matrix.shape[0], q, n)  # raises rather than copy
    return blocks.transpose(1, 0, 2)


def dynamic_biases(params, history, out=None, static=None):
    """Visible and hidden biases of each frame given its flattened history.

    Parameters
    ----------
    params : CRBMParameters
    history : ndarray of shape (n_frames, n_lags * n_features)
    out : ndarray of shape (n_frames, n_features + n_components), default=None
        Where to write both biases side by side (one matrix product).
    static : ndarray of shape (n_features + n_components,), default=None
        ``[visible_bias, hidden_bias]`` if the caller keeps it at hand
        (a loop over frames of a fixed model).

    Returns
    -------
    visible_bias : ndarray of shape (n_frames, n_features)
    hidden_bias : ndarray of shape (n_frames, n_components)
        Views of one array of shape ``(n_frames, n_features + n_components)``.
    """
    n = params.n_features
    ops = params.ops
    if out is None:
        out = ops.empty((history.shape[0], n + params.n_components), params.dtype)
    # one contiguous add is several times faster than two on strided halves
    if static is None:
        static = ops.concatenate((params.visible_bias, params.hidden_bias))
    if params.n_lags == 0:
        out[...] = static
    else:
        out = ops.matmul(history, params.dynamic.T, out=out)
        out += static
    return out[:, :n], out[:, n:]


# Frames whose histories are gathered at once by sequence_dynamic_biases:
# bounds the memory of transform, score and friends on long data.
CHUNK_FRAMES = 4096


def sequence_dynamic_biases(params, X, sequences, frames=None):
    """Yield ``(rows, visible_bias, hidden_bias)`` of frames of ``X``, chunk by chunk.

    The dynamic biases ``c_hat`` and ``b_hat`` of every frame in ``frames``
    (default: all) given its past frames in its own sequence; a lag reaching
    before the start of a sequence reads the sequence's first frame instead
    (edge padding).

    Parameters
    ----------
    params : CRBMParameters
    X : ndarray of shape (n_frames, n_features)
        Long format.
    sequences : Sequences
        From :func:`~sklearn_crbm.utils._sequences.check_sequence_ids`.
    frames : ndarray of int, default=None

    Yields
    ------
    rows : ndarray of int
        Up to ``CHUNK_FRAMES`` entries of ``frames``.
    visible_bias : ndarray of shape (len(rows), n_features)
    hidden_bias : ndarray of shape (len(rows), n_components)
    """
    frames = np.arange(X.shape[0]) if frames is None else frames
    starts = sequences.frame_starts()
    for lo in range(0, len(frames), CHUNK_FRAMES):
        rows = frames[lo : lo + CHUNK_FRAMES]
        history = frame_history(X, rows, params.n_lags, starts[rows])
        yield (rows, *dynamic_biases(params, history))


def sequence_hidden_probabilities(params, X, sequences):
    """``p(h = 1 | x_t, history)`` of every frame of ``X``, edge padded."""
    ops = params.ops
    hidden = ops.empty((X.shape[0], params.n_components), dtype=X.dtype)
    for rows, _, hidden_bias in sequence_dynamic_biases(params, X, sequences):
        if ops is not np:  # every frame: ranges, basic indexing
            rows = slice(int(rows[0]), int(rows[-1]) + 1)
        hidden[rows, ...] = hidden_probabilities(params, X[rows, ...], hidden_bias)
    return hidden


def hidden_probabilities(params, visible, hidden_bias, out=None):
    """p(h = 1 | v, history) = sigmoid(b_hat + W (v / s)) (paper Eq. 2).

    ``out`` (shape ``(n, n_components)``) receives the result if given.
    """
    std = params.visible_std
    if std is not None:
        visible = visible / std
    activation = params.ops.matmul(visible, params.weights.T, out=out)
    activation += hidden_bias
    return logistic(activation, out=activation)


def visible_means(params, hidden, visible_bias, out=None):
    """E[v | h, history] = c_hat + s * (W.T h) (paper Eq. 3).

    ``out`` (shape ``(n, n_features)``) receives the result if given.
    """
    mean = params.ops.matmul(hidden, params.weights, out=out)
    std = params.visible_std
    if std is not None:
        mean *= std
    mean += visible_bias
    if params.visible_type == BINARY:
        mean = logistic(mean, out=mean)
    return mean


def sample_bernoulli(probabilities, rng, out=None):
    """Binary states with the given probabilities, in their dtype.

    One uniform draw per entry, ``state = uniform < probability``; ``out``
    (not ``probabilities`` itself) receives the uniforms, then the states.
    """
    draws = uniform(rng, probabilities.shape, probabilities.dtype, out=out)
    return array_ops(draws).less(draws, probabilities, out=draws)


class HiddenSampler:
    """Draws binary hidden states from p(h | v, history) for fixed dynamic biases.

    ``h_j = 1`` where a uniform draw ``u`` falls below ``sigmoid(a_j)``, ``a =
    v W^T + b_hat``.  The test is evaluated in the form that is fastest,
    each exact up to rounding at the boundary:

    - ``2u - 1 < tanh(a / 2)`` in float32, with ``2u - 1`` drawn directly by
      :func:`uniform` (23 random bits): float32 models, and float64 ones
      drawing at least ``_MIN_BIT_DRAWS`` states at once (a training
      minibatch, many chains), whose activations are rounded to float32 for
      the test only: a probability off by a relative 1e-7 changes a state
      with about that probability, far below the Monte Carlo noise of the
      draw itself;
    - ``u * (1 + exp(-a)) < 1`` in float64 for fewer float64 draws (one
      sequence: numpy's 53-bit uniforms, the stream of earlier versions),
      with ``-b_hat`` prepared once.

    A Gibbs chain prepares one sampler per frame and calls it at every step.

    Parameters
    ----------
    params : CRBMParameters
    hidden_bias : ndarray of shape (n, n_components)
        The dynamic hidden biases ``b_hat``.
    """

    def __init__(self, params, hidden_bias):
        self._ops = ops = params.ops
        self._tanh = (
            params.dtype == ops.float32
            or math.prod(hidden_bias.shape) >= _MIN_BIT_DRAWS
        )
        # the bias in the form the test adds it: b_hat (tanh) or -b_hat (exp)
        self._scale = 1.0 if self._tanh else -1.0
        self.weights = params.weights
        std = params.visible_std
        if std is not None:  # the hidden input is W (v / s)
            self.weights = self.weights / std
        self.bias = hidden_bias
        if not self._tanh or hidden_bias.dtype != params.dtype:
            self.bias = ops.multiply(hidden_bias, self._scale, dtype=params.dtype)
        # float64 activations are tested in a float32 copy
        self._threshold = None
        if self._tanh and params.dtype != ops.float32:
            self._threshold = ops.empty(hidden_bias.shape, ops.float32)

    def __call__(self, visible, rng, out, work, *, hidden_noise=0.0, noise=None):
        """States for ``visible`` (shape ``(n, n_features)``) into ``out``.

        ``work`` (shape ``(n, n_components)``) is scratch; neither it nor
        ``out`` may be an input.  ``hidden_noise`` adds ``N(0,
        hidden_noise^2)`` to every hidden bias for this draw (paper §4.3);
        ``noise`` is then a further scratch array of that shape.

        Call it under ``np.errstate(over="ignore", under="ignore",
        invalid="ignore")`` (a Gibbs loop enters it once): in float64
        ``exp(-a)`` overflows where ``p = 0``, and ``inf * 0`` (``p = 0``,
        ``u = 0``) compares False, as it should.
        """
        ops = self._ops
        bias = self.bias
        if hidden_noise:
            bias = rng.standard_normal(bias.shape, dtype=bias.dtype, out=noise)
            bias *= self._scale * hidden_noise
            bias += self.bias
        activation = ops.matmul(visible, self.weights.T, out=work)
        if self._tanh:
            threshold = activation if self._threshold is None else self._threshold
            threshold = ops.add(activation, bias, out=threshold)
            threshold *= 0.5
            threshold = ops.tanh(threshold, out=threshold)
            draws = uniform(
                rng,
                threshold.shape,
                ops.float32,
                out if self._threshold is None else None,
                symmetric=True,
            )
            return ops.less(draws, threshold, out=out)
        activation = ops.subtract(bias, activation, out=activation)
        draws = uniform(rng, activation.shape, activation.dtype, out=out)
        activation = ops.exp(activation, out=activation)
        activation += 1
        activation *= draws
        return ops.less(activation, 1, out=draws)


def sample_visible_states(params, means, rng, out=None):
    """Draws from p(v | h, history) given its means: N(mean, s^2) or Bernoulli(mean).

    ``out`` (not ``means`` itself) receives the draws if given.
    """
    if params.visible_type == BINARY:
        return sample_bernoulli(means, rng, out=out)
    noise = rng.standard_normal(means.shape, dtype=means.dtype, out=out)
    std = params.visible_std
    if std is not None:
        noise *= std
    return params.ops.add(means, noise, out=noise)


class CDWorkspace:
    """Buffers that :func:`cd_gradients` reuses from one minibatch to the next.

    Sized for minibatches of up to ``batch_size`` frames of one model, so
    that a training loop allocates nothing per minibatch.  ``visible(n)`` and
    ``history`` are where a trainer gathers a minibatch (no copy in
    :func:`cd_gradients` then).
    """

    def __init__(self, params, batch_size):
        n, d, h = batch_size, params.n_features, params.n_components
        dtype, ops = params.dtype, params.ops
        self.batch_size = batch_size
        # [v; v_recon] and [h_data; h_recon]: the W statistics are one product
        self.visible_stack = ops.empty((2 * n, d), dtype)
        self.hidden_stack = ops.empty((2 * n, h), dtype)
        self.hidden = ops.empty((n, h), dtype)
        self.biases = ops.empty((n, d + h), dtype)
        self.delta = ops.empty((n, d + h), dtype)
        self.history = ops.empty((n, params.n_lags * d), dtype)
        self.ones = ops.ones(n, dtype)
        self.bias_sums = ops.empty(d + h, dtype)
        # s * W.T h of the first reconstruction (learned variances, CD-k > 1)
        self.first_mean = ops.empty((n, d), dtype) if params.learned_variance else None
        self.dynamic_mask = None
        if params.order != params.hidden_order:
            self.dynamic_mask = ops.zeros_like(params.dynamic)
            self.dynamic_mask[...] = params.dynamic_mask()  # in the layout of dynamic

    def visible(self, n):
        """Where to gather the visible frames of a minibatch of ``n`` frames."""
        return self.visible_stack[:n, ...]


class MomentumUpdate:
    """Velocities and statistics of one CRBM, laid out like its parameters.

    After every minibatch training applies (the original code's update)::

        velocity = momentum * velocity + statistic         (all groups)
        velocity -= learning_rate * weight_decay * param   (decayed groups)
        param += velocity

    where ``statistic`` is ``learning_rate / n`` times the CD gradient
    (:func:`cd_gradients` writes it into :attr:`statistics`).  Parameters,
    velocities and statistics are :class:`CRBMParameters` with one layout,
    so each line above is one or two numpy passes over a whole buffer.

    Parameters
    ----------
    params : CRBMParameters
        Updated in place.
    velocity : CRBMParameters, default=None
        Laid out like ``params``; zeros if None.

    Attributes
    ----------
    params, velocity, statistics : CRBMParameters
    """

    def __init__(self, params, velocity=None):
        self.params = params
        self.velocity = params.zeros_like() if velocity is None else velocity
        if self.velocity.layout != params.layout:
            self.velocity = self.velocity.copy(params.layout)
        self.statistics = params.zeros_like()
        self._decayed = params.decayed

    def apply(self, momentum, learning_rate, weight_decay):
        """Fold :attr:`statistics` into the velocities and those into the parameters."""
        velocity, statistic = self.velocity.flat, self.statistics.flat
        parameters = self.params.flat
        ops = self.params.ops
        velocity *= momentum
        velocity += statistic
        if weight_decay:  # the statistics are spent: their buffer is scratch
            decay = ops.multiply(
                parameters[self._decayed],
                learning_rate * weight_decay,
                out=statistic[self._decayed],
            )
            velocity[self._decayed] -= decay
        parameters += velocity


class ParameterAverage:
    """Running mean of a CRBM's parameters, one sample per epoch.

    Polyak-Ruppert averaging: with a constant learning rate the CD iterates
    keep wandering around the region they have reached, and their mean is a
    steadier model than any one of them.

    Attributes
    ----------
    mean : CRBMParameters or None
        The mean of the parameters added so far (None before the first).
    count : int
        How many were added.
    """

    def __init__(self):
        self.mean = None
        self.count = 0

    def add(self, params):
        """Fold ``params`` (a :class:`CRBMParameters`) into the mean."""
        self.count += 1
        if self.mean is None:
            self.mean = params.copy()
        else:
            self.mean.flat += (params.flat - self.mean.flat) / self.count


def cd_gradients(
    params,
    visible,
    history,
    cd_steps,
    rng,
    *,
    out=None,
    scale=1.0,
    workspace=None,
    centered=False,
):
    """Contrastive-divergence statistics of one minibatch (paper Eqs. 4-7, §2.2).

    Positive phase: hidden probabilities from the data, binary hidden states
    sampled and used in the positive statistics.  Each reconstruction sets the
    visibles to their mean given sampled hidden states; the negative
    statistics use the hidden *probabilities* of the last reconstruction.
    The visible bias and autoregressive gradients use the residual against
    the dynamic visible bias, which reduces to ``v - v_recon``.

    With learned visible variances (``params.learned_variance``) the weight
    statistics use ``v / s`` and ``v_recon / s``; the visible bias and
    autoregressive statistics stay ``v - v_recon``, which is the gradient
    times ``s^2`` (the natural-gradient scaling of a Gaussian mean, so that
    their steps do not grow as ``s`` shrinks); and the statistic of ``z_i =
    log s_i^2`` is, per frame,

        ((v - c_hat)^2 + c_hat * m_last - v * m_first) / (2 s^2) - 1/2

    with ``m = s * (W.T h)`` for the hidden states behind the first and the
    last reconstruction: the positive term ``-dE/dz`` at the data and the
    sampled ``h_0``, minus the negative term averaged exactly over ``v_k ~
    p(v | h_{k-1})`` (Rao-Blackwellised).  With CD-1 it is ``(v - c_hat)(v
    - v_recon) / (2 s^2) - 1/2``; with no hidden units it vanishes where
    ``s^2`` is the mean squared residual.

    The weight statistics ``h_data.T @ v - h_recon.T @ v_recon`` are one
    matrix product of the stacked ``[h_data; h_recon]`` and ``[v; -v_recon]``;
    those of both directed groups are one product of ``[v - v_recon, h_data -
    h_recon]`` with the history; ``scale`` multiplies these small factors,
    not the products.  :class:`MomentumUpdate` turns the statistics into
    parameter updates.

    With ``centered=True``, ``params`` holds the centred coordinates of
    :func:`shift_centred` (the hidden units see ``(v - c_hat) / s``, the
    residual against the dynamic visible bias) and the statistics are their
    gradients: by the chain rule, those above with, per frame and with
    ``dh = h_data - h_recon``, ``-dh (c_hat / s)`` added to the weights',
    ``-s * (W.T dh)`` to the visible delta (so to the visible bias and
    autoregressive statistics) and ``c_hat (W.T dh) / (2 s)`` to that of
    ``log s^2``; the hidden and past-to-hidden statistics are unchanged.
    Their steps do not drag the hidden units' dynamic biases along with
    every change of the visible mean (Montavon & Müller's centring, Cho,
    Raiko & Ilin's enhanced gradient).

    Parameters
    ----------
    params : CRBMParameters
    visible : ndarray of shape (n, n_features)
    history : ndarray of shape (n, n_lags * n_features)
    cd_steps : int
    rng : numpy.random.Generator
    out : CRBMParameters, default=None
        Receives ``scale * gradient`` group by group (new if None).
    scale : float
    workspace : CDWorkspace, default=None
        Buffers for minibatches of at least ``n`` frames.
    centered : bool, default=False
        Whether ``params`` are centred coordinates (see above).

    Returns
    -------
    gradients : CRBMParameters
        Sums over the batch (not means), group by group; ascent directions
        (``out`` if given).
    squared_error : float or 0-d array
        Sum over the batch of ``||v - v_recon||^2`` (a 0-d array of the
        namespace for other namespaces than numpy).
    """
    n, d = visible.shape
    ops = params.ops
    if workspace is None:
        workspace = CDWorkspace(params, n)
    if out is None:
        out = params.zeros_like()
    stacked_visible = workspace.visible_stack[: 2 * n, ...]
    stacked_hidden = workspace.hidden_stack[: 2 * n, ...]
    data, reconstruction = stacked_visible[:n, ...], stacked_visible[n:, ...]
    positive_states, negative_probabilities = (
        stacked_hidden[:n, ...],
        stacked_hidden[n:, ...],
    )
    if not same_memory(visible, data):
        ops.copyto(data, visible)

    visible_bias, hidden_bias = dynamic_biases(
        params, history, out=workspace.biases[:n, ...]
    )
    std = params.visible_std
    if centered:  # the hidden input of the standard form: b_hat - W (c_hat / s)
        centre = visible_bias if std is None else visible_bias / std
        hidden_bias -= ops.matmul(centre, params.weights.T)
    sample_hidden = HiddenSampler(params, hidden_bias)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        sample_hidden(data, rng, out=positive_states, work=workspace.hidden[:n, ...])

    hidden = positive_states
    learned = params.learned_variance
    for step in range(cd_steps):
        visible_means(params, hidden, visible_bias, out=reconstruction)
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
            hidden_probabilities(
                params, reconstruction, hidden_bias, out=negative_probabilities
            )

    delta = workspace.delta[:n, ...]
    visible_delta = ops.subtract(data, reconstruction, out=delta[:, :d])
    ops.subtract(positive_states, negative_probabilities, out=delta[:, d:])
    squared_error = ops.einsum("ij,ij->", visible_delta, visible_delta)
    if ops is np:  # elsewhere it stays on the device: no sync per minibatch
        squared_error = float(squared_error)

    if learned:
        _log_variance_statistic(
            params,
            data,
            reconstruction,
            visible_bias,
            workspace.first_mean[:n, ...],
            scale,
            out=out.log_visible_variance,
        )
    else:
        out.log_visible_variance[...] = 0
    if centered:
        _centre_statistics(params, std, visible_bias, delta, d, scale, out)
    # the scale goes into the small factors: [v; -v_recon] and delta; W's
    # statistics are those of v / s
    visible_scale = scale if std is None else scale / std
    data *= visible_scale
    ops.multiply(reconstruction, -visible_scale, out=reconstruction)
    delta *= scale
    ops.matmul(stacked_hidden.T, stacked_visible, out=out.weights)
    if centered:
        out.weights -= ops.matmul(delta[:, d:].T, centre)
    bias_sums = ops.dot(workspace.ones[:n], delta, out=workspace.bias_sums)
    out.visible_bias[...] = bias_sums[:d]
    out.hidden_bias[...] = bias_sums[d:]
    if params.n_lags:
        ops.matmul(delta.T, history, out=out.dynamic)
        if workspace.dynamic_mask is not None:
            out.dynamic *= workspace.dynamic_mask
    return out, squared_error


def _centre_statistics(params, std, visible_bias, delta, d, scale, out):
    """The chain-rule terms of the centred coordinates (see cd_gradients).

    Changes the visible part of ``delta`` (not yet scaled) and, with learned
    variances, the statistic of ``log s^2`` in ``out``; ``std`` is
    ``params.visible_std``.
    """
    ops = params.ops
    back = ops.matmul(delta[:, d:], params.weights)  # W.T dh, frame by frame
    if params.learned_variance:
        term = ops.sum(visible_bias * back, axis=0) / (2 * std)
        out.log_visible_variance[...] = out.log_visible_variance + scale * term
    if std is not None:
        back *= std
    delta[:, :d] -= back


def shift_centred(params, direction):
    """Move ``params`` in place to centred coordinates (``+1``) or back (``-1``).

    In centred coordinates the hidden units see the residual against the
    dynamic visible bias, ``b' + B' x_past + W ((v - c_hat) / s)``: the same
    model as the standard form ``b + B x_past + W (v / s)`` with ``b = b' -
    W (c / s)`` and ``B_q = B'_q - W diag(1 / s) A_q``, where ``c`` and
    ``A`` are the static visible bias and the autoregressive weights.
    Needs ``hidden_order >= order``.
    """
    ops = params.ops
    n = params.n_features
    std = params.visible_std
    weights = params.weights if std is None else params.weights / std
    params.hidden_bias[...] = params.hidden_bias + direction * ops.matmul(
        weights, params.visible_bias
    )
    width = params.order * n
    if width:
        shift = ops.matmul(weights, params.dynamic[:n, :width])
        params.dynamic[n:, :width] = params.dynamic[n:, :width] + direction * shift
    return params


def _log_variance_statistic(
    params, data, reconstruction, visible_bias, first, scale, out
):
    """``scale`` times the summed CD statistic of ``z = log s^2`` (see cd_gradients)."""
    ops = params.ops
    last = reconstruction - visible_bias
    statistic = ops.square(data - visible_bias)
    statistic += visible_bias * last
    statistic -= data * first
    total = ops.sum(statistic, axis=0)
    total /= 2 * params.visible_variance
    total -= 0.5 * data.shape[0]
    return ops.multiply(total, scale, out=out)


def gibbs_frames(
    params,
    start,
    visible_bias,
    hidden_bias,
    n_gibbs,
    rng,
    *,
    hidden_noise=0.0,
    observed_mask=None,
    sample_visibles=False,
):
    """Alternating Gibbs sampling of new frames given their dynamic biases.

    The original generation scheme (the original code's ``gen.m``): ``n_gibbs``
    iterations in which the hidden units are sampled and the visibles set to
    their mean, then one final mean-field step with hidden probabilities.
    ``hidden_noise`` adds N(0, hidden_noise^2) to the hidden biases each time
    hidden states are chosen (paper §4.3).  Where ``observed_mask`` is True
    the visibles stay clamped at their value in ``start`` (paper §4.4).
    With ``sample_visibles=True`` the visibles are drawn from ``p(v | h,
    history)`` at every step and the last draw is returned (no mean-field
    step): an exact Gibbs sampler of ``p(v_t | history)``.

    Parameters
    ----------
    start : ndarray of shape (n, n_features)
        Initial visible state of each chain.
    visible_bias, hidden_bias : ndarray
        Dynamic biases from :func:`dynamic_biases`.

    Returns
    -------
    frames : ndarray of shape (n, n_features)
    """
    # every step works in these buffers: no allocation inside the loop
    ops = params.ops
    visible = copy_array(start)
    visible_bias = ops.ascontiguousarray(visible_bias)
    sample_hidden = HiddenSampler(params, hidden_bias)
    hidden = ops.empty_like(sample_hidden.bias)
    work = ops.empty_like(hidden)
    noise = ops.empty_like(hidden) if hidden_noise else None
    drawn = ops.empty_like(visible) if sample_visibles else None
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        for _ in range(n_gibbs):
            sample_hidden(
                visible, rng, hidden, work, hidden_noise=hidden_noise, noise=noise
            )
            visible_means(params, hidden, visible_bias, out=visible)
            if sample_visibles:
                visible, drawn = (
                    sample_visible_states(params, visible, rng, out=drawn),
                    visible,
                )
            if observed_mask is not None:
                ops.copyto(visible, start, where=observed_mask)
    if sample_visibles:
        return visible
    hidden_probabilities(params, visible, hidden_bias, out=hidden)
    visible_means(params, hidden, visible_bias, out=visible)
    if observed_mask is not None:
        ops.copyto(visible, start, where=observed_mask)
    return visible


def mean_field_prediction(params, visible_bias, hidden_bias, n_steps):
    """Deterministic estimate of E[v_t | history] by mean-field iteration.

    Starts from the autoregressive prediction ``c_hat`` (so it uses nothing
    but the model and the history) and alternates hidden probabilities and
    visible means ``n_steps`` times.
    """
    visible = copy_array(visible_bias)
    if params.visible_type == BINARY:
        visible = logistic(visible, out=visible)
    for _ in range(n_steps):
        visible = visible_means(
            params, hidden_probabilities(params, visible, hidden_bias), visible_bias
        )
    return visible


def stacked_gibbs_frames(
    layers,
    start,
    visible_biases,
    hidden_biases,
    n_gibbs,
    rng,
    *,
    hidden_noise=0.0,
    observed_mask=None,
):
    """Alternating Gibbs sampling of new frames through a whole stack of CRBMs.

    With one layer this is :func:`gibbs_frames`.  With more, each iteration
    passes the frame up the lower layers (hidden probabilities, as the
    layers above were trained on), takes one alternating step of the top
    layer (its hidden units sampled, with ``hidden_noise``, by
    :class:`HiddenSampler`; its visibles set to their mean), and passes the
    result down the lower layers as visible means, so that the frame itself
    is the state of the chain and can be clamped: where ``observed_mask`` is
    True it stays at ``start``.  The last iteration is mean field.

    Parameters
    ----------
    layers : list of CRBMParameters
        Bottom layer first; layer ``l + 1``'s visibles are layer ``l``'s
        hidden units.
    start : ndarray of shape (n, n_features)
    visible_biases, hidden_biases : list of ndarray
        Every layer's dynamic biases (:func:`dynamic_biases` with that
        layer's own history).

    Returns
    -------
    frames : ndarray of shape (n, n_features)
    """
    if len(layers) == 1:
        return gibbs_frames(
            layers[0],
            start,
            visible_biases[0],
            hidden_biases[0],
            n_gibbs,
            rng,
            hidden_noise=hidden_noise,
            observed_mask=observed_mask,
        )
    visible = copy_array(start)
    clamped = None if observed_mask is None else start[observed_mask]
    top = layers[-1]
    ops = top.ops
    sample_hidden = HiddenSampler(top, hidden_biases[-1])
    hidden = ops.empty_like(sample_hidden.bias)
    work = ops.empty_like(hidden)
    noise = ops.empty_like(hidden) if hidden_noise else None
    for step in range(n_gibbs + 1):
        state = visible
        for params, hidden_bias in zip(layers[:-1], hidden_biases[:-1], strict=True):
            state = hidden_probabilities(params, state, hidden_bias)
        if step < n_gibbs:
            with np.errstate(over="ignore", under="ignore", invalid="ignore"):
                sample_hidden(
                    state, rng, hidden, work, hidden_noise=hidden_noise, noise=noise
                )
        else:
            hidden_probabilities(top, state, hidden_biases[-1], out=hidden)
        state = visible_means(top, hidden, visible_biases[-1])
        below = zip(layers[-2::-1], visible_biases[-2::-1], strict=True)
        for params, visible_bias in below:
            state = visible_means(params, state, visible_bias)
        visible = state
        if clamped is not None:
            visible[observed_mask] = clamped
    return visible


def stacked_prediction(layers, visible_biases, hidden_biases, n_steps):
    """One-step prediction of a frame through a stack, from the histories alone.

    The top layer's :func:`mean_field_prediction`, passed down the lower
    layers as visible means.
    """
    predicted = mean_field_prediction(
        layers[-1], visible_biases[-1], hidden_biases[-1], n_steps
    )
    below = zip(layers[-2::-1], visible_biases[-2::-1], strict=True)
    for params, visible_bias in below:
        predicted = visible_means(params, predicted, visible_bias)
    return predicted


def observed_log_likelihood(params, prediction, visible, observed_mask):
    """Log-likelihood of a frame's observed channels under a one-step prediction.

    Approximates ``log p(v_o | history)``, up to a constant shared by all
    rows, by the likelihood of ``v_o`` given the model's prediction of the
    frame from its history (:func:`mean_field_prediction` or
    :func:`stacked_prediction`): Gaussian with the model's visible variances
    around it, or Bernoulli with it as probabilities.  Particles of an
    on-line filter are weighted by it.

    Parameters
    ----------
    params : CRBMParameters
        The bottom layer (its visible type).
    prediction : ndarray of shape (n, n_features)
    visible : ndarray of shape (n, n_features)
        Frames; only the entries where ``observed_mask`` is True are read.
    observed_mask : ndarray of bool of shape (n, n_features)

    Returns
    -------
    log_likelihood : ndarray of shape (n,)
    """
    ops = params.ops
    if params.visible_type == BINARY:
        eps = ops.finfo(prediction.dtype).eps
        prediction = ops.clip(prediction, eps, 1 - eps)
        terms = ops.where(visible > 0.5, ops.log(prediction), ops.log1p(-prediction))
        return ops.sum(ops.where(observed_mask, terms, 0), axis=1)
    residual = ops.where(observed_mask, visible - prediction, 0)
    std = params.visible_std
    if std is not None:
        residual /= std
    return -0.5 * ops.einsum("ij,ij->i", residual, residual)
