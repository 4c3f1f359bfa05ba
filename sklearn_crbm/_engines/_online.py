"""Advancing sequences frame by frame from their own past: generation and fill-in.

Every model's ``sample`` (:class:`~sklearn_crbm.ConditionalRBM`,
:class:`~sklearn_crbm.StackedCRBM`, :class:`~sklearn_crbm.FactoredCRBM`,
:class:`~sklearn_crbm.LabelledCRBM`) and
:class:`~sklearn_crbm.impute.CRBMImputer` call :func:`run_online`, with
one layer or a stack, of any kind (:mod:`sklearn_crbm.layers`):

- generation: nothing observed, every frame of every sequence drawn from a
  seed history;
- fill-in: the observed channels of every frame clamped, several chains per
  sequence (``n_draws * n_particles``), particles resampled before every
  frame, and a sequence's first frame filled from itself as its own past.

The loop is written once for numpy and every array API namespace: every
sequence advances at every step (a sequence that has ended repeats its last
frame, a draw its caller ignores), and what differs between sequences is
masked, never scattered, so nothing is indexed on a device but whole axes.
:class:`History` keeps the recent past of every chain at every layer and
gives the frame RBMs of the next frame.
"""

import math
from dataclasses import dataclass
from numbers import Real

import numpy as np

from ..layers._base import sequence_hidden_probabilities
from ..utils._array_api import array_ops, copy_array, to_numpy
from ..utils._sequences import Sequences
from ._gibbs import (
    gibbs_frames,
    stacked_gibbs_frames,
    stacked_prediction,
)
from ._resampling import PREDICTION_STEPS, _ancestors, _take_chains

__all__ = [
    "TOP_LAYER",
    "WHOLE_STACK",
    "History",
    "Observed",
    "collect_fills",
    "run_online",
]

# Frames over which the random offset of hidden_drift persists (0.17 s at
# 30 frames per second).
DRIFT_FRAMES = 5

# How a stack draws a frame (``scheme`` of run_online).  With one layer the two
# are the same alternating Gibbs run of that layer.
TOP_LAYER = "top_layer"
"""The original two-level generation: Gibbs sampling in the top layer given
its own past, then one deterministic pass down (each layer's visible means
given its own past).  Every layer's past is the values that pass produced.
Nothing can be clamped: the data sit at the bottom."""
WHOLE_STACK = "whole_stack"
"""Every Gibbs iteration goes up the stack and down again
(:func:`~sklearn_crbm._engines._gibbs.stacked_gibbs_frames`), so the state of the
chain is the frame itself and its observed channels can be clamped.  The
upper layers' past is the final frame passed up (hidden probabilities)."""

# Rounds of "fill, then use the fill as its own past" for the first frame of a
# sequence in fill-in, which has no past frames.
FIRST_FRAME_ROUNDS = 3


class History:
    """The recent past of chains of sequences at every layer of a model.

    Parameters
    ----------
    layers : list of ConditionalLayer
        Bottom first.
    windows : list of ndarray
        One per layer, of shape ``(n_chains, n_sequences, n_slots,
        n_visible)`` with ``n_slots = max(n_lags, 1)``: the layer's last
        visible values, most recent first (the frames for the bottom layer,
        the layer below's hidden probabilities above it).
    context : ndarray of shape (n_chains, n_sequences, n_context), default=None
        Each chain's own context, used when a step gives none (it follows
        the chain's past when particles are resampled).
    """

    def __init__(self, layers, windows, context=None):
        self.layers = layers
        self.windows = windows
        self.context = context
        self._ops = layers[0].ops
        # the frame RBMs of a model that does not change while it runs
        self._conditioners = [layer.conditioner() for layer in layers]

    @property
    def shape(self):
        """``(n_chains, n_sequences)``."""
        return tuple(self.windows[0].shape[:2])

    @classmethod
    def from_frames(cls, layers, frames, context=None):
        """The past made of ``frames``, passed up the layers with edge padding.

        Parameters
        ----------
        frames : ndarray of shape (n_chains, n_sequences, n_frames, n_features)
            Oldest first.  Layer ``k + 1`` sees layer ``k``'s hidden
            probabilities of these frames, each given its past inside
            ``frames`` (the first frame repeated where that runs out, as
            :meth:`ConditionalRBM.transform` does), and keeps those with a
            full past at layer ``k`` (at least the last one).  A window
            longer than what a layer keeps repeats the oldest kept value.
        context : ndarray of shape (n_chains, n_sequences, n_context), default=None
            Every chain's context, the same for all its frames.
        """
        n_chains, n_sequences = frames.shape[:2]
        ops = layers[0].ops
        windows = []
        values = frames
        for k, layer in enumerate(layers):
            n_frames = values.shape[2]
            n_slots = max(layer.n_lags, 1)
            picks = np.maximum(np.arange(n_frames - 1, n_frames - 1 - n_slots, -1), 0)
            windows.append(ops.ascontiguousarray(ops.take(values, picks, axis=2)))
            if k + 1 < len(layers):
                flat = ops.reshape(values, (-1, values.shape[3]))
                n_rows = n_chains * n_sequences
                sequences = Sequences(
                    starts=np.arange(0, flat.shape[0], n_frames, dtype=np.intp),
                    lengths=np.full(n_rows, n_frames, dtype=np.intp),
                    ids=np.arange(n_rows),
                )
                frame_context = None
                if context is not None:
                    rows = np.repeat(np.arange(n_rows), n_frames)
                    frame_context = ops.take(
                        ops.reshape(context, (n_rows, -1)), rows, axis=0
                    )
                hidden = sequence_hidden_probabilities(
                    layer, flat, sequences, frame_context
                )
                hidden = ops.reshape(hidden, (n_chains, n_sequences, n_frames, -1))
                values = hidden[:, :, min(layer.n_lags, n_frames - 1) :, ...]
        return cls(layers, windows, context)

    def select(self, sequences):
        """The past of some sequences only (for a block of work)."""
        ops = self._ops
        context = self.context
        if context is not None:
            context = ops.take(context, sequences, axis=1)
        return History(
            self.layers,
            [ops.take(w, sequences, axis=1) for w in self.windows],
            context,
        )

    def previous(self, level):
        """The last values at ``level``, ``(n_chains, n_sequences, n_visible)``."""
        return self.windows[level][:, :, 0, ...]

    def frame_rbms(self, context=None):
        """Every layer's frame RBMs for the next frame of every chain.

        ``context`` (shape ``(n_sequences, n_context)``, or with a leading
        chain axis) is the frame's; None uses the chains' own
        :attr:`context`.  The RBMs have one row per chain and sequence,
        chain-major.
        """
        ops = self._ops
        n_chains, n_sequences = self.shape
        if context is None:
            context = self.context
        if context is not None:
            context = ops.broadcast_to(
                context, (n_chains, n_sequences, context.shape[-1])
            )
            context = ops.reshape(context, (n_chains * n_sequences, -1))
        stack = []
        for layer, window, conditioner in zip(
            self.layers, self.windows, self._conditioners, strict=True
        ):
            past = ops.reshape(window, (n_chains * n_sequences, -1))
            past = past[:, : layer.n_lags * layer.n_features]
            stack.append(conditioner(past, context))
        return stack

    def push(self, values, stack):
        """Append a new frame of every chain at every layer.

        ``values`` holds the frame's value at the lowest layers, bottom
        first (at least the frame itself); the layers above get the hidden
        probabilities of the layer below, given ``stack`` (from
        :meth:`frame_rbms` for this frame).
        """
        ops = self._ops
        values = list(values)
        for k in range(len(values), len(self.layers)):
            below = values[-1]
            flat = stack[k - 1].hidden_probabilities(
                ops.reshape(below, (-1, below.shape[-1]))
            )
            values.append(ops.reshape(flat, (*below.shape[:2], -1)))
        for window, value in zip(self.windows, values, strict=True):
            # a copy: the array API leaves overlapping assignment undefined
            window[:, :, 1:, ...] = copy_array(window[:, :, :-1, ...])
            window[:, :, 0, ...] = value

    def reorder(self, chains):
        """Give chain ``i`` of sequence ``s`` the past of chain ``chains[i, s]``."""
        self.windows = [_take_chains(self._ops, w, chains) for w in self.windows]
        if self.context is not None:
            self.context = _take_chains(self._ops, self.context, chains)


@dataclass(frozen=True)
class Observed:
    """The data of fill-in: frames whose missing entries are to be drawn.

    Attributes
    ----------
    X : ndarray of shape (n_frames, n_features)
        Long format, in the model's dtype; where ``missing`` is True it holds
        the value a sequence's first frame starts from (e.g. the training
        mean).
    missing : ndarray of bool of shape (n_frames, n_features)
    sequences : Sequences
    context : ndarray of shape (n_frames, n_context), default=None
        Every frame's context, for a model that uses one.
    """

    X: np.ndarray
    missing: np.ndarray
    sequences: Sequences
    context: np.ndarray = None


class Offsets:
    """Each chain's systematic one-step error per sequence and channel.

    A model that fills a sequence from its own past drifts towards its own
    typical values (a slow posture channel towards the training posture);
    while a channel is observed, its one-step residual ``r_t = x_t -
    x_hat_t`` (``x_hat_t`` the chain's mean-field prediction of the frame
    from its past, :func:`~sklearn_crbm._engines._gibbs.stacked_prediction`) shows
    that error.  The correction of a missing entry is the posterior mean of
    a constant offset ``d`` behind the residuals, ``r_t = d + noise``, with a
    prior worth ``shrinkage`` frames of zero residual: ``sum(r) / (n +
    shrinkage)`` over the ``n`` frames of the sequence in which the channel
    was observed so far (counted from the model's order on: earlier frames
    have an edge-padded past).  Binary visibles' fills are probabilities,
    and stay in [0, 1].

    Parameters
    ----------
    n_chains, n_sequences : int
    bottom : ConditionalLayer
        The bottom layer (its number of features and visible type).
    shrinkage : float
    dtype : dtype
    """

    def __init__(self, n_chains, n_sequences, bottom, shrinkage, *, dtype):
        self._ops = ops = bottom.ops
        self.sums = ops.zeros((n_chains, n_sequences, bottom.n_features), dtype)
        self.counts = ops.zeros((n_sequences, bottom.n_features), dtype)
        self.shrinkage = shrinkage
        self.units = bottom.visible_units

    def update(self, prediction, frames, observed):
        """Add the residuals of ``frames`` (one per sequence) where ``observed``.

        ``prediction`` is every chain's one-step prediction of the frames,
        of shape ``(n_chains, *frames.shape)``.
        """
        ops = self._ops
        self.sums += ops.where(observed, frames - prediction, 0)
        self.counts += ops.astype(observed, self.counts.dtype)

    def corrected(self, frames, missing):
        """Every chain's ``frames``, corrected where ``missing``."""
        ops = self._ops
        # a channel never observed has a zero sum; the floor spares 0 / 0
        denominator = ops.maximum(self.counts + self.shrinkage, 1)
        frames = frames + ops.where(missing, self.sums / denominator, 0)
        return self.units.clip(frames)

    def reorder(self, chains):
        """The chains' offsets follow their pasts (:meth:`History.reorder`)."""
        self.sums = _take_chains(self._ops, self.sums, chains)


def run_online(
    layers,
    rng,
    *,
    history=None,
    n_steps=None,
    observed=None,
    context=None,
    chain_context=None,
    n_chains=1,
    n_particles=1,
    n_gibbs=30,
    scheme=WHOLE_STACK,
    start_jitter=0.0,
    hidden_noise=0.0,
    sample_visibles=False,
    n_mean_field=1,
    offset_shrinkage=None,
    observation_gain=1.0,
    hidden_drift=0.0,
):
    """Draw frames one after another, each given the chains' own past.

    For every frame, every chain starts a Gibbs run at its previous frame
    (plus ``N(0, start_jitter^2)`` noise), with the frame's observed
    channels clamped, and the frame's result joins the chain's past.

    Parameters
    ----------
    layers : list of ConditionalLayer
        The model, bottom layer first.
    rng : numpy.random.Generator or ArrayRandom
    history : History, default=None
        The past the first frame follows (generation).  ``None`` (fill-in
        only) starts every sequence with no past: its first frame is filled
        ``FIRST_FRAME_ROUNDS`` times, each time with the latest fill as its
        own past (edge padding), starting from ``observed.X``.
    n_steps : int, default=None
        Frames to generate; with ``observed``, the longest sequence's length.
    observed : Observed, default=None
        Fill-in: sequence ``s`` has a frame at step ``t`` while ``t`` is below
        its length; only frames with a missing entry are drawn, and their
        observed entries are clamped.  None: generation, every sequence of
        ``history`` draws every entry of ``n_steps`` frames.
    context : ndarray of shape (n_sequences, n_steps, n_context), default=None
        Generation: every new frame's context (e.g. style label weights).
        In fill-in the frames' contexts are ``observed.context``.
    chain_context : ndarray of shape (n_chains, n_sequences, n_context), default=None
        Fill-in without ``observed.context``: each chain's own context
        (hypotheses about it, which particle resampling weighs).
    n_chains : int, default=1
        Chains per sequence (``history``'s, when given).
    n_particles : int, default=1
        With more than one, chains are groups of this many particles:
        before each frame, each group is resampled by how well each
        particle's one-step prediction explains the frame's observed
        channels (systematic resampling).
    n_gibbs : int, default=30
        Alternating Gibbs iterations per frame; the last step is mean field
        unless ``sample_visibles``.
    scheme : {"top_layer", "whole_stack"}, default="whole_stack"
        How a stack draws a frame: :data:`TOP_LAYER` (generation as the
        original code did it) or :data:`WHOLE_STACK` (needed to clamp).  With
        one layer both are the same.
    start_jitter : float, default=0.0
        Standard deviation of the noise on each chain's start.
    hidden_noise : float, default=0.0
        Noise on the (top) hidden biases each time hidden states are drawn
        (paper §4.3).
    sample_visibles : bool, default=False
        Draw the visibles at every step (:func:`gibbs_frames`); one layer,
        or the top layer with :data:`TOP_LAYER`.
    n_mean_field : int, default=1
        Mean-field steps that end each frame's Gibbs run in
        :func:`gibbs_frames` (not with :data:`WHOLE_STACK` on a stack).
    hidden_drift : float, default=0.0
        Generation only: standard deviation of a smooth random offset of
        each chain's (top) hidden biases, which persists over about
        :data:`DRIFT_FRAMES` frames (:func:`_drift_step`) and holds through
        the whole Gibbs run of a frame, mean-field steps included.
    offset_shrinkage : float, default=None
        Fill-in only.  ``None``: no correction.  A number ``lam >= 0``: each
        chain's drawn entries are shifted by the chain's :class:`Offsets`
        correction (its mean one-step residual of that channel in that
        sequence so far, shrunk by ``lam`` frames).
    observation_gain : float or ndarray of shape (n_features,), default=1.0
        Fill-in only.  The hidden units of a chain see each observed channel
        at ``x_hat + observation_gain * (x - x_hat)`` (a gain per channel if
        an array) instead of at its value ``x``, ``x_hat`` being the chain's
        one-step prediction of the frame from its past: the observed
        channels' surprise counts ``observation_gain`` times.  The frame
        keeps the observed values.  ``1``: the model's own conditional.  A
        sequence's first frame (no past) is filled without it.

    Yields
    ------
    step : int
    frames : ndarray of shape (n_chains, n_sequences, n_features)
        Every chain's frame of every sequence at this step, on every
        backend.  In fill-in, a sequence that has ended repeats its last
        frame (to be ignored) and a frame with nothing missing comes back as
        it is.
    """
    if scheme not in (TOP_LAYER, WHOLE_STACK):
        raise ValueError(f"unknown scheme {scheme!r}")
    stacked = len(layers) > 1
    if stacked and scheme == TOP_LAYER and observed is not None:
        raise ValueError("a stack can clamp observed channels only with whole_stack")
    if stacked and scheme == WHOLE_STACK and sample_visibles:
        raise ValueError("sample_visibles needs one layer or the top_layer scheme")

    def draw(start, stack, clamp):
        """One Gibbs run per chain and sequence; the frame's lowest values."""
        shape = start.shape
        flat = [ops.reshape(start, (-1, shape[-1]))]
        clamp = None if clamp is None else ops.reshape(clamp, (-1, shape[-1]))
        if stacked and scheme == WHOLE_STACK:
            frame = stacked_gibbs_frames(
                stack,
                flat[0],
                n_gibbs,
                rng,
                hidden_noise=hidden_noise,
                observed_mask=clamp,
            )
            return [ops.reshape(frame, shape)]
        flat = [
            gibbs_frames(
                stack[-1],
                flat[0],
                n_gibbs,
                rng,
                hidden_noise=hidden_noise,
                observed_mask=clamp,
                sample_visibles=sample_visibles,
                n_mean_field=n_mean_field,
            )
        ]
        for rbms in stack[-2::-1]:
            flat.insert(0, rbms.visible_mean(flat[0]))
        return [ops.reshape(v, (*shape[:2], -1)) for v in flat]

    ops = layers[0].ops
    if observed is None:
        level = len(layers) - 1 if scheme == TOP_LAYER else 0
        drift = None
        for step in range(n_steps):
            stack = history.frame_rbms(
                None if context is None else context[:, step, ...]
            )
            if hidden_drift:
                drift = _drift_step(drift, stack[-1].hidden_bias, rng, hidden_drift)
                stack[-1].hidden_bias = stack[-1].hidden_bias + drift[1]
            start = history.previous(level)
            if start_jitter:
                start = start + start_jitter * rng.standard_normal(
                    start.shape[1:], dtype=start.dtype
                )
            values = draw(start, stack, None)
            yield step, values[0]
            history.push(values, stack)
        return
    yield from _fill(
        layers,
        rng,
        draw,
        observed,
        n_steps,
        chain_context=chain_context,
        n_chains=n_chains,
        n_particles=n_particles,
        start_jitter=start_jitter,
        offset_shrinkage=offset_shrinkage,
        observation_gain=observation_gain,
    )


def _drift_step(drift, like, rng, std, frames=None):
    """The next value of a smooth random offset of the hidden biases.

    Two first-order low-pass filters in a row (``a = exp(-1 / frames)``,
    default :data:`DRIFT_FRAMES`) turn white noise into a process of
    standard deviation ``std`` whose correlation decays over about
    ``frames`` frames and whose steps are small and smooth: ``u`` is a
    unit-variance Ornstein-Uhlenbeck process, ``z`` its low-pass.
    ``drift`` is the state ``(u, z)``, None at the start (both drawn from
    their stationary spread); ``like`` gives the shape and dtype.  Returns
    the next ``(u, z)``; ``z`` is the offset.
    """
    frames = DRIFT_FRAMES if frames is None else frames
    a = math.exp(-1.0 / frames)
    # z's variance is (1 - a)^2 gain^2 std^2 (1 + a^2) / (1 - a^2)^2: std^2
    gain = (1 + a) / math.sqrt(1 + a * a)
    shape, dtype = like.shape, like.dtype
    if drift is None:
        u = rng.standard_normal(shape, dtype=dtype)
        return u, std * rng.standard_normal(shape, dtype=dtype)
    u, z = drift
    u = a * u + math.sqrt(1 - a * a) * rng.standard_normal(shape, dtype=dtype)
    z = a * z + (1 - a) * gain * std * u
    return u, z


def _fill(
    layers,
    rng,
    draw,
    observed,
    n_steps,
    *,
    chain_context,
    n_chains,
    n_particles,
    start_jitter,
    offset_shrinkage,
    observation_gain,
):
    """The fill-in loop of :func:`run_online`: every sequence, every step.

    Which sequences have a frame with a missing entry at a step is known on
    the host: a step where none has is not drawn, only pushed; otherwise
    every sequence draws, a frame with nothing missing being clamped whole
    (it comes back unchanged, its offset correction being zero where nothing
    is missing), and only groups of particles whose frame has a missing
    entry are resampled.
    """
    ops = layers[0].ops
    X, missing, sequences = observed.X, observed.missing, observed.sequences
    starts, lengths = sequences.starts, sequences.lengths
    n_steps = int(lengths.max(initial=0)) if n_steps is None else n_steps
    amplify = _amplifies(observation_gain)
    offsets = None
    if offset_shrinkage is not None:
        offsets = Offsets(
            n_chains, len(starts), layers[0], offset_shrinkage, dtype=X.dtype
        )
    row_has_missing = to_numpy(ops.any(missing, axis=1))
    identity = ops.arange(n_chains, dtype=ops.int64)[:, None]
    history = None
    for step in range(n_steps):
        rows = starts + np.minimum(step, lengths - 1)
        drawn = row_has_missing[rows] & (lengths > step)
        frame_missing = ops.take(missing, rows, axis=0)
        frames = ops.take(X, rows, axis=0)
        context = None
        if observed.context is not None:
            context = ops.take(observed.context, rows, axis=0)
        shape = (n_chains, *frames.shape)
        clamp = ops.broadcast_to(~frame_missing, shape)
        current = ops.broadcast_to(frames, shape)
        if history is None:
            # the first frame's context is its past's (the chains' own, else)
            past_context = chain_context
            if context is not None:
                past_context = ops.broadcast_to(context, (n_chains, *context.shape))
            if drawn.any():
                # No past: the frame stands in for it, and the fill is
                # repeated with the latest fill as the past.
                for _ in range(FIRST_FRAME_ROUNDS):
                    own_past = History.from_frames(
                        layers, current[:, :, None, :], past_context
                    )
                    current = draw(current, own_past.frame_rbms(context), clamp)[0]
            history = History.from_frames(layers, current[:, :, None, :], past_context)
            yield step, current
            continue
        # with a context of their own the chains' every observation is
        # evidence; otherwise only frames to draw tell particles apart
        weighed = drawn if chain_context is None else lengths > step
        if n_particles > 1 and weighed.any():
            some = _ActiveSequences(ops, weighed, n_chains)
            chains = _ancestors(
                some.stack(history.frame_rbms(context)),
                some.frames(frames),
                some.frames(~frame_missing),
                n_particles,
                rng,
            )
            chains = some.put_back(chains, ops.broadcast_to(identity, shape[:2]))
            history.reorder(chains)
            if offsets is not None:
                offsets.reorder(chains)
        stack = history.frame_rbms(context)
        prediction = None
        if offsets is not None or amplify:
            alive = _ActiveSequences(ops, lengths > step, n_chains)
            prediction = stacked_prediction(alive.stack(stack), PREDICTION_STEPS)
            prediction = ops.reshape(prediction, (n_chains, -1, shape[-1]))
            prediction = alive.put_back(prediction, current)
        if offsets is not None and step >= layers[0].n_lags:
            offsets.update(prediction, frames, ~frame_missing)
        if drawn.any():
            seen = frames
            if amplify:
                seen = _amplified(frames, prediction, observation_gain)
            start = ops.where(frame_missing, history.previous(0), seen)
            if start_jitter:
                start = start + start_jitter * rng.standard_normal(
                    start.shape, start.dtype
                )
            some = _ActiveSequences(ops, drawn, n_chains)
            new = draw(some.take(start), some.stack(stack), some.take(clamp))[0]
            current = some.put_back(new, current)
            if amplify:
                current = ops.where(frame_missing, current, frames)
            if offsets is not None:
                current = offsets.corrected(current, frame_missing)
        yield step, current
        history.push([current], stack)


class _ActiveSequences:
    """The sequences of a step that need work: gathered, worked on, put back.

    A block of sequences of different lengths, or with frames to fill at
    different steps, works on those that need it only.  Gathers alone, no
    scatter (which the array API lacks): the results go back among the
    others' values by one more gather.

    Parameters
    ----------
    ops : module or ArrayOps
    mask : ndarray of bool of shape (n_sequences,)
        The sequences that need work (numpy).
    n_chains : int
    """

    def __init__(self, ops, mask, n_chains):
        self._ops = ops
        self.every = bool(mask.all())
        self.which = np.flatnonzero(mask)
        n_sequences = len(mask)
        # chain-major rows of the frame RBMs, as History.frame_rbms has them
        self._rows = (np.arange(n_chains)[:, None] * n_sequences + self.which).ravel()
        # sequence s is column where[s] of [the gathered values | the others']
        self._where = np.arange(len(self.which), len(self.which) + n_sequences)
        self._where[self.which] = np.arange(len(self.which))

    def stack(self, stack):
        """The frame RBMs of the sequences that need work."""
        return stack if self.every else [rbms.take(self._rows) for rbms in stack]

    def take(self, array):
        """Their part of an array of shape ``(n_chains, n_sequences, ...)``."""
        return array if self.every else self._ops.take(array, self.which, axis=1)

    def frames(self, array):
        """Their part of an array of shape ``(n_sequences, ...)``."""
        return array if self.every else self._ops.take(array, self.which, axis=0)

    def put_back(self, values, others):
        """``values`` (theirs) among ``others`` (everyone's), along axis 1."""
        if self.every:
            return values
        ops = self._ops
        return ops.take(ops.concatenate((values, others), axis=1), self._where, axis=1)


def _amplifies(gain):
    """Whether ``observation_gain`` changes anything (anything but the number 1)."""
    return not (isinstance(gain, Real) and gain == 1)


def _amplified(frames, prediction, gain):
    """``prediction + gain * (frames - prediction)``: the surprise, ``gain`` times.

    What the hidden units see of the observed channels with
    ``observation_gain`` (:func:`run_online`); ``frames`` is broadcast over
    the chains of ``prediction``.
    """
    return prediction + gain * (frames - prediction)


def collect_fills(run, sequences, reduce):
    """The frames of fill-in steps, back in the long format of the data.

    Parameters
    ----------
    run : iterator of (step, frames)
        :func:`run_online`'s fill-in.
    sequences : Sequences
    reduce : callable
        ``reduce(frames)`` turns one step's frames, shape ``(n_chains,
        n_sequences, n_features)``, into what is kept of them, shape ``(k,
        n_sequences, n_features)`` (e.g. the mean of each draw's particles).

    Returns
    -------
    fills : ndarray of shape (k, n_frames, n_features)
        Row ``starts[s] + t`` holds step ``t`` of sequence ``s``.
    """
    kept = [reduce(frames) for _, frames in run]
    ops = array_ops(kept[0])
    n_sequences = len(sequences.starts)
    index = np.empty(sequences.n_frames, dtype=np.int64)
    for s, (start, length) in enumerate(
        zip(sequences.starts, sequences.lengths, strict=True)
    ):
        index[start : start + length] = np.arange(length) * n_sequences + s
    steps = ops.stack(kept, axis=1)
    steps = ops.reshape(steps, (steps.shape[0], -1, steps.shape[-1]))
    return ops.take(steps, index, axis=1)
