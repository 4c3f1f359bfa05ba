"""Advancing sequences frame by frame from their own past: generation and fill-in.

:meth:`ConditionalRBM.sample`, :meth:`StackedCRBM.sample` and
:class:`~sklearn_crbm.impute.CRBMImputer` all call :func:`run_online`, with
one layer or a stack:

- generation: nothing observed, every frame of every sequence drawn from a
  seed history;
- fill-in: the observed channels of every frame clamped, several chains per
  sequence (``n_draws * n_particles``), particles resampled before every
  frame, and a sequence's first frame filled from itself as its own past.

:class:`History` keeps the recent past of every chain at every layer and
gives the dynamic biases of the next frame.
"""

from dataclasses import dataclass
from numbers import Real

import numpy as np
from sklearn.utils._array_api import _convert_to_numpy

from ._crbm_math import (
    BINARY,
    dynamic_biases,
    gibbs_frames,
    hidden_probabilities,
    observed_log_likelihood,
    sequence_hidden_probabilities,
    stacked_gibbs_frames,
    stacked_prediction,
    visible_means,
)
from .utils._array_api import copy_array
from .utils._sequences import Sequences

# How a stack draws a frame (``scheme`` of run_online).  With one layer the two
# are the same alternating Gibbs run of that layer.
TOP_LAYER = "top_layer"
"""The original two-level generation (Taylor's ``gen2.m``): Gibbs sampling in
the top layer given its own past, then one deterministic pass down (each
layer's visible means given its own past).  Every layer's past is the values
that pass produced.  Nothing can be clamped: the data sit at the bottom."""
WHOLE_STACK = "whole_stack"
"""Every Gibbs iteration goes up the stack and down again
(:func:`~sklearn_crbm._crbm_math.stacked_gibbs_frames`), so the state of the
chain is the frame itself and its observed channels can be clamped.  The
upper layers' past is the final frame passed up (hidden probabilities)."""

# Rounds of "fill, then use the fill as its own past" for the first frame of a
# sequence in fill-in, which has no past frames.
FIRST_FRAME_ROUNDS = 3
# Mean-field iterations of the one-step prediction that weights particles.
PREDICTION_STEPS = 10


class History:
    """The recent past of chains of sequences at every layer of a model.

    Parameters
    ----------
    layers : list of CRBMParameters
        Bottom first.
    windows : list of ndarray
        One per layer, of shape ``(n_chains, n_sequences, n_slots,
        n_visible)`` with ``n_slots = max(n_lags, 1)``: the layer's last
        visible values, most recent first (the frames for the bottom layer,
        the layer below's hidden probabilities above it).
    """

    def __init__(self, layers, windows):
        self.layers = layers
        self.windows = windows
        self._ops = layers[0].ops
        # the static biases of a model that does not change while it runs
        self._static = [
            self._ops.concatenate((p.visible_bias, p.hidden_bias)) for p in layers
        ]

    @classmethod
    def from_frames(cls, layers, frames):
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
        """
        n_chains, n_sequences = frames.shape[:2]
        ops = layers[0].ops
        windows = []
        values = frames
        for k, params in enumerate(layers):
            n_frames = values.shape[2]
            n_slots = max(params.n_lags, 1)
            picks = np.maximum(np.arange(n_frames - 1, n_frames - 1 - n_slots, -1), 0)
            windows.append(ops.ascontiguousarray(ops.take(values, picks, axis=2)))
            if k + 1 < len(layers):
                flat = ops.reshape(values, (-1, values.shape[3]))
                lengths = np.full(n_chains * n_sequences, n_frames, dtype=np.intp)
                sequences = Sequences(
                    starts=np.arange(0, flat.shape[0], n_frames, dtype=np.intp),
                    lengths=lengths,
                    ids=np.arange(len(lengths)),
                )
                hidden = sequence_hidden_probabilities(params, flat, sequences)
                hidden = ops.reshape(hidden, (n_chains, n_sequences, n_frames, -1))
                values = hidden[:, :, min(params.n_lags, n_frames - 1) :, ...]
        return cls(layers, windows)

    def select(self, sequences):
        """The past of some sequences only (for a block of work)."""
        ops = self._ops
        return History(
            self.layers, [ops.take(w, sequences, axis=1) for w in self.windows]
        )

    def previous(self, level, sequences):
        """The last values at ``level`` of ``sequences``: (n_chains, n, n_visible).

        ``sequences`` (here and below) is an index array, or a slice.
        """
        return self.windows[level][:, sequences, 0, ...]

    def biases(self, sequences):
        """Every layer's dynamic biases for the next frame of ``sequences``.

        Returns a list of arrays of shape ``(n_chains, len(sequences),
        n_visible + n_hidden)``: the visible biases, then the hidden ones.
        """
        biases = []
        for params, window, static in zip(
            self.layers, self.windows, self._static, strict=True
        ):
            ops = self._ops
            past = window[:, sequences, ...]
            n_chains, n_rows = past.shape[:2]
            flat = ops.reshape(past, (n_chains * n_rows, -1))
            flat = flat[:, : params.n_lags * params.n_features]
            both = ops.empty((n_chains, n_rows, static.shape[0]), params.dtype)
            rows = ops.reshape(both, (flat.shape[0], -1))
            dynamic_biases(params, flat, out=rows, static=static)
            biases.append(both)
        return biases

    def push(self, values, sequences, biases):
        """Append a new frame of ``sequences`` at every layer.

        ``values`` holds the frame's value at the lowest layers, bottom
        first (at least the frame itself); the layers above get the hidden
        probabilities of the layer below, given ``biases`` (from
        :meth:`biases` for this frame).
        """
        ops = self._ops
        if len(values) < len(self.layers):
            values = list(values)
        for k in range(len(values), len(self.layers)):
            params = self.layers[k - 1]
            below = values[-1]
            hidden_bias = biases[k - 1][..., params.n_features :]
            flat = hidden_probabilities(
                params,
                ops.reshape(below, (-1, params.n_features)),
                ops.reshape(hidden_bias, (-1, params.n_components)),
            )
            values.append(ops.reshape(flat, (*below.shape[:2], -1)))
        for window, value in zip(self.windows, values, strict=True):
            # a copy: the array API leaves overlapping assignment undefined
            window[:, sequences, 1:, ...] = copy_array(window[:, sequences, :-1, ...])
            window[:, sequences, 0, ...] = value

    def reorder(self, chains, sequences):
        """Give chain ``i`` of each of ``sequences`` the past of chain ``chains[i]``.

        ``chains`` has shape ``(n_chains, len(sequences))``; off numpy,
        ``sequences`` is every sequence (a slice).
        """
        if self._ops is not np:
            self.windows = [_take_chains(self._ops, w, chains) for w in self.windows]
            return
        for window in self.windows:
            window[:, sequences] = window[chains, sequences[None, :]]


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
    """

    X: np.ndarray
    missing: np.ndarray
    sequences: Sequences


class Offsets:
    """Each chain's systematic one-step error per sequence and channel.

    A model that fills a sequence from its own past drifts towards its own
    typical values (a slow posture channel towards the training posture);
    while a channel is observed, its one-step residual ``r_t = x_t -
    x_hat_t`` (``x_hat_t`` the chain's mean-field prediction of the frame
    from its past, :func:`~sklearn_crbm._crbm_math.stacked_prediction`)
    shows that error.  The correction of a missing entry is the posterior
    mean of a constant offset ``d`` behind the residuals, ``r_t = d +
    noise``, with a prior worth ``shrinkage`` frames of zero residual:
    ``sum(r) / (n + shrinkage)`` over the ``n`` frames of the sequence in
    which the channel was observed so far (counted from the model's order
    on: earlier frames have an edge-padded past).  Binary visibles' fills
    are probabilities, and stay in [0, 1].

    Parameters
    ----------
    n_chains, n_sequences : int
    bottom : CRBMParameters
        The bottom layer (its number of features and visible type).
    shrinkage : float
    dtype : dtype
    """

    def __init__(self, n_chains, n_sequences, bottom, shrinkage, *, dtype):
        self._ops = ops = bottom.ops
        self.sums = ops.zeros((n_chains, n_sequences, bottom.n_features), dtype)
        self.counts = ops.zeros((n_sequences, bottom.n_features), dtype)
        self.shrinkage = shrinkage
        self.binary = bottom.visible_type == BINARY

    def update(self, prediction, sequences, frames, observed):
        """Add the residuals of ``frames`` (one per sequence) where ``observed``.

        ``prediction`` is every chain's one-step prediction of the frames
        (:func:`_one_step_predictions`), of shape ``(n_chains, *frames.shape)``.
        """
        ops = self._ops
        self.sums[:, sequences, ...] += ops.where(observed, frames - prediction, 0)
        self.counts[sequences, ...] += ops.astype(observed, self.counts.dtype)

    def corrected(self, frames, sequences, missing):
        """Every chain's ``frames`` of ``sequences``, corrected where ``missing``."""
        ops = self._ops
        # a channel never observed has a zero sum; the floor spares 0 / 0
        denominator = ops.maximum(self.counts[sequences, ...] + self.shrinkage, 1)
        frames = frames + ops.where(
            missing, self.sums[:, sequences, ...] / denominator, 0
        )
        return ops.clip(frames, 0, 1) if self.binary else frames

    def reorder(self, chains, sequences):
        """The chains' offsets follow their pasts (:meth:`History.reorder`)."""
        if self._ops is not np:
            self.sums = _take_chains(self._ops, self.sums, chains)
            return
        self.sums[:, sequences] = self.sums[chains, sequences[None, :]]


def run_online(
    layers,
    rng,
    *,
    history=None,
    n_steps=None,
    observed=None,
    n_chains=1,
    n_particles=1,
    n_gibbs=30,
    scheme=WHOLE_STACK,
    start_jitter=0.0,
    hidden_noise=0.0,
    sample_visibles=False,
    offset_shrinkage=None,
    observation_gain=1.0,
):
    """Draw frames one after another, each given the chains' own past.

    For every frame, every chain starts a Gibbs run at its previous frame
    (plus ``N(0, start_jitter^2)`` noise), with the frame's observed
    channels clamped, and the frame's result joins the chain's past.

    Parameters
    ----------
    layers : list of CRBMParameters
        The model, bottom layer first.
    rng : numpy.random.Generator
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
    offset_shrinkage : float, default=None
        Fill-in only.  ``None``: no correction.  A number ``lam >= 0``: each
        chain's drawn entries are shifted by the chain's
        :class:`Offsets` correction (its mean one-step residual of that
        channel in that sequence so far, shrunk by ``lam`` frames).
    observation_gain : float or ndarray of shape (n_features,), default=1.0
        Fill-in only.  The hidden units of a chain see each observed channel
        at ``x_hat + observation_gain * (x - x_hat)`` (a gain per channel if
        an array) instead of at its value
        ``x``, ``x_hat`` being the chain's one-step prediction of the frame
        from its past (:func:`_one_step_predictions`): the observed
        channels' surprise counts ``observation_gain`` times.  The frame
        keeps the observed values.  ``1``: the model's own conditional.  A
        sequence's first frame (no past) is filled without it.

    Yields
    ------
    step : int
    sequences : ndarray of int
        The sequences that have a frame at this step.
    drawn : ndarray of int
        Indices into ``sequences`` of the frames that were drawn.
    frames : ndarray of shape (n_chains, len(drawn), n_features)
        Every chain's draw of those frames (observed entries included).

    Notes
    -----
    In fill-in on an array API namespace other than numpy
    (:func:`_fill_on_device`), every sequence advances at every step, so that
    nothing is scattered on the device: ``sequences`` and ``drawn`` are all
    sequences, a sequence that has ended repeats its last frame (a draw to
    ignore), and a frame without a missing entry comes back as it is.
    """
    if scheme not in (TOP_LAYER, WHOLE_STACK):
        raise ValueError(f"unknown scheme {scheme!r}")
    stacked = len(layers) > 1
    if stacked and scheme == TOP_LAYER and observed is not None:
        raise ValueError("a stack can clamp observed channels only with whole_stack")
    if stacked and scheme == WHOLE_STACK and sample_visibles:
        raise ValueError("sample_visibles needs one layer or the top_layer scheme")

    def draw(start, biases, clamp):
        """One Gibbs run per (chain, frame) pair; the frame's lowest values."""
        shape = start.shape
        visible_biases, hidden_biases = _split(layers, biases)
        start = ops.reshape(start, (-1, shape[-1]))
        clamp = None if clamp is None else ops.reshape(clamp, (-1, shape[-1]))
        if stacked and scheme == WHOLE_STACK:
            frame = stacked_gibbs_frames(
                layers,
                start,
                visible_biases,
                hidden_biases,
                n_gibbs,
                rng,
                hidden_noise=hidden_noise,
                observed_mask=clamp,
            )
            return [ops.reshape(frame, shape)]
        values = [
            gibbs_frames(
                layers[-1],
                start,
                visible_biases[-1],
                hidden_biases[-1],
                n_gibbs,
                rng,
                hidden_noise=hidden_noise,
                observed_mask=clamp,
                sample_visibles=sample_visibles,
            )
        ]
        below = zip(layers[-2::-1], visible_biases[-2::-1], strict=True)
        for params, visible_bias in below:
            values.insert(0, visible_means(params, values[0], visible_bias))
        return [ops.reshape(v, (*shape[:2], -1)) for v in values]

    ops = layers[0].ops
    level = len(layers) - 1 if scheme == TOP_LAYER else 0
    if observed is None:
        sequences = np.arange(history.windows[0].shape[1])
        every = slice(None)  # all sequences: basic indexing, no gather
        for step in range(n_steps):
            biases = history.biases(every)
            start = history.previous(level, every)
            if start_jitter:
                start = start + start_jitter * rng.standard_normal(
                    start.shape[1:], dtype=start.dtype
                )
            values = draw(start, biases, None)
            yield step, sequences, sequences, values[0]
            history.push(values, every, biases)
        return

    X, missing, all_sequences = observed.X, observed.missing, observed.sequences
    amplify = _amplifies(observation_gain)
    starts, lengths = all_sequences.starts, all_sequences.lengths
    n_features = X.shape[1]
    n_steps = int(lengths.max(initial=0)) if n_steps is None else n_steps
    offsets = None
    if offset_shrinkage is not None:
        offsets = Offsets(
            n_chains, len(starts), layers[0], offset_shrinkage, dtype=X.dtype
        )
    if ops is not np:
        yield from _fill_on_device(
            layers,
            rng,
            draw,
            history,
            observed,
            n_steps,
            n_chains=n_chains,
            n_particles=n_particles,
            offsets=offsets,
            start_jitter=start_jitter,
            observation_gain=observation_gain,
        )
        return
    for step in range(n_steps):
        sequences = np.flatnonzero(lengths > step)
        rows = starts[sequences] + step
        frame_missing = missing[rows]
        drawn = np.flatnonzero(frame_missing.any(axis=1))
        frames = X[rows]
        current = np.broadcast_to(frames, (n_chains, *frames.shape)).copy()
        clamp = np.broadcast_to(
            ~frame_missing[drawn], (n_chains, len(drawn), n_features)
        )
        if history is None:
            # No past: the frame stands in for it, and the fill is repeated
            # with the latest fill as the past.
            for _ in range(FIRST_FRAME_ROUNDS if len(drawn) else 0):
                start = current[:, drawn]
                own_past = History.from_frames(layers, start[:, :, None])
                biases = own_past.biases(np.arange(len(drawn)))
                current[:, drawn] = draw(start, biases, clamp)[0]
            history = History.from_frames(layers, current[:, :, None])
            yield step, sequences, drawn, current[:, drawn]
            continue
        if n_particles > 1 and len(drawn):
            chains = _ancestors(
                history,
                sequences[drawn],
                frames[drawn],
                ~frame_missing[drawn],
                n_particles,
                rng,
            )
            history.reorder(chains, sequences[drawn])
            if offsets is not None:
                offsets.reorder(chains, sequences[drawn])
        biases = history.biases(sequences)
        prediction = None
        if offsets is not None or amplify:
            prediction = _one_step_predictions(layers, biases, frames.shape)
        if offsets is not None and step >= layers[0].n_lags:
            offsets.update(prediction, sequences, frames, ~frame_missing)
        if len(drawn):
            seen = frames[drawn]
            if amplify:
                seen = _amplified(seen, prediction[:, drawn], observation_gain)
            start = np.where(
                frame_missing[drawn], history.previous(0, sequences[drawn]), seen
            )
            if start_jitter:
                start += start_jitter * rng.standard_normal(start.shape, start.dtype)
            current[:, drawn] = draw(start, [b[:, drawn] for b in biases], clamp)[0]
            if amplify:
                current[:, drawn] = np.where(
                    frame_missing[drawn], current[:, drawn], frames[drawn]
                )
            if offsets is not None:
                current[:, drawn] = offsets.corrected(
                    current[:, drawn], sequences[drawn], frame_missing[drawn]
                )
        yield step, sequences, drawn, current[:, drawn]
        history.push([current], sequences, biases)


def _fill_on_device(
    layers,
    rng,
    draw,
    history,
    observed,
    n_steps,
    *,
    n_chains,
    n_particles,
    offsets,
    start_jitter,
    observation_gain,
):
    """The fill-in loop of :func:`run_online` off numpy: every sequence, every step.

    The same procedure as the numpy loop, written without scattering into
    device arrays: every sequence draws every step (a sequence that has ended
    repeats its last frame), a frame with nothing missing is clamped whole
    and comes back unchanged (its offset correction is zero where nothing is
    missing), and only groups of particles whose frame has a missing entry
    are resampled.  The numpy loop skips those draws, so the random streams
    differ; the fills agree in distribution.
    """
    ops = layers[0].ops
    X, missing, sequences = observed.X, observed.missing, observed.sequences
    starts, lengths = sequences.starts, sequences.lengths
    every = slice(None)
    amplify = _amplifies(observation_gain)
    all_sequences = np.arange(len(starts))
    has_missing = _convert_to_numpy(ops.any(missing, axis=1), ops.xp)
    for step in range(n_steps):
        rows = starts + np.minimum(step, lengths - 1)
        frame_missing = ops.take(missing, rows, axis=0)
        frames = ops.take(X, rows, axis=0)
        shape = (n_chains, *frames.shape)
        clamp = ops.broadcast_to(~frame_missing, shape)
        current = ops.broadcast_to(frames, shape)
        if history is None:
            for _ in range(FIRST_FRAME_ROUNDS):
                own_past = History.from_frames(layers, current[:, :, None, :])
                current = draw(current, own_past.biases(every), clamp)[0]
            history = History.from_frames(layers, current[:, :, None, :])
            yield step, all_sequences, all_sequences, current
            continue
        if n_particles > 1:
            chains = _ancestors(
                history, every, frames, ~frame_missing, n_particles, rng
            )
            drawn = ops.asarray(has_missing[rows] & (lengths > step))
            chains = ops.where(
                drawn[None, :], chains, ops.arange(n_chains, dtype=ops.int64)[:, None]
            )
            history.reorder(chains, every)
            if offsets is not None:
                offsets.reorder(chains, every)
        biases = history.biases(every)
        prediction = None
        if offsets is not None or amplify:
            prediction = _one_step_predictions(layers, biases, frames.shape)
        if offsets is not None and step >= layers[0].n_lags:
            offsets.update(prediction, every, frames, ~frame_missing)
        seen = frames
        if amplify:
            seen = _amplified(frames, prediction, observation_gain)
        start = ops.where(frame_missing, history.previous(0, every), seen)
        if start_jitter:
            start = start + start_jitter * rng.standard_normal(start.shape, start.dtype)
        current = draw(start, biases, clamp)[0]
        if amplify:
            current = ops.where(frame_missing, current, frames)
        if offsets is not None:
            current = offsets.corrected(current, every, frame_missing)
        yield step, all_sequences, all_sequences, current
        history.push([current], every, biases)


def _ancestors(history, sequences, frames, observed, n_particles, rng):
    """Resample each group of particles by how well they explain the observed data.

    A particle's weight is the likelihood of the frame's observed channels
    under its own one-step prediction
    (:func:`~sklearn_crbm._crbm_math.observed_log_likelihood`); each group is
    resampled (systematic resampling).  Returns the ancestors, of shape
    ``(n_chains, n_sequences)``, as :meth:`History.reorder` takes them.
    """
    layers = history.layers
    ops = layers[0].ops
    n_chains = history.windows[0].shape[0]
    n_groups = n_chains // n_particles
    n_sequences, n_features = frames.shape
    prediction = stacked_prediction(
        layers, *_split(layers, history.biases(sequences)), PREDICTION_STEPS
    )
    log_weights = observed_log_likelihood(
        layers[0],
        prediction,
        ops.reshape(
            ops.broadcast_to(frames, (n_chains, *frames.shape)), (-1, n_features)
        ),
        ops.reshape(
            ops.broadcast_to(observed, (n_chains, *observed.shape)), (-1, n_features)
        ),
    )
    log_weights = ops.reshape(log_weights, (n_groups, n_particles, n_sequences))
    log_weights = log_weights - ops.max(log_weights, axis=1, keepdims=True)
    cumulative = ops.cumsum(ops.exp(log_weights), axis=1)
    cumulative = cumulative / cumulative[:, -1:, ...]
    positions = (
        rng.random((n_groups, 1, n_sequences))
        + ops.arange(n_particles, dtype=ops.float64)[:, None]
    ) / n_particles
    # ancestor of particle i: how many cumulative weights lie below position i
    below = cumulative[:, None, :, :] < positions[:, :, None, :]
    ancestors = ops.sum(ops.astype(below, ops.int64), axis=2)
    ancestors = ops.minimum(ancestors, n_particles - 1)
    chains = (
        ancestors + (ops.arange(n_groups, dtype=ops.int64) * n_particles)[:, None, None]
    )
    return ops.reshape(chains, (n_chains, n_sequences))


def _take_chains(ops, array, chains):
    """``array[chains[i, s], s]`` for every chain ``i`` and sequence ``s``."""
    n_chains, n_sequences = chains.shape
    flat = ops.reshape(array, (n_chains * n_sequences, -1))
    index = chains * n_sequences + ops.arange(n_sequences, dtype=ops.int64)
    return ops.reshape(ops.take(flat, ops.reshape(index, (-1,)), axis=0), array.shape)


def _one_step_predictions(layers, biases, shape):
    """Every chain's mean-field prediction of the next frame from its past.

    ``biases`` from :meth:`History.biases` for ``shape[0]`` sequences of
    ``shape[1]`` features; returns shape ``(n_chains, *shape)``
    (:func:`~sklearn_crbm._crbm_math.stacked_prediction`).
    """
    ops = layers[0].ops
    prediction = stacked_prediction(layers, *_split(layers, biases), PREDICTION_STEPS)
    return ops.reshape(prediction, (-1, *shape))


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


def _split(layers, biases):
    """:meth:`History.biases` as two lists of 2-D arrays: visible, hidden."""
    visible, hidden = [], []
    for params, both in zip(layers, biases, strict=True):
        both = params.ops.reshape(both, (-1, both.shape[-1]))
        visible.append(both[:, : params.n_features])
        hidden.append(both[:, params.n_features :])
    return visible, hidden
