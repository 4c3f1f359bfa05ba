"""Gibbs sampling and mean-field prediction of frames, through one layer or a stack.

Everything here works on :class:`~sklearn_crbm.layers.FrameRBMs`, a layer
given each frame's past and context, so it serves every kind of layer.  A
stack is a list of frame RBMs, bottom first: layer ``k + 1``'s visible
units are layer ``k``'s hidden units.
"""

import math

import numpy as np

from ..utils._array_api import copy_array
from ..utils._random import _MIN_BIT_DRAWS, uniform

__all__ = [
    "HiddenSampler",
    "gibbs_frames",
    "mean_field_prediction",
    "observed_log_likelihood",
    "stacked_gibbs_frames",
    "stacked_prediction",
]


class HiddenSampler:
    """Draws binary hidden states from p(h | v, past) of a set of frame RBMs.

    ``h_j = 1`` where a uniform draw ``u`` falls below ``sigmoid(a_j)``, ``a
    = b_hat + W_t (v / s)``.  The test is evaluated in the form that is
    fastest, each exact up to rounding at the boundary:

    - ``2u - 1 < tanh(a / 2)`` in float32, with ``2u - 1`` drawn directly
      by :func:`~sklearn_crbm.utils._random.uniform` (23 random bits):
      float32 models, and float64 ones drawing at least ``_MIN_BIT_DRAWS``
      states at once (a training minibatch, many chains), whose activations
      are rounded to float32 for the test only: a probability off by a
      relative 1e-7 changes a state with about that probability, far below
      the Monte Carlo noise of the draw itself;
    - ``u * (1 + exp(-a)) < 1`` in float64 for fewer float64 draws (one
      sequence: numpy's 53-bit uniforms), with ``-b_hat`` prepared once.

    A Gibbs chain prepares one sampler per frame and calls it at every step.

    Parameters
    ----------
    rbms : FrameRBMs
    """

    def __init__(self, rbms):
        self._rbms = rbms
        self._ops = ops = rbms.ops
        hidden_bias = rbms.hidden_bias
        self._tanh = (
            rbms.dtype == ops.float32 or math.prod(hidden_bias.shape) >= _MIN_BIT_DRAWS
        )
        # the bias in the form the test adds it: b_hat (tanh) or -b_hat (exp)
        self._scale = 1.0 if self._tanh else -1.0
        self.bias = hidden_bias
        if not self._tanh:
            self.bias = ops.multiply(hidden_bias, self._scale, dtype=rbms.dtype)
        # float64 activations are tested in a float32 copy
        self._threshold = None
        if self._tanh and rbms.dtype != ops.float32 and ops is np:
            self._threshold = np.empty(hidden_bias.shape, np.float32)

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
        activation = self._rbms.interaction_input(visible, out=work)
        if self._tanh:
            if ops is np:
                threshold = activation if self._threshold is None else self._threshold
                threshold = np.add(activation, bias, out=threshold)
            else:  # float64 activations tested in float32, without out=
                threshold = ops.astype(activation + bias, ops.float32)
            threshold *= 0.5
            threshold = ops.tanh(threshold, out=threshold)
            own_draws = out if out.dtype == threshold.dtype else None
            draws = uniform(
                rng, threshold.shape, ops.float32, own_draws, symmetric=True
            )
            return ops.less(draws, threshold, out=out)
        activation = ops.subtract(bias, activation, out=activation)
        draws = uniform(rng, activation.shape, activation.dtype, out=out)
        activation = ops.exp(activation, out=activation)
        activation += 1
        activation *= draws
        return ops.less(activation, 1, out=draws)


def gibbs_frames(
    rbms,
    start,
    n_gibbs,
    rng,
    *,
    hidden_noise=0.0,
    observed_mask=None,
    sample_visibles=False,
    n_mean_field=1,
):
    """Alternating Gibbs sampling of new frames given their frame RBMs.

    The original generation scheme: ``n_gibbs`` iterations in which the
    hidden units are sampled and the visibles set to their mean, then
    ``n_mean_field`` final mean-field steps with hidden probabilities (the
    original code takes one).  ``hidden_noise`` adds N(0, hidden_noise^2)
    to the hidden biases each time hidden states are chosen (paper §4.3).
    Where ``observed_mask`` is True the visibles stay clamped at their value
    in ``start`` (paper §4.4).  With ``sample_visibles=True`` the visibles
    are drawn from ``p(v | h, past)`` at every step and the last draw is
    returned (no mean-field step): an exact Gibbs sampler of ``p(v_t |
    past)``.

    Parameters
    ----------
    rbms : FrameRBMs
        One per chain.
    start : ndarray of shape (n, n_features)
        Initial visible state of each chain.

    Returns
    -------
    frames : ndarray of shape (n, n_features)
    """
    # every step works in these buffers: no allocation inside the loop
    ops = rbms.ops
    visible = copy_array(start)
    sample_hidden = HiddenSampler(rbms)
    hidden = ops.empty_like(rbms.hidden_bias)
    work = ops.empty_like(hidden)
    noise = ops.empty_like(hidden) if hidden_noise else None
    drawn = ops.empty_like(visible) if sample_visibles else None
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        for _ in range(n_gibbs):
            sample_hidden(
                visible, rng, hidden, work, hidden_noise=hidden_noise, noise=noise
            )
            rbms.visible_mean(hidden, out=visible)
            if sample_visibles:
                visible, drawn = rbms.sample_visibles(visible, rng, out=drawn), visible
            if observed_mask is not None:
                ops.copyto(visible, start, where=observed_mask)
    if sample_visibles:
        return visible
    for _ in range(n_mean_field):
        rbms.hidden_probabilities(visible, out=hidden)
        rbms.visible_mean(hidden, out=visible)
        if observed_mask is not None:
            ops.copyto(visible, start, where=observed_mask)
    return visible


def mean_field_prediction(rbms, n_steps):
    """Deterministic estimate of E[v_t | past] by mean-field iteration.

    Starts from the visible bias ``c_hat`` (the directed prediction, so it
    uses nothing but the model and the past) and alternates hidden
    probabilities and visible means ``n_steps`` times.
    """
    visible = rbms.units.activate(copy_array(rbms.visible_bias))
    for _ in range(n_steps):
        visible = rbms.visible_mean(rbms.hidden_probabilities(visible))
    return visible


def stacked_gibbs_frames(
    stack, start, n_gibbs, rng, *, hidden_noise=0.0, observed_mask=None
):
    """Alternating Gibbs sampling of new frames through a whole stack.

    With one layer this is :func:`gibbs_frames`.  With more, each iteration
    passes the frame up the lower layers (hidden probabilities, as the
    layers above were trained on), takes one alternating step of the top
    layer (its hidden units sampled, with ``hidden_noise``; its visibles set
    to their mean), and passes the result down the lower layers as visible
    means, so that the frame itself is the state of the chain and can be
    clamped: where ``observed_mask`` is True it stays at ``start``.  The
    last iteration is mean field.

    Parameters
    ----------
    stack : list of FrameRBMs
        Bottom layer first, each given its own past.
    start : ndarray of shape (n, n_features)

    Returns
    -------
    frames : ndarray of shape (n, n_features)
    """
    if len(stack) == 1:
        return gibbs_frames(
            stack[0],
            start,
            n_gibbs,
            rng,
            hidden_noise=hidden_noise,
            observed_mask=observed_mask,
        )
    ops = stack[0].ops
    visible = copy_array(start)
    top = stack[-1]
    sample_hidden = HiddenSampler(top)
    hidden = ops.empty_like(top.hidden_bias)
    work = ops.empty_like(hidden)
    noise = ops.empty_like(hidden) if hidden_noise else None
    for step in range(n_gibbs + 1):
        state = visible
        for rbms in stack[:-1]:
            state = rbms.hidden_probabilities(state)
        if step < n_gibbs:
            with np.errstate(over="ignore", under="ignore", invalid="ignore"):
                sample_hidden(
                    state, rng, hidden, work, hidden_noise=hidden_noise, noise=noise
                )
        else:
            top.hidden_probabilities(state, out=hidden)
        state = top.visible_mean(hidden)
        for rbms in stack[-2::-1]:
            state = rbms.visible_mean(state)
        visible = state
        if observed_mask is not None:
            visible = ops.where(observed_mask, start, visible)
    return visible


def stacked_prediction(stack, n_steps):
    """One-step prediction of a frame through a stack, from the pasts alone.

    The top layer's :func:`mean_field_prediction`, passed down the lower
    layers as visible means.
    """
    predicted = mean_field_prediction(stack[-1], n_steps)
    for rbms in stack[-2::-1]:
        predicted = rbms.visible_mean(predicted)
    return predicted


def observed_log_likelihood(bottom, prediction, visible, observed_mask):
    """Log-likelihood of a frame's observed channels under a one-step prediction.

    Approximates ``log p(v_o | past)``, up to a constant shared by all rows,
    by the likelihood of ``v_o`` given the model's prediction of the frame
    from its past (:func:`stacked_prediction`): Gaussian with the model's
    visible variances around it, or Bernoulli with it as probabilities.
    Particles of an on-line filter are weighted by it.

    Parameters
    ----------
    bottom : FrameRBMs
        The bottom layer's (its visible type and variances).
    prediction : ndarray of shape (n, n_features)
    visible : ndarray of shape (n, n_features)
        Frames; only the entries where ``observed_mask`` is True are read.
    observed_mask : ndarray of bool of shape (n, n_features)

    Returns
    -------
    log_likelihood : ndarray of shape (n,)
    """
    return bottom.units.observed_log_likelihood(
        bottom, prediction, visible, observed_mask
    )
